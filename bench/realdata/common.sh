#!/usr/bin/env bash
# Shared by the real-data benchmark scripts of bench/realdata/ (one per data set; ctest runs each as
# realdata.<name>, label realdata, in the Release build; docs/gallery.md shows their numbers next to the published
# references). Every script identifies models with the ctid command line, validates them on held-out data and checks
# each number against the bound printed next to it (exit 1 when one is outside); a data set that is absent makes the
# script exit 77 (ctest: skipped).
# Usage of every script: bench/realdata/NAME.sh CTID_BINARY OUT_DIR SHARED_DATA_DIR EXAMPLES_DATA_DIR
# (e.g. bench/realdata/silverbox.sh build/ctid /tmp/sb ../shared/data examples/data)
set -euo pipefail
ctid="$(realpath "$1")"; out="$2"; shared="$(realpath -m "$3")"; examples="$(realpath "$4")"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
mkdir -p "$out"
cd "$out"
fail=0
skip() { echo "== $1: SKIPPED ($2)"; exit 77; }
check() {  # check NAME VALUE OP BOUND   (OP: lt | gt)
  local ok
  ok=$(awk -v v="$2" -v b="$4" -v op="$3" 'BEGIN { print (op == "lt" ? (v < b) : (v > b)) ? 1 : 0 }')
  if [ "$ok" = 1 ]; then echo "  $1 = $2 (bound: $3 $4)"; else echo "  FAILED: $1 = $2 (bound: $3 $4)"; fail=1; fi
}
fit_of() { "$ctid" validate "$@" | awk '/^fit:/ { print $2; exit }'; }
# The validation fit of every output, the initial state estimated by least squares on the record validated:
# fits_of MODEL.json DATA [validate options]  ->  "fit1 fit2 ..." on one line
fits_of() { "$ctid" validate "$@" --initial estimated | awk '/fit:/ { for (i = 1; i < NF; ++i) if ($i == "fit:") printf "%s ", $(i + 1) } END { print "" }'; }
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
