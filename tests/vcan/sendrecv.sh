#!/usr/bin/env bash
# First vcan test, COMMAND part: a receiver process and a sender process talk
# over vcan0 through SocketCanBus. Usage: sendrecv.sh VCAN_SENDRECV_BINARY COUNT
set -euo pipefail
bin="$1" count="$2"
out="$CANMOTION_ARTIFACTS/received.txt"
ready="$CANMOTION_ARTIFACTS/receiver.ready"
rm -f "$ready"
"$bin" recv vcan0 "$count" 60000 "$ready" > "$out" &
rpid=$!
for ((t = 0; t < 200; t++)); do [[ -f "$ready" ]] && break; sleep 0.05; done
[[ -f "$ready" ]] || { echo "receiver never became ready" >&2; exit 1; }
"$bin" send vcan0 "$count" 500  # 2 frames/ms, like one axis at 1 ms
wait "$rpid"
[[ $(wc -l < "$out") == "$count" ]] || { echo "receiver printed $(wc -l < "$out") lines, want $count" >&2; exit 1; }
