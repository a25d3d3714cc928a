#!/usr/bin/env bash
# golden.sh TOOL BIN EXPECTED_DIR: compare a tool's output with the recorded
# one; TOOLS_UPDATE_GOLDEN=1 rewrites the expected files after a deliberate
# change (review the diff before committing).
set -euo pipefail
tool="$1" bin="$2" exp="$3"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "golden: $tool: $*" >&2; exit 1; }
check() {  # NAME: compare $tmp/NAME with $exp/NAME
  if [[ "${TOOLS_UPDATE_GOLDEN:-0}" == 1 ]]; then
    cp "$tmp/$1" "$exp/$1"
    echo "golden: updated $exp/$1"
    return
  fi
  diff -u "$exp/$1" "$tmp/$1" || fail "$1 differs from $exp/$1 (TOOLS_UPDATE_GOLDEN=1 accepts a deliberate change)"
}
# run NAME ARGS...: stdout, stderr and the exit status of one call into $tmp/NAME
run() {
  local name="$1"; shift
  local rc=0
  "$bin" "$@" > "$tmp/out" 2> "$tmp/err" || rc=$?
  { echo "\$ $tool $*"; cat "$tmp/out"; echo "--- stderr"; cat "$tmp/err"; echo "--- exit $rc"; } >> "$tmp/$name"
}

case "$tool" in
  fieldbus-demo)
    run fieldbus-demo-cli.txt --help
    run fieldbus-demo-cli.txt --nodes 0
    run fieldbus-demo-cli.txt --cycle-us 5
    run fieldbus-demo-cli.txt --bogus
    run fieldbus-demo-cli.txt --trace /nonexistent/dir/t.log --duration 0.1
    check fieldbus-demo-cli.txt
    # A fixed run: the report (wall-clock figures masked) and the trace.
    "$bin" --nodes 2 5 9 --duration 1.5 --cycle-us 2000 --lag 3 --trace "$tmp/t.log" |
      sed -E "s#^(  wall time +)[0-9.]+ s \([0-9]+x real time\)#\1W s (Nx real time)#; s#$tmp/##" > "$tmp/fieldbus-demo-run.txt"
    check fieldbus-demo-run.txt
    sha256sum < "$tmp/t.log" | cut -d' ' -f1 > "$tmp/fieldbus-demo-trace.sha256"
    check fieldbus-demo-trace.sha256
    ;;
  rt-latency)
    run rt-latency-cli.txt --help
    run rt-latency-cli.txt --check-args -i 500 -p 0 -l 10
    run rt-latency-cli.txt -i 5
    run rt-latency-cli.txt -p 100
    run rt-latency-cli.txt --bogus
    check rt-latency-cli.txt
    # A short run: the lines main() prints, numbers masked (the scheduler decides them, and the
    # set-up report between them depends on the host's privileges).
    "$bin" -i 200 -l 30 -p 0 --no-mlock --no-dma-latency --histogram "$tmp/h.txt" 2>/dev/null |
      sed -n -E '1p; /^RESULT/p' | sed -E 's/[0-9]+(\.[0-9]+)?/N/g; s/realtime=(yes|no)/realtime=R/' > "$tmp/rt-latency-run.txt"
    [[ -s "$tmp/h.txt" ]] || fail "--histogram wrote nothing"
    check rt-latency-run.txt
    ;;
  *) fail "unknown tool" ;;
esac
echo "golden: $tool: ok"
