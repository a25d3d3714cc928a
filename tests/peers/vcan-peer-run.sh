#!/usr/bin/env bash
# vcan.peer.*, COMMAND part (runs where vcan0 is up, candump -L writing
# $CANMOTION_TRACE): canmotiond against the independent peer as separate
# processes.
#   vcan-peer-run.sh SCENARIO CANMOTIOND [PEER_OPTION...]
# SCENARIO is boot_enable_move, fault_recovery, vanish, nmt_preop,
# boot_late, power_cycle, link_down, never_heard, units_rpm or units_rpm_boot
# (scenarios/*.script; units_rpm_boot runs units_rpm.script).
# 1. the peer powers up (/usr/bin/python3 cia402_peer.py -i vcan0 -n 5
#    --position 123456 --heartbeat-ms 100 --control FIFO -v PEER_OPTION...),
#    then canmotiond
#    --config vcan.yaml --script scenarios/SCENARIO.script --csv, real time;
#    never_heard: --config vcan-two.yaml (a second axis, on node 6, where
#    nothing answers);
#    units_rpm: --config vcan-units.yaml with tests/units/rpm-drive.eds (the
#    peer gets --velocity-unit rpm --encoder-increments 4096 from ctest);
#    units_rpm_boot: --config vcan-units-boot.yaml, no EDS (the units are
#    read from the peer at boot);
#    boot_late: the peer process starts first but --powered-off (silent);
# 2. fault_recovery: after canmotiond printed the `X.JogStatus` line, the
#    peer gets `fault 0xFF00` on its control FIFO; nmt_preop: `nmt preop`
#    there (it leaves NMT operational by itself); vanish: the peer is
#    killed with SIGKILL at that point (the kill time is logged);
#    boot_late: 0.5 s after canmotiond's first `X.Statusword` line the peer
#    gets `power on` (boot-up, pre-operational);
#    power_cycle: after the `X.JogStatus` line the peer gets `power off`,
#    0.3 s later `power on` (its boot-up while canmotiond has it operational);
#    link_down: after the `X.JogStatus` line `ip link set vcan0 down`, 1.5 s
#    later `ip link set vcan0 up` (needs root: the VM's, or a host's);
# 3. canmotiond's exit status goes to canmotiond.status (vcan_peer_check.py
#    fails on anything but 0, after its analysis of the trace); then the
#    peer is stopped (SIGTERM: it prints its summary); run-vcan-test lets
#    the trace settle. This script fails only when the processes cannot be run.
# Artefacts: vcan.yaml (never_heard: vcan-two.yaml, units_rpm: vcan-units.yaml,
# units_rpm_boot: vcan-units-boot.yaml), canmotiond.log,
# canmotiond.csv, canmotiond.status, peer.log, events.log.
set -euo pipefail
scenario="$1" daemon="$2"; shift 2
peer_opts=("$@")
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)"
art="$CANMOTION_ARTIFACTS" trace="$CANMOTION_TRACE"
fail() { echo "vcan-peer-run: $*" >&2; exit 1; }
script="$here/scenarios/${scenario%_boot}.script"
[[ -f "$script" ]] || fail "no scenario '$scenario' ($script)"
config=vcan.yaml
[[ $scenario == never_heard ]] && config=vcan-two.yaml
[[ $scenario == units_rpm ]] && config=vcan-units.yaml
[[ $scenario == units_rpm_boot ]] && config=vcan-units-boot.yaml
[[ $scenario == ip_move ]] && config=vcan-ip.yaml
[[ $scenario == sdo_block ]] && config=vcan-sdo-block.yaml
rm -f "$art/vcan.yaml" "$art/vcan-two.yaml" "$art/vcan-units.yaml" "$art/vcan-units-boot.yaml" "$art/vcan-sdo-block.yaml" "$art/vcan-ip.yaml"
# sdo_block: the DOMAIN file next to the configuration (a path relative to it).
[[ $scenario == sdo_block ]] && cp "$here/sdo-block.bin" "$art/sdo-block.bin"
cp "$here/$config" "$art/$config"
# units_rpm: the drive's units come from its EDS (next to the configuration).
[[ $scenario == units_rpm ]] && cp "$here/../units/rpm-drive.eds" "$art/rpm-drive.eds"
ctl_dir="$(mktemp -d)"            # VM-local: a FIFO cannot live on the shared build tree, and a log polled there can be seen stale
ctl="$ctl_dir/peer.ctl"
rm -f "$art/events.log"
mkfifo "$ctl"
event() { echo "$EPOCHREALTIME $*" >> "$art/events.log"; }   # no fork: a `date` takes seconds in the VM

ppid_=""
cleanup() {
  if [[ -n "$ppid_" ]]; then kill -TERM "$ppid_" 2>/dev/null || true; wait "$ppid_" 2>/dev/null || true; fi
  ppid_=""
  rm -rf "$ctl_dir"
}
trap cleanup EXIT

# The peer powers up first: Python and python-can take about a minute to
# start under the VM's emulation (measured: `import can` 48-64 s), far more
# than canmotiond waits for a boot-up. It sends a heartbeat (0x1017 = 100 ms
# until canmotiond writes its own), so canmotiond finds it in
# pre-operational and configures it without waiting for a boot-up.
# boot_late: the process starts first too (for that minute), but without
# power: nothing in or out until `power on`, after canmotiond is running.
ready='boot-up, NMT pre-operational'
if [[ $scenario == boot_late ]]; then
  peer_opts=(--powered-off "${peer_opts[@]}")
  ready='powered off: no frames in or out'
fi
/usr/bin/python3 "$here/cia402_peer.py" -i vcan0 -n 5 --position 123456 --heartbeat-ms 100 --control "$ctl" -v \
  "${peer_opts[@]}" \
  > "$art/peer.log" 2>&1 &
ppid_=$!
for ((i = 0; i < 2400; i++)); do
  grep -q "$ready" "$art/peer.log" && break
  kill -0 "$ppid_" 2>/dev/null || break
  sleep 0.1
done
grep -q "$ready" "$art/peer.log" || { cat "$art/peer.log" >&2; fail "the peer did not start"; }
event "peer started (pid $ppid_)"
timeout -s INT -k 30 120 stdbuf -oL "$daemon" --config "$art/$config" --script "$script" --csv "$art/canmotiond.csv" \
  > "$ctl_dir/canmotiond.log" 2>&1 &
dpid=$!
event "canmotiond started (pid $dpid)"
echo "vcan-peer-run: $scenario: the peer (node 5, position 123456${peer_opts[*]:+, ${peer_opts[*]}}), then canmotiond"

wait_line() {  # wait_line REGEX: canmotiond printed it (true), or it exited / 1200 polls (false)
  for ((i = 0; i < 1200; i++)); do
    grep -q "$1" "$ctl_dir/canmotiond.log" && return 0
    kill -0 "$dpid" 2>/dev/null || break
    sleep 0.05
  done
  grep -q "$1" "$ctl_dir/canmotiond.log"
}
if [[ $scenario == boot_late ]]; then
  if wait_line 'X.Statusword='; then
    sleep 0.5                      # canmotiond runs (SYNC, its waits for the node) before the drive has power
    echo 'power on' > "$ctl"
    event "peer: power on"
  else
    event "no 'X.Statusword=' line from canmotiond (it exited, or 1200 polls): the peer stays off"
  fi
fi
if [[ $scenario == fault_recovery || $scenario == vanish || $scenario == nmt_preop || $scenario == power_cycle ||
      $scenario == link_down ]]; then
  if wait_line 'X.JogStatus='; then
    if [[ $scenario == power_cycle ]]; then
      echo 'power off' > "$ctl"
      event "peer: power off"
      sleep 0.3
      echo 'power on' > "$ctl"
      event "peer: power on"
    elif [[ $scenario == link_down ]]; then
      if ip link set vcan0 down; then event "vcan0 down"; else event "ip link set vcan0 down failed"; fi
      sleep 1.5
      if ip link set vcan0 up; then event "vcan0 up"; else event "ip link set vcan0 up failed"; fi
    elif [[ $scenario == fault_recovery ]]; then
      echo 'fault 0xFF00' > "$ctl"
      event "peer: fault 0xFF00 injected"
    elif [[ $scenario == nmt_preop ]]; then
      echo 'nmt preop' > "$ctl"
      event "peer: nmt preop"
    else
      kill -KILL "$ppid_"
      event "peer killed (SIGKILL)"
      wait "$ppid_" 2>/dev/null || true
      ppid_=""
    fi
  else
    event "no 'X.JogStatus=' line from canmotiond (it exited, or 1200 polls): nothing injected"
  fi
fi

status=0
wait "$dpid" || status=$?
event "canmotiond exit $status"
echo "vcan-peer-run: canmotiond exit $status"
cp "$ctl_dir/canmotiond.log" "$art/canmotiond.log"
cat "$art/canmotiond.log"
cleanup
trap - EXIT
echo "$status" > "$art/canmotiond.status"
echo "--- peer.log (last lines)"
tail -n 25 "$art/peer.log"
