#!/usr/bin/env bash
# Checks canmotion's systemd units with systemd-analyze, meaningfully:
#  - `systemd-analyze verify` in a temporary root that holds the system's own
#    units plus executable stubs at every path the units execute (ExecStart=,
#    ExecStartPre=, ...; found in the units), so a unit is checked in full
#    (dependencies, paths, directives) without installing canmotion; ANY
#    message counts as a failure (unknown keys only warn otherwise);
#  - a deliberately broken copy must be caught (proves the check can fail);
#  - the systemd-networkd files use only known sections and keys;
#  - canmotion-vcan@.service gets vcan from modprobe@vcan.service, not by itself;
#  - `systemd-analyze security --offline` exposure level of every unit stays
#    at or under 1.5, and is printed.
# Usage: verify-units.sh DIR   (exit 0 = all good)
#   DIR holds the units filled in with their installed paths (the .service
#   files, 80-vcan0.netdev/.network, cia402-emu-example.conf): <build>/systemd/
#   (ctest systemd_units_verify), or the files the Debian package installed
#   (ctest package_deb).
set -euo pipefail
[[ $# -eq 1 && -d $1 ]] || { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
dir=$(cd "$1" && pwd)
for f in canmotiond.service cia402-emu@.service canmotion-vcan@.service 80-vcan0.netdev 80-vcan0.network \
         cia402-emu-example.conf; do
  [[ -f $dir/$f ]] || { echo "verify-units.sh: $dir/$f missing" >&2; exit 2; }
done
if grep -l '@[A-Z_]*@' "$dir"/*.service; then
  echo "verify-units.sh: unfilled @VARIABLE@ in the units above (give the configured copies, e.g. build/systemd)" >&2; exit 2
fi
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
fail=0

mkdir -p "$root/etc/systemd/system" "$root/usr/lib/systemd"
# The host's own units (sysinit.target, network.target, ...), so dependencies resolve.
for d in /usr/lib/systemd/system /lib/systemd/system; do
  if [[ -d $d ]]; then cp -r "$d" "$root/usr/lib/systemd/system"; break; fi
done
cp "$dir"/*.service "$root/etc/systemd/system/"
# Stubs for every program the units run: absolute paths as written, bare names
# (ip) where systemd searches them.
stub() { mkdir -p "$root/$(dirname "$1")"; printf '#!/bin/sh\nexit 0\n' >"$root/$1"; chmod +x "$root/$1"; }
while read -r exe; do
  if [[ $exe == /* ]]; then stub "$exe"; else stub "/usr/sbin/$exe"; fi
done < <(sed -n 's/^Exec[A-Za-z]*=[-@:+!]*\([^ ]*\).*/\1/p' "$dir"/*.service | sort -u)
# The emulator's instance file where its unit reads it (EnvironmentFile=, %i = x-axis).
envfile=$(sed -n 's/^EnvironmentFile=\([^-].*\)/\1/p' "$dir/cia402-emu@.service")
envfile=${envfile//%i/x-axis}
mkdir -p "$root/$(dirname "$envfile")"
cp "$dir/cia402-emu-example.conf" "$root/$envfile"

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

echo "== canmotiond.service reaches /dev/cpu_dma_latency (PM QoS) without giving up PrivateDevices="
unit="$dir/canmotiond.service"
rules="$(cd "$(dirname "$0")" && pwd)/60-canmotion-cpu-dma-latency.rules"  # the source's (not installed yet)
if grep -qx 'PrivateDevices=yes' "$unit" && grep -qx 'DevicePolicy=closed' "$unit" \
   && grep -qx 'BindPaths=-/dev/cpu_dma_latency' "$unit" && grep -qx 'DeviceAllow=/dev/cpu_dma_latency rw' "$unit" \
   && grep -q 'KERNEL=="cpu_dma_latency", GROUP="canmotion", MODE="0660"' "$rules"; then
  echo "ok: PrivateDevices=yes, DevicePolicy=closed, BindPaths=-/dev/cpu_dma_latency, DeviceAllow rw, udev rule"
else
  echo "FAIL: canmotiond.service must keep PrivateDevices=yes + DevicePolicy=closed and bind and allow"
  echo "      /dev/cpu_dma_latency (BindPaths=-/dev/cpu_dma_latency, DeviceAllow=/dev/cpu_dma_latency rw),"
  echo "      and $rules must give the group canmotion write access"; fail=1
fi

echo "== canmotion-vcan@.service: an unprivileged user with CAP_NET_ADMIN only; vcan from modprobe@vcan.service"
unit="$dir/canmotion-vcan@.service" bad=()
for want in DynamicUser=yes CapabilityBoundingSet=CAP_NET_ADMIN AmbientCapabilities=CAP_NET_ADMIN \
            ProtectKernelModules=yes Wants=modprobe@vcan.service After=modprobe@vcan.service; do
  grep -qx "$want" "$unit" || bad+=("lacks $want")
done
grep -q '^RestrictAddressFamilies=.*AF_NETLINK' "$unit" || bad+=("RestrictAddressFamilies= without AF_NETLINK (ip talks rtnetlink)")
grep -qE '^PrivateNetwork=(yes|true|on|1)' "$unit" && bad+=("PrivateNetwork= on: the interface would be made in a private namespace")
grep -v '^[#;]' "$unit" | grep -qiE '^Exec[A-Za-z]*=.*modprobe|SYS_MODULE' && bad+=("loads a module itself (modprobe / CAP_SYS_MODULE)")
if [[ ${#bad[@]} -eq 0 ]]; then
  echo "ok: DynamicUser=yes, CAP_NET_ADMIN only, AF_NETLINK, host network, ProtectKernelModules=yes, vcan from modprobe@vcan.service"
else
  printf 'FAIL: canmotion-vcan@.service: %s\n' "${bad[@]}"; fail=1
fi

echo "== systemd-analyze security --offline (exposure 0 = best, 10 = worst)"
# Threshold 1.5 for every unit (issue 19; systemd/README.md; measured 1.5, 1.2,
# 1.1 with systemd 252).
declare -A threshold=([canmotiond.service]=1.5 [cia402-emu@.service]=1.5 [canmotion-vcan@.service]=1.5)
for u in canmotiond.service cia402-emu@.service canmotion-vcan@.service; do
  out=$(systemd-analyze security --offline=yes --root="$root" "$root/etc/systemd/system/$u" 2>&1 || true)
  level=$(sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\) \([A-Z]*\).*/\1 \2/p' <<<"$out")
  value=${level%% *}
  echo "$u: exposure $value (systemd's rating: ${level#* }; threshold ${threshold[$u]})"
  if [[ -z $value ]] || awk -v v="$value" -v t="${threshold[$u]}" 'BEGIN { exit !(v > t) }'; then
    echo "FAIL: $u exposure above threshold"; fail=1
  fi
done

exit $fail
