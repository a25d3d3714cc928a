#!/usr/bin/env bash
# canmotiond with drive.eds (issue 17), as a user runs it (--sim):
# 1. a configuration needing an object the drive's EDS lacks is refused
#    (exit 2) naming the axis, the object, the EDS file:line and the YAML
#    key, before any frame (no trace file is written);
# 2. the minimal drive (no 0x1016, 2 PDOs each way) boots, enables and
#    moves; the trace shows no SDO download to an object its EDS lacks;
# 3. --write-dcf writes one DCF per node that our own reader parses back
#    (cia402-emu --eds ... --check-args).
# 4. cantrace --eds names node 2's objects by the EDS.
# Usage: eds-daemon-test.sh CANMOTIOND CIA402_EMU EXAMPLES_DIR WORKDIR CANTRACE
set -uo pipefail
bin="$1" emu="$2" ex="$3" work="$4" cantrace="$5"
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"; mkdir -p "$work"
fail() { echo "eds-daemon-test: FAIL: $*" >&2; exit 1; }
cp "$ex/minimal-drive.eds" "$work/"
conf() {  # $1: extra drive keys (one line, already indented)
  cat <<YAML
controller: {period_ms: 1, priority: 0, lock_memory: false}
buses:
  - {name: can0, interface: sim}
drives:
  eds: minimal-drive.eds
  heartbeat_ms: 100
$1
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
}

# 1. 0x1016 asked for explicitly: refused.
conf "  master_heartbeat_timeout_ms: 300" > "$work/refused.yaml"
out=$("$bin" --config "$work/refused.yaml" --sim --duration 1 --trace "$work/refused.log" 2>&1); rc=$?
[[ $rc == 2 ]] || fail "refused configuration: exit $rc, want 2: $out"
line=$(grep -n '^\[OptionalObjects\]' "$ex/minimal-drive.eds" | cut -d: -f1)
grep -qF "error: axes[0].drive.master_heartbeat_timeout_ms (or drives.master_heartbeat_timeout_ms): axis 'X' (node 2): $work/minimal-drive.eds:$line: 0x1016:01 (Consumer heartbeat time) is not in the EDS" <<<"$out" ||
  fail "refusal message: $out"
grep -q "nothing was sent on any bus" <<<"$out" || fail "no 'nothing was sent' line: $out"
[[ ! -e "$work/refused.log" ]] || fail "a trace was written for a refused configuration"

# 2. The default heartbeat: 0x1016 left out; boot, enable, move.
conf "" > "$work/ok.yaml"
cat > "$work/move.script" <<'S'
MSO(X, mso);
WAIT UNTIL mso.DN TIMEOUT 5;
MAM(X, mam, Absolute, 20, 50, UnitsPerSec, 500, UnitsPerSec2, 500, UnitsPerSec2, Trapezoidal, 100, 100, %ofTime, Disabled, Programmed, 0, None, 0, 0);
WAIT UNTIL mam.PC TIMEOUT 5;
WAIT 0.1;
PRINT X.ActualPosition;
S
out=$("$bin" --config "$work/ok.yaml" --sim --script "$work/move.script" --trace "$work/ok.log" 2>&1); rc=$?
[[ $rc == 0 ]] || fail "minimal drive run: exit $rc: $out"
grep -q "minimal-drive.eds has no 0x1016:01: the write is left out" <<<"$out" || fail "no warning for the left-out 0x1016: $out"
grep -qE "X.ActualPosition=(20|20\.0[0-9]*|19\.99[0-9]*)$" <<<"$out" || fail "the move did not reach 20 mm: $out"
"$here/tools/check-trace-writes.sh" "$work/ok.log" "$ex/minimal-drive.eds" 2 || fail "trace check"

# 3. --write-dcf: one DCF per node, read back by our EDS reader.
out=$("$bin" --config "$work/ok.yaml" --write-dcf "$work/dcf" 2>&1); rc=$?
[[ $rc == 0 ]] || fail "--write-dcf exit $rc: $out"
[[ -s "$work/dcf/X.dcf" ]] || fail "no $work/dcf/X.dcf: $out"
grep -q '^NodeId=2$' "$work/dcf/X.dcf" || fail "DCF without NodeId=2"
grep -q '^\[1016' "$work/dcf/X.dcf" && fail "the DCF has 0x1016, which the master does not write"
"$emu" -i vcan0 -n 2 --eds "$work/dcf/X.dcf" --check-args >/dev/null || fail "the DCF does not parse back"
# 4. A vendor's name in the EDS shows in cantrace; without --eds, CiA 402's.
sed 's/^ParameterName=Modes of operation$/ParameterName=Betriebsart/' "$ex/minimal-drive.eds" > "$work/vendor.eds"
"$cantrace" --eds 2="$work/vendor.eds" "$work/ok.log" | grep -q 'SDO node 2 write 0x6060:00 Betriebsart = 8' ||
  fail "cantrace --eds: no vendor name for 0x6060"
"$cantrace" "$work/ok.log" | grep -q 'SDO node 2 write 0x6060:00 Modes of operation = 8' || fail "cantrace: no CiA 402 name"
echo "eds-daemon-test: refusal before any frame (exit 2), minimal drive moved without writing absent objects, DCF parses back, cantrace names objects by the EDS"
