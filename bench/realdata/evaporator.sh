#!/usr/bin/env bash
# Real-data benchmark: four-stage evaporator (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
source "$here/mimo_compare.sh"
evap="$shared/daisy_evaporator/evaporator.dat"
[ -f "$evap" ] || skip "evaporator" "$evap not available"
echo "== evaporator (DaISy, 3 x 3; no sampling period given: Ts = 1 sample): estimation on the first 70 % (4 410"
echo "   samples), validation on the last 30 % (1 895), means removed from each record"
head -4410 "$evap" > evap_est.dat
tail -1895 "$evap" > evap_val.dat
mimo_compare evap evap_est.dat evap_val.dat "--ts 1 --input 1 --input 2 --input 3 --detrend mean" "4 5 6" 10
exit $fail
