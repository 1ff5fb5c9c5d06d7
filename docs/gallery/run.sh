#!/usr/bin/env bash
# The real-data gallery (docs/gallery.md), run by ctest as `gallery`: every entry identifies models with the
# ctid command line, validates them on held-out data and writes an HTML report. Entries whose data folder is
# absent are skipped. Each checked number must stay within the bound printed next to it, or the run fails.
# Usage: docs/gallery/run.sh CTID_BINARY OUT_DIR SHARED_DATA_DIR EXAMPLES_DATA_DIR
# The F-16 entry runs in Python: CTID_PYTHON names the interpreter and PYTHONPATH must find the ctid package.
set -euo pipefail
ctid="$1"; out="$2"; shared="$3"; examples="$4"
mkdir -p "$out"
cd "$out"
fail=0
check() {  # check NAME VALUE OP BOUND   (OP: lt | gt)
  local ok
  ok=$(awk -v v="$2" -v b="$4" -v op="$3" 'BEGIN { print (op == "lt" ? (v < b) : (v > b)) ? 1 : 0 }')
  if [ "$ok" = 1 ]; then echo "  $1 = $2 (bound: $3 $4)"; else echo "  FAILED: $1 = $2 (bound: $3 $4)"; fail=1; fi
}
fit_of() { "$ctid" validate "$@" | awk '/^fit:/ { print $2; exit }'; }
mse_of() { "$ctid" validate "$@" | awk '/^fit:/ { for (i = 1; i < NF; ++i) if ($i == "MSE") print $(i + 1); exit }'; }
# RMS of (simulated - measured) after removing the measured mean, skipping the first 50 samples:
# rms SIM.csv DATA.csv COLUMN_OF_Y_IN_DATA
rms() {
  awk -F, -v col="$3" 'NR == FNR { if (FNR > 1) { y[FNR - 1] = $col; m += $col; n++ } next }
                       FNR > 1 { s[FNR - 1] = $NF }
                       END { m /= n; for (k = 51; k <= n; ++k) { e = s[k] - (y[k] - m); acc += e * e; c++ } printf "%.6f", sqrt(acc / c) }' "$2" "$1"
}
# RMS of (simulated - measured) as they are (the benchmark protocol), skipping the first SKIP samples:
# rms_raw SIM.csv DATA.csv COLUMN_OF_Y_IN_DATA SKIP
rms_raw() {
  awk -F, -v col="$3" -v skip="$4" 'NR == FNR { if (FNR > 1) y[FNR - 1] = $col; n = FNR - 1; next }
                       FNR > 1 { s[FNR - 1] = $NF }
                       END { for (k = skip + 1; k <= n; ++k) { e = s[k] - y[k]; acc += e * e; c++ } printf "%.7f", sqrt(acc / c) }' "$2" "$1"
}

echo "== hair dryer (DaISy, bundled): SRIVC, tfest and modal functions; validation on the last 30 %"
dryer="$examples/dryer.dat"
head -700 "$dryer" > dryer_est.dat
tail -300 "$dryer" > dryer_val.dat
d="--ts 0.08 --input 1 --output 2 --detrend mean"
"$ctid" fit dryer_est.dat $d --method srivc --nb 2 --nf 2 --nk 2 --json dryer_srivc.json --report dryer_srivc.html --force >/dev/null
"$ctid" fit dryer_est.dat $d --method tfest --nb 2 --nf 2 --nk 2 --json dryer_tfest.json --force >/dev/null
"$ctid" fit dryer_est.dat $d --method modal --nf 2 --nk 2 --set shift_samples=1,2 --set basis=discrete --json dryer_modal.json --force >/dev/null
"$ctid" fit dryer_est.dat $d --method fsf --set T=4 --set n=21 --report dryer_fsf.html --force >/dev/null
check "SRIVC validation fit %" "$(fit_of dryer_srivc.json dryer_val.dat $d)" gt 85
check "tfest validation fit %" "$(fit_of dryer_tfest.json dryer_val.dat $d)" gt 85
check "modal validation fit %" "$(fit_of dryer_modal.json dryer_val.dat $d)" gt 80

winding="$shared/daisy_winding_process/winding.dat"
if [ -f "$winding" ]; then
  echo "== winding process (DaISy): five inputs -> each web tension, MISO SRIVC with a common denominator;"
  echo "   validation fit on the last 30 %"
  head -1750 "$winding" > winding_est.dat
  tail -750 "$winding" > winding_val.dat
  w="--ts 0.1 --input 1 --input 2 --input 3 --input 4 --input 5 --detrend mean"
  for y in 6 7; do
    "$ctid" fit winding_est.dat $w --output $y --method srivc --nf 1 --set common_denominator=1 --json winding_$y.json \
      --force >/dev/null
  done
  check "tension T1 (column 6), first order: validation fit %" "$(fit_of winding_6.json winding_val.dat $w --output 6)" gt 55
  check "tension T3 (column 7), first order: validation fit %" "$(fit_of winding_7.json winding_val.dat $w --output 7)" gt 42
  # Separate first-order denominators (backfitting): T1 converges and validates better; for T3 the correlated
  # reel speeds leave the instrumental-variable matrix singular, which ctid reports (exit 1).
  "$ctid" fit winding_est.dat $w --output 6 --method srivc --nf 1 --json winding_6s.json --report winding_6s.html \
    --force >/dev/null
  check "tension T1, separate denominators: validation fit %" "$(fit_of winding_6s.json winding_val.dat $w --output 6)" gt 62
  code=0
  "$ctid" fit winding_est.dat $w --output 7 --method srivc --nf 1 --json winding_7s.json --force >/dev/null 2>&1 || code=$?
  check "tension T3, separate denominators: exit code (1 = not usable, reported)" "$code" gt 0.5
  # T3 with a common third-order denominator converges and validates best.
  "$ctid" fit winding_est.dat $w --output 7 --method srivc --nf 3 --set common_denominator=1 --json winding_7c3.json \
    --force >/dev/null
  check "tension T3, common third-order denominator: validation fit %" \
    "$(fit_of winding_7c3.json winding_val.dat $w --output 7)" gt 50
else
  echo "== winding process: SKIPPED ($winding not available)"
fi

exchanger="$shared/daisy_heat_exchanger/exchanger.dat"
if [ -f "$exchanger" ]; then
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
else
  echo "== heat exchanger: SKIPPED ($exchanger not available)"
fi

dryer2="$shared/daisy_industrial_dryer/dryer2.dat"
if [ -f "$dryer2" ]; then
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
else
  echo "== industrial dryer: SKIPPED ($dryer2 not available)"
fi

wall="$shared/daisy_thermic_wall/thermic_res_wall.dat"
if [ -f "$wall" ]; then
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
else
  echo "== thermic wall: SKIPPED ($wall not available)"
fi

f16="$shared/f16_gvt"
if [ -f "$f16/F16Data_FullMSine_Level1.csv" ] && [ -n "${CTID_PYTHON:-}" ] && "$CTID_PYTHON" -c "import ctid" 2>/dev/null; then
  echo "== F-16 ground vibration test: the torsion mode at 7 excitation levels (Python: FFT + ctid.tf_from_frequency)"
  "$CTID_PYTHON" "$(dirname "$0")/f16_modes.py" "$f16" "$out"
  col() { awk -F, -v l="$1" -v c="$2" 'NR > 1 && $1 == l { print $c }' "$out/f16_modes.csv"; }
  check "torsion frequency drop from 12 N to 98 N rms (Hz)" "$(awk -v a="$(col 1 3)" -v b="$(col 7 3)" 'BEGIN { print a - b }')" gt 0.1
  check "torsion damping ratio at 98 N over that at 12 N" "$(awk -v a="$(col 1 4)" -v b="$(col 7 4)" 'BEGIN { print b / a }')" gt 2
  check "worst FRF fit on the validation periods over the 7 levels %" \
    "$(awk -F, 'NR > 1 && (m == "" || $6 < m) { m = $6 } END { print m }' "$out/f16_modes.csv")" gt 75
else
  echo "== F-16 GVT: SKIPPED (data in $f16 or the Python module (CTID_PYTHON) not available)"
fi

tanks="$shared/cascaded_tanks/dataBenchmark.csv"
if [ -f "$tanks" ]; then
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
  # Grey box (issue 15): Torricelli-type outflows with free exponents, overflow of both tanks, a sensor offset; no mean
  # removed; the test record's state from its first 5 samples only (the benchmark protocol), RMSE over the whole record.
  "$ctid" fit "$tanks" --ts 4 --input uEst --output yEst --method greybox --model "$examples/cascaded_tanks_greybox.json" \
    --set max_iterations=1000 --json tanks_greybox.json --report tanks_greybox.html --force | grep -E "^fit:"
  check "grey box: test RMSE, state from the first 5 test samples (required <= 0.30; SUBNET 0.30, NLSS2 0.34)" \
    "$(awk -v m="$(mse_of tanks_greybox.json "$tanks" --ts 4 --input uVal --output yVal --initial estimated \
      --initial-samples 5)" 'BEGIN { printf "%.4f", sqrt(m) }')" lt 0.25
else
  echo "== cascaded tanks: SKIPPED ($tanks not available)"
fi

sb="$shared/silverbox/SNLS80mV.csv"
if [ -f "$sb" ]; then
  echo "== Silverbox (nonlinearbenchmark.org): NARX, then the continuous-time Duffing equation by KIA + output error;"
  echo "   free-run RMS (V) on the arrow (full) test record"
  sed -n '1p;40652,60651p' "$sb" > sb_est.csv      # 20000 samples of the multisine part
  sed -n '1p;40652,45651p' "$sb" > sb_est5k.csv    # 5000 of them for the output-error refinement
  sed -n '1p;102,40576p' "$sb" > sb_test.csv       # the arrow test [100, 40575)
  s="--ts 0.0016384 --input V1 --output V2 --detrend mean"
  "$ctid" fit sb_est.csv $s --method narx --set degree=3 --set ylag=3 --set ulag=3 --set max_terms=10 --set criterion=aic \
    --json sb_narx.json --report sb_narx.html --force >/dev/null
  "$ctid" fit sb_est5k.csv $s --intersample foh --method kia --narx sb_narx.json --set max=1000 --set quadratic=y^2 \
    --set cubic=y^3 --json sb_nde.json --report sb_kia.html --force | grep -E "^(NDE|refined)"
  "$ctid" simulate sb_narx.json sb_test.csv --ts 0.0016384 --input V1 --detrend mean --out sb_narx_sim.csv --force >/dev/null
  "$ctid" simulate sb_nde.json sb_test.csv --ts 0.0016384 --input V1 --detrend mean --intersample foh --out sb_nde_sim.csv \
    --force >/dev/null
  check "NARX free-run RMS (references: SysIdentPy NARX 0.00415, SUBNET 0.00579)" "$(rms sb_narx_sim.csv sb_test.csv 2)" lt 0.0045
  check "KIA + output-error Duffing equation free-run RMS" "$(rms sb_nde_sim.csv sb_test.csv 2)" lt 0.0015
  # Grey box (issue 15), the benchmark protocol exactly: nothing removed from either record (offsets are parameters),
  # 10000 samples of the multisine part; the test state from its first 50 samples, the RMS over the rest.
  sed -n '1p;40652,50651p' "$sb" > sb_est10k.csv
  sed -n '1p;102,32101p' "$sb" > sb_test_noex.csv  # the arrow without extrapolation [100, 32100)
  g="--ts 0.0016384 --input V1 --intersample foh"
  "$ctid" fit sb_est10k.csv $g --output V2 --method greybox --model "$examples/silverbox_greybox.json" \
    --json sb_greybox.json --report sb_greybox.html --force | grep -E "^fit:"
  for t in test test_noex; do
    "$ctid" simulate sb_greybox.json sb_$t.csv $g --output V2 --initial estimated --initial-samples 50 \
      --out sb_greybox_$t.csv --force >/dev/null
  done
  check "grey-box Duffing equation, arrow (full): RMS (required <= 0.001; SUBNET 0.00141)" \
    "$(rms_raw sb_greybox_test.csv sb_test.csv 2 50)" lt 0.001
  check "grey-box Duffing equation, arrow without extrapolation: RMS (required 0.0005 not met; SUBNET 0.00032)" \
    "$(rms_raw sb_greybox_test_noex.csv sb_test_noex.csv 2 50)" lt 0.00075
else
  echo "== Silverbox: SKIPPED ($sb not available)"
fi

echo "reports: $(ls "$out"/*.html | wc -l) HTML files in $out"
exit $fail
