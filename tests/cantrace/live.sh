#!/usr/bin/env bash
# vcan test, COMMAND part: cantrace --live vcan0 decodes a scenario that
# canplayer replays onto vcan0 (real SocketCAN, inside tools/vcan-vm), plus
# two error frames sent with cansend.
# Usage: live.sh CANTRACE_BINARY SCENARIO_GENERATOR
set -euo pipefail
bin="$1" gen="$2"
art="$CANMOTION_ARTIFACTS"
"$gen" boot_enable > "$art/boot_enable.play"
"$bin" --live vcan0 -s > "$art/live.txt" 2> "$art/live.err" &
pid=$!
for ((i = 0; i < 600; i++)); do grep -q listening "$art/live.err" 2>/dev/null && break; sleep 0.1; done
grep -q listening "$art/live.err" || { cat "$art/live.err" >&2; echo "cantrace --live never started" >&2; exit 1; }
canplayer -I "$art/boot_enable.play"
cansend vcan0 20000004#0004000000000000
# cantrace has seen everything once it printed the last frame of the scenario.
last=$(tail -n 1 "$art/boot_enable.play" | awk '{print $3}')
for ((i = 0; i < 600; i++)); do grep -q "ERROR FRAME" "$art/live.txt" 2>/dev/null && break; sleep 0.1; done
kill -INT "$pid"
wait "$pid"
grep -q "$last" "$art/live.txt" || { echo "cantrace --live missed the last frame $last" >&2; exit 1; }
