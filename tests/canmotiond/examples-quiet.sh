#!/usr/bin/env bash
# The shipped examples start without warnings (issue 29 part 6): for every
# config/examples/*.yaml, `canmotiond --check-args` and a `--sim` run (the
# example's own script for demo.yaml and coordinated.yaml, as README's demo
# commands run them, else 2 s) print nothing on stderr: no warning of the
# configuration or of an EDS, no "axes without drive.eds" note; and every
# CIP axis of them names an EDS (the emulated drive's, cia402-emu.eds).
# Usage: examples-quiet.sh CANMOTIOND EXAMPLES_DIR WORKDIR
set -uo pipefail
bin="$1" ex="$2" work="$3"
mkdir -p "$work"
fail() { echo "examples-quiet: FAIL: $*" >&2; exit 1; }
n=0
for cfg in "$ex"/*.yaml; do
  name=$(basename "$cfg" .yaml)
  "$bin" --config "$cfg" --check-args 2> "$work/$name.check.err" > "$work/$name.check.out"; rc=$?
  [[ $rc == 0 ]] || fail "$name: --check-args exit $rc: $(cat "$work/$name.check.err")"
  [[ ! -s "$work/$name.check.err" ]] || fail "$name: --check-args says on stderr: $(cat "$work/$name.check.err")"
  if grep -q '^ *type: AXIS_CIP_DRIVE' "$cfg"; then
    grep -q '^ *eds: cia402-emu.eds' "$cfg" || fail "$name: CIP axes without the emulated drive's EDS (drive.eds)"
    run=(--duration 2)
    [[ -f "$ex/$name.script" ]] && run=(--script "$ex/$name.script")
    timeout -k 5 120 "$bin" --config "$cfg" --sim "${run[@]}" \
      2> "$work/$name.sim.err" > "$work/$name.sim.out"; rc=$?
    [[ $rc == 0 ]] || fail "$name: --sim exit $rc: $(tail -5 "$work/$name.sim.err")"
    [[ ! -s "$work/$name.sim.err" ]] || fail "$name: --sim says on stderr: $(head -5 "$work/$name.sim.err")"
  fi
  n=$((n + 1))
done
[[ $n -ge 3 ]] || fail "only $n example configurations in $ex"
echo "examples-quiet: $n example configurations, nothing on stderr"
