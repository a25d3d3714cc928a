#!/usr/bin/env bash
# latency.sh [CANMOTIOND] [LOOPS] [REPEATS]
# Wake-up latency of the canmotiond cycle (1 ms, 16 AXIS_CIP_DRIVE axes on 8
# `interface: sim` buses, SCHED_FIFO 80, drives enabled and jogging: see
# gen-config.sh) against cyclictest -m -p 80 -i 1000 -l LOOPS -q
# (tools/rt-latency/compare-cyclictest.sh -x), REPEATS times in each of
# four cases:
#   idle-seq   no load added; one after the other (the acceptance case:
#              cyclictest and canmotiond alternate which runs first)
#   idle-par   no load added; side by side
#   load-seq   under LATENCY_LOAD; one after the other
#   load-par   under LATENCY_LOAD; side by side
# canmotiond's percentiles come from its --stats summary (rt::format_summary).
# "idle" means only that this script adds no load: the 1-minute load average
# is recorded before and after every run and the summary says how idle the
# machine was. Side by side, cyclictest's PM QoS request (/dev/cpu_dma_latency
# = 0, system-wide) also serves canmotiond, so only the sequential cases show
# what canmotiond gets by itself.
#
# Environment:
#   LATENCY_CASES  which cases, default "idle-seq idle-par load-seq load-par"
#   LATENCY_LOAD   the load command, run in the background for the load-*
#                  cases and killed after each run; default: hackbench
#                  (rt-tests) with 2 groups of 4 sender/receiver pairs,
#                  scheduler and IPC stress
#   LATENCY_DMA    controller.cpu_dma_latency_us written to the configuration
#                  (default: not written, i.e. the daemon's default 0; -1 =
#                  do not hold the PM QoS request, to see what it is worth;
#                  leave unset for builds that predate the key)
#   LATENCY_CPU    pin both to this CPU: controller.cpu in the configuration
#                  (canmotiond's RT thread) and cyclictest -a (default: neither
#                  pinned, as in the acceptance case)
#   LATENCY_OUT    folder for the raw outputs (default: a temporary folder)
# Run as root (or with CAP_SYS_NICE + CAP_IPC_LOCK and write access to
# /dev/cpu_dma_latency). Prints one line per run and a summary with the
# median ratios per case.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
repo="$(cd "$here/../.." && pwd -P)"
daemon="${1:-$repo/build/tools/canmotiond/canmotiond}"
loops="${2:-30000}" repeats="${3:-3}"
cases="${LATENCY_CASES:-idle-seq idle-par load-seq load-par}"
load_cmd="${LATENCY_LOAD:-hackbench -g 2 -f 4 -l 1000000000}"
[[ -x "$daemon" ]] || { echo "latency: canmotiond not found: $daemon" >&2; exit 1; }
out="${LATENCY_OUT:-$(mktemp -d)}"
mkdir -p "$out"
"$here/gen-config.sh" 16 1 8 "$out/bench16"
pin=()
if [[ -n ${LATENCY_CPU:-} ]]; then
  sed -i "s/^  cpu: -1$/  cpu: $LATENCY_CPU/" "$out/bench16.yaml"
  grep -q "^  cpu: $LATENCY_CPU$" "$out/bench16.yaml" || { echo "latency: could not set controller.cpu" >&2; exit 1; }
  pin=(-a "$LATENCY_CPU")
fi
if [[ -n ${LATENCY_DMA:-} ]]; then
  sed -i "s/^  cpu: \(-\?[0-9]\+\)$/  cpu: \1\n  cpu_dma_latency_us: $LATENCY_DMA/" "$out/bench16.yaml"
fi
# --duration in controller seconds; the controlled stop adds a few cycles.
secs=$(awk -v l="$loops" 'BEGIN { printf "%.3f", l / 1000 }')
cmd="$daemon --config $out/bench16.yaml --script $out/bench16.script --duration $secs --stats --quiet"

# canmotiond --histogram (builds since 2026-11-28): the summary also pools
# every run's histograms per case (see below).
has_hist=false
"$daemon" --help 2>/dev/null | grep -q -- '--histogram' && has_hist=true

load_pid=""
stop_load() {
  if [[ -n $load_pid ]]; then
    kill -- -"$load_pid" 2>/dev/null || kill "$load_pid" 2>/dev/null || true
    wait "$load_pid" 2>/dev/null || true
    load_pid=""
  fi
}
trap stop_load EXIT

echo "# $(date -u +%FT%TZ) $(uname -r), $(nproc) CPUs, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "# daemon: $cmd"
echo "# cases: $cases; $repeats runs each of $loops cycles; load command: $load_cmd"
[[ -n ${LATENCY_DMA:-} ]] && echo "# controller.cpu_dma_latency_us: $LATENCY_DMA"
[[ -n ${LATENCY_CPU:-} ]] && echo "# pinned to CPU $LATENCY_CPU (controller.cpu, cyclictest -a)"
: >"$out/results.txt"
for c in $cases; do
  case $c in
    idle-seq | load-seq) mode=sequential ;;
    idle-par | load-par) mode=parallel ;;
    *) echo "latency: unknown case $c" >&2; exit 1 ;;
  esac
  for ((r = 1; r <= repeats; r++)); do
    if [[ $c == load-* ]]; then
      set -m
      $load_cmd >/dev/null 2>&1 &
      load_pid=$!
      set +m
      sleep 2  # let the load build up
    fi
    rev=()
    # One after the other: alternate which program runs first.
    [[ $mode == sequential && $((r % 2)) == 0 ]] && rev=(-r)
    run_cmd=$cmd
    $has_hist && run_cmd+=" --histogram $out/$c-run$r/canmotiond.hist"
    "$repo/tools/rt-latency/compare-cyclictest.sh" -m "$mode" "${rev[@]}" "${pin[@]}" -i 1000 -p 80 -l "$loops" \
      -o "$out/$c-run$r" -x "$run_cmd" >"$out/$c-run$r.txt" 2>&1 || { cat "$out/$c-run$r.txt" >&2; exit 1; }
    stop_load
    res=$(grep '^RESULT ' "$out/$c-run$r.txt")
    echo "case=$c run=$r ${res#RESULT }" | tee -a "$out/results.txt"
    grep -E '^(exec |canmotiond: real-time set-up)' "$out/$c-run$r/rt-latency.txt" | sed 's/^/#   /' || true
  done
done

echo
echo "# summary: medians over the runs of each case (ratio = canmotiond / cyclictest; load = 1-minute load average)"
printf '%-9s %5s %16s %16s %16s %9s %9s %13s\n' case runs "ct p50/p99 us" "cm p50/p99 us" "p99.9 ct/cm" "p50 ratio" "p99 ratio" "load min-max"
for c in $cases; do
  awk -v c="$c" '
    function med(a, n,   i, j, t) { for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
                                    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2 }
    { for (i = 1; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] } }
    v["case"] != c { next }
    { n++; cp50[n] = v["ct_p50"]; cp99[n] = v["ct_p99"]; mp50[n] = v["rl_p50"]; mp99[n] = v["rl_p99"]
      cp999[n] = v["ct_p999"]; mp999[n] = v["rl_p999"]; r50[n] = v["ratio_p50"]; r99[n] = v["ratio_p99"]
      for (k in v) if (k ~ /^load_/) { if (lo == "" || v[k] < lo) lo = v[k]; if (hi == "" || v[k] > hi) hi = v[k] } }
    END { if (!n) exit
          printf "%-9s %5d %16s %16s %16s %9.2f %9.2f %13s\n", c, n, med(cp50, n) "/" med(cp99, n), med(mp50, n) "/" med(mp99, n),
                 med(cp999, n) "/" med(mp999, n), med(r50, n), med(r99, n), lo "-" hi }' "$out/results.txt"
done
if $has_hist; then
  echo
  echo "# pooled: every run's samples of a case together (cyclictest's 1 us histogram, canmotiond's --histogram"
  echo "# buckets truncated to whole us like cyclictest's), so minutes of drift in the machine weigh on both alike"
  printf '%-9s %8s %22s %22s %9s %9s %11s\n' case samples "ct p50/p99/p99.9 us" "cm p50/p99/p99.9 us" "p50 ratio" "p99 ratio" "p99.9 ratio"
  for c in $cases; do
    ls "$out/$c"-run*/canmotiond.hist >/dev/null 2>&1 || continue
    # cyclictest: "us count" lines and its overflows (above -h, counted at the top);
    # canmotiond: "lower_ns upper_ns count", counted at the whole us of the bucket's middle.
    awk '
      function pct(h, n, q,   rank, s, us) { rank = int(q * n); if (rank < q * n) rank++; if (rank < 1) rank = 1
                                             s = 0; for (us = 0; us <= top; us++) { s += h[us]; if (s >= rank) return us } return top }
      FNR == 1 { ct = FILENAME ~ /cyclictest.txt$/ }
      ct && /^[0-9]+ [0-9]+$/ { c[$1 + 0] += $2; nc += $2; if ($1 + 0 > top) top = $1 + 0; next }
      ct && /# Histogram Overflows:/ { ov += $4 + 0; next }
      !ct && /^[0-9]+ [0-9]+ [0-9]+$/ { us = int(($1 + $2) / 2000); m[us] += $3; nm += $3; if (us > top) top = us }
      END { top++; c[top] += ov; nc += ov
            if (!nc || !nm) exit
            c50 = pct(c, nc, 0.5); c99 = pct(c, nc, 0.99); c999 = pct(c, nc, 0.999)
            m50 = pct(m, nm, 0.5); m99 = pct(m, nm, 0.99); m999 = pct(m, nm, 0.999)
            printf "%-9s %8d %22s %22s %9.2f %9.2f %11.2f\n", C, nm, c50 "/" c99 "/" c999, m50 "/" m99 "/" m999,
                   c50 ? m50 / c50 : 0, c99 ? m99 / c99 : 0, c999 ? m999 / c999 : 0 }' C="$c" \
      "$out/$c"-run*/cyclictest.txt "$out/$c"-run*/canmotiond.hist
  done
fi
echo "# raw outputs kept in $out"
