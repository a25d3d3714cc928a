#!/usr/bin/env bash
# End to end: canmotiond --sim --socket with the demo configuration, driven by
# canmotionctl: status, an instruction, get/set, a script, a watch, stats; then
# SIGTERM and a clean exit 0. Then the same configuration in real time (its
# buses are `interface: sim`) for the executive's statistics. --sim runs faster than real time, so the daemon
# gets a long --duration and is stopped by the signal when the checks are done.
# Usage: daemon-e2e.sh CANMOTIOND CANMOTIONCTL CONFIG
set -u
daemon=$1 ctl=$2 config=$3
dir=$(mktemp -d /tmp/canmotion-e2e-XXXXXX)
sock=$dir/canmotiond.sock
pid=
cleanup() {
  [ -n "$pid" ] && kill -KILL "$pid" 2>/dev/null
  rm -rf "$dir"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  echo "--- canmotiond stderr:" >&2
  cat "$dir/daemon.err" >&2
  exit 1
}

# wait_socket WHAT: wait up to 10 s for canmotiond ($pid) to create $sock.
wait_socket() {
  for _ in $(seq 1 200); do
    [ -S "$sock" ] && return 0
    kill -0 "$pid" 2>/dev/null || fail "canmotiond$1 exited before creating $sock"
    sleep 0.05
  done
  fail "no socket $sock after 10 s$1"
}

# The daemon's own --script shares user tags with the socket's clients: it
# waits for a tag that canmotionctl sets.
cat >"$dir/daemon.script" <<'SCRIPT'
E2eGo := 0;
WAIT UNTIL E2eGo = 1 TIMEOUT 600;
PRINT E2eGo;
SCRIPT
start=$(date +%s.%N)
"$daemon" --config "$config" --sim --socket "$sock" --script "$dir/daemon.script" --duration 1000000 --quiet \
  >"$dir/daemon.out" 2>"$dir/daemon.err" &
pid=$!
wait_socket ""
mode=$(stat -c %a "$sock")
[ "$mode" = 660 ] || fail "socket mode is $mode, not 660"

export CANMOTIOND_SOCKET=$sock
out=$("$ctl" status) || fail "status: $out"
echo "$out"
grep -q '^Gear ' <<<"$out" || fail "status has no Gear row"
grep -q '^Master ' <<<"$out" || fail "status has no Master row"

out=$("$ctl" 'MSO(Mover, e2e_mso)') || fail "MSO: $out"
grep -q '^e2e_mso EN=1 ' <<<"$out" || fail "MSO reply: $out"

"$ctl" set E2eTarget 7.5 || fail "set"
[ "$("$ctl" get E2eTarget)" = 7.5 ] || fail "get E2eTarget"

cat >"$dir/e2e.script" <<'SCRIPT'
WAIT UNTIL e2e_mso.DN TIMEOUT 5;
MAM(Mover, e2e_mam, 0, 7.5, 100, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 100, 100,
    %oftime, disabled, programmed, 0, none, 0, 0);
WAIT UNTIL e2e_mam.PC TIMEOUT 5;
PRINT Mover.CommandPosition;
SCRIPT
out=$("$ctl" run "$dir/e2e.script") || fail "run: $out"
echo "$out"
grep -q 'Mover.CommandPosition=7.5$' <<<"$out" || fail "script output: $out"

out=$("$ctl" watch Controller.Time --interval 0.5 --count 3) || fail "watch: $out"
[ "$(wc -l <<<"$out")" = 3 ] || fail "watch printed: $out"

out=$("$ctl" stats) || fail "stats: $out"
grep -q '^cycle ' <<<"$out" || fail "stats: $out"

"$ctl" set E2eGo 1 || fail "set E2eGo"
for _ in $(seq 1 100); do grep -q 'E2eGo=1' "$dir/daemon.out" && break; sleep 0.05; done
grep -q 'E2eGo=1' "$dir/daemon.out" || fail "the daemon's script did not see the client's SET E2eGo 1"

# --sim with --socket is paced at real time by default (--sim-rate 1): the
# controller's clock never runs ahead of the wall clock.
ctime=$("$ctl" get Controller.Time) || fail "get Controller.Time"
awk -v c="$ctime" -v s="$start" -v n="$(date +%s.%N)" 'BEGIN { exit !(c <= n - s + 0.5) }' ||
  fail "--sim --socket ran ahead of real time: controller time $ctime s after $(awk -v s="$start" -v n="$(date +%s.%N)" 'BEGIN{print n-s}') s"

if out=$("$ctl" 'MSO(Nope, x)' 2>&1); then fail "an unknown axis was accepted: $out"; fi
grep -q "Nope" <<<"$out" || fail "error does not name the axis: $out"

kill -TERM "$pid"
wait "$pid"
rc=$?
pid=
[ "$rc" = 0 ] || fail "canmotiond exited $rc after SIGTERM"
[ ! -e "$sock" ] || fail "the socket file was left behind"
grep -q 'socket: client .* connected: pid' "$dir/daemon.err" || fail "connections are not logged"

# Real time: `interface: sim` without --sim runs the cycle on the monotonic
# clock; STATS then includes the executive's latency statistics, also as tags.
"$daemon" --config "$config" --socket "$sock" --quiet >"$dir/daemon.out" 2>"$dir/daemon.err" &
pid=$!
wait_socket " (real time)"
sleep 0.3
out=$("$ctl" stats) || fail "stats (real time): $out"
echo "$out"
grep -q '^latency_p99 .* us$' <<<"$out" || fail "real-time stats have no latency_p99: $out"
lat=$("$ctl" get Controller.latency_max_ns) || fail "get Controller.latency_max_ns: $lat"
[ "$lat" -gt 0 ] 2>/dev/null || fail "Controller.latency_max_ns is '$lat'"
out=$("$ctl" 'MSO(Gear, rt_mso)') || fail "MSO (real time): $out"
kill -TERM "$pid"
wait "$pid"
rc=$?
pid=
[ "$rc" = 0 ] || fail "canmotiond (real time) exited $rc after SIGTERM"
echo "PASS"
