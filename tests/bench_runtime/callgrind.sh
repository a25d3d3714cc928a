#!/usr/bin/env bash
# callgrind.sh [CANMOTIOND] [SIM_SECONDS] [TOP]
# Instruction count (Ir, repeatable on a noisy machine) of canmotiond --sim
# for SIM_SECONDS (default 1) simulated seconds of 8 axes at 1 ms on 4 buses
# (gen-config.sh: enable, then jog), no outputs, and the TOP (default 5)
# functions by exclusive (self) and by inclusive cost. A run of 0.2 s
# (start-up, boot, enable, the start of the jog and the stop) is subtracted to give the steady-state
# instructions per cycle. Build with -O2 (the default RelWithDebInfo/Release)
# and symbols for readable names.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
daemon="${1:-$here/../../build-verify/tools/canmotiond/canmotiond}"
secs="${2:-1}" top="${3:-5}"
command -v valgrind >/dev/null || { echo "callgrind: valgrind not found (apt install valgrind)" >&2; exit 1; }
out="${CALLGRIND_OUT:-$(mktemp -d)}"
mkdir -p "$out"
"$here/gen-config.sh" 8 1 4 "$out/c8"
run() {  # run SECONDS NAME -> total Ir
  valgrind --tool=callgrind --callgrind-out-file="$out/$2.out" "$daemon" --sim --config "$out/c8.yaml" \
    --script "$out/c8.script" --duration "$1" -q > "$out/$2.log" 2>&1 ||
    { cat "$out/$2.log" >&2; exit 1; }
  sed -nE 's/^summary: ([0-9]+) cycles.*/\1/p' "$out/$2.log" > "$out/$2.cycles" || true
  callgrind_annotate "$out/$2.out" > "$out/$2.txt" 2>/dev/null
  awk '/PROGRAM TOTALS/ { gsub(/,/, "", $1); print $1; exit }' "$out/$2.txt"
}
base=$(run 0.2 base)
full=$(run "$(awk -v s="$secs" 'BEGIN { print s + 0.2 }')" full)
cycles=$(awk -v s="$secs" 'BEGIN { print int(s * 1000 + 0.5) }')
echo "# $(date -u +%FT%TZ) valgrind $(valgrind --version | sed 's/valgrind-//'), $daemon"
echo "# total Ir: ${secs} s of 8 axes: $full; 0.2 s (start-up, boot, enable, stop): $base"
awk -v f="$full" -v b="$base" -v c="$cycles" 'BEGIN { printf "# steady state: %.0f Ir per 1 ms cycle of 8 axes (%.0f per axis)\n", (f - b) / c, (f - b) / c / 8 }'
callgrind_annotate --auto=no --threshold=100 "$out/full.out" > "$out/self.txt" 2>/dev/null
callgrind_annotate --auto=no --threshold=100 "$out/base.out" > "$out/self-base.txt" 2>/dev/null
steady=$(awk -v f="$full" -v b="$base" 'BEGIN { print f - b }')
top_steady() {  # top_steady BYFN N: self cost of the full run minus the base run
  awk -v byfn="$1" '
    FNR == 1 { on = 0; file++ }
    /^ *Ir +file:function/ { on = 1; next }
    on && $1 ~ /^[0-9,]+$/ { v = $1; gsub(/,/, "", v); sub(/^ *[0-9,]+ +\([^)]*\) +/, ""); if (byfn) { sub(/ \[[^]]*\]$/, ""); sub(/^[^:]*:/, "") } ir[$0] += (file == 1 ? v : -v) }
    END { for (f in ir) print ir[f] "\t" f }' "$out/self.txt" "$out/self-base.txt" | sort -t$'\t' -k1,1nr |
    awk -F'\t' -v n="$2" -v total="$steady" 'NR <= n { printf "%12d (%5.1f%%)  %s\n", $1, 100 * $1 / total, $2 }'
}
echo "# top $top functions by self cost in the steady state (full run minus the 0.2 s run; inlined code counted in its caller):"
top_steady 1 "$top"
echo "# top $((top * 2)) source file:function pairs by self cost in the steady state (shows inlined headers, e.g. pdo.hpp packing):"
top_steady 0 "$((top * 2))"
echo "# top $((top * 2)) by inclusive cost:"
callgrind_annotate --auto=no --inclusive=yes --threshold=100 "$out/full.out" > "$out/incl.txt" 2>/dev/null
awk -v n="$((top * 2))" '
  /^ *Ir +file:function/ { on = 1; next } on && NF > 0 && k < n && $1 ~ /^[0-9,]+$/ { k++; print }' "$out/incl.txt"
echo "# callgrind outputs in $out (callgrind_annotate $out/full.out)"
