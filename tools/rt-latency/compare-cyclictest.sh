#!/usr/bin/env bash
# Side-by-side wake-up latency of canmotion's cyclic executive (rt-latency)
# and cyclictest (rt-tests) at the same period and priority, in one run.
# Prints p50/p99/p99.9/max of both and the ratio rt-latency / cyclictest.
# With -x, any program that prints canmotion's statistics summary (e.g.
# canmotiond --stats) is measured instead of rt-latency.
set -euo pipefail

usage() {
  cat <<'USAGE'
Usage: compare-cyclictest.sh [OPTIONS]

Runs cyclictest and rt-latency with the same period, priority and cycle
count, and prints a table of p50, p99, p99.9 and max wake-up latency with
their ratios (rt-latency / cyclictest). Run as root for SCHED_FIFO.

Options:
  -i US          period in microseconds (default 1000)
  -p PRIO        SCHED_FIFO priority (default 80)
  -l LOOPS       cycles per program (default 20000)
  -m MODE        parallel (both at once, same load; default) or sequential
                 (one after the other: cyclictest first)
  -r             sequential: run the measured program first, then cyclictest
  -a CPU         pin cyclictest's thread to CPU (cyclictest -a CPU); pin the
                 measured program's RT thread to the same CPU yourself (for
                 canmotiond: controller.cpu), rt-latency is given -a CPU
  -b PATH        rt-latency binary (default: build*/tools/rt-latency/rt-latency)
  -x 'COMMAND'   measure COMMAND instead of rt-latency: any program that prints
                 canmotion's statistics summary (rt::format_summary), e.g.
                 'canmotiond --config demo.yaml --duration 20 --stats --quiet'
                 (give it the same period and priority as -i/-p)
  -o DIR         keep the raw outputs in DIR (default: a temporary folder)
  -h             this help

Example:
  sudo tools/rt-latency/compare-cyclictest.sh -i 1000 -p 80 -l 20000

cyclictest reports whole microseconds (truncated); rt-latency reports the
upper edge of its log-linear bucket (at most 1/64 above the exact value).

Note: cyclictest holds /dev/cpu_dma_latency at 0 while it runs, and the PM
QoS request is system-wide: side by side (parallel) the other program gets
the shallow idle states too, whether it asks for them or not. Only the
sequential mode shows what a program gets by itself.

The last line is machine-readable:
  RESULT mode=M ct_p50=.. ct_p99=.. ct_p999=.. ct_max=.. rl_p50=.. ... ratio_p50=.. ratio_p99=..
  load_before=L1 load_after=L1 (1-minute load averages)
USAGE
}

interval=1000 prio=80 loops=20000 mode=parallel bin="" outdir="" cmd="" reverse=0 cpu=""
while getopts "i:p:l:m:b:o:x:a:rh" opt; do
  case $opt in
    i) interval=$OPTARG ;; p) prio=$OPTARG ;; l) loops=$OPTARG ;; m) mode=$OPTARG ;; r) reverse=1 ;;
    b) bin=$OPTARG ;; o) outdir=$OPTARG ;; x) cmd=$OPTARG ;; a) cpu=$OPTARG ;; h) usage; exit 0 ;; *) usage >&2; exit 1 ;;
  esac
done
here=$(cd "$(dirname "$0")" && pwd)
if [[ -z $bin ]]; then
  bin=$(ls -t "$here"/../../build*/tools/rt-latency/rt-latency 2>/dev/null | head -1 || true)
fi
if [[ -z $cmd ]]; then
  [[ -x $bin ]] || { echo "compare-cyclictest.sh: rt-latency not found (build it, or pass -b PATH)" >&2; exit 1; }
fi
command -v cyclictest >/dev/null || { echo "compare-cyclictest.sh: cyclictest not found (apt install rt-tests)" >&2; exit 1; }
[[ $mode == parallel || $mode == sequential ]] || { echo "compare-cyclictest.sh: -m parallel|sequential" >&2; exit 1; }
if [[ -z $outdir ]]; then outdir=$(mktemp -d); fi
mkdir -p "$outdir"

histmax=$(( interval * 20 ))  # cyclictest histogram range in us; beyond it counts as overflow
ct_cmd=(cyclictest -m -p "$prio" -i "$interval" -l "$loops" -q -h "$histmax")
[[ -n $cpu ]] && ct_cmd+=(-a "$cpu")
if [[ -n $cmd ]]; then
  read -r -a rl_cmd <<<"$cmd"
  name=$(basename "${rl_cmd[0]}")
else
  rl_cmd=("$bin" -q -p "$prio" -i "$interval" -l "$loops" --histogram "$outdir/rt-latency.hist")
  [[ -n $cpu ]] && rl_cmd+=(-a "$cpu")
  name=rt-latency
fi
load1() { cut -d' ' -f1 /proc/loadavg; }
order=""
[[ $mode == sequential ]] && order=$([[ $reverse == 1 ]] && echo ", $name first" || echo ", cyclictest first")
load_before=$(load1)
echo "# $(date -u +%FT%TZ) $(uname -r), $(nproc) CPUs, mode $mode$order, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "# cyclictest: ${ct_cmd[*]}"
echo "# $name: ${rl_cmd[*]}"
if [[ $mode == parallel ]]; then
  "${ct_cmd[@]}" >"$outdir/cyclictest.txt" 2>&1 &
  ct_pid=$!
  "${rl_cmd[@]}" >"$outdir/rt-latency.txt" 2>&1 || true
  wait "$ct_pid"
elif [[ $reverse == 1 ]]; then
  "${rl_cmd[@]}" >"$outdir/rt-latency.txt" 2>&1 || true
  "${ct_cmd[@]}" >"$outdir/cyclictest.txt" 2>&1
else
  "${ct_cmd[@]}" >"$outdir/cyclictest.txt" 2>&1
  "${rl_cmd[@]}" >"$outdir/rt-latency.txt" 2>&1 || true
fi
load_after=$(load1)

# cyclictest: percentiles from its 1 us histogram ("us count" lines); the
# overflow count sits above the histogram range (reported as >histmax).
read -r ct_p50 ct_p99 ct_p999 ct_max ct_n < <(awk -v hm="$histmax" '
  /^[0-9]+ [0-9]+$/ { c[$1+0] = $2+0; n += $2; next }
  /# Max Latencies:/ { max = $4+0 }
  /# Histogram Overflows:/ { ov = $4+0 }
  END {
    total = n + ov
    split("0.5 0.99 0.999", q, " ")
    for (k = 1; k <= 3; k++) {
      rank = int(q[k] * total); if (rank < q[k] * total) rank++; if (rank < 1) rank = 1
      seen = 0; v = "overflow"
      for (us = 0; us <= hm; us++) { seen += c[us]; if (seen >= rank) { v = us; break } }
      out[k] = v
    }
    print out[1], out[2], out[3], max, total
  }' "$outdir/cyclictest.txt")

# The measured program prints rt::format_summary():
#   cycles N  overruns ...
#   latency  min A  mean B  p50 C  p99 D  p99.9 E  max F us
summary=$(grep -E '^(cycles [0-9]+ |latency  min )' "$outdir/rt-latency.txt" | tail -2) \
  || { echo "compare-cyclictest.sh: no statistics summary in the output of $name:" >&2; cat "$outdir/rt-latency.txt" >&2; exit 1; }
kw() { awk -v k="$1" '{ for (i = 1; i < NF; i++) if ($i == k) { print $(i + 1); exit } }' <<<"$summary"; }
rl_p50=$(kw p50) rl_p99=$(kw p99) rl_p999=$(kw p99.9) rl_max=$(kw max) rl_n=$(kw cycles)
[[ -n $rl_p99 ]] || { echo "compare-cyclictest.sh: cannot parse: $summary" >&2; exit 1; }

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b + 0 > 0) printf "%.2f", a / b; else print "n/a" }'; }
printf '\n%-12s %10s %10s %10s %10s %8s\n' "program" "p50_us" "p99_us" "p99.9_us" "max_us" "cycles"
printf '%-12s %10s %10s %10s %10s %8s\n' cyclictest "$ct_p50" "$ct_p99" "$ct_p999" "$ct_max" "$ct_n"
printf '%-12s %10s %10s %10s %10s %8s\n' "$name" "$rl_p50" "$rl_p99" "$rl_p999" "$rl_max" "$rl_n"
printf '%-12s %10s %10s %10s %10s\n' "ratio" "$(ratio "$rl_p50" "$ct_p50")" "$(ratio "$rl_p99" "$ct_p99")" \
  "$(ratio "$rl_p999" "$ct_p999")" "$(ratio "$rl_max" "$ct_max")"
echo "# raw outputs: $outdir"
echo "RESULT mode=$mode$([[ $mode == sequential && $reverse == 1 ]] && echo -reversed) ct_p50=$ct_p50 ct_p99=$ct_p99" \
  "ct_p999=$ct_p999 ct_max=$ct_max rl_p50=$rl_p50 rl_p99=$rl_p99 rl_p999=$rl_p999 rl_max=$rl_max" \
  "ratio_p50=$(ratio "$rl_p50" "$ct_p50") ratio_p99=$(ratio "$rl_p99" "$ct_p99")" \
  "ratio_p999=$(ratio "$rl_p999" "$ct_p999") ratio_max=$(ratio "$rl_max" "$ct_max")" \
  "load_before=$load_before load_after=$load_after"
