# Shared by the MIMO real-data scripts (sourced after common.sh).

# ssest_and_n4sid NAME EST VAL "INPUT OPTIONS" "OUTPUT COLUMNS" NXMAX: one MIMO ssest model (order by BIC over
# 1..NXMAX on EST) and the discrete-time N4SID route (MOESP + logm) at its order, validated on VAL with the initial
# state estimated there; sets nx and the arrays ss and n4 (the validation fit of each output) and prints them.
ssest_and_n4sid() {
  local name=$1 est=$2 val=$3 i=$4 outs=$5 nxmax=$6 o="" y
  for y in $outs; do o="$o --output $y"; done
  "$ctid" fit "$est" $i $o --method ssest --nx "1:$nxmax" --json "${name}_ss.json" --force > "${name}_ss.txt"
  nx=$(awk '/states$/ { print $(NF - 1); exit }' "${name}_ss.txt")
  grep "order search" "${name}_ss.txt"
  read -r -a ss < <(fits_of "${name}_ss.json" "$val" $i $o)
  echo "  MIMO ssest, nx = $nx: ${ss[*]}"
  "$ctid" fit "$est" $i $o --method subspace --set route=discrete --nx "$nx" --json "${name}_n4.json" --force >/dev/null
  read -r -a n4 < <(fits_of "${name}_n4.json" "$val" $i $o)
  echo "  discrete N4SID (MOESP + logm), nx = $nx: ${n4[*]}"
}

# evaporator.sh, glass_furnace.sh: one MIMO ssest
# model (order by BIC over 1..NXMAX on the estimation part) against a MISO SRIVC model per output (a common
# denominator of order 1..3 for all inputs, the order by least BIC on the estimation part) and the discrete-time
# N4SID route (MOESP + logm) at ssest's order; validation fits with the initial state estimated on the validation
# part. Usage: mimo_compare NAME EST VAL "INPUT OPTIONS" "OUTPUT COLUMNS" NXMAX
mimo_compare() {
  local name=$1 est=$2 val=$3 i=$4 outs=$5 nxmax=$6 y best bic nf
  local -a miso=()
  for y in $outs; do
    best="" bic=""
    for nf in 1 2 3; do
      # An unusable fit (exit 1) is not a candidate.
      "$ctid" fit "$est" $i --output "$y" --method srivc --nf $nf --set common_denominator=1 \
        --json "${name}_${y}_$nf.json" --force > "${name}_${y}_$nf.txt" 2>&1 || continue
      b=$(awk '/^fit:/ { for (k = 1; k < NF; ++k) if ($k == "BIC") print $(k + 1) }' "${name}_${y}_$nf.txt")
      if [ -z "$bic" ] || awk -v a="$b" -v c="$bic" 'BEGIN { exit !(a < c) }'; then bic=$b; best=$nf; fi
    done
    read -r f < <(fits_of "${name}_${y}_$best.json" "$val" $i --output "$y")
    miso+=("$f")
    echo "  MISO SRIVC, output $y (common denominator of order $best by BIC): $f"
  done
  ssest_and_n4sid "$name" "$est" "$val" "$i" "$outs" "$nxmax"
  local k=0
  for y in $outs; do
    check "output $y: ssest validation fit minus MISO SRIVC's (at least as good)" \
      "$(awk -v a="${ss[$k]}" -v b="${miso[$k]}" 'BEGIN { print a - b }')" gt -0.5
    k=$((k + 1))
  done
}
