#!/usr/bin/env bash
# vcan.peer.conformance: the peer as a separate process on vcan0, checked by
# conformance.py (spec_checks.py) over real SocketCAN.
#   vcan-conformance-run.sh PYTHON
# Artefact: peer.log (the peer's verbose log and its summary).
set -uo pipefail
py="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
art="${CANMOTION_ARTIFACTS:-.}"
"$py" "$here/cia402_peer.py" -i vcan0 -n 5 --position 123456 -v > "$art/peer.log" 2>&1 &
peer=$!
for ((i = 0; i < 2400; i++)); do  # Python starts slowly in the VM (about a minute)
  grep -q '^cia402_peer: node 5 on vcan0' "$art/peer.log" && break
  kill -0 "$peer" 2>/dev/null || break
  sleep 0.1
done
"$py" "$here/conformance.py" -i vcan0 -n 5
rc=$?
kill -TERM "$peer"
wait "$peer"
tail -n 1 "$art/peer.log"
exit $rc
