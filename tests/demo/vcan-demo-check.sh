#!/usr/bin/env bash
# vcan.demo, CHECK part: the candump -L trace ($CANMOTION_TRACE) of the demo
# on real SocketCAN.
#   vcan-demo-check.sh PERIOD_MS IFACE:NODE...
# Per node: boot-up, then the SDO configuration (0x6060 = 8 CSP, 0x60C2 = the
# period, RPDO1/TPDO1 mapping and COB-IDs), every request acknowledged and
# none aborted, then NMT start; in steady state (first SYNC after the node's
# NMT start up to its NMT pre-operational) exactly one RPDO and one TPDO of
# the node between consecutive SYNCs of its bus (exceptions are counted and
# reported: at most DEMO_EDGE_EXCEPTIONS (default 4) in the first and last 20
# cycles each, at most DEMO_MID_EXCEPTIONS (default 0) in between); the NMT
# pre-operational at the end, with no RPDO after it. Per bus: the SYNC
# interval mean within 5 % of the period (mean, min, p99, max reported). No
# EMCY on any bus.
set -euo pipefail
period_ms="$1"; shift
trace="$CANMOTION_TRACE"
art="${CANMOTION_ARTIFACTS:-$(dirname "$trace")}"
edge_max="${DEMO_EDGE_EXCEPTIONS:-4}" mid_max="${DEMO_MID_EXCEPTIONS:-0}"
fail() { echo "vcan-demo-check: FAIL: $*" >&2; exit 1; }
[[ -s "$trace" ]] || fail "empty trace $trace"

# No EMCY (0x081..0x0FF) on any bus.
emcy="$(awk '{ split($3, a, "#"); id = a[1] } id ~ /^0[89A-F][0-9A-F]$/ && id != "080" { print; n++ } END { exit n > 0 ? 0 : 1 }' "$trace" | head -5)" &&
  fail "EMCY frames in the trace:"$'\n'"$emcy"
echo "vcan-demo-check: no EMCY on any bus"

buses=()
for spec in "$@"; do
  iface="${spec%:*}" node="${spec#*:}"
  [[ " ${buses[*]} " == *" $iface "* ]] || buses+=("$iface")
  awk -v ifc="$iface" -v n="$node" -v p="$period_ms" -v edge_max="$edge_max" -v mid_max="$mid_max" '
    function hex3(v) { return sprintf("%03X", v) }
    function le32(v,   s, i) { s = ""; for (i = 0; i < 4; i++) { s = s sprintf("%02X", v % 256); v = int(v / 256) } return s }
    BEGIN {
      boot = hex3(1792 + n); req = hex3(1536 + n); rsp = hex3(1408 + n)
      for (k = 0; k < 4; k++) { rpdo[hex3(512 + 256 * k + n)] = 1; tpdo[hex3(384 + 256 * k + n)] = 1 }
      # The configuration writes that must be there (expedited SDO download requests).
      need["2F60600008000000"] = "0x6060 = 8 (CSP)"
      need["2FC26001" sprintf("%02X", p) "000000"] = "0x60C2:1 = " p
      need["2FC26002FD000000"] = "0x60C2:2 = -3 (ms)"
      need["2F00160000000000"] = "0x1600:0 = 0 (RPDO1 mapping cleared)"
      need["2F001A0000000000"] = "0x1A00:0 = 0 (TPDO1 mapping cleared)"
      need["23001401" le32(512 + n)] = "0x1400:1 = RPDO1 COB-ID valid"
      need["23001801" le32(384 + n)] = "0x1800:1 = TPDO1 COB-ID valid"
      need["23001601"] = "0x1600:1 (RPDO1 mapping entry 1)"
      need["23001A01"] = "0x1A00:1 (TPDO1 mapping entry 1)"
      nmt_start = "01" sprintf("%02X", n); preop = "80" sprintf("%02X", n)
    }
    $2 != ifc { next }
    {
      t = substr($1, 2, length($1) - 2) + 0; split($3, a, "#"); id = a[1]; d = a[2]; line++
      if (id == boot && d == "00" && !boot_at) boot_at = line
      if (id == req) {
        nreq++; if (!first_req) first_req = line
        for (w in need) if (index(d, w) == 1) { got[w] = line; last_cfg = line }
      }
      if (id == rsp) { nrsp++; if (substr(d, 1, 2) == "80") { aborts++; if (!abort1) abort1 = $0 } }
      if (id == "000" && (d == nmt_start || d == "0100") && !start_at) start_at = line
      if (id == "000" && (d == preop || d == "8000") && start_at) preop_at = line
      if (preop_at && line > preop_at) { if (id in rpdo) rp_after++; if (id == "080") sync_after++ }
      if (!start_at || preop_at) next
      if (id == "080") {
        if (k > 0) { K++; r[K] = rp; tt[K] = tp; ts[K] = t0 }
        k++; rp = tp = 0; t0 = t
      } else if (k > 0 && (id in rpdo)) { rp++; nr++ }
      else if (k > 0 && (id in tpdo)) { tp++; nt++ }
    }
    END {
      pre = "vcan-demo-check: " ifc " node " n ": "
      if (!boot_at) { print pre "FAIL: no boot-up (" boot "#00)"; exit 1 }
      if (!first_req || first_req < boot_at) { print pre "FAIL: no SDO request after the boot-up"; exit 1 }
      for (w in need) if (!got[w]) { print pre "FAIL: no SDO write " need[w] " (" req "#" w "...)"; exit 1 }
      if (aborts) { print pre "FAIL: " aborts " SDO aborts, first: " abort1; exit 1 }
      if (nrsp < nreq) { print pre "FAIL: " nreq " SDO requests but " nrsp " responses"; exit 1 }
      if (!start_at) { print pre "FAIL: no NMT start (000#" nmt_start ")"; exit 1 }
      if (start_at < last_cfg) { print pre "FAIL: NMT start before the end of the SDO configuration"; exit 1 }
      if (!preop_at) { print pre "FAIL: no NMT pre-operational (000#" preop ") after the start"; exit 1 }
      printf "%sboot-up, %d SDO requests (%d acknowledged, 0 aborted) incl. 0x6060, 0x60C2, RPDO1/TPDO1 mapping, then NMT start; NMT pre-operational at the end (%d RPDO, %d SYNC after it)\n", pre, nreq, nrsp, rp_after, sync_after
      if (rp_after > 0) { print pre "FAIL: RPDOs after the NMT pre-operational"; exit 1 }
      edge = 20; es = ee = em = 0; shown = 0
      for (i = 1; i <= K; i++) if (r[i] != 1 || tt[i] != 1) {
        if (i <= edge) es++; else if (i > K - edge) ee++; else em++
        if (shown++ < 8) list = list sprintf(" [cycle %d at %.6f: %d RPDO %d TPDO]", i, ts[i], r[i], tt[i])
      }
      printf "%s%d SYNC intervals in steady state: %d RPDO, %d TPDO; intervals without exactly one RPDO and one TPDO: %d at start, %d in the middle, %d at shutdown%s\n", pre, K, nr, nt, es, em, ee, list
      if (K < 500) { print pre "FAIL: fewer than 500 cycles in steady state"; exit 1 }
      if (es > edge_max || ee > edge_max || em > mid_max) { print pre "FAIL: too many exceptions (allowed " edge_max " at each end, " mid_max " in the middle)"; exit 1 }
    }' "$trace" || fail "node $node on $iface"
done

# SYNC period per bus, from the first to the last SYNC of the bus.
for iface in "${buses[@]}"; do
  awk -v ifc="$iface" '$2 == ifc && $3 == "080#" { t = substr($1, 2, length($1) - 2) + 0; if (n++) print (t - last) * 1e6; last = t }' "$trace" |
    sort -n > "$art/sync-intervals-$iface.txt"
  awk -v ifc="$iface" -v p="$period_ms" '{ v[NR] = $1; s += $1 }
    END {
      if (NR < 500) { printf "vcan-demo-check: FAIL: %s: only %d SYNC intervals\n", ifc, NR; exit 1 }
      m = s / NR; q = v[int(NR * 0.99)]
      printf "vcan-demo-check: %s: %d SYNC intervals: mean %.1f us, min %.1f us, p99 %.1f us, max %.1f us (period %d us)\n", ifc, NR, m, v[1], q, v[NR], p * 1000
      if (m < 0.95 * p * 1000 || m > 1.05 * p * 1000) { printf "vcan-demo-check: FAIL: %s: mean SYNC interval not within 5 %% of the period\n", ifc; exit 1 }
    }' "$art/sync-intervals-$iface.txt" || fail "SYNC period on $iface"
done
echo "vcan-demo-check: PASS"
