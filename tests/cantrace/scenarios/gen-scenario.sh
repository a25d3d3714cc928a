#!/usr/bin/env bash
# gen-scenario.sh NAME: print a canplayer input log (candump -L format with
# synthetic times) for one CANopen CiA 402 scenario. Replayed onto vcan0 by
# canplayer inside tools/vcan-vm while real candump processes record it; the
# recordings are the golden traces in ../data/.
#
# Scenarios (master = this script, drives = nodes 1 and 2, 2 ms SYNC cycle):
#   boot_enable  boot-up, SDO configuration incl. PDO remapping and a segmented
#                upload, NMT start, CiA 402 enable sequence (Shutdown, Switch on,
#                Enable operation)
#   csp_motion   enabled drives following a cyclic synchronous position profile,
#                with three SYNC cycles in which node 1 sends no TPDO
#   fault_emcy   a following-error fault on node 2 (EMCY 0x8611, Fault state),
#                EMCY reset and fault reset back to Switch on disabled
#   sdo_abort    SDO writes rejected by the drive (abort 0x06090030 and 0x06020000)
set -euo pipefail
name="${1:?usage: gen-scenario.sh boot_enable|csp_motion|fault_emcy|sdo_abort}"

t=0  # microseconds
f() { printf '(%d.%06d) vcan0 %s\n' $((1700000000 + t / 1000000)) $((t % 1000000)) "$1"; t=$((t + 100)); }
adv() { t=$((t + $1 * 1000)); }
hex8() { printf '%02X' $(($1 & 255)); }
le16() { printf '%02X%02X' $(($1 & 255)) $((($1 >> 8) & 255)); }
le32() { printf '%02X%02X%02X%02X' $(($1 & 255)) $((($1 >> 8) & 255)) $((($1 >> 16) & 255)) $((($1 >> 24) & 255)); }
# sdo_write NODE INDEX SUB SIZE VALUE: expedited download + the drive's confirmation
sdo_write() {
  local n=$1 idx=$2 sub=$3 size=$4 val=$5 cmd
  case $size in 1) cmd=2F ;; 2) cmd=2B ;; 4) cmd=23 ;; esac
  local data
  data="$(le32 "$val")"
  f "$(printf '%03X' $((0x600 + n)))#${cmd}$(le16 "$idx")$(hex8 "$sub")${data}"
  f "$(printf '%03X' $((0x580 + n)))#60$(le16 "$idx")$(hex8 "$sub")00000000"
  adv 1
}
sdo_abort() {  # NODE INDEX SUB SIZE VALUE CODE: a write the drive rejects
  local n=$1 idx=$2 sub=$3 size=$4 val=$5 code=$6 cmd
  case $size in 1) cmd=2F ;; 2) cmd=2B ;; 4) cmd=23 ;; esac
  f "$(printf '%03X' $((0x600 + n)))#${cmd}$(le16 "$idx")$(hex8 "$sub")$(le32 "$val")"
  f "$(printf '%03X' $((0x580 + n)))#80$(le16 "$idx")$(hex8 "$sub")$(le32 "$code")"
  adv 1
}
sync_() { f "080#"; }
rpdo() { f "$(printf '%03X' $((0x200 + $1)))#$(le16 "$2")$(le32 "$3")"; }   # NODE CW TARGET
tpdo1() { f "$(printf '%03X' $((0x180 + 1)))#$(le16 "$1")$(le32 "$2")"; }   # node 1: SW ACTUAL
# node 2: SW ACTUAL, plus MODE (CSP) after boot_enable remapped its TPDO1 to 7 bytes
mode2=""
tpdo2() { f "$(printf '%03X' $((0x180 + 2)))#$(le16 "$1")$(le32 "$2")${mode2}"; }

boot() {
  f "701#00"; f "702#00"; adv 5
  f "701#7F"; f "702#7F"; adv 5
  for n in 1 2; do
    # identity: device type (expedited upload)
    f "$(printf '%03X' $((0x600 + n)))#4000100000000000"
    f "$(printf '%03X' $((0x580 + n)))#4300100092010200"; adv 1
    # device name (segmented upload, 13 bytes "canmotion-emu")
    f "$(printf '%03X' $((0x600 + n)))#4008100000000000"
    f "$(printf '%03X' $((0x580 + n)))#410810000D000000"; adv 1
    f "$(printf '%03X' $((0x600 + n)))#6000000000000000"
    f "$(printf '%03X' $((0x580 + n)))#0063616E6D6F7469"; adv 1
    f "$(printf '%03X' $((0x600 + n)))#7000000000000000"
    f "$(printf '%03X' $((0x580 + n)))#136F6E2D656D7500"; adv 1
    sdo_write $n 0x1017 0 2 100                      # producer heartbeat 100 ms
    # RPDO1: controlword + target position
    sdo_write $n 0x1400 1 4 $((0x80000200 + n))
    sdo_write $n 0x1600 0 1 0
    sdo_write $n 0x1600 1 4 0x60400010
    sdo_write $n 0x1600 2 4 0x607A0020
    sdo_write $n 0x1600 0 1 2
    sdo_write $n 0x1400 2 1 1
    sdo_write $n 0x1400 1 4 $((0x200 + n))
    # TPDO1: statusword + position actual (+ mode display on node 2)
    sdo_write $n 0x1800 1 4 $((0x80000180 + n))
    sdo_write $n 0x1A00 0 1 0
    sdo_write $n 0x1A00 1 4 0x60410010
    sdo_write $n 0x1A00 2 4 0x60640020
    if [[ $n == 2 ]]; then
      sdo_write $n 0x1A00 3 4 0x60610008
      sdo_write $n 0x1A00 0 1 3
    else
      sdo_write $n 0x1A00 0 1 2
    fi
    sdo_write $n 0x1800 2 1 1
    sdo_write $n 0x1800 1 4 $((0x180 + n))
    sdo_write $n 0x6060 0 1 8                        # CSP
    sdo_write $n 0x1006 0 4 2000                     # 2 ms cycle
  done
  f "000#0100"; adv 2                                # NMT start all
  f "701#05"; f "702#05"; adv 2
}

# cycle CW1 TGT1 SW1 ACT1 CW2 TGT2 SW2 ACT2 [skip1]: one 2 ms SYNC cycle
cycle() {
  local start=$t
  rpdo 1 "$1" "$2"; rpdo 2 "$5" "$6"; sync_
  [[ "${9:-}" == skip1 ]] || tpdo1 "$3" "$4"
  tpdo2 "$7" "$8"
  t=$((start + 2000))
}

enable() {
  cycle 0x0000 0 0x0250 0 0x0000 0 0x0250 0
  cycle 0x0006 0 0x0250 0 0x0006 0 0x0250 0
  cycle 0x0006 0 0x0231 0 0x0006 0 0x0231 0
  cycle 0x0007 0 0x0233 0 0x0007 0 0x0233 0
  cycle 0x000F 0 0x0233 0 0x000F 0 0x0233 0
  cycle 0x000F 0 0x1237 0 0x000F 0 0x1237 0
}

# CSP: trapezoidal velocity profile, 100 cycles. The drive reports, after
# SYNC k, the position it reached for the target applied at SYNC k, with a
# small tracking error that grows with speed (node 1) or none (node 2).
motion() {
  local i v=0 p1=0 p2=0 skip
  for ((i = 0; i < 100; i++)); do
    if ((i < 25)); then v=$((v + 40)); elif ((i >= 75)); then v=$((v - 40)); fi
    p1=$((p1 + v)); p2=$((p2 - v / 2))
    skip=""; ((i >= 50 && i < 53)) && skip=skip1
    cycle 0x000F "$p1" 0x1237 "$((p1 - v / 100 - (i % 3) + 1))" 0x000F "$p2" 0x1237 "$p2" $skip
  done
}

fault() {
  local i p1=1000 p2=-500
  for ((i = 0; i < 5; i++)); do cycle 0x000F $p1 0x1237 $p1 0x000F $p2 0x1237 $p2; done
  # node 2 loses track: following error, fault reaction, fault
  rpdo 1 0x000F $p1; rpdo 2 0x000F $p2; sync_; tpdo1 0x1237 $p1; tpdo2 0x321F $((p2 + 900))
  f "082#118621000000E803"; adv 2
  cycle 0x000F $p1 0x1237 $p1 0x000F $p2 0x0218 $((p2 + 950))
  cycle 0x000F $p1 0x1237 $p1 0x0000 $p2 0x0218 $((p2 + 950))
  # fault reset (rising edge of bit 7), EMCY "no error", back to Switch on disabled
  cycle 0x000F $p1 0x1237 $p1 0x0080 $p2 0x0218 $((p2 + 950))
  f "082#0000000000000000"
  cycle 0x000F $p1 0x1237 $p1 0x0000 $p2 0x0250 $((p2 + 950))
  cycle 0x000F $p1 0x1237 $p1 0x0006 $p2 0x0231 $((p2 + 950))
}

aborts() {
  f "701#7F"; f "702#7F"; adv 2
  sdo_abort 2 0x6060 0 1 0x42 0x06090030              # invalid mode of operation
  sdo_abort 1 0x2100 0 4 1 0x06020000                 # object does not exist
  # a read that is aborted by the drive
  f "601#4041600000000000"; f "581#8041600000000008"; adv 1
  sdo_write 1 0x6060 0 1 8
}

case "$name" in
  boot_enable) boot; mode2=08; enable ;;
  csp_motion) f "701#05"; f "702#05"; adv 2; enable; motion ;;
  fault_emcy) f "701#05"; f "702#05"; adv 2; enable; fault ;;
  sdo_abort) aborts ;;
  *) echo "gen-scenario.sh: unknown scenario '$name'" >&2; exit 1 ;;
esac
