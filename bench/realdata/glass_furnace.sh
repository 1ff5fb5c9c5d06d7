#!/usr/bin/env bash
# Real-data benchmark: glass furnace (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
source "$here/mimo_compare.sh"
glass="$shared/daisy_glass_furnace/glassfurnace.dat"
[ -f "$glass" ] || skip "glass furnace" "$glass not available"
echo "== glass furnace (DaISy, 3 inputs x 6 temperatures; no sampling period given: Ts = 1 sample): estimation on"
echo "   the first 70 % (873 samples), validation on the last 30 % (374), means removed from each record"
head -873 "$glass" > glass_est.dat
tail -374 "$glass" > glass_val.dat
mimo_compare glass glass_est.dat glass_val.dat "--ts 1 --input 2 --input 3 --input 4 --detrend mean" "5 6 7 8 9 10" 10
exit $fail
