#!/usr/bin/env bash
# rt-latency end to end: --help, a short run, and (when root) the same run as
# user nobody, which must still run and print exactly ONE warning that says
# how to grant real time.
set -euo pipefail
bin=$1
fail() { echo "FAIL: $*"; exit 1; }

"$bin" --help | grep -q -- "--interval" || fail "--help does not list --interval"

out=$("$bin" -i 200 -l 100 -p 0 --no-mlock --no-dma-latency -q)
grep -q '^RESULT cycles=100 ' <<<"$out" || fail "short run: no RESULT line with 100 cycles: $out"
grep -q '^latency  min' <<<"$out" || fail "short run: no summary"

if "$bin" -i 200 -l 10 -a 99999 -q >/dev/null 2>&1; then fail "an impossible CPU must be an error (exit 1)"; fi

if [[ $(id -u) -eq 0 ]] && command -v setpriv >/dev/null; then
  err=$(mktemp)
  trap 'rm -f "$err"' EXIT
  out=$(setpriv --reuid=nobody --regid=nogroup --clear-groups -- "$bin" -i 500 -l 50 -p 80 -q --no-dma-latency 2>"$err") \
    || fail "unprivileged run failed: $(cat "$err")"
  grep -q '^RESULT cycles=50 .*realtime=no' <<<"$out" || fail "unprivileged run: $out"
  n=$(grep -c 'warning' "$err" || true)
  [[ $n -eq 1 ]] || fail "expected exactly one warning, got $n: $(cat "$err")"
  grep -q 'CAP_SYS_NICE' "$err" || fail "the warning does not say how to grant SCHED_FIFO: $(cat "$err")"
  grep -q 'LimitRTPRIO=80' "$err" || fail "the warning does not name LimitRTPRIO: $(cat "$err")"
  echo "unprivileged warning: $(cat "$err")"
  # With the PM QoS request (root's /dev/cpu_dma_latency is 0600): still ONE warning, naming it.
  if [[ -e /dev/cpu_dma_latency ]]; then
    out=$(setpriv --reuid=nobody --regid=nogroup --clear-groups -- "$bin" -i 500 -l 50 -p 80 -q 2>"$err") \
      || fail "unprivileged run with the PM QoS request failed: $(cat "$err")"
    n=$(grep -c 'warning' "$err" || true)
    [[ $n -eq 1 ]] || fail "expected exactly one warning with cpu_dma_latency refused, got $n: $(cat "$err")"
    grep -q '/dev/cpu_dma_latency' "$err" || fail "the warning does not name /dev/cpu_dma_latency: $(cat "$err")"
  fi
else
  echo "not root: unprivileged part skipped"
fi
echo "ok"
