#!/usr/bin/env bash
# Real-data benchmark: heat exchanger (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
exchanger="$shared/daisy_heat_exchanger/exchanger.dat"
[ -f "$exchanger" ] || skip "heat exchanger" "$exchanger not available"
echo "== heat exchanger (DaISy): flow -> outlet temperature, linear CT models; validation fit on the last 1000 samples"
head -3000 "$exchanger" > exchanger_est.dat
tail -1000 "$exchanger" > exchanger_val.dat
x="--ts 1 --input 2 --output 3 --detrend linear"
"$ctid" fit exchanger_est.dat $x --method srivc --nb 1 --nf 1 --json exchanger_srivc.json --force >/dev/null
"$ctid" fit exchanger_est.dat $x --method tfest --nb 2 --nf 2 --json exchanger_tfest.json --report exchanger_tfest.html \
  --force >/dev/null
check "SRIVC [1 1] validation fit %" "$(fit_of exchanger_srivc.json exchanger_val.dat $x)" gt 38
check "tfest [2 2] validation fit %" "$(fit_of exchanger_tfest.json exchanger_val.dat $x)" gt 40
"$ctid" fit exchanger_est.dat $x --method narx --set degree=2 --set ylag=4 --set ulag=4 --set criterion=bic \
  --json exchanger_narx.json --force >/dev/null
check "NARX (degree 2, lags 4, BIC) free-run validation fit %" "$(fit_of exchanger_narx.json exchanger_val.dat $x)" gt 15
exit $fail
