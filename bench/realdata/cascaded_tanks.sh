#!/usr/bin/env bash
# Real-data benchmark: cascaded tanks (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
tanks="$shared/cascaded_tanks/dataBenchmark.csv"
[ -f "$tanks" ] || skip "cascaded tanks" "$tanks not available"
echo "== cascaded tanks (nonlinearbenchmark.org): linear CT models and a NARX model; test-record RMSE (V)"
e="--ts 4 --input uEst --output yEst --detrend mean"
v="--ts 4 --input uVal --output yVal --detrend mean"
"$ctid" fit "$tanks" $e --method srivc --nb 1 --nf 2 --json tanks_srivc.json --report tanks_srivc.html --force >/dev/null
"$ctid" fit "$tanks" $e --method tfest --nb 1 --nf 3 --json tanks_tfest.json --force >/dev/null
check "SRIVC [1 2] test RMSE (reference: best linear approximation 0.75)" \
  "$(awk -v m="$(mse_of tanks_srivc.json "$tanks" $v)" 'BEGIN { printf "%.4f", sqrt(m) }')" lt 0.75
check "tfest [1 3] test RMSE" "$(awk -v m="$(mse_of tanks_tfest.json "$tanks" $v)" 'BEGIN { printf "%.4f", sqrt(m) }')" lt 0.75
"$ctid" fit "$tanks" $e --method narx --set degree=3 --set ylag=3 --set ulag=3 --set criterion=bic --json tanks_narx.json \
  --report tanks_narx.html --force >/dev/null
"$ctid" simulate tanks_narx.json "$tanks" --ts 4 --input uVal --detrend mean --out tanks_narx_sim.csv --force >/dev/null
check "NARX (degree 3, lags 3, BIC) free-run test RMSE" "$(rms tanks_narx_sim.csv "$tanks" 4)" lt 0.75
# Grey box: Torricelli-type outflows with free exponents, overflow of both tanks, a sensor offset; no mean
# removed; the test record's state from its first 5 samples only (the benchmark protocol), RMSE over the whole record.
"$ctid" fit "$tanks" --ts 4 --input uEst --output yEst --method greybox --model "$examples/cascaded_tanks_greybox.json" \
  --set max_iterations=1000 --json tanks_greybox.json --report tanks_greybox.html --force | grep -E "^fit:"
check "grey box: test RMSE, state from the first 5 test samples (required <= 0.30; SUBNET 0.30, NLSS2 0.34)" \
  "$(awk -v m="$(mse_of tanks_greybox.json "$tanks" --ts 4 --input uVal --output yVal --initial estimated \
    --initial-samples 5)" 'BEGIN { printf "%.4f", sqrt(m) }')" lt 0.25
exit $fail
