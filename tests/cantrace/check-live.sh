#!/usr/bin/env bash
# vcan test, CHECK part: the candump -L trace of the run and cantrace's live
# output decode to the same frames as the checked-in golden decode of the
# boot_enable capture (times differ from run to run, so they are cut off).
# Usage: check-live.sh CANTRACE_BINARY EXPECTED_DIR
set -euo pipefail
bin="$1" exp="$2"
art="$CANMOTION_ARTIFACTS"
strip() { cut -d' ' -f2-; }
frames=$(grep -c . "$art/boot_enable.play")
head -n "$frames" "$exp/boot_enable.txt" | strip > "$art/want.txt"
"$bin" "$CANMOTION_TRACE" > "$art/trace-decoded.txt"
grep -v 'ERROR FRAME' "$art/trace-decoded.txt" | sed -n "1,${frames}p" | strip > "$art/got-trace.txt"
diff -u "$art/want.txt" "$art/got-trace.txt" || { echo "decoded candump trace differs from the golden decode" >&2; exit 1; }
grep -v 'ERROR FRAME' "$art/live.txt" | sed -n "1,${frames}p" | strip > "$art/got-live.txt"
diff -u "$art/want.txt" "$art/got-live.txt" || { echo "cantrace --live output differs from the golden decode" >&2; exit 1; }
grep -q 'ERROR FRAME: controller-problem' "$art/live.txt" || { echo "live decode lacks the error frame" >&2; exit 1; }
grep -q 'Operation enabled' "$art/live.txt" || { echo "live summary lacks the state timeline" >&2; exit 1; }
echo "check-live: candump trace and live decode match the golden decode ($frames frames)"
