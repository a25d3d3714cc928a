#!/usr/bin/env bash
# run-soak.sh CANMOTIOND HOURS OUTDIR [CLOCK_START_S]
# The simulation soak (tests/soak/README.md): canmotiond --sim runs
# soak.yaml / soak.script for HOURS simulated hours (a gear, a time cam and a
# coordinated loop, SYNC counter 1..240), its virtual clock starting at
# CLOCK_START_S (default 4293167.296 s: 2^32 ms are crossed 30 min in, so a
# 32-bit millisecond timer anywhere in the master or the drives would wrap
# there); then check-soak.py checks every lap line and the summary and
# prints the hourly figures. Outputs kept in OUTDIR (soak.log, soak.script).
# SOAK_NO_RSS=1 skips the RSS check (sanitizer builds).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
case "${1:-}" in -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
[[ $# -ge 3 ]] || { echo "usage: run-soak.sh CANMOTIOND HOURS OUTDIR [CLOCK_START_S] (see --help)" >&2; exit 2; }
daemon="$1" hours="$2" out="$3" start="${4:-4293167.296}"
[[ "$hours" =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "run-soak.sh: HOURS must be a number, not '$hours'" >&2; exit 2; }
mkdir -p "$out"
secs=$(awk -v h="$hours" 'BEGIN { printf "%d", h * 3600 }')
sed "s/WHILE Controller.Time < 3600 DO/WHILE Controller.Time < $secs DO/" "$here/soak.script" > "$out/soak.script"
grep -q "WHILE Controller.Time < $secs DO" "$out/soak.script" || { echo "run-soak.sh: could not set the soak's length" >&2; exit 1; }
echo "run-soak.sh: $hours simulated hours, clock from $start s: $daemon --sim --config $here/soak.yaml --script $out/soak.script"
t0=$(date +%s.%N)
status=0
"$daemon" --config "$here/soak.yaml" --sim --script "$out/soak.script" --sim-clock-start "$start" -q --stats \
  > "$out/soak.log" 2>&1 || status=$?
wall=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
echo "run-soak.sh: canmotiond exited with status $status after $wall s wall"
[[ $status == 0 ]] || { tail -20 "$out/soak.log" >&2; exit 1; }
check=(--seconds "$secs" --clock-start "$start")
[[ "${SOAK_NO_RSS:-}" == 1 ]] && check+=(--no-rss)  # sanitizer builds: ASan's quarantine keeps freed memory
exec python3 "$here/check-soak.py" "$out/soak.log" "${check[@]}"
