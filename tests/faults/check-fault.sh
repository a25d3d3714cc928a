#!/usr/bin/env bash
# The fault matrix on real SocketCAN, CHECK part: the candump -L trace
# ($CANMOTION_TRACE), canmotiond's own trace and log (artefacts of
# run-fault.sh). Writes the measured reaction times to measure.txt.
#   check-fault.sh SCENARIO PERIOD_MS
# Times: candump's stamps are the kernel's (CLOCK_REALTIME) for every frame;
# canmotiond's trace has its receive stamps and its cycle times on one clock
# (CLOCK_MONOTONIC, printed on the realtime scale), so a "first cycle after
# the timeout" criterion is checked there exactly. The VM runs under TCG
# emulation: its figures are behaviour and upper bounds, not performance.
set -euo pipefail
scn="$1" period_ms="$2"
trace="$CANMOTION_TRACE"
art="${CANMOTION_ARTIFACTS:-$(dirname "$trace")}"
fail() { echo "check-fault: $scn: FAIL: $*" >&2; exit 1; }
say() { echo "check-fault: $scn: $*"; }
measure() { echo "$scn: $*" >> "$art/measure.txt"; say "measured: $*"; }
: > "$art/measure.txt"
[[ -s "$trace" ]] || fail "empty trace $trace"
log="$art/canmotiond.log"
# awk helpers (mawk has no strtonum/and): hex string -> number, bitwise and,
# the little-endian 16-bit word at character `at` of a candump data field.
lib='function hex(s,  i, v) { v = 0; for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789ABCDEF", toupper(substr(s, i, 1))) - 1; return v }
function band(a, b,  r, k) { r = 0; for (k = 1; a > 0 && b > 0; k *= 2) { if (a % 2 == 1 && b % 2 == 1) r += k; a = int(a / 2); b = int(b / 2) } return r }
function word(d, at) { return hex(substr(d, at + 2, 2) substr(d, at, 2)) }'

# The script's last PRINT: the move after the recovery arrived, no axis fault.
final_ok() {  # final_ok LOG
  grep -qE '^t=[0-9.]+ mam1\.PC=1 X\.AxisFault=0 X\.ActualPosition=' "$1" ||
    { cat "$1" >&2; fail "the recovery's move did not complete (no 'mam1.PC=1 X.AxisFault=0' line in $(basename "$1"))"; }
  say "recovery: $(grep -E '^t=[0-9.]+ mam1\.PC=1' "$1")"
}
# First line number (>= $2) of a frame matching regex $1 in file $3 (default: the candump trace); 0 if none.
first() { awk -v re="$1" -v from="${2:-1}" 'NR >= from && $0 ~ re { print NR; found = 1; exit } END { if (!found) print 0 }' "${3:-$trace}"; }
count() { awk -v re="$1" -v from="${2:-1}" 'NR >= from && $0 ~ re { n++ } END { print n + 0 }' "${3:-$trace}"; }
t_of() { sed -n "${1}p" "${2:-$trace}" | sed -E 's/^\(([0-9.]+)\).*/\1/'; }
ms() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", (b - a) * 1000 }'; }
# Boot-up -> SDO configuration (0x6060 = 8) -> NMT start, from line $1; prints the NMT start's line.
configured_after() {
  local b s n
  b=$(first ' vcan0 702#00$' "$1")
  [[ $b -gt 0 ]] || fail "no boot-up of node 2 after line $1"
  s=$(first ' vcan0 602#2F60600008' "$b")
  [[ $s -gt 0 ]] || fail "no SDO configuration (0x6060 = 8) after the boot-up at line $b"
  n=$(first ' vcan0 000#0102$' "$s")
  [[ $n -gt 0 ]] || fail "no NMT start after the configuration at line $s"
  echo "$n"
}
# The drive enabled and moving again after line $1: RPDOs 0x0006, 0x0007, 0x000F, then
# a TPDO in Operation enabled.
reenabled_after() {
  local a b c d
  a=$(first ' vcan0 202#0600' "$1"); b=$(first ' vcan0 202#0700' "$a"); c=$(first ' vcan0 202#0F00' "$b")
  [[ $a -gt 0 && $b -gt 0 && $c -gt 0 ]] || fail "no enable sequence (controlword 6, 7, 15) after line $1"
  d=$(awk -v from="$c" "$lib"' NR > from && $3 ~ /^182#/ { if (band(word($3, 5), 111) == 39) { print NR; exit } }' "$trace")
  [[ -n $d ]] || fail "no TPDO in Operation enabled after the enable sequence (line $c)"
  say "re-enabled: controlword 6/7/15 at lines $a/$b/$c, Operation enabled at line $d"
}

case $scn in
  vanish)
    final_ok "$log"
    # Two boot-ups; the second is configured and the drive re-enabled.
    [[ $(count ' vcan0 702#00$') -eq 2 ]] || fail "expected 2 boot-ups of node 2, got $(count ' vcan0 702#00$')"
    b1=$(first ' vcan0 702#00$')
    n2=$(configured_after $((b1 + 1)))
    reenabled_after "$n2"
    # Heartbeat loss, in canmotiond's own clock: the RPDO of the cycle that
    # detected it is the first with controlword 0 after enabling; the cycle
    # before must be within the consumer time of the last heartbeat, that
    # cycle beyond it.
    dtrace="$art/canmotiond-trace.log"
    read -r t_hb t_prev t_react <<<"$(awk '
      { t = substr($1, 2, length($1) - 2) + 0; split($3, f, "#") }
      f[1] == "702" && f[2] == "05" { hb = t }
      f[1] == "202" { cw = substr(f[2], 1, 4)
        if (cw == "0F00") enabled = 1
        else if (enabled && cw == "0000") { printf "%.6f %.6f %.6f\n", hb, prev, t; exit }
        prev = t }' "$dtrace")"
    [[ -n ${t_react:-} ]] || fail "no reaction (controlword 0 after enabling) in canmotiond's trace"
    consumer=0.600  # 3 x drives.heartbeat_ms (faults.yaml.in)
    awk -v hb="$t_hb" -v p="$t_prev" -v r="$t_react" -v c="$consumer" 'BEGIN {
      if (p - hb > c + 2e-6) { printf "the cycle at +%.1f ms (after the last heartbeat) was already past the consumer time\n", (p - hb) * 1000; exit 1 }
      if (r - hb <= c - 2e-6) { printf "reacted at +%.1f ms, before the consumer time\n", (r - hb) * 1000; exit 1 } }' ||
      fail "the lost heartbeat was not detected in the first cycle after the consumer time"
    measure "heartbeat lost: axis reaction $(ms "$t_hb" "$t_react") ms after the drive's last heartbeat (consumer 600 ms; cycle before it at $(ms "$t_hb" "$t_prev") ms; canmotiond's clock)"
    # The same on candump's stamps (independent of canmotiond's clock handling).
    k=$(awk '$1 == "kill" { print $2 }' "$art/marks.txt")
    c_react=$(first ' vcan0 202#0000' "$k")
    [[ $c_react -gt 0 ]] || fail "no controlword 0 after the kill in the candump trace"
    c_hb=$(awk -v to="$c_react" 'NR < to && $3 == "702#05" { last = NR } END { print last + 0 }' "$trace")
    measure "heartbeat lost (candump stamps): $(ms "$(t_of "$c_hb")" "$(t_of "$c_react")") ms from the last heartbeat to the disabling RPDO; consumer + 1 cycle = $(awk -v p="$period_ms" 'BEGIN { print 600 + p }') ms"
    ;;
  emcy)
    final_ok "$log"
    e=$(first ' vcan0 082#00FF')
    [[ $e -gt 0 ]] || fail "no EMCY 0xFF00 from node 2"
    r0=$(awk -v from="$e" 'NR > from && $3 ~ /^202#0000/ { print NR; exit }' "$trace")
    [[ -n $r0 ]] || fail "no controlword 0 after the EMCY"
    measure "EMCY 0xFF00 -> controlword 0 (drive fault seen): $(ms "$(t_of "$e")" "$(t_of "$r0")") ms"
    # Rising edges of bit 7 (the fault reset) after the EMCY: the strict
    # drive refuses them while the fault's cause lasts (20 SYNCs), the master
    # repeats the edge (every 50 ms) until one is taken: the last one.
    read -r edges first_edge last_edge <<<"$(awk -v from="$e" "$lib"' NR > from && $3 ~ /^202#/ {
        b = band(word($3, 5), 128) != 0
        if (b && !last) { n++; if (!at) at = NR; lat = NR } last = b }
      END { print n + 0, at + 0, lat + 0 }' "$trace")"
    [[ $edges -ge 1 ]] || fail "no fault reset (bit 7 rising) after the EMCY"
    say "fault-reset edges after the EMCY: $edges (repeated while the drive refused them)"
    [[ $(sed -n "${first_edge}p" "$trace" | awk '{ print substr($3, 5, 4) }') == 8000 ]] || fail "the fault reset is not controlword 0x0080: $(sed -n "${first_edge}p" "$trace")"
    # The drive leaves Fault at the next SYNC after the edge it takes: its next TPDO shows Switch on disabled.
    first_edge=$last_edge
    read -r sod_line n_tpdo <<<"$(awk -v from="$first_edge" "$lib"' NR > from && $3 ~ /^182#/ { k++
        if (band(word($3, 5), 79) == 64) { print NR, k; exit } }' "$trace")"
    [[ -n ${sod_line:-} && $n_tpdo -le 3 ]] || fail "the drive did not leave Fault within 3 TPDOs of the last fault reset"
    measure "fault reset (bit 7) -> Switch on disabled in the drive's TPDO: $(ms "$(t_of "$first_edge")" "$(t_of "$sod_line")") ms ($n_tpdo TPDO)"
    reenabled_after "$sod_line"
    ;;
  reboot)
    final_ok "$log"
    rs=$(first ' vcan0 000#8102$')
    [[ $rs -gt 0 ]] || fail "no NMT reset node in the trace"
    n2=$(configured_after "$rs")
    b2=$(first ' vcan0 702#00$' "$rs")
    s2=$(first ' vcan0 602#' "$b2")
    measure "unexpected boot-up -> first SDO configuration request: $(ms "$(t_of "$b2")" "$(t_of "$s2")") ms; -> NMT start $(ms "$(t_of "$b2")" "$(t_of "$n2")") ms"
    reenabled_after "$n2"
    ;;
  sdo_timeout | sdo_abort)
    final_ok "$log"
    grep -qE '^t=[0-9.]+ mso0\.ER=1 mso0\.ERR=11 ' "$log" || { cat "$log" >&2; fail "MSO on the failed drive did not end with ERR 11"; }
    say "MSO on the failed drive: $(grep -E '^t=[0-9.]+ mso0\.ER=' "$log")"
    why=$(grep -m1 -E 'configuration (write to|read of)' "$log") || fail "canmotiond did not explain the failed boot"
    say "message: $why"
    if [[ $scn == sdo_timeout ]]; then
      parts=("node 2: configuration read of 0x1000:0" "aborted with 0x05040000" "the drive did not answer")
      lo=1000 hi=1500  # sdo_ms 500, tried twice (one retry): 2 x 500 ms + up to 3 cycles
    else
      parts=("node 2: configuration write to 0x1016:1" "aborted with 0x06020000 (object does not exist in the object dictionary)"
             "the drive refused it" "set axes[0].drive.master_heartbeat_timeout_ms (or drives.master_heartbeat_timeout_ms): 0")
      lo=0 hi=1000
      grep -qE ' vcan0 582#80161001' "$trace" || fail "no SDO abort of 0x1016:1 in the trace"
    fi
    for p in "${parts[@]}"; do [[ $why == *"$p"* ]] || fail "the message lacks '$p'"; done
    waited=$(sed -E 's/.* after ([0-9.]+) ms.*/\1/' <<<"$why")
    awk -v w="$waited" -v lo="$lo" -v hi="$hi" 'BEGIN { exit !(w >= lo && w < hi) }' ||
      fail "the message says 'after $waited ms' (expected $lo..$hi ms: both times on one clock)"
    measure "failed boot: the message's duration $waited ms"
    # The working drive's boot-up is configured without a restart of canmotiond.
    rp=$(awk '$1 == "replace" { print $2 }' "$art/marks.txt")
    n2=$(configured_after $((rp + 1)))
    reenabled_after "$n2"
    ;;
  master)
    final_ok "$art/canmotiond-2.log"
    k=$(awk '$1 == "kill" { print $2 }' "$art/marks.txt")
    e=$(first ' vcan0 082#3081' "$k")
    [[ $e -gt 0 ]] || fail "no EMCY 0x8130 (master heartbeat lost) after canmotiond was killed"
    hb=$(awk -v to="$e" 'NR < to && $3 ~ /^77F#05$/ { last = NR } END { print last + 0 }' "$trace")
    [[ $hb -gt 0 ]] || fail "no master heartbeat before the EMCY"
    dt=$(ms "$(t_of "$hb")" "$(t_of "$e")")
    awk -v d="$dt" 'BEGIN { exit !(d > 995 && d <= 1500) }' ||
      fail "the drive reacted $dt ms after the master's last heartbeat (0x1016: 1000 ms; VM bound 1500 ms)"
    measure "master killed: the drive's EMCY 0x8130 $dt ms after the master's last heartbeat (0x1016 = 1000 ms)"
    # Nothing from canmotiond between its kill and its restart.
    rs=$(awk '$1 == "restart" { print $2 }' "$art/marks.txt")
    [[ $(awk -v a="$e" -v b="$rs" 'NR > a && NR <= b && $3 ~ /^(080|202|77F)#/ { n++ } END { print n + 0 }' "$trace") -eq 0 ]] ||
      fail "frames of canmotiond after it was killed"
    n2=$(first ' vcan0 000#0102$' "$rs")
    [[ $n2 -gt 0 ]] || fail "the restarted canmotiond did not start the node"
    # The strict drive (0x1029:1 = 0) went pre-operational with its fault: its
    # heartbeat shows 0x7F between the EMCY and the NMT start. The restarted
    # canmotiond configures it as it is (0x6060 = 8 written before the NMT
    # start) and needs no NMT enter pre-operational (000#8002, sent only to
    # an operational or stopped node).
    pre=$(awk -v a="$e" -v b="$n2" 'NR > a && NR < b && $3 == "702#7F" { n++ } END { print n + 0 }' "$trace")
    [[ $pre -gt 0 ]] || fail "the drive's heartbeat never showed pre-operational (702#7F) after its EMCY 0x8130 (0x1029:1 = 0)"
    c2=$(first ' vcan0 602#2F60600008' "$rs")
    [[ $c2 -gt 0 && $c2 -lt $n2 ]] || fail "the restarted canmotiond did not configure the node (0x6060 = 8) before starting it"
    [[ $(awk -v a="$rs" -v b="$n2" 'NR > a && NR < b && $3 == "000#8002" { n++ } END { print n + 0 }' "$trace") -eq 0 ]] ||
      fail "NMT enter pre-operational sent to a node that was pre-operational"
    say "the drive was pre-operational after its EMCY ($pre heartbeats 702#7F); configured at line $c2, started at line $n2"
    reenabled_after "$n2"
    ;;
  fewer)
    final_ok "$log"
    [[ $(count ' vcan0 602#2[3F]161001') -eq 0 ]] || fail "0x1016 was written although master_heartbeat_timeout_ms is 0"
    # SDO abort responses 582#80 <index LE> <sub> <code LE>, as 0xINDEX:SUB=0xCODE.
    aborts=$(awk '$3 ~ /^582#80/ { d = substr($3, 5); printf "0x%s%s:%d=0x%s%s%s%s\n", substr(d, 5, 2), substr(d, 3, 2), substr(d, 7, 2) + 0,
      substr(d, 15, 2), substr(d, 13, 2), substr(d, 11, 2), substr(d, 9, 2) }' "$trace" | sort | tr '\n' ' ')
    # and the strict drive's read-only 0x60C2:2 (the master then reads it and
    # writes 0x60C2:1 in its unit); the axis has no drive.eds, so the factor
    # group is read at boot (README "Drive units"), and this drive has none of
    # it: 0x06020000 for each (increments).
    units="0x608F:1=0x06020000 0x608F:2=0x06020000 0x6091:1=0x06020000 0x6091:2=0x06020000 0x6092:1=0x06020000 0x6092:2=0x06020000 0x60A8:0=0x06020000 0x60A9:0=0x06020000 0x60AA:0=0x06020000 "
    [[ "$aborts" == "0x1402:1=0x06020000 0x1403:1=0x06020000 0x1802:1=0x06020000 0x1803:1=0x06020000 ${units}0x60C2:2=0x06010002 " ]] ||
      fail "expected exactly the aborts of 0x1402:1, 0x1403:1, 0x1802:1, 0x1803:1, the factor group 0x608F..0x60AA (0x06020000) and 0x60C2:2 (0x06010002), got: $aborts"
    say "tolerated: the drive has no RPDO3/4, TPDO3/4, no factor group (0x06020000), no 0x1016 written"
    ;;
  *) fail "unknown scenario" ;;
esac
say "OK"
