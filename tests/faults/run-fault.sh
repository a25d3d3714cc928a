#!/usr/bin/env bash
# The fault matrix on real SocketCAN, COMMAND part (inside tests/vcan/run-vcan-test:
# vcan0 up, candump -L writing $CANMOTION_TRACE). canmotiond, cia402-emu and
# cansend run as separate processes; canmotiond runs a motion script
# (SCENARIO.script) that waits on the tags `Step` (set by the script: where it
# is) and `Go` (set here with canmotionctl: the fault has been applied).
#
#   run-fault.sh SCENARIO CANMOTIOND CIA402_EMU CANMOTIONCTL PERIOD_MS
#
# Scenarios (the reaction and the recovery, see README.md "Real drives"):
#   vanish     the drive is killed (SIGKILL) while jogging, and started again:
#              the axis faults (node lost), the new boot-up is configured,
#              MASR + MSO + a move work
#   emcy       the drive faults while jogging (EMCY 0xFF00 injected by a
#              cansend SDO write of 0x2000): MAFR + MSO + a move
#   reboot     the drive is reset while jogging (cansend NMT reset node): the
#              unexpected boot-up faults the axis and is configured again;
#              MAFR + MSO + a move
#   sdo_timeout  a node that sends boot-up and heartbeats but never answers
#              SDO: the boot fails ("did not answer"), MSO ERR 11; then a
#              working drive boots and is configured, MSO + a move
#   sdo_abort  a drive without 0x1016 while the configuration asks it to
#              watch the master: the refused write names the key; MSO ERR
#              11; then a drive with 0x1016 replaces it, MSO + a move
#   master     canmotiond is killed (SIGKILL) while the drive jogs: the drive
#              faults (EMCY 0x8130) after its 0x1016 time (1 s) and goes
#              pre-operational (0x1029:1 = 0); canmotiond started again
#              configures it, MAFR + MSO + a move
#   fewer      a drive without 0x1016 and with two PDOs per direction, not
#              asked to watch the master: boots, enables, moves
# Artefacts: faults.yaml, canmotiond*.log, canmotiond-trace*.log, emu-*.log.
set -euo pipefail
scn="$1" daemon="$2" emu="$3" ctl="$4" period="$5"
art="$CANMOTION_ARTIFACTS" trace="$CANMOTION_TRACE"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
fail() { echo "run-fault: $scn: $*" >&2; exit 1; }

mhb=1000
[[ $scn == fewer ]] && mhb=0
sed -e "s/@PERIOD@/$period/" -e "s/@MHB@/$mhb/" "$here/faults.yaml.in" > "$art/faults.yaml"
script="$here/$scn.script"
case $scn in sdo_timeout | sdo_abort) script="$here/boot.script" ;; esac
# The socket in a local tmpfs: the artefacts folder is a 9p share in the VM,
# where UNIX sockets cannot be created.
sockdir="$(mktemp -d /tmp/canmotion-faults.XXXXXX)"
export CANMOTIOND_SOCKET="$sockdir/canmotiond.sock"

pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  pids=()
}
trap 'cleanup; rm -rf "$sockdir"' EXIT

dpid=""
start_daemon() {  # start_daemon SCRIPT LOG-SUFFIX
  rm -f "$CANMOTIOND_SOCKET"
  timeout -s INT -k 30 400 stdbuf -oL "$daemon" --config "$art/faults.yaml" --script "$1" --socket "$CANMOTIOND_SOCKET" \
    --trace "$art/canmotiond-trace$2.log" > "$art/canmotiond$2.log" 2>&1 &
  dpid=$!
  for ((i = 0; i < 600; i++)); do  # the socket exists once the buses are open
    [[ -S $CANMOTIOND_SOCKET ]] && break
    kill -0 "$dpid" 2>/dev/null || break
    sleep 0.05
  done
  [[ -S $CANMOTIOND_SOCKET ]] || { cat "$art/canmotiond$2.log" >&2; fail "canmotiond did not start"; }
}
epid=""
# faults.yaml sets master_heartbeat_timeout_ms (but for `fewer`): a drive
# asked to watch the master must have 0x1016, which the strict profile (the
# default) lacks; --without-object 0x1016 still removes it (sdo_abort, fewer).
optional=()
[[ $mhb -gt 0 ]] && optional=(--optional-objects-absent false)
start_emu() {  # start_emu LOG-NAME [cia402-emu options]
  local log="$1"
  shift
  "$emu" --interface vcan0 --node 2 --verbose "${optional[@]}" "$@" > "$art/$log" 2>&1 &
  epid=$!
  pids+=("$epid")
}
tag() { "$ctl" get "$1" 2>/dev/null || echo "?"; }
wait_tag() {  # wait_tag TAG VALUE SECONDS
  for ((i = 0; i < $3 * 10; i++)); do
    [[ "$(tag "$1")" == "$2" ]] && return 0
    kill -0 "$dpid" 2>/dev/null || break
    sleep 0.1
  done
  cat "$art"/canmotiond*.log >&2
  fail "tag $1 did not become $2 within $3 s (it is $(tag "$1"))"
}
# Lines of the candump trace, counted now, and a wait for a frame after them.
lines() { wc -l < "$trace"; }
wait_frame() {  # wait_frame FROM_LINE REGEX SECONDS
  for ((i = 0; i < $3 * 10; i++)); do
    tail -n +"$(($1 + 1))" "$trace" | grep -qE "$2" && return 0
    sleep 0.1
  done
  fail "no frame matching '$2' in the trace within $3 s"
}
finish_daemon() {  # the script ends; canmotiond must exit 0
  local status=0
  wait "$dpid" || status=$?
  cat "$art/canmotiond$1.log"
  [[ $status == 0 ]] || { cat "$art"/emu-*.log >&2; fail "canmotiond exited with status $status"; }
}
settle() {  # wait (bounded, 60 s) until the trace has not grown for 1.5 s
  local last=-1 n i same=0
  for ((i = 0; i < 120 && same < 3; i++)); do
    n=$(lines)
    if [[ $n == "$last" ]]; then same=$((same + 1)); else same=0; fi
    last=$n
    sleep 0.5
  done
}
# A working drive starts (boot-up); once canmotiond has configured and
# started it, the script may go on (Go = 1).
replace_drive() {  # replace_drive LOG-NAME
  local from
  from=$(lines)
  mark replace
  start_emu "$1"
  wait_frame "$from" ' vcan0 000#0102$' 60
  "$ctl" set Go 1
}
mark() { echo "$1 $(lines) $(date +%s.%N)" >> "$art/marks.txt"; }  # NAME TRACE-LINE WALL-TIME
: > "$art/marks.txt"

case $scn in
  vanish)
    start_daemon "$script" ""
    start_emu emu-1.log
    wait_tag Step 1 60
    sleep 0.5
    mark kill
    kill -KILL "$epid"
    wait "$epid" 2>/dev/null || true
    wait_tag Step 2 30
    replace_drive emu-2.log  # the same drive started again: boot-up, configuration, NMT start
    finish_daemon ""
    ;;
  emcy)
    start_daemon "$script" ""
    # Strict: the injected fault's cause lasts 20 SYNCs and a reset meanwhile
    # is refused; the master repeats the reset edge until the drive takes it.
    start_emu emu-1.log
    wait_tag Step 1 60
    sleep 0.5
    mark inject
    cansend vcan0 602#2B00200000FF0000  # SDO write 0x2000 = 0xFF00: the drive faults with that EMCY
    finish_daemon ""
    ;;
  reboot)
    start_daemon "$script" ""
    start_emu emu-1.log
    wait_tag Step 1 60
    sleep 0.5
    mark reset
    cansend vcan0 000#8102  # NMT reset node 2
    finish_daemon ""
    ;;
  sdo_timeout)
    start_daemon "$script" ""
    # A node that is there (boot-up, pre-operational heartbeats) but never answers SDO.
    (
      cansend vcan0 702#00
      while :; do
        sleep 0.1
        cansend vcan0 702#7F
      done
    ) &
    fake=$!
    pids+=("$fake")
    wait_tag Step 1 90
    kill "$fake"
    wait "$fake" 2>/dev/null || true
    replace_drive emu-1.log
    finish_daemon ""
    ;;
  sdo_abort)
    start_daemon "$script" ""
    start_emu emu-1.log --without-object 0x1016
    wait_tag Step 1 90
    kill -TERM "$epid"
    wait "$epid" 2>/dev/null || true
    replace_drive emu-2.log
    finish_daemon ""
    ;;
  master)
    start_daemon "$script" ""
    # The strict drive's 0x1029:1 = 0: with the master's heartbeat it also
    # leaves NMT operational (pre-operational); the restarted master
    # configures it from there.
    start_emu emu-1.log --heartbeat-reaction fault
    wait_tag Step 1 60
    sleep 0.5
    mark kill
    # $dpid is timeout(1); canmotiond is its child (stdbuf execs it).
    kill -KILL "$(pgrep -P "$dpid")"
    wait "$dpid" 2>/dev/null || true
    # The drive watches the master (0x1016 = 1000 ms): wait for its EMCY 0x8130.
    wait_frame "$(awk '$1 == "kill" { print $2 }' "$art/marks.txt")" ' vcan0 082#3081' 30
    sleep 0.5
    mark restart
    start_daemon "$here/master-restart.script" "-2"
    finish_daemon "-2"
    ;;
  fewer)
    start_daemon "$script" ""
    start_emu emu-1.log --without-object 0x1016 --without-object 0x1402 --without-object 0x1403 \
      --without-object 0x1602 --without-object 0x1603 --without-object 0x1802 --without-object 0x1803 \
      --without-object 0x1A02 --without-object 0x1A03
    finish_daemon ""
    ;;
  *) fail "unknown scenario" ;;
esac
# Stop the drives (their heartbeats would keep the trace growing), then let
# candump, which lags behind under emulation, catch up before it is stopped.
cleanup
settle
rm -rf "$sockdir"
trap - EXIT
echo "run-fault: $scn: done; trace has $(lines) frames"
