#!/usr/bin/env bash
# run-wrap.sh CANMOTIOND OUTDIR
# The long run past the 32-bit range (tests/longrun/README.md): canmotiond
# --sim on wrap.yaml / wrap.script with --csv, then check-wrap.py on its
# output (Debian's /usr/bin/python3 when there is one). Outputs kept in OUTDIR.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
case "${1:-}" in -h|--help) sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
[[ $# -eq 2 ]] || { echo "usage: run-wrap.sh CANMOTIOND OUTDIR" >&2; exit 2; }
daemon="$1" out="$2"
rm -rf "$out"; mkdir -p "$out"
status=0
"$daemon" --sim --config "$here/wrap.yaml" --script "$here/wrap.script" --csv "$out/wrap.csv" -q > "$out/wrap.log" 2>&1 ||
  status=$?
cat "$out/wrap.log"
[[ $status == 0 ]] || { echo "run-wrap.sh: canmotiond exited with status $status" >&2; exit 1; }
py=python3
[[ -x /usr/bin/python3 ]] && py=/usr/bin/python3
exec "$py" "$here/check-wrap.py" "$out/wrap.log" "$out/wrap.csv"
