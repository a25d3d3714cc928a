#!/usr/bin/env bash
# MAH over vcan, CHECK part: canmotiond's log (the script's PRINT lines) and
# the candump -L trace ($CANMOTION_TRACE) of run-homing.sh.
#   check-homing.sh NODE METHOD HOME_POSITION
# The log: before MAH AxisHomedStatus=0 at 20 mm; after it h.PC=1, h.ER=0,
# AxisHomedStatus=1, no fault, actual and command position = HOME_POSITION.
# The trace, in this order after the move: an SDO write of 0x6060 = 6 (the
# csp PDO profile switches modes over SDO), an SDO write of 0x6098 = METHOD,
# a rising edge of controlword bit 4 in the node's RPDO, a TPDO with
# statusword bit 12 (homing attained) after the edge; it took time (more than
# one TPDO between the edge and bit 12: the strict drive searches its switch).
set -euo pipefail
node="$1" method="$2" home="$3"
trace="$CANMOTION_TRACE"
art="${CANMOTION_ARTIFACTS:-$(dirname "$trace")}"
log="$art/canmotiond.log"
fail() { echo "check-homing: FAIL: $*" >&2; exit 1; }
measure() { echo "$*" >> "$art/measure.txt"; echo "check-homing: measured: $*"; }
: > "$art/measure.txt"
[[ -s $trace ]] || fail "empty trace $trace"
num() { sed -nE "s/.* $1=([-0-9.e+]+).*/\1/p" <<<"$2"; }
near() { awk -v a="$1" -v b="$2" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d < 0.001) }'; }

before=$(grep -E '^t=[0-9.]+ X\.AxisHomedStatus=' "$log") || fail "no PRINT before MAH in the log"
[[ $(num X.AxisHomedStatus "$before") == 0 ]] || fail "AxisHomedStatus was already 1 before MAH: $before"
after=$(grep -E '^t=[0-9.]+ h\.PC=' "$log") || fail "no PRINT after MAH in the log (did h.PC time out?)"
[[ $(num h.PC "$after") == 1 && $(num h.ER "$after") == 0 ]] || fail "MAH did not complete: $after"
[[ $(num X.AxisHomedStatus "$after") == 1 ]] || fail "AxisHomedStatus is not 1 after MAH: $after"
[[ $(num X.AxisFault "$after") == 0 ]] || fail "axis fault after MAH: $after"
near "$(num X.ActualPosition "$after")" "$home" || fail "ActualPosition is not the home position $home: $after"
near "$(num X.CommandPosition "$after")" "$home" || fail "CommandPosition is not the home position $home: $after"
echo "check-homing: log: $after"

lib='function hex(s,  i, v) { v = 0; for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789ABCDEF", toupper(substr(s, i, 1))) - 1; return v }
function band(a, b,  r, k) { r = 0; for (k = 1; a > 0 && b > 0; k *= 2) { if (a % 2 == 1 && b % 2 == 1) r += k; a = int(a / 2); b = int(b / 2) } return r }
function word(d, at) { return hex(substr(d, at + 2, 2) substr(d, at, 2)) }
function t(s) { return substr(s, 2, length(s) - 2) + 0 }'
sdo=$(printf '%03X' $((0x600 + node))) rpdo=$(printf '%03X' $((0x200 + node))) tpdo=$(printf '%03X' $((0x180 + node)))
m6=$(awk -v id="$sdo#2F60600006" '$3 ~ "^" id { print NR; exit }' "$trace")
[[ -n $m6 ]] || fail "no SDO write of 0x6060 = 6 to node $node"
m98=$(awk -v from="$m6" -v id="$sdo#2F986000$(printf '%02X' "$method")" 'NR > from && $3 ~ "^" id { print NR; exit }' "$trace")
if [[ -z $m98 ]]; then  # the homing objects may be written before the mode switch
  m98=$(awk -v id="$sdo#2F986000$(printf '%02X' "$method")" '$3 ~ "^" id { print NR; exit }' "$trace")
fi
[[ -n $m98 ]] || fail "no SDO write of 0x6098 = $method to node $node"
read -r edge t_edge <<<"$(awk -v from="$m6" -v id="$rpdo" "$lib"' NR > from { split($3, f, "#") }
  NR > from && f[1] == id { b = band(word(f[2], 1), 16) != 0; if (b && seen && !last) { printf "%d %.6f\n", NR, t($1); exit } last = b; seen = 1 }' "$trace")"
[[ -n ${edge:-} ]] || fail "no rising edge of controlword bit 4 in RPDO $rpdo after the mode switch"
read -r att t_att n_tpdo <<<"$(awk -v from="$edge" -v id="$tpdo" "$lib"' NR > from { split($3, f, "#") }
  NR > from && f[1] == id { n++; if (band(word(f[2], 1), 4096) != 0) { printf "%d %.6f %d\n", NR, t($1), n; exit } }' "$trace")"
[[ -n ${att:-} ]] || fail "no TPDO $tpdo with statusword bit 12 (homing attained) after the bit 4 edge at line $edge"
[[ $n_tpdo -gt 2 ]] || fail "homing attained in TPDO $n_tpdo after the edge: the strict drive should take time"
measure "0x6060=6 at line $m6, 0x6098=$method at line $m98, bit 4 edge at line $edge, bit 12 at line $att ($n_tpdo TPDOs, $(awk -v a="$t_edge" -v b="$t_att" 'BEGIN { printf "%.0f", (b - a) * 1000 }') ms on candump stamps)"
echo "check-homing: OK"
