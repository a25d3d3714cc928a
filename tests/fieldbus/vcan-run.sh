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
# drives node 3 in CSP: reset node, NMT start, the default RPDO1 (controlword
# + target position) through Shutdown / Switch on / Enable operation, each
# applied at a SYNC, then a target of 100100 counts (the drive is at 100000).
cansend vcan0 000#8103
sleep 0.3
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
