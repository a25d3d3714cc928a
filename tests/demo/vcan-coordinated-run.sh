#!/usr/bin/env bash
# vcan.demo_coordinated, COMMAND part (runs inside the VM, vcan0 up, candump
# -L writing $CANMOTION_TRACE): the coordinated motion demo (issue 14,
# coordinated.yaml + coordinated.script) on real SocketCAN, canmotiond in
# real time and cia402-emu (nodes 2 and 3) as separate processes.
#   vcan-coordinated-run.sh CANMOTIOND CIA402_EMU EXAMPLES_DIR PERIOD_MS
# 1. config: coordinated.yaml with can0 -> vcan0 and period PERIOD_MS
#    (make-vcan-config.sh), SDO timeout 2 s and transition timeout 5 s;
# 2. canmotiond --config ... --script coordinated.script --csv, then the
#    emulator; canmotiond must exit 0 and print the script's PRINT lines
#    with the rectangle back at (0, 0), the half circle at (60, 0) and the
#    master-driven pass at (160, 30);
# 3. the CSV: the last row of X and of Y commands (160, 30) exactly and the
#    drives' actual positions there within 0.01 mm (behaviour, not timing).
# Artefacts: coordinated-vcan.yaml, canmotiond.log, xy.csv, emu-vcan0.log.
set -euo pipefail
daemon="$1" emu="$2" examples="$3" period="$4"
art="$CANMOTION_ARTIFACTS" trace="$CANMOTION_TRACE"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
fail() { echo "vcan-coordinated: FAIL: $*" >&2; exit 1; }

cfg="$art/coordinated-vcan.yaml"
"$here/make-vcan-config.sh" "$examples/coordinated.yaml" "$period" > "$cfg"
# The VM (TCG, loaded host) answers SDOs late and stalls: seen aborting the boot
# configuration at the default 200 ms SDO timeout and losing heartbeats after
# 150 ms. Behaviour, not timing, is checked here: heartbeat 1 s, SDO 2 s.
printf 'drives:\n  heartbeat_ms: 1000\n  timeouts: {sdo_ms: 2000, transition_ms: 5000}\n' >> "$cfg"
csv="$art/xy.csv"
emu_pid=""
cleanup() { [[ -z "$emu_pid" ]] || { kill -TERM "$emu_pid" 2>/dev/null || true; wait "$emu_pid" 2>/dev/null || true; }; }
trap cleanup EXIT
status=0
timeout -s INT -k 30 240 stdbuf -oL "$daemon" --config "$cfg" --script "$examples/coordinated.script" --csv "$csv" \
  > "$art/canmotiond.log" 2>&1 &
dpid=$!
for ((i = 0; i < 600; i++)); do   # the banner is printed after the bus is open
  grep -q '^canmotiond: .* buses (real time)' "$art/canmotiond.log" && break
  kill -0 "$dpid" 2>/dev/null || break
  sleep 0.05
done
"$emu" --interface vcan0 --node 2 --node 3 --verbose > "$art/emu-vcan0.log" 2>&1 &
emu_pid=$!
wait "$dpid" || status=$?
cat "$art/canmotiond.log"
[[ $status == 0 ]] || { cat "$art/emu-vcan0.log" >&2; fail "canmotiond exited with status $status"; }
expect() { grep -Eq "$1" "$art/canmotiond.log" || fail "$2: no line matching /$1/ in canmotiond's output"; }
expect 'X\.CommandPosition=0 Y\.CommandPosition=0 XY\.MoveStatus=0' "rectangle end"
expect 'X\.CommandPosition=60 Y\.CommandPosition=0$' "arc end"
expect 'X\.CommandPosition=160 Y\.CommandPosition=30 XY\.CommandPosition\[0\]=160 XY\.CommandPosition\[1\]=30' "pass end"
# CSV: cycle,time,axis,cmd_pos,act_pos,cmd_vel,act_vel,motion_status,axis_status; the last row per axis
awk -F, '
  $3 == "X" { xc = $4; xa = $5 } $3 == "Y" { yc = $4; ya = $5 }
  END {
    printf "path end: command (%s, %s), actual (%s, %s)\n", xc, yc, xa, ya
    d = (xa - 160) ^ 2 + (ya - 30) ^ 2
    exit !(xc == 160 && yc == 30 && d <= 1e-4)
  }' "$csv" || fail "the path end in the CSV is not (160, 30) ($csv)"
grep -q ' vcan0 702#00$' "$trace" && grep -q ' vcan0 703#00$' "$trace" || fail "no boot-up of nodes 2 and 3 in the trace"
echo "vcan-coordinated: PASS"
