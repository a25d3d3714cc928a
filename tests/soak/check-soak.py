#!/usr/bin/env python3
"""check-soak.py LOG --seconds S --clock-start C: check a simulation soak's output.

LOG is canmotiond's output for tests/soak/soak.script (run-soak.sh): one
PRINT line per lap of the coordinated loop, then the --stats summary. Checks:

  gear     every lap: G's command position in counts is 3/7 of M's, to
           within one count (MAG fraction 3:7, no clutch: exact integer
           counts, so no drift whatever the run's length)
  cam      every lap: C's continuous time cam (+360 deg a 2 s pass, counted
           from the cycle of the line printed after MATC) is exactly
           360 k deg in the pass's first dwell, 360 (k + 1) in its last,
           and in between otherwise: no pass lost or gained, no drift
  wrap     G and C run past 2^31 and 2^32 counts (their ActualCounts, the
           drive frame of 64-bit counts) when the run is long enough for
           it (G: 1.4 h, C: 40 min), and ActualPosition x conversion
           constant stays that count (the feedback is unwrapped, never
           saturated)
  lap      every lap ends exactly where it started (X = Y = 0)
  cycle    Controller.Cycle equals the lap's time / period (the cycle
           counter and the clock agree), and grows lap by lap
  motion   the gear and the cam stay in process (IP), no axis fault, no TPDO
           missed on any axis
  counters every emulated drive took every SYNC after its boot with 0
           counter errors (the SYNC counter ran 1..240 and wrapped), booted
           once, and got one RPDO and sent one TPDO per SYNC since then; the
           bus sent one SYNC per cycle
  rss      the resident set after the first 10 minutes never grows by more
           than --rss-slack-kib (default 256); not with --no-rss

Prints one line per simulated hour (laps, RSS, the largest gear error) and
PASS, or each failure and FAIL (exit status 1).
"""
import argparse
import re
import sys

PERIOD_S = 0.001
CONV_M = CONV_G = 100000.0  # counts/mm (soak.yaml): the gear is in counts
CONV_C = 10000.0            # counts/deg
CAM_PASS_S, CAM_RISE = 2.0, 360.0
LINE = re.compile(r"^t=([0-9.]+) (.*)$")
DRIVE = re.compile(r"^summary: emulated drive node +(\d+) on bus (\S+): (\d+) SYNCs taken \((\d+) counter errors, "
                   r"(\d+) of the wrong length\), (\d+) RPDOs, (\d+) TPDOs, (\d+) boot-ups, (\d+) EMCYs$")
BUS = re.compile(r"^summary: bus (\S+): (\d+) SYNCs sent, (\d+) refused")
CYCLES = re.compile(r"^summary: (\d+) cycles, ")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("log")
    ap.add_argument("--seconds", type=float, required=True, help="the soak's length in simulated seconds")
    ap.add_argument("--clock-start", type=float, default=0.0, help="the run's --sim-clock-start, seconds")
    ap.add_argument("--rss-slack-kib", type=float, default=256.0)
    ap.add_argument("--no-rss", action="store_true",
                    help="do not check the RSS (sanitizer builds: ASan's quarantine keeps freed memory resident)")
    a = ap.parse_args()

    fails = []
    laps = []
    cam_start = None
    drives, buses, cycles = [], {}, None
    with open(a.log) as f:
        for raw in f:
            line = raw.rstrip("\n")
            m = LINE.match(line)
            if m and "Controller.Cycle=" in line:
                v = {k: float(x) for k, x in (kv.split("=", 1) for kv in m.group(2).split())}
                v["t"] = float(m.group(1))
                if "M.CommandPosition" not in v:  # the line after MATC: the cam's start
                    cam_start = v
                    continue
                laps.append(v)
                continue
            if (m := DRIVE.match(line)):
                drives.append(tuple(int(x) if x.isdigit() else x for x in m.groups()))
            elif (m := BUS.match(line)):
                buses[m.group(1)] = (int(m.group(2)), int(m.group(3)))
            elif (m := CYCLES.match(line)):
                cycles = int(m.group(1))
            elif "script failed" in line or "ended before the script" in line:
                fails.append(line)

    if not laps:
        print(f"check-soak: FAIL: no lap lines in {a.log}")
        return 1
    if laps[-1]["t"] < a.seconds - 30:
        fails.append(f"the last lap ended at t={laps[-1]['t']:.3f} s, not near {a.seconds:.0f} s")

    gear_max = 0.0
    prev_cycle = -1
    for v in laps:
        where = f"lap at t={v['t']:.3f}"
        m_counts, g_counts = v["M.CommandPosition"] * CONV_M, v["G.CommandPosition"] * CONV_G
        err = g_counts - m_counts * 3 / 7
        gear_max = max(gear_max, abs(err))
        v["gear_err"] = err
        if abs(err) > 1.0 + 1e-3:
            fails.append(f"{where}: gear off by {err:.3f} counts (G {g_counts:.3f}, 3/7 M {m_counts * 3 / 7:.3f})")
        if v["X.CommandPosition"] != 0 or v["Y.CommandPosition"] != 0:
            fails.append(f"{where}: the lap ended at ({v['X.CommandPosition']}, {v['Y.CommandPosition']}), not (0, 0)")
        c = v["Controller.Cycle"]
        if abs(c - round(v["t"] / PERIOD_S)) > 0.5 or c <= prev_cycle:
            fails.append(f"{where}: Controller.Cycle {c:.0f} does not match t / period or did not grow (previous {prev_cycle:.0f})")
        prev_cycle = c
        if cam_start is not None:
            # The MATC starts in the cycle of the line after it or the next:
            # the cam coordinate is (cycle - start) ms less 0..2 ms.
            x = (c - cam_start["Controller.Cycle"]) * PERIOD_S
            k = int(x // CAM_PASS_S)
            phase = x - k * CAM_PASS_S
            cp = v["C.CommandPosition"]
            if 0.01 <= phase <= 0.39 and cp != CAM_RISE * k:
                fails.append(f"{where}: cam pass {k} first dwell: C at {cp}, not {CAM_RISE * k}")
            elif 1.61 <= phase <= 1.99 and cp != CAM_RISE * (k + 1):
                fails.append(f"{where}: cam pass {k} last dwell: C at {cp}, not {CAM_RISE * (k + 1)}")
            elif not (CAM_RISE * k - 1e-6 <= cp <= CAM_RISE * (k + 1) + 1e-6):
                fails.append(f"{where}: cam pass {k}: C at {cp}, outside [{CAM_RISE * k}, {CAM_RISE * (k + 1)}]")
            v["cam_pass"] = k
        for ax, conv in (("G", CONV_G), ("C", CONV_C)):
            counts, act = v[f"{ax}.ActualCounts"], v[f"{ax}.ActualPosition"] * conv
            if abs(counts - act) > 1.0:
                fails.append(f"{where}: {ax}.ActualCounts {counts:.0f} but ActualPosition x {conv:.0f} = {act:.1f}")
        if v["mag1.IP"] != 1 or v["matc1.IP"] != 1:
            fails.append(f"{where}: the gear (IP {v['mag1.IP']:.0f}) or the cam (IP {v['matc1.IP']:.0f}) is no longer in process")
        for ax in "GCXY":
            if v[f"{ax}.AxisFault"] != 0:
                fails.append(f"{where}: {ax}.AxisFault = {v[f'{ax}.AxisFault']:.0f}")
            if v[f"{ax}.TpdoMissed"] != 0:
                fails.append(f"{where}: {ax}.TpdoMissed = {v[f'{ax}.TpdoMissed']:.0f}")

    if cam_start is None:
        fails.append("no line after MATC (Controller.Cycle, C.CommandPosition): the cam cannot be checked")
    # Past the 32-bit wire range: the drive frame is 64-bit counts.
    for ax, speed in (("G", 20 * 3 / 7 * CONV_G), ("C", CAM_RISE / CAM_PASS_S * CONV_C)):
        top = max(v[f"{ax}.ActualCounts"] for v in laps)
        for bound, name in ((2**31, "2^31"), (2**32, "2^32")):
            if laps[-1]["t"] > bound / speed + 600 and top <= bound:
                fails.append(f"{ax} never ran past {name} counts (at most {top:.0f}) in {laps[-1]['t']:.0f} s")
        print(f"check-soak: {ax} reached {top:.0f} counts ({top / 2**32:.2f} x 2^32)")

    # The summary: SYNC counter, TPDO/RPDO and cycle counters.
    if cycles is None or not buses or len(drives) != 4:
        fails.append(f"summary incomplete: cycles {cycles}, buses {sorted(buses)}, {len(drives)} emulated drives (want 4)")
    else:
        for name, (sent, refused) in buses.items():
            if sent != cycles or refused != 0:
                fails.append(f"bus {name}: {sent} SYNCs sent ({refused} refused) in {cycles} cycles")
        for node, bus, taken, cerr, lerr, rpdos, tpdos, boots, emcys in drives:
            who = f"emulated drive node {node} on {bus}"
            if cerr != 0:
                fails.append(f"{who}: {cerr} SYNC counter errors")
            if boots != 1:
                fails.append(f"{who}: {boots} boot-ups")
            if taken + lerr != cycles or lerr > 100:
                fails.append(f"{who}: {taken} SYNCs taken + {lerr} of the wrong length (before 0x1019 was written) "
                             f"!= {cycles} cycles")
            if abs(tpdos - taken) > 100 or abs(rpdos - taken) > 100:
                fails.append(f"{who}: {rpdos} RPDOs, {tpdos} TPDOs for {taken} SYNCs")

    # RSS after a 10-minute warm-up (or the first lap of a shorter run).
    base = next((v for v in laps if v["t"] >= 600), laps[0])
    rss_max = max(v["Controller.RssKiB"] for v in laps if v["t"] >= base["t"])
    if a.no_rss:
        print("check-soak: RSS not checked (--no-rss)")
    elif rss_max - base["Controller.RssKiB"] > a.rss_slack_kib:
        fails.append(f"RSS grew from {base['Controller.RssKiB']:.0f} KiB (t={base['t']:.0f} s) to {rss_max:.0f} KiB")

    wrap_s = 2**32 / 1000 - a.clock_start
    if 0 < wrap_s < laps[-1]["t"]:
        print(f"check-soak: the clock passed 2^32 ms at t={wrap_s:.3f} s of controller time")
    print(f"check-soak: {len(laps)} laps, {cycles} cycles; per simulated hour:")
    print(f"{'hour':>5} {'t s':>9} {'laps':>6} {'RSS KiB':>8} {'max |gear error| counts':>24} {'M mm':>12} {'G mm':>12} "
          f"{'G counts':>13} {'C deg':>11} {'C counts':>13}")
    h, i0 = 1, 0
    for i, v in enumerate(laps):
        last = i == len(laps) - 1
        if v["t"] >= h * 3600 or last:
            seg = laps[i0:i + 1]
            print(f"{h:>5} {v['t']:>9.1f} {len(seg):>6} {v['Controller.RssKiB']:>8.0f} "
                  f"{max(abs(x['gear_err']) for x in seg):>24.3f} {v['M.CommandPosition']:>12.3f} {v['G.CommandPosition']:>12.3f} "
                  f"{v['G.ActualCounts']:>13.0f} {v['C.CommandPosition']:>11.1f} {v['C.ActualCounts']:>13.0f}")
            h, i0 = h + 1, i + 1
    print(f"check-soak: largest gear error {gear_max:.3f} counts; RSS {base['Controller.RssKiB']:.0f} KiB at "
          f"t={base['t']:.0f} s, at most {rss_max:.0f} KiB after")
    for m in fails[:50]:
        print(f"check-soak: {m}")
    if fails:
        print(f"check-soak: FAIL ({len(fails)} problems)")
        return 1
    print("check-soak: PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
