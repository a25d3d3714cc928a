#!/usr/bin/env bash
# canmotiond as a user runs it (--sim): statistics tags in scripts, and the
# exit status contract: 0 ok, 1 script failure, 2 bad configuration or script.
# Usage: daemon-test.sh CANMOTIOND EXAMPLES_DIR WORKDIR
set -uo pipefail
bin="$1" ex="$2" work="$3"
mkdir -p "$work"
fail() { echo "daemon-test: FAIL: $*" >&2; exit 1; }

# 1. Statistics and controller tags in a script; exit 0.
printf 'WAIT 0.5;\nPRINT Controller.cycles, Controller.overruns, Controller.Time;\n' > "$work/stats.script"
out=$("$bin" --config "$ex/demo.yaml" --sim --script "$work/stats.script" -q 2>&1); rc=$?
[[ $rc == 0 ]] || fail "stats script exit $rc: $out"
# The script starts after the first cycle (t=0.001); the executive counts completed cycles.
grep -q '^t=0.501 Controller.cycles=500 Controller.overruns=0 Controller.Time=0.501$' <<<"$out" || fail "stats line: $out"

# 2. A WAIT UNTIL that times out fails the script: exit 1, with the reason.
printf 'WAIT UNTIL Master.CommandPosition > 1 TIMEOUT 0.2;\n' > "$work/timeout.script"
out=$("$bin" --config "$ex/demo.yaml" --sim --script "$work/timeout.script" -q 2>&1); rc=$?
[[ $rc == 1 ]] || fail "timeout script exit $rc, want 1: $out"
grep -q 'timeout.script:1: WAIT UNTIL Master.CommandPosition > 1 timed out after 0.2 s (Master.CommandPosition = 0)' <<<"$out" ||
  fail "timeout message: $out"

# 3. A bad configuration: exit 2, file:line:column and key named, nothing run.
sed 's/max_speed: 500/max_sped: 500/' "$ex/demo.yaml" > "$work/bad.yaml"
out=$("$bin" --config "$work/bad.yaml" --sim --duration 1 --trace "$work/bad-trace.log" 2>&1); rc=$?
[[ $rc == 2 ]] || fail "bad config exit $rc, want 2: $out"
grep -qE "bad.yaml:[0-9]+:[0-9]+: error: axes\[0\]\.max_sped: unknown key 'max_sped'; did you mean 'max_speed'\?" <<<"$out" ||
  fail "bad config message: $out"
grep -q "nothing was sent on any bus" <<<"$out" || fail "bad config: no 'nothing was sent' line: $out"
[[ ! -e "$work/bad-trace.log" ]] || fail "a trace was written for a bad configuration"

# 4. A bad script: exit 2 before anything runs.
printf 'MSO(Nobody, mso1);\n' > "$work/bad.script"
out=$("$bin" --config "$ex/demo.yaml" --sim --script "$work/bad.script" -q 2>&1); rc=$?
[[ $rc == 2 ]] || fail "bad script exit $rc, want 2: $out"
grep -q 'bad.script:1:1:' <<<"$out" || fail "bad script message: $out"

# 5. A configuration without buses (virtual axes only) runs in --sim.
printf 'controller: {period_ms: 1}\naxes:\n  - {name: V, type: AXIS_VIRTUAL}\n' > "$work/nobus.yaml"
printf 'MSO(V, mso1);\nMAJ(V, maj1, 0, 10, unitspersec, 100, unitspersec2, 100, unitspersec2, trapezoidal, 100, 100, %%oftime, disabled, programmed, 0, none);\nWAIT 1;\nPRINT V.CommandVelocity;\n' > "$work/nobus.script"
out=$("$bin" --config "$work/nobus.yaml" --sim --script "$work/nobus.script" -q 2>&1); rc=$?
[[ $rc == 0 ]] || fail "no-bus configuration exit $rc: $out"
grep -q 'V.CommandVelocity=10$' <<<"$out" || fail "no-bus run: $out"

# 6. An axis fault is logged with its value, key, action and what clears it;
# the script goes on (a soft overtravel on a virtual axis: Stop Planner).
printf 'controller: {period_ms: 1}\naxes:\n  - {name: V, type: AXIS_VIRTUAL, units: mm, soft_limits: {enabled: true, positive: 5, negative: -5}}\n' > "$work/soft.yaml"
printf 'MSO(V, mso1);\nMAJ(V, maj1, 0, 10, unitspersec, 100, unitspersec2, 100, unitspersec2, trapezoidal, 100, 100, %%oftime, disabled, programmed, 0, none);\nWAIT 1;\nPRINT V.AxisFault, V.JogStatus;\n' > "$work/soft.script"
out=$("$bin" --config "$work/soft.yaml" --sim --script "$work/soft.script" -q 2>&1); rc=$?
[[ $rc == 0 ]] || fail "soft overtravel run exit $rc: $out"
grep -qE '^canmotiond: axis V: command position 5\.0[0-9]* mm beyond the positive soft limit 5 mm \(axes\[0\]\.soft_limits\.positive\): Stop Planner \(axes\[0\]\.exception_actions\.soft_overtravel_positive\): motion stopped, the servo stays on; MAFR clears it$' <<<"$out" ||
  fail "soft overtravel message: $out"
[[ $(grep -c 'soft limit' <<<"$out") == 1 ]] || fail "soft overtravel reported more than once: $out"
grep -q 'V.AxisFault=16 V.JogStatus=0$' <<<"$out" || fail "soft overtravel tags: $out"

# 7. --histogram is for real time: refused with --sim (exit 2, nothing run).
out=$("$bin" --config "$ex/demo.yaml" --sim --duration 1 --histogram "$work/h.txt" 2>&1); rc=$?
[[ $rc == 2 ]] || fail "--sim --histogram exit $rc, want 2: $out"
grep -q -- '--sim excludes --histogram' <<<"$out" || fail "--sim --histogram message: $out"
[[ ! -e "$work/h.txt" ]] || fail "--sim --histogram wrote a file"

# 8. --help works and names the options.
"$bin" --help | grep -q -- '--script' || fail "--help"
echo "daemon-test: statistics tags, exit statuses 0/1/2, axis fault messages as documented"
