#!/usr/bin/env bash
# MCCP at run time, as a user runs it (issue #5): canmotiond --sim with a
# script that fills a CAM array tag, calculates a CAM_PROFILE with MCCP and
# cams an axis with it. The same script run on the profile the configuration
# computed from the same points must print the same positions, digit for digit.
# Then the same tags through canmotionctl get/set on a running daemon.
# Usage: mccp-test.sh CANMOTIOND WORKDIR [CANMOTIONCTL]
set -uo pipefail
bin="$1" work="$2" ctl="${3:-}"
mkdir -p "$work"
pid=
trap '[ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null' EXIT
fail() { echo "mccp-test: FAIL: $*" >&2; exit 1; }

# (a bus is declared although no axis uses it: canmotiond --sim needs one)
cat > "$work/mccp.yaml" <<'YAML'
buses:
  - {name: can0, interface: sim}
axes:
  - {name: X, type: AXIS_VIRTUAL, max_speed: 1000, max_accel: 10000, max_decel: 10000}
cams:
  - name: ref
    start_slope: 0.5
    end_slope: -2
    points: [[0, 0, cubic], [0.2, 1, cubic], [0.5, 4, linear], [0.7, 5, cubic], [1, 2, linear]]
arrays:
  - {name: pts, type: CAM, size: 16}
  - {name: prof, type: CAM_PROFILE, size: 16}
YAML

script() {  # $1 = the profile MATC runs on
  cat <<SCRIPT
pts[0].Master := 0;   pts[0].Slave := 0; pts[0].SegmentType := 1;
pts[1].Master := 0.2; pts[1].Slave := 1; pts[1].SegmentType := 1;
pts[2].Master := 0.5; pts[2].Slave := 4; pts[2].SegmentType := 0;
pts[3].Master := 0.7; pts[3].Slave := 5; pts[3].SegmentType := 1;
pts[4].Master := 1;   pts[4].Slave := 2; pts[4].SegmentType := 0;
PRINT pts[3].Master, pts[3].Slave, pts[3].SegmentType, prof[0].Status;
MCCP(mc, pts[0], 5, 0.5, -2, prof[0]);
WAIT UNTIL mc.DN TIMEOUT 1;
PRINT mc.DN, mc.ER, prof[0].Status;
MSO(X, on);
WAIT UNTIL on.DN;
MATC(X, t, same, $1[0], 2, 1.5, once, immediate, 0, none, timedrivenmode);
WAIT 0.123; PRINT X.CommandPosition, X.CommandVelocity, $1[0].Status;
WAIT 0.5;   PRINT X.CommandPosition, X.CommandVelocity;
WAIT 0.4;   PRINT X.CommandPosition, X.CommandVelocity;
WAIT UNTIL t.PC TIMEOUT 3;
PRINT X.CommandPosition, $1[0].Status;
SCRIPT
}
script prof > "$work/run.script"
script ref > "$work/ref.script"
run=$("$bin" --config "$work/mccp.yaml" --sim --script "$work/run.script" -q 2>&1); rc=$?
[[ $rc == 0 ]] || fail "run-time profile: exit $rc: $run"
ref=$("$bin" --config "$work/mccp.yaml" --sim --script "$work/ref.script" -q 2>&1); rc=$?
[[ $rc == 0 ]] || fail "config profile: exit $rc: $ref"
grep -q 'pts\[3\].Master=0.7 pts\[3\].Slave=5 pts\[3\].SegmentType=1 prof\[0\].Status=0$' <<<"$run" || fail "tags: $run"
grep -q 'mc.DN=1 mc.ER=0 prof\[0\].Status=2$' <<<"$run" || fail "MCCP: $run"
grep -q 'X.CommandPosition=[-0-9.]* X.CommandVelocity=[-0-9.]* prof\[0\].Status=3$' <<<"$run" || fail "in use: $run"
grep -q 'X.CommandPosition=4 prof\[0\].Status=2$' <<<"$run" || fail "end of the Once cam (2 x slave 2): $run"
# Same motion, digit for digit (profile names aside).
diff <(grep -o 'X.Command[A-Za-z]*=[-0-9.]*' <<<"$run") <(grep -o 'X.Command[A-Za-z]*=[-0-9.]*' <<<"$ref") ||
  fail "the run-time profile moves the axis differently from the configured one"
[[ $(grep -c 'X.CommandPosition' <<<"$run") == 4 ]] || fail "expected 4 position lines: $run"

# A bad MCCP (masters not increasing) is reported with its ERR and the script goes on.
printf 'pts[0].Master := 1; pts[1].Master := 0.5;\nMCCP(mc, pts[0], 2, 0, 0, prof[0]);\nPRINT mc.ERR, prof[0].Status;\n' > "$work/bad.script"
out=$("$bin" --config "$work/mccp.yaml" --sim --script "$work/bad.script" -q 2>&1); rc=$?
[[ $rc == 0 ]] || fail "bad MCCP script exit $rc: $out"
grep -q 'MCCP set mc.ER: ERR 29 EXERR 0' <<<"$out" || fail "ERR 29 note: $out"
grep -q 'mc.ERR=29 prof\[0\].Status=0$' <<<"$out" || fail "ERR 29: $out"

# An element outside the array is refused when the script is loaded (exit 2).
printf 'pts[16].Slave := 1;\n' > "$work/range.script"
out=$("$bin" --config "$work/mccp.yaml" --sim --script "$work/range.script" -q 2>&1); rc=$?
[[ $rc == 2 ]] || fail "out-of-range script exit $rc, want 2: $out"
grep -q "range.script:1:1: pts\[16\]: array 'pts' has 16 elements (\[0\] .. \[15\])" <<<"$out" || fail "range message: $out"

# canmotionctl set/get of array elements, MCCP as a call (when the tool is given).
if [[ -n "$ctl" ]]; then
  sock="$work/d.sock"
  rm -f "$sock"
  "$bin" --config "$work/mccp.yaml" --sim --socket "$sock" --duration 1000000 --quiet >"$work/d.out" 2>"$work/d.err" &
  pid=$!
  for _ in $(seq 1 200); do [ -S "$sock" ] && break; sleep 0.05; done
  [ -S "$sock" ] || fail "no socket: $(cat "$work/d.err")"
  export CANMOTIOND_SOCKET=$sock
  i=0
  for p in "0 0 1" "0.2 1 1" "0.5 4 0" "0.7 5 1" "1 2 0"; do
    read -r m sl ty <<<"$p"
    "$ctl" set "pts[$i].Master" "$m" >/dev/null && "$ctl" set "pts[$i].Slave" "$sl" >/dev/null &&
      "$ctl" set "pts[$i].SegmentType" "$ty" >/dev/null || fail "set pts[$i]"
    i=$((i + 1))
  done
  [ "$("$ctl" get 'pts[3].Slave')" = 5 ] || fail "get pts[3].Slave: $("$ctl" get 'pts[3].Slave')"
  out=$("$ctl" 'MCCP(mc, pts[0], 5, 0.5, -2, prof[0])') || fail "MCCP call: $out"
  grep -q '^mc EN=1 DN=1 ER=0 ' <<<"$out" || fail "MCCP reply: $out"
  [ "$("$ctl" get 'prof[0].Status')" = 2 ] || fail "prof[0].Status after MCCP"
  out=$("$ctl" set 'pts[16].Slave' 1 2>&1) && fail "set outside the array succeeded: $out"
  grep -q "array 'pts' has 16 elements" <<<"$out" || fail "set outside the array: $out"
  kill -TERM "$pid"; wait "$pid"; pid=
fi
echo "mccp-test: run-time MCCP profile cams exactly like the configured one; errors as documented"
