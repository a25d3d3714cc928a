#!/usr/bin/env bash
# demo.coordinated: the coordinated motion demo (issue 14) end to end in
# --sim: canmotiond --sim --config coordinated.yaml --script
# coordinated.script --csv, twice.
#   coordinated.sh CANMOTIOND EXAMPLES_DIR TOOLS_DIR OUTDIR
# Checks:
# 1. exit 0 both times, CSV byte-identical (deterministic);
# 2. the PRINT lines: the rectangle ends at (0, 0), the half circle at
#    (60, 0), the master-driven pass at (160, 30) (X/Y.CommandPosition and
#    XY.CommandPosition[i]); the pass runs at 1.5 x the conveyor's 40 mm/s
#    (XY.Speed = 60) with CoordinateSystemLockStatus, mdcc1 IP and AC; MCS All
#    breaks the link (mdcc1.IP = 0);
# 3. the CSV (X and Y command positions per cycle): during the rectangle the
#    path stays inside it, passes each blended corner (100,0), (100,60),
#    (0,60) at a distance in (0, 5] (the command tolerance) and never stops
#    there (vector speed > 1 mm/s within 6 mm of the corner); the arc stays
#    within 1e-6 of its circle (CSV resolution);
# 4. with gnuplot: tools/plot-xy writes a PNG of the path.
set -euo pipefail
daemon="$1" examples="$2" tools="$3" out="$4"
fail() { echo "coordinated: FAIL: $*" >&2; exit 1; }
rm -rf "$out"; mkdir -p "$out"
for run in a b; do
  status=0
  timeout -k 5 120 "$daemon" -q --sim --config "$examples/coordinated.yaml" --script "$examples/coordinated.script" \
    --csv "$out/$run.csv" > "$out/$run.log" 2> "$out/$run.err" || status=$?
  [[ $status == 0 ]] || { cat "$out/$run.log" "$out/$run.err" >&2; fail "run $run exited with status $status"; }
done
cmp "$out/a.csv" "$out/b.csv" || fail "--csv outputs differ between two runs"
cat "$out/a.log"
expect() {  # expect 'regex' description
  grep -Eq "$1" "$out/a.log" || fail "$2: no line matching /$1/ in the output"
}
expect 'X\.CommandPosition=0 Y\.CommandPosition=0 XY\.MoveStatus=0' "rectangle end"
expect 'X\.CommandPosition=60 Y\.CommandPosition=0$' "arc end"
expect 'XY\.Speed=60 XY\.CoordinateSystemLockStatus=1 mdcc1\.IP=1 mdcc1\.AC=1 md1\.AC=1' "master-driven pass"
expect 'X\.CommandPosition=160 Y\.CommandPosition=30 XY\.CommandPosition\[0\]=160 XY\.CommandPosition\[1\]=30' "pass end"
expect 'mdcc1\.IP=0 XY\.MoveStatus=0' "MCS All"
# CSV: cycle,time_s,axis,cmd_pos,act_pos,cmd_vel,act_vel,motion_status,axis_status
awk -F, '
  $3 == "X" { x[$1] = $4; vx[$1] = $6 }
  $3 == "Y" { y[$1] = $4; vy[$1] = $6 }
  END {
    n = 0; for (c in x) if (c in y) n++
    if (n < 1000) { print "too few cycles: " n; exit 1 }
    # phase 1: from the first motion until back at (0,0) after passing (0,60)
    split("100 0 100 60 0 60", k, " ")
    for (i = 0; i < 3; i++) { dmin[i] = 1e9; vmin[i] = 1e9 }
    phase = 0; moved = 0; bad = 0
    for (c = 0; c <= 1e7 && phase < 2; c++) {
      if (!(c in x) || !(c in y)) { if (moved) break; else continue }
      if (x[c] > 0.001 || y[c] > 0.001) moved = 1
      if (!moved) continue
      if (x[c] < -1e-6 || x[c] > 100 + 1e-6 || y[c] < -1e-6 || y[c] > 60 + 1e-6) { print "outside the rectangle at cycle " c ": " x[c] ", " y[c]; bad = 1 }
      v = sqrt(vx[c] * vx[c] + vy[c] * vy[c])
      for (i = 0; i < 3; i++) {
        d = sqrt((x[c] - k[2 * i + 1]) ^ 2 + (y[c] - k[2 * i + 2]) ^ 2)
        if (d < dmin[i]) dmin[i] = d
        if (d < 6 && v < vmin[i]) vmin[i] = v
      }
      if (dmin[2] < 6 && x[c] < 0.001 && y[c] < 0.001) phase = 2
    }
    for (i = 0; i < 3; i++) {
      printf "corner (%s, %s): closest %.4f mm, slowest %.2f mm/s within 6 mm\n", k[2 * i + 1], k[2 * i + 2], dmin[i], vmin[i]
      if (!(dmin[i] > 0.01 && dmin[i] <= 5.0 + 1e-6)) { print "corner deviation outside (0, 5]"; bad = 1 }
      if (!(vmin[i] > 1)) { print "the path stopped at a corner"; bad = 1 }
    }
    # the half circle around (30, 0), radius 30, below the x axis
    arc = 0; rmax = 0
    for (c in x) if ((c in y) && y[c] < -0.5) { arc++; r = sqrt((x[c] - 30) ^ 2 + y[c] ^ 2); e = r - 30; if (e < 0) e = -e; if (e > rmax) rmax = e }
    printf "arc: %d cycles, max |r - 30| = %.2e mm\n", arc, rmax
    if (arc < 100 || rmax > 1e-5) { print "arc off its circle"; bad = 1 }
    exit bad
  }' "$out/a.csv" || fail "path checks on the CSV ($out/a.csv)"
if command -v gnuplot > /dev/null; then
  "$tools/plot-xy" "$out/a.csv" X Y "$out/xy.png" "coordinated demo: XY path" || fail "plot-xy"
  [[ $(head -c 4 "$out/xy.png" | od -An -c | tr -d ' ') == '211PNG' ]] || fail "plot-xy did not write a PNG"
else
  echo "coordinated: gnuplot not installed: picture skipped"
fi
echo "coordinated: PASS"
