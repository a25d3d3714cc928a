#!/usr/bin/env python3
"""check-wrap.py LOG CSV: check canmotiond --sim on wrap.yaml / wrap.script.

The axis X (1000 counts/mm, 20 m/s) homes, jogs past +2^31 and +2^32 drive
counts, stops, MRP, homes there, jogs back past -2^31 counts, homes again.
LOG has the script's six PRINT lines, CSV the --csv rows (one per cycle).

  homing   each MAH ends PC without ER, the axis at the home position 10 mm
           exactly and the drive at its home offset 5000 counts (0x607C),
           before the wrap, past +2^32 and past -2^31
  range    the drive frame reached past +2^31 and +2^32 counts (TargetCounts
           and ActualCounts), then past -2^31; at each stop the actual
           position is ActualCounts / 1000 + the frame offset (5 mm): the
           feedback was unwrapped, never saturated
  MRP      redefines the actual position to 1000 mm without moving the drive
  tracking from the CSV: every cycle's actual position is within TRACK_MM of
           the command 3 cycles earlier (the emulated drive applies a target
           2 SYNCs late, its TPDO is read a cycle later) and the largest
           |command - actual| stays below 3 cycles of travel at 20 m/s plus
           TRACK_MM; the actual position jumps only at the MRP and at the
           three homings (frame changes), nowhere else; the CSV covers
           positions past 2^32 counts / 1000 + 5 mm
  faults   no axis fault; X.MaxPositionError below the tolerance
PASS or each failure and FAIL (exit status 1).
"""
import csv
import re
import sys

CONV = 1000.0          # counts/mm (wrap.yaml)
HOME_MM, OFFSET_COUNTS = 10.0, 5000  # homing.position, homing.offset x CONV
SPEED, PERIOD = 20000.0, 0.001       # mm/s of the jogs, s
LAG = 3                # cycles between a command and the actual showing it
TRACK_MM = 1.0         # actual vs the command LAG cycles earlier (accelerations settle geometrically)
TOLERANCE_MM = 80.0    # position_error_tolerance (wrap.yaml)
LINE = re.compile(r"^t=([0-9.]+) (.*)$")


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    fails = []
    lines = []
    with open(sys.argv[1]) as f:
        for raw in f:
            m = LINE.match(raw.strip())
            if m:
                v = {k: float(x) for k, x in (kv.split("=", 1) for kv in m.group(2).split())}
                v["t"] = float(m.group(1))
                lines.append(v)
            elif "script failed" in raw or "ended before the script" in raw or "position error" in raw:
                fails.append(raw.strip())
    if len(lines) != 6:
        fails.append(f"{len(lines)} PRINT lines, want 6 (the script did not run to its end)")
        lines += [{}] * (6 - len(lines))
    home1, stop1, mrp, home2, stop2, home3 = lines

    def near(v, key, want, tol, what):
        got = v.get(key)
        if got is None or abs(got - want) > tol:
            fails.append(f"{what}: {key} = {got}, want {want} (+-{tol})")

    for v, name in ((home1, "MAH before the wrap"), (home2, "MAH past +2^32 counts"), (home3, "MAH past -2^31 counts")):
        mah = next((k[:-3] for k in v if k.endswith(".PC")), "mah")
        if v.get(f"{mah}.PC") != 1 or v.get(f"{mah}.ER") != 0:
            fails.append(f"{name}: {mah}.PC = {v.get(mah + '.PC')}, ER = {v.get(mah + '.ER')}")
        near(v, "X.ActualPosition", HOME_MM, 1e-9, name)
        near(v, "X.CommandPosition", HOME_MM, 1e-9, name)
        near(v, "X.ActualCounts", OFFSET_COUNTS, 0, name)
    for v, name, beyond in ((stop1, "stop past +2^32", 2**32), (stop2, "stop past -2^31", -2**31)):
        for key in ("X.ActualCounts", "X.TargetCounts"):
            got = v.get(key, 0.0)
            if (beyond > 0 and got <= beyond) or (beyond < 0 and got >= beyond):
                fails.append(f"{name}: {key} = {got:.0f}, not past {beyond}")
        # user = drive counts / conv + frame offset (the first homing: 10 mm at 5000 counts)
        near(v, "X.ActualPosition", v.get("X.ActualCounts", 0.0) / CONV + (HOME_MM - OFFSET_COUNTS / CONV), 1e-3, name)
    near(mrp, "X.ActualPosition", 1000.0, 1e-9, "MRP")
    near(mrp, "X.ActualCounts", stop1.get("X.ActualCounts", 0.0), 1000.0, "MRP (the drive is not moved)")
    for v in lines:
        if v.get("X.AxisFault", 0) != 0:
            fails.append(f"t={v.get('t')}: X.AxisFault = {v.get('X.AxisFault')}")
    if not 0 < home3.get("X.MaxPositionError", 1e9) < TOLERANCE_MM:
        fails.append(f"X.MaxPositionError = {home3.get('X.MaxPositionError')}, want below {TOLERANCE_MM}")

    # The CSV, cycle by cycle.
    cmd, act = [], []
    with open(sys.argv[2]) as f:
        r = csv.reader(f)
        head = next(r)
        ci, ai = head.index("cmd_pos"), head.index("act_pos")
        for row in r:
            cmd.append(float(row[ci]))
            act.append(float(row[ai]))
    # A frame change (MRP, a homing's completion): the command's step changes
    # by more than 1 mm in one cycle (its acceleration allows 0.05 mm), and
    # the actual moves with it. Exactly four: MAH, MRP, MAH, MAH.
    # A step, not a spike: the step after it is an ordinary one again.
    def step(i):
        return cmd[i] - cmd[i - 1]
    frame_changes = [i for i in range(2, len(act) - 1)
                     if abs(step(i) - step(i - 1)) > 1.0 and abs(step(i + 1) - step(i - 1)) < 1.0 and
                     abs((act[i] - act[i - 1]) - step(i)) < 1.0]
    skip = {j + k for j in frame_changes for k in range(LAG)}
    if len(frame_changes) != 4:
        fails.append(f"{len(frame_changes)} frame changes (command and actual jumping together), want 4 "
                     f"(MAH, MRP, MAH, MAH): at rows {frame_changes[:10]}")
    jump = 1.5 * SPEED * PERIOD
    jumps = [i for i in range(1, len(act)) if abs(act[i] - act[i - 1]) > jump and i not in frame_changes]
    if jumps:
        fails.append(f"the actual position jumped by more than {jump} mm in {len(jumps)} cycles: at rows {jumps[:10]}")
    worst_track, worst_at, worst_err = 0.0, 0, 0.0
    for i in range(LAG, len(act)):
        if i in skip:
            continue  # the command and the actual change frame in the same cycle
        d = abs(act[i] - cmd[i - LAG])
        if d > worst_track:
            worst_track, worst_at = d, i
        worst_err = max(worst_err, abs(cmd[i] - act[i]))
    if worst_track > TRACK_MM:
        fails.append(f"row {worst_at}: actual {act[worst_at]} is {worst_track:.3f} mm from the command {LAG} cycles "
                     f"earlier ({cmd[worst_at - LAG]})")
    if worst_err > LAG * SPEED * PERIOD + TRACK_MM:
        fails.append(f"largest |command - actual| {worst_err:.3f} mm, more than {LAG} cycles at {SPEED} mm/s")
    top, bottom = max(act), min(act)
    if top < 2**32 / CONV + HOME_MM - OFFSET_COUNTS / CONV:
        fails.append(f"the CSV's actual position reached {top} mm only, not past 2^32 counts")
    print(f"check-wrap: {len(act)} CSV rows; actual from {bottom:.3f} to {top:.3f} mm; drive counts "
          f"{stop1.get('X.ActualCounts', 0):.0f} and {stop2.get('X.ActualCounts', 0):.0f} at the stops; "
          f"frame changes at rows {frame_changes}; largest |actual - command {LAG} cycles earlier| "
          f"{worst_track:.3f} mm, largest |command - actual| {worst_err:.3f} mm; "
          f"MaxPositionError {home3.get('X.MaxPositionError')}")
    for m in fails[:30]:
        print(f"check-wrap: {m}")
    if fails:
        print(f"check-wrap: FAIL ({len(fails)} problems)")
        return 1
    print("check-wrap: PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
