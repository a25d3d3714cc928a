#!/usr/bin/env bash
# vcan.peer.conformance and vcan.peer.conformance_emu: one drive as a separate
# process on vcan0 (node 5), checked by conformance.py (spec_checks.py) over
# real SocketCAN.
#   vcan-conformance-run.sh PYTHON                         the peer (cia402_peer.py)
#   vcan-conformance-run.sh PYTHON CIA402_EMU [OPTION...]  canmotion's emulator
#                                                          (cia402-emu -v OPTION...;
#                                                          none: --profile strict)
# Artefacts: peer.log or emu.log (the drive's verbose log and its summary),
# conformance.log (every check's result and note).
set -uo pipefail
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
"$py" "$here/conformance.py" -i vcan0 -n 5 | tee "$art/conformance.log"
rc=${PIPESTATUS[0]}
kill -TERM "$drive"
wait "$drive"
tail -n 1 "$log"
exit $rc
