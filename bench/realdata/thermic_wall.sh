#!/usr/bin/env bash
# Real-data benchmark: thermic wall (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
wall="$shared/daisy_thermic_wall/thermic_res_wall.dat"
[ -f "$wall" ] || skip "thermic wall" "$wall not available"
echo "== thermic wall (DaISy): internal and external wall temperatures -> heat flux, MISO SRIVC with a common"
echo "   denominator (Ts not given: 1 s normalised); validation fit on the last 30 %"
head -1176 "$wall" > wall_est.dat
tail -504 "$wall" > wall_val.dat
m="--ts 1 --input 1 --input 2 --output 3 --detrend mean"
"$ctid" fit wall_est.dat $m --method srivc --nf 1 --nb 1,1 --set common_denominator=1 --json wall_11.json --force >/dev/null
"$ctid" fit wall_est.dat $m --method srivc --nf 1 --nb 2,2 --set common_denominator=1 --json wall_12.json \
  --report wall_12.html --force > wall_12.txt
check "strictly proper first order: validation fit %" "$(fit_of wall_11.json wall_val.dat $m)" gt 25
check "with a direct term (nb = 2): validation fit %" "$(fit_of wall_12.json wall_val.dat $m)" gt 80
# Static gains b1/a1 of the two channels: a flux driven by the temperature difference has opposite, equal gains.
check "static gains: |internal + external| / external (0 for a pure temperature difference)" \
  "$(awk '$1 == "u1.b1" { b1 = $3 } $1 == "u2.b1" { b2 = $3 } END { r = (b1 + b2) / b2; print (r < 0 ? -r : r) }' \
     wall_12.txt)" lt 0.1
exit $fail
