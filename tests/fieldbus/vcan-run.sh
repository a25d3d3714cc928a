#!/usr/bin/env bash
# vcan integration test, COMMAND part: cia402-emu (nodes 2 and 3) and the
# master test program as separate processes on vcan0, then a raw cansend SDO
# upload of 0x1000 from node 2.
#   vcan-run.sh CIA402_EMU FIELDBUS_VCAN_MASTER CYCLE_US RAMP_CYCLES
set -euo pipefail
emu="$1" master="$2" cycle_us="$3" ramp="$4"
art="$CANMOTION_ARTIFACTS"
"$emu" --interface vcan0 --node 2 --node 3 --verbose > "$art/emu.log" 2>&1 &
epid=$!
trap 'kill $epid 2>/dev/null || true' EXIT
# Wait for both boot-up messages in the trace (the emulator is up).
for ((i = 0; i < 400; i++)); do
  grep -q ' 702#00$' "$CANMOTION_TRACE" 2>/dev/null && grep -q ' 703#00$' "$CANMOTION_TRACE" && break
  sleep 0.05
done
grep -q ' 703#00$' "$CANMOTION_TRACE" || { echo "vcan-run: cia402-emu sent no boot-up" >&2; cat "$art/emu.log" >&2; exit 1; }
status=0
"$master" vcan0 "$cycle_us" "$ramp" 2 3 > "$art/master.log" 2>&1 || status=$?
cat "$art/master.log"
[[ $status == 0 ]] || { echo "vcan-run: master failed ($status)" >&2; cat "$art/emu.log" >&2; exit 1; }
# A raw SDO upload of 0x1000 (device type) from node 2, like any CANopen tool.
echo "CANSEND-MARK" > "$art/cansend.mark"
cansend vcan0 602#4000100000000000
# An independent CANopen tool (plain can-utils cansend, no canmotion code)
# drives node 3 in CSP: reset node, then in Pre-operational the CiA 301 PDO
# remap a real drive needs (its power-on PDOs are the CiA 402 predefined
# ones: RPDO1 = controlword, TPDO1 = statusword, event-driven): RPDO1 =
# controlword + target position, TPDO1 = statusword + position actual, both
# synchronous (type 1), mode 8 (CSP); NMT start; RPDO1 through Shutdown /
# Switch on / Enable operation, each applied at a SYNC, then a target of
# 100100 counts (the drive is at 100000). Each SDO write waits for its reply
# (583#60...), as a tool would.
boots() { grep -c ' 703#00$' "$CANMOTION_TRACE" || true; }
booted=$(boots)
cansend vcan0 000#8103
for ((i = 0; i < 200; i++)); do
  [[ $(boots) -gt $booted ]] && break
  sleep 0.05
done
sleep 0.3  # the drive's DC bus charges for 100 ms after a reset (Not ready to switch on)
replies() { grep -c ' 583#60' "$CANMOTION_TRACE" || true; }
sdo3() {
  local before; before=$(replies)
  cansend vcan0 "603#$1"
  for ((j = 0; j < 200; j++)); do
    [[ $(replies) -gt $before ]] && return 0
    grep -q " 583#80${1:2:6}" "$CANMOTION_TRACE" && { echo "vcan-run: node 3 aborted SDO write 603#$1" >&2; return 0; }
    sleep 0.05
  done
  echo "vcan-run: no reply from node 3 to 603#$1" >&2
}
for w in 2300140103020080 2F00160000000000 2300160110004060 2300160220007A60 2F00160002000000 \
         2F00140201000000 2300140103020000 \
         2300180183010080 2F001A0000000000 23001A0110004160 23001A0220006460 2F001A0002000000 \
         2F00180201000000 2300180183010000 2F60600008000000; do
  sdo3 "$w"
done
cansend vcan0 000#0103
for cw in 0600 0700 0F00; do
  cansend vcan0 203#${cw}A0860100
  cansend vcan0 080#
done
for ((i = 0; i < 12; i++)); do
  cansend vcan0 203#0F0004870100
  cansend vcan0 080#
done
# candump runs slower than the test under emulation and drops what is still
# queued when it is stopped: wait until it has written the reply (everything
# before it is then in the trace too).
for ((i = 0; i < 600; i++)); do
  grep -q ' 582#4300100092010200$' "$CANMOTION_TRACE" && grep -q ' 183#371204870100$' "$CANMOTION_TRACE" && break
  sleep 0.1
done
kill -TERM $epid
wait $epid || true
trap - EXIT
cat "$art/emu.log"
