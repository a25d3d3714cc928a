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
# candump runs slower than the test under emulation and drops what is still
# queued when it is stopped: wait until it has written the reply (everything
# before it is then in the trace too).
for ((i = 0; i < 300; i++)); do
  grep -q ' 582#4300100092010200$' "$CANMOTION_TRACE" && break
  sleep 0.1
done
kill -TERM $epid
wait $epid || true
trap - EXIT
cat "$art/emu.log"
