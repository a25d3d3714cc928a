#!/usr/bin/env bash
# vcan (issue 17), COMMAND part inside tests/vcan/run-vcan-test: canmotiond
# drives `cia402-emu --eds minimal-drive.eds` (no 0x1016, two PDOs each way)
# through boot, enable and a move, as separate processes on vcan0, with
# `drive.eds: minimal-drive.eds` in its configuration. The CHECK part
# (tools/check-trace-writes.sh on the candump trace) proves the master never
# wrote an object the EDS lacks.
#   vcan-minimal.sh CANMOTIOND CIA402_EMU EDS PERIOD_MS
set -euo pipefail
daemon="$1" emu="$2" eds="$3" period="$4"
art="$CANMOTION_ARTIFACTS"
fail() { echo "vcan-minimal: FAIL: $*" >&2; exit 1; }
cat > "$art/minimal.yaml" <<YAML
controller: {period_ms: $period, priority: 0, lock_memory: false}
buses:
  - {name: can0, interface: vcan0, master_heartbeat_ms: 100}
drives:
  eds: $eds                # master_heartbeat_timeout_ms not set: 0x1016 is optional, left out
  heartbeat_ms: 200
  timeouts: {sdo_ms: 500, boot_ms: 3000, transition_ms: 1000}
axes:
  - name: X
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    units: mm
    conversion_constant: 1000
    max_speed: 100
    max_accel: 1000
    max_decel: 1000
YAML
cat > "$art/minimal.script" <<'S'
MSO(X, mso1);
WAIT UNTIL mso1.DN TIMEOUT 30;
MAM(X, mam1, Incremental, 20, 20, UnitsPerSec, 200, UnitsPerSec2, 200, UnitsPerSec2, Trapezoidal, 100, 100, %ofTime, Disabled, Programmed, 0, None, 0, 0);
WAIT UNTIL mam1.PC TIMEOUT 30;
PRINT mam1.PC, X.AxisFault, X.ActualPosition;
WAIT 0.2;
S
"$emu" --interface vcan0 --node 2 --eds "$eds" --verbose > "$art/emu.log" 2>&1 &
epid=$!
trap 'kill -TERM $epid 2>/dev/null || true; wait $epid 2>/dev/null || true' EXIT
rc=0
timeout -s INT -k 30 300 "$daemon" --config "$art/minimal.yaml" --script "$art/minimal.script" \
  --trace "$art/canmotiond-trace.log" > "$art/canmotiond.log" 2>&1 || rc=$?
cat "$art/canmotiond.log"
[[ $rc == 0 ]] || fail "canmotiond exit $rc"
# The move completes without an axis fault (the actual position lags the
# command on the real bus at PC: the strict drive applies an RPDO at the
# next SYNC, so the script waits 0.2 s before its end disables the drive),
# and the axis ends at 20 mm.
grep -qE '^t=[0-9.]+ mam1\.PC=1 X\.AxisFault=0 X\.ActualPosition=' "$art/canmotiond.log" || fail "the move did not complete"
grep -qE '^summary: axis X +node +2 .*final position 20\.0000 ' "$art/canmotiond.log" || fail "the axis did not end at 20 mm"
grep -q "minimal-drive.eds has no 0x1016:01: the write is left out" "$art/canmotiond.log" || fail "no note on 0x1016"
echo "vcan-minimal: boot, enable and a 20 mm move against cia402-emu --eds $(basename "$eds")"
