#!/usr/bin/env bash
# demo.sim_deterministic: the demo on a virtual clock is deterministic and
# the emulated drives follow the commanded motion within the delay of the
# CSP pipeline.
#   sim-deterministic.sh CANMOTIOND EXAMPLES_DIR OUTDIR
# 1. canmotiond --sim --config demo.yaml --script demo.script --trace --csv,
#    twice: exit 0 both times; --trace and --csv byte-identical; stdout
#    identical apart from the wall-time figures. Each run is bounded (120 s,
#    it takes about 1 s).
# 2. Sanity of what was compared: the trace has SYNC, the RPDO and TPDO of
#    every node; the CSV has one row per axis per cycle.
# 3. Max following error per CIP axis (the summary's figure) <= the bound
#       vmax * (lag + 2) * T + 2 / conversion_constant
#    vmax = the largest |cmd_vel| of the axis in the CSV; lag = 2 SYNCs (the
#    emulated drive's default, EmulatorConfig::lag_cycles); +2 cycles: the
#    target packed in cycle k is applied at SYNC k + lag and its position is
#    received in cycle k + lag + 1 (one more cycle of slack); 2 counts of
#    rounding. The emulated motor's own limits (2e6 counts/s, 5e7 counts/s^2)
#    are far above the demo's moves, so they add nothing.
#    The summary's figure must also be > 0 (the axes moved), and the CSV's
#    max |cmd_pos - act_pos| (rotary axes: modulo the unwind) is held to the
#    same bound.
# 4. No TPDO missed on any axis (the summary's count).
set -euo pipefail
daemon="$1" examples="$2" out="$3"
fail() { echo "sim-deterministic: FAIL: $*" >&2; exit 1; }
rm -rf "$out"; mkdir -p "$out"
for run in a b; do
  status=0
  timeout -k 5 120 "$daemon" --sim --config "$examples/demo.yaml" --script "$examples/demo.script" \
    --trace "$out/$run.trace" --csv "$out/$run.csv" > "$out/$run.log" 2> "$out/$run.err" || status=$?
  [[ $status == 0 ]] || { cat "$out/$run.log" "$out/$run.err" >&2; fail "run $run exited with status $status"; }
done
cat "$out/a.log"
cmp "$out/a.trace" "$out/b.trace" || fail "--trace outputs differ ($out/a.trace, $out/b.trace)"
cmp "$out/a.csv" "$out/b.csv" || fail "--csv outputs differ ($out/a.csv, $out/b.csv)"
strip() { sed -E -e 's/ in [0-9.]+ s wall \([0-9]+x real time\)//' -e 's#(written to ).*/([ab])\.#\1X.#' "$1"; }
diff <(strip "$out/a.log") <(strip "$out/b.log") || fail "stdout differs between the two runs"
echo "sim-deterministic: trace ($(wc -l < "$out/a.trace") frames, $(wc -c < "$out/a.trace") bytes) and CSV ($(wc -l < "$out/a.csv") lines) byte-identical over two runs"

# What was compared is not empty.
cycles=$(sed -nE 's/^summary: ([0-9]+) cycles.*/\1/p' "$out/a.log")
[[ -n "$cycles" && "$cycles" -gt 5000 ]] || fail "summary has no cycle count above 5000: '$cycles'"
for id in 080 202 182 203 183 204 184; do
  grep -q "^([0-9.]*) can[01] $id#" "$out/a.trace" || fail "no frame with COB-ID $id in the trace"
done
rows=$(( $(wc -l < "$out/a.csv") - 1 ))
axes=$(awk -F, 'NR > 1 { a[$3] = 1 } END { print length(a) }' "$out/a.csv")
[[ $axes == 4 ]] || fail "the CSV has $axes axes, expected 4"
awk -F, 'NR > 1 { n[$2]++ } END { for (t in n) if (n[t] != 4) { print "time " t ": " n[t] " rows"; exit 1 } }' "$out/a.csv" ||
  fail "the CSV does not have one row per axis per cycle"
echo "sim-deterministic: $cycles cycles, $rows CSV rows for $axes axes"

# Following error bound per CIP axis.
period=$(awk '/^  period_ms:/ { print $2 / 1000; exit }' "$examples/demo.yaml")
while read -r axis err units; do
  conv=$(awk -v a="$axis" '$1 == "-" && $2 == "name:" { cur = $3 } cur == a && $1 == "conversion_constant:" { print $2; exit }' "$examples/demo.yaml")
  [[ -n "$conv" ]] || fail "no conversion_constant for axis $axis in demo.yaml"
  unwind=$(awk -v a="$axis" '$1 == "-" && $2 == "name:" { cur = $3 } cur == a && $1 == "unwind:" { print $2; exit }' "$examples/demo.yaml")
  awk -F, -v a="$axis" -v e="$err" -v T="$period" -v conv="$conv" -v u="$units" -v U="${unwind:-0}" '
    $3 == a { v = $6 < 0 ? -$6 : $6; if (v > vmax) vmax = v; d = $4 - $5; if (d < 0) d = -d; if (U > 0) { d -= U * int(d / U); if (U - d < d) d = U - d } if (d > dmax) dmax = d }
    END {
      bound = vmax * (2 + 2) * T + 2 / conv
      printf "sim-deterministic: axis %-6s max following error %.6f %s (CSV max |cmd-act| %.6f), vmax %.3f %s/s, bound %.6f %s\n", a, e, u, dmax, vmax, u, bound, u
      if (e <= 0) { print "sim-deterministic: FAIL: axis " a " has no following error at all: did it move?"; exit 1 }
      if (e > bound) { print "sim-deterministic: FAIL: axis " a " following error above the bound"; exit 1 }
      if (dmax > bound) { print "sim-deterministic: FAIL: axis " a " CSV |cmd-act| above the bound"; exit 1 }
    }' "$out/a.csv" || fail "following error of $axis"
done < <(sed -nE 's/^summary: axis ([A-Za-z0-9_]+) +node +[0-9]+ +max following error ([0-9.eE+-]+) ([^ ]+) .*/\1 \2 \3/p' "$out/a.log")
n=$(grep -c 'max following error' "$out/a.log")
[[ $n == 3 ]] || fail "expected 3 CIP axes in the summary, found $n"
# On the in-process bus every SYNC is answered in time: no TPDO missed.
missed=$(grep 'max following error' "$out/a.log" | grep -v 'TPDOs missed 0$' || true)
[[ -z "$missed" ]] || fail "TPDOs missed on the simulated bus:"$'\n'"$missed"
echo "sim-deterministic: no TPDO missed on any axis"
echo "sim-deterministic: PASS"
