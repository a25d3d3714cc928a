// What member-axis instructions and faults do to a running coordinate system
// (reference coordinated-motion.md, "Member axes and single-axis
// instructions"; issue 14 item 5): MSF, MASD, Stop Drive / Shutdown faults
// end the moves and path-stop the other members at the system's max decel;
// MAS All, MGS and Stop Planner stop the whole system along its path; ERR 52
// for MRP/MAH/MDS on a member; ERR 39 for an axis moved by two systems; the
// MDCC link breaks when its master is shut down. Seeded property tests: seed
// and count from CANMOTION_SEED / CANMOTION_PROP_COUNT, printed on failure.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "motion/instr/coord.hpp"
#include "tests/motion/prop_util.hpp"
#include "tests/motion_coord/array_rig.hpp"

namespace canmotion::motion::test {
namespace {

namespace cms = coordinate_motion_status;
bool cs_bit(const CoordSystemTag& t, unsigned b) { return (t.motion_status >> b) & 1u; }
bool coord_bit(const AxisTag& t) { return (t.motion_status >> motion_status::CoordinatedMotionStatus) & 1u; }

/// Virtual axes X, Y, Z (servo on) in group g, masters M and M2; the
/// coordinate system cs {X, Y, Z} (or {X, Y}) with the given ratios and max
/// decel; REAL arrays p1, p2 (3 elements) and ctr.
struct MemberRig : ArrayRig {
  int dim;
  explicit MemberRig(int dim_ = 3, double max_decel = 1000, std::array<double, 3> ratio = {1, 1, 1},
                     AxisConfig a = {}) : dim(dim_) {
    a.max_speed = 1000;
    a.max_accel = a.max_decel = 1e4;
    a.max_accel_jerk = a.max_decel_jerk = 1e6;
    for (const char* n : {"X", "Y", "Z", "M", "M2"}) {
      add_axis(n, a);
      EXPECT_EQ(exec(std::string("MSO(") + n + ", mso" + n + ");"), Err::None);
    }
    CoordSystemConfig c;
    c.dim = dim;
    c.axes = {sym.axes.at("X"), sym.axes.at("Y"), dim == 3 ? sym.axes.at("Z") : kNoAxis};
    c.ratio = ratio;
    c.max_speed = 500;
    c.max_accel = 5000;
    c.max_decel = max_decel;
    c.max_accel_jerk = c.max_decel_jerk = 1e6;
    EXPECT_TRUE(p->configure_coordinate_system(0, c));
    sym.coordinate_systems["cs"] = 0;
    for (const char* n : {"p1", "p2", "ctr"}) add_array(n, 3);
    step();
  }
  void set(const std::string& name, double x, double y, double z = 0) { arrays[sym.real_arrays.at(name)] = {x, y, z}; }
  const CoordSystemTag& cs() { return p->coordinate_system(0); }
};

std::string mclm(const std::string& cs, const std::string& c, const std::string& pos, double v, double a,
                 const std::string& profile = "trapezoidal", double j = 0, const std::string& su = "unitspersec",
                 const std::string& au = "unitspersec2", const std::string& ju = "unitspersec3",
                 const std::string& lock = "none") {
  return "MCLM(" + cs + "," + c + ",0," + pos + "," + num(v) + "," + su + "," + num(a) + "," + au + "," + num(a) + "," +
         au + "," + profile + "," + num(j) + "," + num(j) + "," + ju + ",nosettle,disabled,programmed,0,0," + lock +
         ",0,0);";
}
std::string mccm_center(const std::string& c, bool cw, double v, double a, const std::string& profile, double j) {
  return "MCCM(cs," + c + ",absolute,p1,center,ctr," + (cw ? "clockwise" : "counterclockwise") + "," + num(v) +
         ",unitspersec," + num(a) + ",unitspersec2," + num(a) + ",unitspersec2," + profile + "," + num(j) + "," +
         num(j) + ",unitspersec3,nosettle,disabled,programmed,0,0,none,0,0);";
}

double dist_to_segment(const std::array<double, 3>& p, const std::array<double, 3>& a, const std::array<double, 3>& b,
                       int skip) {
  double d[3], w[3], l2 = 0, t = 0;
  for (int i = 0; i < 3; ++i) {
    d[i] = i == skip ? 0 : b[i] - a[i];
    w[i] = i == skip ? 0 : p[i] - a[i];
    l2 += d[i] * d[i];
    t += w[i] * d[i];
  }
  t = l2 > 0 ? std::clamp(t / l2, 0.0, 1.0) : 0.0;
  double e = 0;
  for (int i = 0; i < 3; ++i) e += (w[i] - t * d[i]) * (w[i] - t * d[i]);
  return std::sqrt(e);
}

enum class Cause { Msf, Masd, MasAll, Mgs };
const char* name(Cause c) {
  switch (c) {
    case Cause::Msf: return "MSF";
    case Cause::Masd: return "MASD";
    case Cause::MasAll: return "MAS All";
    case Cause::Mgs: return "MGS";
  }
  return "?";
}

// The maths of the stop that a member's stop, servo off or shutdown starts:
// random 3-D lines and XY arcs (random ratios, dynamics, S-curve or
// trapezoid, system max decel), interrupted at a random instant. While it
// stops: the path (the members that still follow it; all of them for MAS
// All / MGS) stays on the line / circle within 1e-9 of its size, the vector
// speed never rises, the stop ends within v0 / Dmax (+ 1 cycle) and within
// the stop distance v0^2 / (2 Dmax); the move ends without PC or ER, the CS
// shows StoppingStatus until standstill and then neither MoveStatus nor the
// members' bit 16.
TEST(CoordMemberStop, PathStopsAlongItselfAtTheMaxDecel) {
  const std::uint64_t seed = prop_seed();
  const std::uint64_t count = prop_count(80);
  Rng g(seed);
  int interrupted = 0;
  for (std::uint64_t trial = 0; trial < count; ++trial) {
    const std::array<double, 3> ratio = {g.uni(0.5, 2), g.uni(0.5, 2), g.uni(0.5, 2)};
    const double D = g.logu(100, 5000);
    MemberRig r(3, D, ratio);
    const bool arc = g.coin(0.4);
    const Cause cause = static_cast<Cause>(g.pick(4));
    const bool scurve = g.coin();
    const double v = g.uni(20, 300), a = g.logu(300, 5000), j = scurve ? g.logu(1e4, 1e6) : 0.0;
    const std::string prof = scurve ? "scurve" : "trapezoidal";
    std::array<double, 3> P1{}, C{};
    double R = 0, L = 0;
    std::string text;
    if (arc) {  // in the XY plane from the origin, around C, to a random point of the circle
      C = {g.uni(-50, 50), g.uni(-50, 50), 0};
      R = std::hypot(C[0], C[1]);
      if (R < 5) continue;
      const double phi = std::atan2(-C[1], -C[0]) + g.uni(0.3, 2 * std::numbers::pi - 0.3);
      P1 = {C[0] + R * std::cos(phi), C[1] + R * std::sin(phi), 0};
      r.set("ctr", C[0], C[1], 0);
      L = 2 * std::numbers::pi * R;
      text = mccm_center("m1", g.coin(), v, a, prof, j);
    } else {
      P1 = {g.uni(-100, 100), g.uni(-100, 100), g.uni(-100, 100)};
      L = std::sqrt(P1[0] * P1[0] + P1[1] * P1[1] + P1[2] * P1[2]);
      if (L < 5) continue;
      text = mclm("cs", "m1", "p1", v, a, prof, j);
    }
    r.set("p1", P1[0], P1[1], P1[2]);
    // the member that leaves (MSF/MASD): on an arc Z, whose share is 0, so
    // that X and Y still show the circle
    const int k = arc ? 2 : g.pick(3);
    const char* ax[] = {"X", "Y", "Z"};
    const bool leaves = cause == Cause::Msf || cause == Cause::Masd;
    SCOPED_TRACE("seed " + std::to_string(seed) + " trial " + std::to_string(trial) + (arc ? " arc" : " line") +
                 " " + name(cause) + " member " + ax[k] + " " + text + " D=" + num(D, 6));
    ASSERT_EQ(r.exec(text), Err::None);
    const int at = 1 + g.pick(static_cast<int>(std::max(2.0, 1000 * (L / v + v / a))));
    r.step(at);
    if (r.tag("m1").pc() || !(r.cs().speed > 1e-3)) continue;  // ended (or still starting) before the interrupt
    ++interrupted;
    const double v0 = r.cs().speed;
    std::array<double, 3> prev = r.cs().command_position;
    Err e = Err::None;
    switch (cause) {
      case Cause::Msf: e = r.exec(std::string("MSF(") + ax[k] + ", f);"); break;
      case Cause::Masd: e = r.exec(std::string("MASD(") + ax[k] + ", f);"); break;
      case Cause::MasAll:
        e = r.exec(std::string("MAS(") + ax[k] + ", f, all, no, 0, unitspersec2, no, 0, unitspersec3);");
        break;
      case Cause::Mgs: e = r.exec("MGS(g, f, faststop);"); break;
    }
    ASSERT_EQ(e, Err::None);
    EXPECT_FALSE(r.tag("m1").ip());
    EXPECT_FALSE(r.tag("m1").ac());
    EXPECT_FALSE(r.tag("m1").pc());
    EXPECT_FALSE(r.tag("m1").er());
    if (!leaves) {
      EXPECT_TRUE(r.tag("f").ip());  // MAS All / MGS: IP while the path stops
    }
    double vprev = v0, travelled = 0;
    int n = 0;
    const std::array<double, 3> O{0, 0, 0};
    while (n < 100000) {
      r.step();
      ++n;
      const CoordSystemTag& t = r.cs();
      const bool stopping = cs_bit(t, cms::StoppingStatus);
      EXPECT_LE(t.speed, vprev * (1 + 1e-9) + 1e-12) << "cycle " << n;
      vprev = t.speed;
      const std::array<double, 3>& p = t.command_position;
      double d2 = 0;
      for (int i = 0; i < 3; ++i)
        if (!leaves || i != k) d2 += (p[i] - prev[i]) * (p[i] - prev[i]);
      travelled += std::sqrt(d2);
      prev = p;
      if (arc) {
        EXPECT_NEAR(std::hypot(p[0] - C[0], p[1] - C[1]), R, 1e-9 * R) << "cycle " << n;
      } else {
        // the members that follow the path: on the line (its projection without the member that left)
        std::array<double, 3> q = p;
        EXPECT_LE(dist_to_segment(q, O, P1, leaves ? k : -1), 1e-9 * L) << "cycle " << n;
      }
      if (!stopping && !cs_bit(t, cms::MoveStatus)) break;
      EXPECT_TRUE(stopping) << "cycle " << n;
    }
    EXPECT_LE(n * 0.001, v0 / D + 0.002);
    // not dropped: the stop sheds v0 at D (harder only when it would pass the move's end)
    bool at_end = true;
    for (int i = 0; i < 3; ++i)
      if (!leaves || i != k) at_end = at_end && std::fabs(r.cs().command_position[i] - P1[i]) < 1e-6 * L;
    if (!at_end) {
      EXPECT_GE(n * 0.001, v0 / D - 0.0015);
    }
    EXPECT_LE(travelled, v0 * v0 / (2 * D) * (1 + 1e-9) + v0 * 0.001);
    r.step();
    EXPECT_FALSE(cs_bit(r.cs(), cms::MoveStatus));
    EXPECT_FALSE(cs_bit(r.cs(), cms::StoppingStatus));
    for (const char* m : ax) EXPECT_FALSE(coord_bit(r.axis(m))) << m;
    EXPECT_FALSE(r.tag("m1").pc());
    if (!leaves) {
      EXPECT_TRUE(r.tag("f").pc());
      EXPECT_FALSE(r.tag("f").ip());
    }
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(interrupted, static_cast<int>(count / 3)) << "seed " << seed;
}

// ---------------------------------------------------------- the triggers

/// A line from the origin to (100, 50, 0) at 100/s; interrupted after 300 ms.
void start_line(MemberRig& r) {
  r.set("p1", 100, 50, 0);
  ASSERT_EQ(r.exec(mclm("cs", "m1", "p1", 100, 1000)), Err::None);
  r.step(300);
}

/// Steps until the path stands; returns the cycles it took. Checks Y / X
/// stays on the line y = x / 2 all along and the speed never rises.
int until_standstill(MemberRig& r, bool x_follows = true) {
  int n = 0;
  double vprev = r.cs().speed;
  while (n < 10000) {
    r.step();
    ++n;
    EXPECT_LE(r.cs().speed, vprev * (1 + 1e-9));
    vprev = r.cs().speed;
    if (x_follows) {
      EXPECT_NEAR(r.cs().command_position[1], r.cs().command_position[0] / 2, 1e-9 * 100);
    }
    if (!cs_bit(r.cs(), cms::MoveStatus)) break;
    EXPECT_TRUE(cs_bit(r.cs(), cms::StoppingStatus));
  }
  return n;
}

TEST(CoordMemberStop, MsfOnAMemberStopsTheOthersAlongThePath) {
  MemberRig r(3, 500);
  start_line(r);
  const double v0 = r.cs().speed;
  ASSERT_GT(v0, 99);
  const double z = r.axis("Z").command_position;
  ASSERT_EQ(r.exec("MSF(Z, f);"), Err::None);
  EXPECT_FALSE(r.tag("m1").ip());
  EXPECT_FALSE(r.tag("m1").pc());
  const double x0 = r.axis("X").command_position;
  const int n = until_standstill(r);
  EXPECT_NEAR(n * 0.001, v0 / 500, 0.002);
  const double dx = r.axis("X").command_position - x0;  // X's share of the stop distance v0^2/(2 D)
  EXPECT_NEAR(dx * std::sqrt(1.25), v0 * v0 / 1000, 0.2);
  EXPECT_EQ(r.axis("Z").command_position, z);
  EXPECT_EQ(r.exec(mclm("cs", "m2", "p1", 100, 1000)), Err::ServoOffState);
}

TEST(CoordMemberStop, McsInProgressEndsWithoutPcWhenAMemberLeaves) {
  MemberRig r(3, 2000);
  start_line(r);
  ASSERT_EQ(r.exec("MCS(cs, s1, coordinatedmove, yes, 50, unitspersec2, no, 0, unitspersec3);"), Err::None);
  r.step(10);
  EXPECT_TRUE(r.tag("s1").ip());
  ASSERT_EQ(r.exec("MSF(Z, f);"), Err::None);  // "Fault Action" ends the MCS [RM002H p.469]
  EXPECT_FALSE(r.tag("s1").ip());
  EXPECT_FALSE(r.tag("s1").pc());
  const int n = until_standstill(r);
  EXPECT_LT(n, 60);  // at 2000/s^2 from below 100/s, not the MCS's 50/s^2
}

TEST(CoordMemberStop, MasdOnAMemberStopsTheOthersAndBreaksTheMdccLink) {
  MemberRig r(3, 500);
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  start_line(r);  // time-driven: the link is only held
  ASSERT_EQ(r.exec("MASD(Z, sd);"), Err::None);
  EXPECT_FALSE(r.tag("md1").ip());  // MASD on the slave system breaks the link (seed 001, p.531)
  EXPECT_FALSE(r.tag("m1").ip());
  until_standstill(r);
  EXPECT_EQ(r.axis("Z").state, AxisState::Shutdown);
  EXPECT_GT(r.axis("X").command_position, 30.0);
}

TEST(CoordMemberStop, MasAllOnAMemberStopsTheWholeSystemAlongThePath) {
  MemberRig r(3, 500);
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  ASSERT_EQ(r.exec(maj("Z", "jz", 0, 5)), Err::None);  // the member's own motion, superposed
  ASSERT_EQ(r.exec(maj("M2", "j2", 0, 5)), Err::None);  // not a member
  start_line(r);
  ASSERT_EQ(r.exec("MAS(X, s, all, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_TRUE(r.tag("s").ip());
  EXPECT_FALSE(r.tag("md1").ip());  // MAS All on the slave system breaks the link
  EXPECT_FALSE(r.tag("m1").ip());
  EXPECT_TRUE(r.tag("jz").ip());    // another member's single-axis motion goes on
  const int n = until_standstill(r);
  EXPECT_NEAR(n * 0.001, 0.1 / 0.5, 0.002);
  EXPECT_TRUE(r.tag("s").pc());
  EXPECT_FALSE(r.tag("s").ip());
  EXPECT_TRUE(r.tag("jz").ip());
  EXPECT_TRUE(r.tag("j2").ip());
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
}

TEST(CoordMemberStop, MasAllPcWaitsForTheMembersOwnRampAndThePath) {
  MemberRig r(3, 5000);
  ASSERT_EQ(r.exec(maj("X", "jx", 0, 50, 1000, 100)), Err::None);  // decel 100: the ramp outlasts the path stop
  start_line(r);
  ASSERT_EQ(r.exec("MAS(X, s, all, yes, 100, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(r.tag("jx").ip());
  r.step(40);  // the path stands after 20 ms at 5000/s^2
  EXPECT_FALSE(cs_bit(r.cs(), cms::MoveStatus));
  EXPECT_TRUE(r.tag("s").ip());
  EXPECT_FALSE(r.tag("s").pc());
  r.step_until([&] { return r.tag("s").pc(); }, 2000);
  EXPECT_FALSE(r.tag("s").ip());
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
}

TEST(CoordMemberStop, MgsStopsTheSystemAlongThePath) {
  MemberRig r(3, 500);
  start_line(r);
  ASSERT_EQ(r.exec("MGS(g, s, faststop);"), Err::None);
  EXPECT_TRUE(r.tag("s").ip());
  const int n = until_standstill(r);
  EXPECT_NEAR(n * 0.001, 0.2, 0.002);
  EXPECT_TRUE(r.tag("s").pc());
  EXPECT_FALSE(r.tag("m1").pc());
}

/// X faults on its positive soft limit at 40 (the exception action under
/// test), during a line to (100, 50, 0).
void soft_limit_fault(ExceptionAction action, bool x_leaves) {
  AxisConfig a;
  a.soft_limits_enabled = true;
  a.soft_limit_pos = 40;
  a.soft_limit_neg = -1000;
  a.exception_actions[static_cast<std::size_t>(ExceptionKind::SoftOvertravelPos)] = action;
  MemberRig r(3, 500, {1, 1, 1}, a);
  r.set("p1", 100, 50, 0);
  ASSERT_EQ(r.exec(mclm("cs", "m1", "p1", 100, 1000)), Err::None);
  r.step_until([&] { return !r.tag("m1").ip(); }, 5000);
  EXPECT_FALSE(r.tag("m1").pc());
  EXPECT_FALSE(r.tag("m1").er());
  ASSERT_LT(r.axis("X").command_position, 42.0);
  const double y0 = r.axis("Y").command_position;
  EXPECT_NEAR(y0, 20.0, 0.1);  // the move ended where X crossed 40
  until_standstill(r, !x_leaves);
  const double dy = r.axis("Y").command_position - y0;  // Y's share of 100^2 / (2 * 500)
  EXPECT_NEAR(dy * std::sqrt(5.0), 10.0, 0.25);
}

TEST(CoordMemberStop, StopDriveFaultOnAMemberStopsTheOthers) {
  soft_limit_fault(ExceptionAction::StopDrive, true);
}
TEST(CoordMemberStop, ShutdownFaultOnAMemberStopsTheOthers) { soft_limit_fault(ExceptionAction::Shutdown, true); }
TEST(CoordMemberStop, StopPlannerOnAMemberStopsTheWholeSystem) {
  soft_limit_fault(ExceptionAction::StopPlanner, false);
}

TEST(CoordMemberStop, LastMemberLeavingDropsThePath) {
  MemberRig r(2, 500);
  start_line(r);
  ASSERT_EQ(r.exec("MGSD(g, sd);"), Err::None);  // every member shut down in the same execution
  EXPECT_FALSE(r.tag("m1").ip());
  r.step();
  EXPECT_FALSE(cs_bit(r.cs(), cms::MoveStatus));
  EXPECT_FALSE(cs_bit(r.cs(), cms::StoppingStatus));
}

// ------------------------------------------------------------------ ERR 52

TEST(CoordMemberStop, MrpMahMdsOnAMemberInCoordinatedMotionGiveErr52) {
  MemberRig r(2, 500);
  start_line(r);
  EXPECT_EQ(r.exec("MRP(X, rp, relative, actual, 5);"), Err::CoordinatedMotionInProcess);
  EXPECT_EQ(r.tag("rp").err, 52);
  EXPECT_EQ(r.exec("MAH(Y, ah);"), Err::CoordinatedMotionInProcess);
  EXPECT_EQ(r.exec("MDS(X, ds, 10, unitspersec);"), Err::CoordinatedMotionInProcess);
  EXPECT_TRUE(r.tag("m1").ip());  // nothing changed
  EXPECT_EQ(r.exec("MRP(Z, rp2, relative, actual, 5);"), Err::None);  // Z is not a member of this cs
  r.step_until([&] { return r.tag("m1").pc(); }, 5000);
  r.step();
  EXPECT_EQ(r.exec("MRP(X, rp, relative, actual, 5);"), Err::None);
  EXPECT_NE(r.exec("MDS(X, ds, 10, unitspersec);"), Err::CoordinatedMotionInProcess);
}

// ------------------------------------------------------------------ ERR 39

TEST(CoordMemberStop, AnAxisMovedByTwoSystemsGivesErr39) {
  MemberRig r(2, 500);
  CoordSystemConfig c;
  c.dim = 2;
  c.axes = {r.sym.axes.at("X"), r.sym.axes.at("Z"), kNoAxis};
  c.max_speed = c.max_accel = c.max_decel = 1000;
  ASSERT_TRUE(r.p->configure_coordinate_system(1, c));
  r.sym.coordinate_systems["cs2"] = 1;
  r.set("p1", 100, 50, 0);
  r.set("p2", 10, 10, 0);
  ASSERT_EQ(r.exec(mclm("cs", "m1", "p1", 100, 1000)), Err::None);
  r.step(10);
  EXPECT_EQ(r.exec(mclm("cs2", "m2", "p2", 100, 1000)), Err::ProcessConflict);
  EXPECT_EQ(r.tag("m2").err, 39);
  r.step_until([&] { return r.tag("m1").pc(); }, 5000);
  EXPECT_EQ(r.axis("X").command_position, 100.0);
  r.step();
  ASSERT_EQ(r.exec(mclm("cs2", "m2", "p2", 100, 1000)), Err::None);  // one system at a time is fine
  r.step_until([&] { return r.tag("m2").pc(); }, 5000);
  EXPECT_EQ(r.axis("X").command_position, 10.0);
  EXPECT_EQ(r.axis("Z").command_position, 10.0);
}

// ------------------------------------------------------- MDCC master shut down

std::string mdmove(const std::string& c, const std::string& pos, double speed_per_master) {
  return mclm("cs", c, pos, speed_per_master, 100, "trapezoidal", 0, "unitspermasterunit", "unitspermasterunit2",
              "unitspermasterunit3", "immediateforwardonly");
}

TEST(CoordMemberStop, MasdOnTheMasterBreaksTheMdccLinkAndEndsTheMasterDrivenMove) {
  MemberRig r(2, 500);
  ASSERT_EQ(r.exec(maj("M", "jm", 0, 10, 10000, 10000)), Err::None);
  r.step(5);
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 100, 50, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 1.0)), Err::None);
  r.step(200);
  EXPECT_TRUE(r.tag("md1").ac());
  ASSERT_EQ(r.exec("MASD(M2, sd2);"), Err::None);  // not the master: nothing
  EXPECT_TRUE(r.tag("md1").ip());
  ASSERT_EQ(r.exec("MASD(M, sd);"), Err::None);
  EXPECT_FALSE(r.tag("md1").ip());
  EXPECT_FALSE(r.tag("md1").ac());
  EXPECT_FALSE(r.tag("m1").ip());  // the master is gone: the master-driven move ends, the path stops
  EXPECT_FALSE(r.tag("m1").pc());
  r.step(50);
  EXPECT_FALSE(cs_bit(r.cs(), cms::MoveStatus));
  // a new master-driven move needs a new MDCC
  EXPECT_EQ(r.exec(mdmove("m2", "p1", 1.0)), Err::MdscNotActivated);
}

TEST(CoordMemberStop, MasdOnTheMasterLeavesATimeDrivenMoveRunning) {
  MemberRig r(2, 500);
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  start_line(r);
  ASSERT_EQ(r.exec("MASD(M, sd);"), Err::None);
  EXPECT_FALSE(r.tag("md1").ip());
  EXPECT_TRUE(r.tag("m1").ip());
  r.step_until([&] { return r.tag("m1").pc(); }, 5000);
  EXPECT_EQ(r.axis("X").command_position, 100.0);
}

}  // namespace
}  // namespace canmotion::motion::test
