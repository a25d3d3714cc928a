#!/usr/bin/env bash
# golden.sim: canmotiond --sim output is byte-identical to the recorded one.
#   sim-golden.sh CANMOTIOND EXAMPLES_DIR HASH_FILE OUTDIR
# For each run (demo.script and mapc.script on demo.yaml, coordinated.script on
# coordinated.yaml), for a fixed 10 s of controller time: sha256 of the --trace
# file and of the --csv file, each compared with its line in HASH_FILE
# (sha256sum format, names demo.trace, demo.csv, mapc.trace, mapc.csv,
# coordinated.trace, coordinated.csv; coordinated added before issue 27's
# refactor).
# The hashes were first recorded on main 94e8130, before the planner refactor
# of issue 13 started, and held through it; deliberate fieldbus changes since
# re-recorded them (git log tests/golden/sim.sha256 says which and why). A
# deliberate behaviour change (planner or fieldbus) changes them: the failure message prints both hashes and the command; re-record with
#   CANMOTION_GOLDEN_UPDATE=1 sim-golden.sh ...   (or ctest with that variable set)
# and say in the commit why the output changed.
set -euo pipefail
daemon="$1" examples="$2" hashes="$3" out="$4"
rm -rf "$out"; mkdir -p "$out"
duration=10
actual="$out/actual.sha256"
: > "$actual"
# the configuration each script runs on
config_of() { case "$1" in coordinated) echo coordinated.yaml ;; *) echo demo.yaml ;; esac; }
for s in demo mapc coordinated; do
  cmd=("$daemon" --sim --config "$examples/$(config_of "$s")" --script "$examples/$s.script" --duration "$duration"
       --trace "$out/$s.trace" --csv "$out/$s.csv" -q)
  status=0
  timeout -k 5 100 "${cmd[@]}" > "$out/$s.log" 2>&1 || status=$?
  [[ $status == 0 ]] || { cat "$out/$s.log" >&2; echo "sim-golden: FAIL: ${cmd[*]} exited with status $status" >&2; exit 1; }
  [[ -s "$out/$s.trace" && -s "$out/$s.csv" ]] || { echo "sim-golden: FAIL: empty output of ${cmd[*]}" >&2; exit 1; }
  (cd "$out" && sha256sum "$s.trace" "$s.csv") >> "$actual"
  echo "sim-golden: $s: $(wc -l < "$out/$s.trace") frames, $(wc -l < "$out/$s.csv") CSV lines"
done
if [[ "${CANMOTION_GOLDEN_UPDATE:-}" == 1 ]]; then
  cp "$actual" "$hashes"
  echo "sim-golden: recorded $hashes:"; cat "$hashes"
  exit 0
fi
fail=0
while read -r want name; do
  got=$(awk -v n="$name" '$2 == n { print $1 }' "$actual")
  if [[ "$got" != "$want" ]]; then
    s=${name%.*}
    echo "sim-golden: FAIL: $name changed" >&2
    echo "  recorded sha256 $want ($hashes)" >&2
    echo "  now      sha256 $got ($out/$name)" >&2
    echo "  command: $daemon --sim --config $examples/$(config_of "$s") --script $examples/$s.script --duration $duration --trace $s.trace --csv $s.csv -q" >&2
    fail=1
  else
    echo "sim-golden: $name sha256 $got as recorded"
  fi
done < "$hashes"
if [[ $fail != 0 ]]; then
  echo "sim-golden: if the change is deliberate, re-record with CANMOTION_GOLDEN_UPDATE=1 $0 $* and say why in the commit" >&2
  exit 1
fi
[[ $(wc -l < "$hashes") == 6 ]] || { echo "sim-golden: FAIL: $hashes should have 6 lines" >&2; exit 1; }
echo "sim-golden: PASS"
