#!/usr/bin/env bash
# First vcan test, CHECK part: candump -L saw exactly the frames the sender sent,
# in order, in `(sec.usec) vcan0 ID#DATA` form, and the receiver printed the same.
set -euo pipefail
count="$1"
trace="$CANMOTION_TRACE"
bad=$(grep -cvE '^\([0-9]+\.[0-9]{6}\) vcan0 [0-9A-F]{3}#[0-9A-F]*$' "$trace" || true)
[[ "$bad" == 0 ]] || { echo "trace has $bad lines not in candump -L form" >&2; exit 1; }
awk '{print $3}' "$trace" > "$CANMOTION_ARTIFACTS/trace-frames.txt"
want="$CANMOTION_ARTIFACTS/expected.txt"
for ((i = 0; i < count; i++)); do
  printf '%03X#%02X%02X%02X%02XCAFE\n' $((0x100 + i % 16)) $((i & 255)) $(((i >> 8) & 255)) $(((i >> 16) & 255)) $(((i >> 24) & 255))
done > "$want"
diff -q "$want" "$CANMOTION_ARTIFACTS/trace-frames.txt" >/dev/null ||
  { echo "candump trace differs from the frames sent:"; diff "$want" "$CANMOTION_ARTIFACTS/trace-frames.txt" | head; exit 1; } >&2
diff -q "$want" "$CANMOTION_ARTIFACTS/received.txt" >/dev/null ||
  { echo "receiver output differs from the frames sent"; exit 1; } >&2
echo "check-sendrecv: candump saw all $count frames in order; receiver agrees"
