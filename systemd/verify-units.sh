#!/usr/bin/env bash
# Checks canmotion's systemd units with systemd-analyze, meaningfully:
#  - `systemd-analyze verify` in a temporary root that holds the system's own
#    units plus executable stubs at every ExecStart path, so a unit is checked
#    in full (dependencies, paths, directives) without installing canmotion;
#    ANY message counts as a failure (unknown keys only warn otherwise);
#  - a deliberately broken copy must be caught (proves the check can fail);
#  - the systemd-networkd files use only known sections and keys;
#  - `systemd-analyze security --offline` exposure levels stay under a
#    threshold, and are printed.
# Usage: verify-units.sh [SYSTEMD_DIR]   (exit 0 = all good)
set -euo pipefail
dir=$(cd "${1:-$(dirname "$0")}" && pwd)
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
fail=0

mkdir -p "$root/etc/systemd/system" "$root/usr/lib/systemd" "$root/usr/local/bin" "$root/usr/sbin" \
         "$root/etc/canmotion/cia402-emu"
# The host's own units (sysinit.target, network.target, ...), so dependencies resolve.
for d in /usr/lib/systemd/system /lib/systemd/system; do
  if [[ -d $d ]]; then cp -r "$d" "$root/usr/lib/systemd/system"; break; fi
done
cp "$dir"/*.service "$root/etc/systemd/system/"
for b in usr/local/bin/canmotiond usr/local/bin/cia402-emu usr/sbin/ip usr/sbin/modprobe; do
  printf '#!/bin/sh\nexit 0\n' >"$root/$b"
  chmod +x "$root/$b"
done
cp "$dir/cia402-emu-example.conf" "$root/etc/canmotion/cia402-emu/x-axis.conf"

units=(canmotiond.service cia402-emu@x-axis.service canmotion-vcan@vcan0.service)

verify() {  # verify UNIT...: prints messages, returns 1 if any
  local out
  out=$(cd "$root/etc/systemd/system" && systemd-analyze verify --man=no --generators=no --root="$root" "$@" 2>&1) \
    || { echo "$out"; return 1; }
  [[ -z $out ]] || { echo "$out"; return 1; }
}

echo "== systemd-analyze verify (root $root)"
if verify "${units[@]}"; then
  echo "ok: ${units[*]}"
else
  echo "FAIL: systemd-analyze verify reported the messages above"; fail=1
fi

echo "== self-check: a broken unit must be caught"
cp "$root/etc/systemd/system/canmotiond.service" "$root/etc/systemd/system/broken-canmotiond.service"
sed -i 's/^ProtectSystem=/ProtectSytem=/' "$root/etc/systemd/system/broken-canmotiond.service"
if verify broken-canmotiond.service >/dev/null; then
  echo "FAIL: a misspelt key (ProtectSytem=) was not reported: the verification is not meaningful"; fail=1
else
  echo "ok: misspelt key reported"
fi
rm "$root/etc/systemd/system/broken-canmotiond.service"

echo "== systemd-networkd files"
check_networkd() {  # FILE SECTION:KEY...
  local file=$1; shift
  local allowed=" $* " section="" line key ok=0
  while IFS= read -r line; do
    line=${line%%#*}; line=${line//[[:space:]]/}
    [[ -z $line ]] && continue
    if [[ $line =~ ^\[(.*)\]$ ]]; then section=${BASH_REMATCH[1]}; continue; fi
    key=${line%%=*}
    if [[ $allowed != *" $section:$key "* && $allowed != *" $section: "* ]]; then
      echo "FAIL: $file: unknown key $key in [$section]"; ok=1
    fi
  done <"$file"
  return $ok
}
check_networkd "$dir/80-vcan0.netdev" NetDev:Name NetDev:Kind && grep -q '^Kind=vcan' "$dir/80-vcan0.netdev" \
  && echo "ok: 80-vcan0.netdev" || fail=1
check_networkd "$dir/80-vcan0.network" Match:Name Link:RequiredForOnline Link:ActivationPolicy Network: \
  && echo "ok: 80-vcan0.network" || fail=1

echo "== systemd-analyze security --offline (exposure 0 = best, 10 = worst)"
declare -A threshold=([canmotiond.service]=2.5 [cia402-emu@.service]=2.5 [canmotion-vcan@.service]=3.0)
for u in canmotiond.service cia402-emu@.service canmotion-vcan@.service; do
  out=$(systemd-analyze security --offline=yes --root="$root" "$root/etc/systemd/system/$u" 2>&1 || true)
  level=$(sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\) \([A-Z]*\).*/\1 \2/p' <<<"$out")
  echo "$u: exposure $level (threshold ${threshold[$u]})"
  value=${level%% *}
  if [[ -z $value ]] || awk -v v="$value" -v t="${threshold[$u]}" 'BEGIN { exit !(v > t) }'; then
    echo "FAIL: $u exposure above threshold"; fail=1
  fi
done

exit $fail
