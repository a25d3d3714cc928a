#!/usr/bin/env bash
# capture.sh OUTDIR: record the golden traces with REAL candump on vcan0.
# Run inside tools/vcan-vm (or on any host with vcan0 up):
#   tools/vcan-vm -- tests/cantrace/scenarios/capture.sh tests/cantrace/data
# Each scenario of gen-scenario.sh is replayed onto vcan0 with canplayer
# (cyclic scenarios, so the SYNC timing is the replay's real timing) or with
# a cansend sequence (sdo_abort), while candump processes record it:
#   NAME.log              candump -L (log format, 6-digit fraction)
#   boot_enable.screen    candump            (screen format, no timestamps)
#   boot_enable.ta        candump -t a       (screen, absolute)
#   boot_enable.td        candump -t d       (screen, delta)
#   boot_enable.tz        candump -t z       (screen, zero-based)
#   boot_enable.tA        candump -t A       (screen, date)
# fault_emcy also gets two error frames (cansend with CAN_ERR_FLAG), recorded
# with an error filter (#FFFFFFFF) as real candump logs them.
set -euo pipefail
out="${1:?usage: capture.sh OUTDIR [SCENARIO...]}"
shift
scenarios=("$@")
[[ ${#scenarios[@]} -gt 0 ]] || scenarios=(boot_enable csp_motion fault_emcy sdo_abort)
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
iface=vcan0
# A queue on vcan0, so canplayer's bursts (4 frames per cycle) are not dropped with ENOBUFS.
ip link set "$iface" txqueuelen 1000 2>/dev/null || true

start_dump() {  # FILE ARGS...: candump in the background
  local file="$1"; shift
  candump -r 4194304 "$@" > "$file" &
  pids+=($!)
}
stop_dumps() {
  sleep 3  # candump -t A is slow under emulation: let every process drain its socket
  kill -INT "${pids[@]}" 2>/dev/null || true
  wait "${pids[@]}" 2>/dev/null || true
  pids=()
}

for s in "${scenarios[@]}"; do
  pids=()
  "$here/gen-scenario.sh" "$s" > "$tmp/$s.play"
  start_dump "$out/$s.log" -L "$iface,0:0,#FFFFFFFF"
  if [[ $s == boot_enable ]]; then
    start_dump "$out/$s.screen" "$iface"
    for ts in a d z A; do start_dump "$out/$s.t$ts" -t "$ts" "$iface"; done
  fi
  sleep 1  # let every candump open its socket
  if [[ $s == sdo_abort ]]; then
    # A cansend sequence: one process per frame.
    while read -r _ _ frame; do cansend "$iface" "$frame"; done < "$tmp/$s.play"
  else
    canplayer -I "$tmp/$s.play"
  fi
  if [[ $s == fault_emcy ]]; then
    cansend "$iface" 20000004#0004000000000000   # controller problem: rx error warning
    cansend "$iface" 20000004#0010000000000000   # controller problem: rx error passive
  fi
  stop_dumps
  want=$(wc -l < "$tmp/$s.play")
  [[ $s == fault_emcy ]] && want=$((want + 2))
  for f in "$out/$s".*; do
    got=$(grep -c 'vcan0' "$f" || true)
    [[ $got == "$want" ]] || { echo "capture.sh: $f has $got frames, sent $want (frames lost under load?)" >&2; exit 1; }
  done
  echo "capture.sh: $s: $want frames" >&2
done
