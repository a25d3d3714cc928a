#!/usr/bin/env bash
# vcan.peer.conformance, vcan.peer.conformance_emu and vcan.peer.master_csp_eds:
# one drive as a separate process on vcan0 (node 5), checked over real
# SocketCAN by conformance.py (spec_checks.py) or, with --run, by another
# program of this folder taking -i vcan0 -n 5 (master_csp.py: the
# independent CSP master).
#   vcan-conformance-run.sh [--run SCRIPT] PYTHON                         the peer (cia402_peer.py)
#   vcan-conformance-run.sh [--run SCRIPT] PYTHON CIA402_EMU [OPTION...]  canmotion's emulator
#                                                          (cia402-emu -v OPTION...;
#                                                          none: --profile strict)
# Artefacts: peer.log or emu.log (the drive's verbose log and its summary),
# conformance.log or SCRIPT's name .log (every check's or step's result and note).
set -uo pipefail
checker=conformance.py
if [[ "${1:-}" == --run ]]; then checker="$2"; shift 2; fi
py="$1"; shift
emu="${1:-}"; [[ $# -gt 0 ]] && shift
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
art="${CANMOTION_ARTIFACTS:-.}"
if [[ -z "$emu" ]]; then
  log="$art/peer.log" ready='^cia402_peer: node 5 on vcan0'
  "$py" "$here/cia402_peer.py" -i vcan0 -n 5 --position 123456 -v > "$log" 2>&1 &
else
  log="$art/emu.log" ready='^cia402-emu: 1 drive\(s\) on vcan0: 5'
  "$emu" -i vcan0 -n 5 -v "$@" > "$log" 2>&1 &
fi
drive=$!
for ((i = 0; i < 2400; i++)); do  # Python starts slowly in the VM (about a minute)
  grep -Eq "$ready" "$log" && break
  kill -0 "$drive" 2>/dev/null || break
  sleep 0.1
done
if ! grep -Eq "$ready" "$log"; then
  cat "$log" >&2
  echo "vcan-conformance-run: the drive did not start" >&2
  kill -TERM "$drive" 2>/dev/null
  exit 1
fi
echo "vcan-conformance-run: $(head -n 1 "$log")"
"$py" "$here/$checker" -i vcan0 -n 5 | tee "$art/${checker%.py}.log"
rc=${PIPESTATUS[0]}
kill -TERM "$drive"
wait "$drive"
tail -n 1 "$log"
exit $rc
