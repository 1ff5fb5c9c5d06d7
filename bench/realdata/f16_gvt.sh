#!/usr/bin/env bash
# Real-data benchmark: f16 gvt (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
f16="$shared/f16_gvt"
[ -f "$f16/F16Data_FullMSine_Level1.csv" ] && [ -n "${CTID_PYTHON:-}" ] && "$CTID_PYTHON" -c "import ctid" 2>/dev/null ||
  skip "F-16 GVT" "data in $f16 or the Python module (CTID_PYTHON) not available"
echo "== F-16 ground vibration test: the torsion mode at 7 excitation levels (Python: FFT + ctid.tf_from_frequency)"
"$CTID_PYTHON" "$here/f16_modes.py" "$f16" "$out"
col() { awk -F, -v l="$1" -v c="$2" 'NR > 1 && $1 == l { print $c }' "$out/f16_modes.csv"; }
check "torsion frequency drop from 12 N to 98 N rms (Hz)" "$(awk -v a="$(col 1 3)" -v b="$(col 7 3)" 'BEGIN { print a - b }')" gt 0.1
check "torsion damping ratio at 98 N over that at 12 N" "$(awk -v a="$(col 1 4)" -v b="$(col 7 4)" 'BEGIN { print b / a }')" gt 2
check "worst FRF fit on the validation periods over the 7 levels %" \
  "$(awk -F, 'NR > 1 && (m == "" || $6 < m) { m = $6 } END { print m }' "$out/f16_modes.csv")" gt 75
echo "== F-16, the whole 2-15 Hz band: MIMO state space (force -> 3 accelerations) from the FRF matrix (ctid.ssest)"
"$CTID_PYTHON" "$here/f16_mimo.py" "$f16" "$out" 20
# The torsion mode: the listed mode nearest 7.3 Hz at each level (f16_mimo_modes.csv: level,force,f,f_std,zeta,zeta_std).
torsion() { awk -F, -v l="$1" -v c="$2" 'NR > 1 && $1 == l { d = ($3 - 7.3) ^ 2; if (b == "" || d < b) { b = d; v = $c } } END { print v }' "$out/f16_mimo_modes.csv"; }
check "MIMO: torsion frequency drop from 12 N to 98 N rms (Hz)" "$(awk -v a="$(torsion 1 3)" -v b="$(torsion 7 3)" 'BEGIN { print a - b }')" gt 0.1
check "MIMO: torsion damping ratio at 98 N over that at 12 N" "$(awk -v a="$(torsion 1 5)" -v b="$(torsion 7 5)" 'BEGIN { print b / a }')" gt 2
check "MIMO: worst FRF fit on the validation periods over the 7 levels %" \
  "$(awk -F, 'NR > 1 && (m == "" || $5 < m) { m = $5 } END { print m }' "$out/f16_mimo.csv")" gt 80
exit $fail
