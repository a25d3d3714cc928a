#!/usr/bin/env bash
# sim-speed.sh [CANMOTIOND] [SIM_SECONDS]
# --sim speed of canmotiond: simulated seconds per wall second (and per CPU
# second, user+sys, which the machine's load disturbs less) and peak RSS, for
#   8 axes, 1 ms, 4 buses   and   64 axes, 4 ms, 8 buses,
# each without outputs and with --trace and --csv (written to a temporary
# folder). The axes are enabled and jog (gen-config.sh). /usr/bin/time -v
# gives the wall time, CPU time and peak RSS.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
daemon="${1:-$here/../../build-verify/tools/canmotiond/canmotiond}"
secs="${2:-120}"
[[ -x "$daemon" ]] || { echo "sim-speed: canmotiond not found: $daemon" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "sim-speed: /usr/bin/time not found (apt install time)" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "# $(date -u +%FT%TZ) $(uname -r), $(nproc) CPUs, load $(cut -d' ' -f1-3 /proc/loadavg); $daemon; $secs simulated s per run"
printf '%-6s %-7s %-13s %9s %9s %11s %11s %9s\n' axes period outputs wall_s cpu_s sim/wall sim/cpu rss_MB
for case in "8 1 4" "64 4 8"; do
  read -r axes period buses <<<"$case"
  "$here/gen-config.sh" "$axes" "$period" "$buses" "$tmp/c$axes"
  for outputs in none trace+csv; do
    extra=()
    [[ $outputs == none ]] || extra=(--trace "$tmp/t.log" --csv "$tmp/t.csv")
    t0=$(date +%s%N)
    /usr/bin/time -v -o "$tmp/time.txt" "$daemon" --sim --config "$tmp/c$axes.yaml" --script "$tmp/c$axes.script" \
      --duration "$secs" -q "${extra[@]}" > "$tmp/out.txt" 2>&1 ||
      { echo "sim-speed: canmotiond failed:" >&2; cat "$tmp/out.txt" "$tmp/time.txt" >&2; exit 1; }
    wall=$(( $(date +%s%N) - t0 ))
    awk -v axes="$axes" -v wall_ns="$wall" -v p="$period" -v o="$outputs" -v s="$secs" '
      BEGIN { w = wall_ns / 1e9 }
      /User time/ { u = $NF } /System time/ { sy = $NF } /Maximum resident/ { r = $NF }
      END { c = u + sy; printf "%-6s %-7s %-13s %9.2f %9.2f %11.0f %11.0f %9.1f\n", axes, p " ms", o, w, c, s / w, (c > 0 ? s / c : 0), r / 1024 }' "$tmp/time.txt"
    rm -f "$tmp/t.log" "$tmp/t.csv"
  done
done
