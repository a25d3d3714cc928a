#!/usr/bin/env bash
# latency.sh [CANMOTIOND] [LOOPS] [REPEATS]
# Wake-up latency of the canmotiond cycle (1 ms, 16 AXIS_CIP_DRIVE axes on 8
# `interface: sim` buses, SCHED_FIFO 80, drives enabled and jogging: see
# gen-config.sh) against cyclictest -m -p 80 -i 1000 -l LOOPS -q, one after
# the other (tools/rt-latency/compare-cyclictest.sh -m sequential -x), REPEATS
# times. canmotiond's percentiles come from its --stats summary
# (rt::format_summary). Run as root (or with CAP_SYS_NICE + CAP_IPC_LOCK).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
repo="$(cd "$here/../.." && pwd -P)"
daemon="${1:-$repo/build-verify/tools/canmotiond/canmotiond}"
loops="${2:-30000}" repeats="${3:-3}"
[[ -x "$daemon" ]] || { echo "latency: canmotiond not found: $daemon" >&2; exit 1; }
out="${LATENCY_OUT:-$(mktemp -d)}"
mkdir -p "$out"
"$here/gen-config.sh" 16 1 8 "$out/bench16"
# --duration in controller seconds; the controlled stop adds a few cycles.
secs=$(awk -v l="$loops" 'BEGIN { printf "%.3f", l / 1000 }')
for ((r = 1; r <= repeats; r++)); do
  echo "## run $r of $repeats, load $(cut -d' ' -f1-3 /proc/loadavg)"
  "$repo/tools/rt-latency/compare-cyclictest.sh" -m sequential -i 1000 -p 80 -l "$loops" -o "$out/run$r" \
    -x "$daemon --config $out/bench16.yaml --script $out/bench16.script --duration $secs --stats --quiet"
  grep -E '^(summary: wake-up|cycles |exec )' "$out/run$r/rt-latency.txt" || true
done
echo "# outputs kept in $out"
