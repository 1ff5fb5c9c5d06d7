#!/usr/bin/env bash
# Real-data benchmark: hair dryer (docs/gallery.md). Usage: see bench/realdata/common.sh.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
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
exit $fail
