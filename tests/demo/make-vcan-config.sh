#!/usr/bin/env bash
# make-vcan-config.sh DEMO_YAML PERIOD_MS > OUT.yaml
# The demo configuration on real SocketCAN: bus can0 -> vcan0, can1 -> vcan1
# (if the configuration has it: coordinated.yaml has only can0),
# controller.period_ms -> PERIOD_MS, `drives.eds` made absolute (the copy is
# written elsewhere; the EDS stays next to DEMO_YAML), and every position_error_tolerance
# multiplied by PERIOD_MS / the demo's period (the following error of a drive
# that follows N cycles late grows with the period: same tolerance in cycles).
# Generated from config/examples/demo.yaml at test time so that the two never
# drift apart; fails if demo.yaml no longer has the expected shape.
set -euo pipefail
src="$1" period="$2"
srcdir=$(cd "$(dirname "$src")" && pwd)
p0=$(awk '/^  period_ms:/ { print $2; exit }' "$src")
[[ -n "$p0" ]] || { echo "make-vcan-config: no controller period_ms in $src" >&2; exit 1; }
out="$(awk -v f="$(awk -v a="$period" -v b="$p0" 'BEGIN { print a / b }')" '
  $1 == "position_error_tolerance:" { sub(/position_error_tolerance: [0-9.]+/, "position_error_tolerance: " $2 * f) } { print }' "$src" | sed -e '/^  - name: can0$/,/^    interface:/ s/^    interface: sim$/    interface: vcan0/' \
           -e '/^  - name: can1$/,/^    interface:/ s/^    interface: sim$/    interface: vcan1/' \
           -e "s/^  period_ms: [0-9.]*\( .*\)\{0,1\}$/  period_ms: $period\1/" \
           -e "s|^  eds: \([^/ #][^ #]*\)|  eds: $srcdir/\1|")"
changed=$(printf '%s\n' "$out" | awk 'NR == FNR { a[FNR] = $0; next } a[FNR] != $0 { c++ } END { print c + 0 }' "$src" -)
buses=$(grep -c '^  - name: can[01]$' "$src" || true)
grep -q '^    interface: vcan0$' <<<"$out" && { [[ $buses -lt 2 ]] || grep -q '^    interface: vcan1$' <<<"$out"; } &&
  ! grep -q 'interface: sim$' <<<"$out" && grep -q "^  period_ms: $period\b" <<<"$out" &&
  [[ $changed -le $((buses + 1 + $(grep -c 'position_error_tolerance:' "$src") + $(grep -c '^  eds:' "$src"))) ]] ||
  { echo "make-vcan-config: $src does not have the expected shape (buses can0[/can1] with 'interface: sim', controller.period_ms); update tests/demo/make-vcan-config.sh" >&2; exit 1; }
printf '%s\n' "$out"
