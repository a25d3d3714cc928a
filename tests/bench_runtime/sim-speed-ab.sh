#!/usr/bin/env bash
# sim-speed-ab.sh CANMOTIOND_A CANMOTIOND_B [SIM_SECONDS] [REPEATS]
# Side-by-side --sim speed of two canmotiond builds (e.g. before/after an
# optimisation), in one session so that both meet the same machine load:
# for each case of sim-speed.sh (8 axes, 1 ms, 4 buses; 64 axes, 4 ms,
# 8 buses; without outputs and with --trace + --csv) the two binaries run
# alternately REPEATS times (default 5). Prints every run and, per case and
# binary, the median simulated seconds per wall second and per CPU second
# (user + sys) and the peak RSS, with the load average before and after.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
a="${1:?usage: sim-speed-ab.sh CANMOTIOND_A CANMOTIOND_B [SIM_SECONDS] [REPEATS]}"
b="${2:?usage: sim-speed-ab.sh CANMOTIOND_A CANMOTIOND_B [SIM_SECONDS] [REPEATS]}"
secs="${3:-60}" reps="${4:-5}"
for d in "$a" "$b"; do [[ -x "$d" ]] || { echo "sim-speed-ab: canmotiond not found: $d" >&2; exit 1; }; done
[[ -x /usr/bin/time ]] || { echo "sim-speed-ab: /usr/bin/time not found (apt install time)" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "# $(date -u +%FT%TZ) $(uname -r), $(nproc) CPUs, load before $(cut -d' ' -f1-3 /proc/loadavg); $secs simulated s per run, $reps runs each"
echo "# A = $a"
echo "# B = $b"
printf '%-3s %-6s %-7s %-10s %9s %9s %9s %9s %8s\n' bin axes period outputs wall_s cpu_s sim/wall sim/cpu rss_MB
for case in "8 1 4" "64 4 8"; do
  read -r axes period buses <<<"$case"
  "$here/gen-config.sh" "$axes" "$period" "$buses" "$tmp/c$axes"
  for outputs in none trace+csv; do
    extra=()
    [[ $outputs == none ]] || extra=(--trace "$tmp/t.log" --csv "$tmp/t.csv")
    for ((r = 0; r < reps; ++r)); do
      for which in A B; do
        daemon="$a"
        [[ $which == B ]] && daemon="$b"
        t0=$(date +%s%N)
        /usr/bin/time -v -o "$tmp/time.txt" "$daemon" --sim --config "$tmp/c$axes.yaml" --script "$tmp/c$axes.script" \
          --duration "$secs" -q "${extra[@]}" > "$tmp/out.txt" 2>&1 ||
          { echo "sim-speed-ab: canmotiond failed:" >&2; cat "$tmp/out.txt" "$tmp/time.txt" >&2; exit 1; }
        wall=$(( $(date +%s%N) - t0 ))
        awk -v w="$which" -v axes="$axes" -v wall_ns="$wall" -v p="$period" -v o="$outputs" -v s="$secs" '
          BEGIN { wl = wall_ns / 1e9 }
          /User time/ { u = $NF } /System time/ { sy = $NF } /Maximum resident/ { r = $NF }
          END { c = u + sy; printf "%-3s %-6s %-7s %-10s %9.3f %9.2f %9.0f %9.0f %8.1f\n", w, axes, p "ms", o, wl, c, s / wl, (c > 0 ? s / c : 0), r / 1024 }' \
          "$tmp/time.txt" | tee -a "$tmp/rows.txt"
        rm -f "$tmp/t.log" "$tmp/t.csv"
      done
    done
  done
done
echo "# load after $(cut -d' ' -f1-3 /proc/loadavg)"
echo "# medians (simulated s per wall s, per CPU s; peak RSS MB):"
for case in "8 1" "64 4"; do
  read -r axes period <<<"$case"
  for outputs in none trace+csv; do
    for which in A B; do
      med() {  # med COLUMN: median of that column over the case's runs (mawk has no asort)
        awk -v w="$which" -v axes="$axes" -v o="$outputs" -v c="$1" '$1 == w && $2 == axes && $4 == o { print $c }' \
          "$tmp/rows.txt" | sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'
      }
      printf '%-3s %-6s %-7s %-10s  sim/wall %5s  sim/cpu %5s  rss %5s\n' "$which" "$axes" "${period}ms" "$outputs" \
        "$(med 7)" "$(med 8)" "$(med 9)"
    done
  done
done
