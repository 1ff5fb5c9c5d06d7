#!/usr/bin/env bash
# Real-data benchmark: industrial dryer (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
source "$here/mimo_compare.sh"
dryer2="$shared/daisy_industrial_dryer/dryer2.dat"
[ -f "$dryer2" ] || skip "industrial dryer" "$dryer2 not available"
echo "== industrial dryer (DaISy): order selection, then fuel flow, fan speed and raw-material flow -> each output,"
echo "   MISO SRIVC with a common first-order denominator; validation fit on the last 267 samples"
head -600 "$dryer2" > dryer2_est.dat
tail -267 "$dryer2" > dryer2_val.dat
"$ctid" order dryer2_est.dat --ts 10 --input 2 --output 5 --detrend mean --nb 1:2 --nf 1:3 --nk 0:3 --rank yic \
  > dryer2_order.txt
check "order selection, fuel -> dry bulb: best [nb nf nk] by YIC is [1 1 0] (rank-1 line)" \
  "$(awk '$1 == 1 { print ($2 == 1 && $3 == 1 && $4 == 0) ? 1 : 0 }' dryer2_order.txt)" gt 0.5
i="--ts 10 --input 2 --input 3 --input 4 --detrend mean"
for y in 5 6 7; do
  "$ctid" fit dryer2_est.dat $i --output $y --method srivc --nf 1 --set common_denominator=1 --json dryer2_$y.json \
    --report dryer2_$y.html --force >/dev/null
done
check "dry bulb temperature (column 5): validation fit %" "$(fit_of dryer2_5.json dryer2_val.dat $i --output 5)" gt 30
check "wet bulb temperature (column 6): validation fit %" "$(fit_of dryer2_6.json dryer2_val.dat $i --output 6)" gt 25
check "moisture content (column 7): validation fit % (no linear model generalises)" \
  "$(fit_of dryer2_7.json dryer2_val.dat $i --output 7)" lt 0

echo "== the same, initial state of the validation part estimated (least squares on it; MATLAB compare's default):"
echo "   MISO SRIVC per output, MIMO ssest (order by BIC over 1..6 on the estimation part), discrete N4SID (MOESP + logm)"
read -r s5 < <(fits_of dryer2_5.json dryer2_val.dat $i --output 5)
read -r s6 < <(fits_of dryer2_6.json dryer2_val.dat $i --output 6)
read -r s7 < <(fits_of dryer2_7.json dryer2_val.dat $i --output 7)
echo "  MISO SRIVC: $s5 $s6 $s7"
ssest_and_n4sid dryer2 dryer2_est.dat dryer2_val.dat "$i" "5 6 7" 6
check "ssest order chosen by BIC" "$nx" gt 1
for k in 5 6 7; do
  m=${ss[$((k - 5))]}; eval "s=\$s$k"
  check "output $k: ssest validation fit minus MISO SRIVC's (at least as good)" "$(awk -v a="$m" -v b="$s" 'BEGIN { print a - b }')" gt -0.5
done
exit $fail
