#!/usr/bin/env bash
# Every SDO download (initiate, client command 0x2n) to NODE in a candump -L
# trace TRACE is to an index:sub that EDS has. Prints the objects written and
# exits 1 naming the first one the EDS lacks (or when nothing was written).
# Usage: check-trace-writes.sh TRACE EDS NODE  (TRACE "-": $CANMOTION_TRACE)
set -uo pipefail
trace="$1" eds="$2" node="$3"
[[ $trace == - ]] && trace="$CANMOTION_TRACE"  # the vcan runner's candump log
id=$(printf '%03X' $((0x600 + node)))
# The EDS's sub-objects: [XXXXsubN] sections, and [XXXX] sections with no sub-sections (VARs, sub 0).
hexfn='function hex(s,  i, n) { n = 0; s = toupper(s); for (i = 1; i <= length(s); i++) n = n * 16 + index("0123456789ABCDEF", substr(s, i, 1)) - 1; return n }'
have=$(awk "$hexfn"'
  /^\[[0-9A-Fa-f][0-9A-Fa-f][0-9A-Fa-f][0-9A-Fa-f]sub[0-9A-Fa-f]+\]/ { i=toupper(substr($0,2,4)); s=substr($0,9); sub(/\].*/,"",s); printf "%s:%02X\n", i, hex(s); subs[i]=1; next }
  /^\[[0-9A-Fa-f][0-9A-Fa-f][0-9A-Fa-f][0-9A-Fa-f]\]/ { i=toupper(substr($0,2,4)); var[i]=1 }
  END { for (i in var) if (!(i in subs)) printf "%s:00\n", i }' "$eds" | sort -u)
# SDO requests to the node: ID#CCLLHHSS...: command byte, index little-endian, sub.
written=$(awk -v id="$id" "$hexfn"'{ split($3, f, "#"); if (toupper(f[1]) != id) next; d=toupper(f[2]);
  c=hex(substr(d,1,2)); if (int(c/32) != 1) next;
  printf "%s%s:%s\n", substr(d,5,2), substr(d,3,2), substr(d,7,2) }' "$trace" | sort | uniq -c)
[[ -n "$written" ]] || { echo "check-trace-writes: no SDO download to node $node in $trace" >&2; exit 1; }
echo "$written"
while read -r count obj; do
  grep -qx "$obj" <<<"$have" || { echo "check-trace-writes: FAIL: the master wrote $obj ($count times), which $eds lacks" >&2; exit 1; }
done <<<"$written"
echo "check-trace-writes: $(wc -l <<<"$written") objects written to node $node, all in $(basename "$eds")"
