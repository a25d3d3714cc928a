#!/usr/bin/env bash
# golden.sh CANTRACE DATA_DIR EXPECTED_DIR CASE
# One golden test of cantrace on traces recorded by real candump (see
# scenarios/capture.sh). The output is compared with the checked-in expected
# output; set CANTRACE_UPDATE_GOLDEN=1 to rewrite the expected files after a
# deliberate change (then review the diff before committing).
set -euo pipefail
bin="$1" data="$2" exp="$3" case="$4"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

check() {  # NAME: compare $tmp/NAME with $exp/NAME
  if [[ "${CANTRACE_UPDATE_GOLDEN:-0}" == 1 ]]; then
    cp "$tmp/$1" "$exp/$1"
    echo "golden: updated $exp/$1"
    return
  fi
  if ! diff -u "$exp/$1" "$tmp/$1"; then
    echo "golden: $case: $1 differs from $exp/$1 (CANTRACE_UPDATE_GOLDEN=1 accepts a deliberate change)" >&2
    exit 1
  fi
}
fail() { echo "golden: $case: $*" >&2; exit 1; }
strip_time() { cut -d' ' -f2-; }

case "$case" in
  boot_enable | csp_motion | fault_emcy | sdo_abort)
    # Every frame decoded, then the analysis.
    "$bin" -s "$data/$case.log" > "$tmp/$case.txt"
    check "$case.txt"
    ;;
  fault_emcy_json)
    "$bin" -j -s "$data/fault_emcy.log" > "$tmp/fault_emcy.json"
    jq -e . "$tmp/fault_emcy.json" > /dev/null || fail "output is not valid JSON"
    [[ $(jq -s 'map(select(.kind == "emcy")) | length' "$tmp/fault_emcy.json") == 2 ]] || fail "want 2 EMCY objects"
    [[ $(jq -s 'map(select(.buses)) | .[0].buses[0].nodes[1].emcy[0].code' "$tmp/fault_emcy.json") == $((0x8611)) ]] ||
      fail "summary does not list EMCY 0x8611 for node 2"
    check "fault_emcy.json"
    ;;
  csp_motion_csv)
    "$bin" -q --csv "$tmp/csv" "$data/csp_motion.log"
    ls "$tmp/csv" > "$tmp/csp_motion_csv_files.txt"
    check "csp_motion_csv_files.txt"
    cp "$tmp/csv/vcan0_node1.csv" "$tmp/csp_motion_vcan0_node1.csv"
    check "csp_motion_vcan0_node1.csv"
    ;;
  csp_motion_config)
    # Axis names, user units (following error in mm/deg) and the config's cycle period.
    "$bin" -q -s -c "$data/axes.yaml" "$data/csp_motion.log" > "$tmp/csp_motion_config.txt"
    check "csp_motion_config.txt"
    ;;
  formats)
    # Every candump format of the same real capture decodes to the same frames.
    "$bin" "$data/boot_enable.log" > "$tmp/ref.txt"
    "$bin" "$data/boot_enable.ta" > "$tmp/ta.txt"
    diff -u "$tmp/ref.txt" "$tmp/ta.txt" || fail "-t a screen output decodes differently from -L"
    "$bin" "$data/boot_enable.tA" > "$tmp/tA.txt"
    diff -u "$tmp/ref.txt" "$tmp/tA.txt" || fail "-t A screen output decodes differently from -L"
    "$bin" "$data/boot_enable.log9" > "$tmp/log9.txt"
    diff -u <(sed -E 's/^([0-9]+\.[0-9]{6})/\1000/' "$tmp/ref.txt") "$tmp/log9.txt" || fail "9-digit log decodes differently"
    for v in screen tz; do
      "$bin" "$data/boot_enable.$v" | strip_time > "$tmp/$v.txt"
      diff -u <(strip_time < "$tmp/ref.txt") "$tmp/$v.txt" || fail "$v decodes differently from -L"
    done
    "$bin" "$data/boot_enable.tz" > "$tmp/tz-full.txt"
    "$bin" --delta "$data/boot_enable.td" > "$tmp/td.txt"
    diff -u "$tmp/tz-full.txt" "$tmp/td.txt" || fail "-t d with --delta does not reproduce -t z times"
    "$bin" "$data/boot_enable.td" > /dev/null 2> "$tmp/td.err"
    grep -q -- '--delta' "$tmp/td.err" || fail "no hint to use --delta on -t d input"
    # Piped input, as from 'candump -L vcan0 | cantrace'.
    "$bin" - < "$data/boot_enable.log" > "$tmp/stdin.txt"
    diff -u "$tmp/ref.txt" "$tmp/stdin.txt" || fail "stdin input decodes differently"
    ;;
  protocol)
    # Synthetic (scenarios/gen-synthetic.py): every kind of frame and SDO transfer shape, then the analysis.
    "$bin" -s "$data/protocol.log" > "$tmp/protocol.txt"
    check "protocol.txt"
    ;;
  protocol_json)
    "$bin" -j -s "$data/protocol.log" > "$tmp/protocol.json"
    jq -e . "$tmp/protocol.json" > /dev/null || fail "output is not valid JSON"
    check "protocol.json"
    ;;
  protocol_eds)
    # Node 1's objects named and typed by an EDS (--eds), text and JSON.
    eds="$data/../../../config/examples/cia402-emu.eds"
    "$bin" --eds "1=$eds" "$data/protocol.log" > "$tmp/protocol_eds.txt"
    check "protocol_eds.txt"
    "$bin" -j --eds "1=$eds" "$data/protocol.log" > "$tmp/protocol_eds.json"
    jq -e . "$tmp/protocol_eds.json" > /dev/null || fail "output is not valid JSON"
    check "protocol_eds.json"
    ;;
  cyclic)
    # Synthetic, two buses: jitter beyond the histogram, missing and late TPDOs, a fault, error frames.
    "$bin" -q -s "$data/cyclic.log" > "$tmp/cyclic.txt"
    check "cyclic.txt"
    "$bin" -q -j -s "$data/cyclic.log" > "$tmp/cyclic.json"
    jq -e . "$tmp/cyclic.json" > /dev/null || fail "output is not valid JSON"
    check "cyclic.json"
    ;;
  cyclic_options)
    # The analysis options: lag, nominal period, bitrate, a window small enough to group the load rows.
    opts=(--lag 1 --period 990 --bitrate 500000 --window 2)
    "$bin" -q -s "${opts[@]}" "$data/cyclic.log" > "$tmp/cyclic_options.txt"
    check "cyclic_options.txt"
    "$bin" -q -j -s "${opts[@]}" "$data/cyclic.log" > "$tmp/cyclic_options.json"
    jq -e . "$tmp/cyclic_options.json" > /dev/null || fail "output is not valid JSON"
    check "cyclic_options.json"
    ;;
  cyclic_config)
    # Axis names and units from a configuration, on both buses; the CSV files with user units.
    "$bin" -q -s -c "$data/axes.yaml" --csv "$tmp/csv" "$data/cyclic.log" > "$tmp/cyclic_config.txt"
    check "cyclic_config.txt"
    "$bin" -q -j -s -c "$data/axes.yaml" "$data/cyclic.log" > "$tmp/cyclic_config.json"
    check "cyclic_config.json"
    (cd "$tmp/csv" && for f in *.csv; do echo "== $f"; cat "$f"; done) > "$tmp/cyclic_config_csv.txt"
    check "cyclic_config_csv.txt"
    ;;
  no_time)
    # Screen output without timestamps: "-" times, no timing statistics.
    "$bin" -s "$data/boot_enable.screen" > "$tmp/no_time.txt"
    check "no_time.txt"
    "$bin" -j -s "$data/boot_enable.screen" > "$tmp/no_time.json"
    jq -e . "$tmp/no_time.json" > /dev/null || fail "output is not valid JSON"
    check "no_time.json"
    ;;
  malformed)
    # Bad lines are reported with their line number and skipped; exit status 0.
    "$bin" -s "$data/malformed.log" > "$tmp/malformed.out" 2> "$tmp/malformed.err"
    cat "$tmp/malformed.out" "$tmp/malformed.err" | sed "s|$data/||" > "$tmp/malformed.txt"
    check "malformed.txt"
    ;;
  cli)
    "$bin" --help > "$tmp/help.txt"
    for w in Usage: Options: Examples:; do grep -q "^$w" "$tmp/help.txt" || fail "--help lacks '$w'"; done
    if "$bin" --bogus 2> "$tmp/err.txt"; then fail "unknown option accepted"; fi
    grep -q "unknown option '--bogus'" "$tmp/err.txt" || fail "unknown option not named"
    if "$bin" /nonexistent/trace.log 2> "$tmp/err.txt"; then fail "missing file accepted"; fi
    grep -q "/nonexistent/trace.log" "$tmp/err.txt" || fail "missing file not named"
    if "$bin" --plot out.jpg "$data/sdo_abort.log" 2> /dev/null; then fail "--plot .jpg accepted"; fi
    if echo "garbage" | "$bin" 2> "$tmp/err.txt"; then fail "input without frames exits 0"; fi
    grep -q "no CAN frames" "$tmp/err.txt" || fail "no message for input without frames"
    if "$bin" -c "$data/../golden.sh" "$data/sdo_abort.log" 2> "$tmp/err.txt"; then fail "bad config accepted"; fi
    grep -q "golden.sh" "$tmp/err.txt" || fail "bad config file not named"
    ;;
  plot)
    command -v gnuplot > /dev/null || { echo "golden: gnuplot not installed: skipped"; exit 0; }
    "$bin" -q -c "$data/axes.yaml" --plot "$tmp/motion.png" "$data/csp_motion.log"
    [[ "$(head -c 8 "$tmp/motion.png" | od -An -tx1 | tr -d ' \n')" == 89504e470d0a1a0a ]] || fail "not a PNG file"
    [[ $(stat -c %s "$tmp/motion.png") -gt 20000 ]] || fail "PNG suspiciously small"
    "$bin" -q --plot "$tmp/motion.svg" "$data/fault_emcy.log"
    grep -q '<svg' "$tmp/motion.svg" || fail "not an SVG file"
    grep -q 'following error' "$tmp/motion.svg" || fail "SVG lacks the following-error panel"
    ;;
  *)
    fail "unknown case"
    ;;
esac
echo "golden: $case: ok"
