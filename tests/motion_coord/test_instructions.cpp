// The coordinated instructions through the planner (issue 14 phase 2):
// MCLM, MCCM, MCS, MCSD, MCCD, MDCC on a coordinate system of two virtual
// axes, driven by ST text; the seed 001 rules of master-driven coordinated
// motion, each a test.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "motion/instr/coord.hpp"
#include "tests/motion_coord/array_rig.hpp"
#include "tests/support/allocation_counter.hpp"

namespace canmotion::motion::test {
namespace {

using cms = std::uint32_t;
bool cs_bit(const CoordSystemTag& t, unsigned b) { return (t.motion_status >> b) & 1u; }

/// Two virtual axes X, Y (servo on), a master M, the coordinate system cs
/// {X, Y}, REAL arrays p1, p2, p3 (2 elements) and ctr.
struct CoordRig : ArrayRig {
  CoordRig(double max_speed = 200, double ratio_y = 1.0) {
    AxisConfig a;
    a.max_speed = 500;
    a.max_accel = a.max_decel = 5000;
    a.max_accel_jerk = a.max_decel_jerk = 1e5;
    add_axis("X", a);
    add_axis("Y", a);
    add_axis("M", a);
    add_axis("M2", a);
    for (const char* n : {"X", "Y", "M", "M2"}) EXPECT_EQ(exec(std::string("MSO(") + n + ", mso" + n + ");"), Err::None);
    CoordSystemConfig c;
    c.dim = 2;
    c.axes = {sym.axes.at("X"), sym.axes.at("Y"), kNoAxis};
    c.ratio = {1.0, ratio_y, 1.0};
    c.max_speed = max_speed;
    c.max_accel = c.max_decel = 1000;
    c.max_accel_jerk = c.max_decel_jerk = 1e5;
    c.command_tolerance = 0.5;
    EXPECT_TRUE(p->configure_coordinate_system(0, c));
    sym.coordinate_systems["cs"] = 0;
    for (const char* n : {"p1", "p2", "p3", "ctr"}) add_array(n, 2);
    step();
  }
  void set(const std::string& name, double x, double y) {
    auto& a = arrays[sym.real_arrays.at(name)];
    a[0] = x;
    a[1] = y;
  }
  const CoordSystemTag& cs() { return p->coordinate_system(0); }
  double x() { return axis("X").command_position; }
  double y() { return axis("Y").command_position; }
};

/// MCLM with the common operands.
std::string mclm(const std::string& c, const std::string& pos, double speed, const std::string& tt = "nosettle",
                 const std::string& su = "unitspersec", const std::string& au = "unitspersec2",
                 const std::string& lock = "none", int type = 0, const std::string& merge = "disabled",
                 double accel = 1000) {
  const std::string a = std::to_string(accel);
  return "MCLM(cs," + c + "," + std::to_string(type) + "," + pos + "," + std::to_string(speed) + "," + su + "," + a +
         "," + au + "," + a + "," + au + ",trapezoidal,0,0,unitspersec3," + tt + "," + merge + ",programmed,0,0," +
         lock + ",0,0);";
}

TEST(CoordInstr, McLmDrawsALineAndEndsExactly) {
  CoordRig r;
  r.set("p1", 30, 40);
  EXPECT_EQ(r.exec(mclm("m1", "p1", 100)), Err::None);
  EXPECT_TRUE(r.tag("m1").dn());
  EXPECT_TRUE(r.tag("m1").ip());
  EXPECT_TRUE(r.tag("m1").ac());
  int cycles = 0;
  double vmax = 0;
  while (!r.tag("m1").pc() && cycles < 10000) {
    r.step();
    ++cycles;
    // every sample on the line y = 4/3 x
    EXPECT_NEAR(r.y() * 3.0, r.x() * 4.0, 1e-9 * 50 * 4) << cycles;
    vmax = std::max(vmax, r.cs().speed);
    if (!r.tag("m1").pc()) {
      EXPECT_TRUE(cs_bit(r.cs(), coordinate_motion_status::MoveStatus));
      EXPECT_TRUE(((r.axis("X").motion_status >> motion_status::CoordinatedMotionStatus) & 1u));
      EXPECT_TRUE(((r.axis("Y").motion_status >> motion_status::CoordinatedMotionStatus) & 1u));
    }
  }
  EXPECT_EQ(r.x(), 30.0);
  EXPECT_EQ(r.y(), 40.0);
  EXPECT_LE(vmax, 100 * (1 + 1e-9));
  EXPECT_GT(vmax, 99);
  EXPECT_FALSE(r.tag("m1").ip());
  EXPECT_FALSE(r.tag("m1").ac());
  r.step();
  EXPECT_FALSE(((r.axis("X").motion_status >> motion_status::CoordinatedMotionStatus) & 1u));
  EXPECT_FALSE(cs_bit(r.cs(), coordinate_motion_status::MoveStatus));
  EXPECT_EQ(r.cs().command_position[0], 30.0);
  EXPECT_EQ(r.cs().command_position[1], 40.0);
  // a second, incremental move starts from there
  r.set("p2", -10, 0);
  EXPECT_EQ(r.exec(mclm("m2", "p2", 50, "nosettle", "unitspersec", "unitspersec2", "none", 1)), Err::None);
  r.step_until([&] { return r.tag("m2").pc(); }, 10000);
  EXPECT_EQ(r.x(), 20.0);
  EXPECT_EQ(r.y(), 40.0);
}

TEST(CoordInstr, RatioScalesTheMemberAxis) {
  CoordRig r(200, 2.0);  // 2 coordination units per Y unit
  r.set("p1", 10, 10);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 100)), Err::None);
  r.step_until([&] { return r.tag("m1").pc(); }, 10000);
  EXPECT_EQ(r.x(), 10.0);
  EXPECT_DOUBLE_EQ(r.y(), 5.0);
  EXPECT_DOUBLE_EQ(r.cs().command_position[1], 10.0);
}

TEST(CoordInstr, QueueHoldsOnePendingMoveAndRefusesAThird) {
  CoordRig r;
  r.set("p1", 20, 0);
  r.set("p2", 20, 20);
  r.set("p3", 0, 20);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 100, "actualtolerance")), Err::None);
  ASSERT_EQ(r.exec(mclm("m2", "p2", 100)), Err::None);
  r.step();
  EXPECT_TRUE(r.tag("m2").ip());
  EXPECT_FALSE(r.tag("m2").ac());
  EXPECT_TRUE(cs_bit(r.cs(), coordinate_motion_status::MovePendingStatus));
  EXPECT_EQ(r.exec(mclm("m3", "p3", 100)), Err::CoordinateSystemQueueFull);
  EXPECT_TRUE(r.tag("m3").er());
  EXPECT_EQ(r.tag("m3").err, 43);
  r.step_until([&] { return r.tag("m1").pc(); }, 10000);
  EXPECT_EQ(r.x(), 20.0);  // m2 runs from the exact corner (20, 0)
  EXPECT_LT(r.y(), 1e-3);
  EXPECT_TRUE(r.tag("m2").ac());
  r.step_until([&] { return r.tag("m2").pc(); }, 10000);
  EXPECT_EQ(r.x(), 20.0);
  EXPECT_EQ(r.y(), 20.0);
}

TEST(CoordInstr, BlendedCornerNeverStops) {
  CoordRig r;
  r.set("p1", 20, 0);
  r.set("p2", 20, 20);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 100, "commandtolerance")), Err::None);
  ASSERT_EQ(r.exec(mclm("m2", "p2", 100)), Err::None);
  double vmin_mid = 1e9, dev = 0;
  bool started = false;
  while (!r.tag("m2").pc()) {
    r.step();
    EXPECT_LE(r.x(), 20.0);
    if (r.cs().speed > 50) started = true;
    if (started && !r.tag("m2").pc() && r.x() > 19 && r.y() < 1) {
      vmin_mid = std::min(vmin_mid, r.cs().speed);
      dev = std::max(dev, std::hypot(20 - r.x(), r.y()));
    }
  }
  EXPECT_GT(vmin_mid, 10.0);  // never 0 at the corner
  EXPECT_EQ(r.x(), 20.0);
  EXPECT_EQ(r.y(), 20.0);
}

TEST(CoordInstr, McsStopsOnThePathAndClearsTheQueue) {
  CoordRig r;
  r.set("p1", 100, 100);
  r.set("p2", 0, 0);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 100)), Err::None);
  ASSERT_EQ(r.exec(mclm("m2", "p2", 100)), Err::None);
  r.step(300);
  ASSERT_EQ(r.exec("MCS(cs, s1, coordinatedmove, yes, 500, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_TRUE(r.tag("s1").dn());
  EXPECT_TRUE(r.tag("s1").ip());
  EXPECT_FALSE(r.tag("m1").ip());
  EXPECT_FALSE(r.tag("m2").ip());
  const double v0 = r.cs().speed;
  int n = r.step_until([&] { return r.tag("s1").pc(); }, 10000);
  EXPECT_NEAR(n * 0.001, v0 / 500, 0.003);  // within the decel
  EXPECT_FALSE(r.tag("s1").ip());
  EXPECT_NEAR(r.x(), r.y(), 1e-9 * 100);  // on the path
  EXPECT_LT(r.x(), 100.0);
  r.step(5);
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
}

TEST(CoordInstr, McsTransformTypeIsDoneAtOnce) {
  CoordRig r;
  ASSERT_EQ(r.exec("MCS(cs, s1, coordinatedtransform, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_TRUE(r.tag("s1").pc());
}

TEST(CoordInstr, MccmCenterArcStaysOnTheCircle) {
  CoordRig r;
  r.set("p1", 20, 0);
  r.set("ctr", 10, 0);
  ASSERT_EQ(r.exec("MCCM(cs, c1, absolute, p1, center, ctr, counterclockwise, 50, unitspersec, 1000, unitspersec2,"
                   " 1000, unitspersec2, trapezoidal, 0, 0, unitspersec3, nosettle, disabled, programmed, 0, 0, none, 0, 0);"),
            Err::None);
  double ymin = 0;
  while (!r.tag("c1").pc()) {
    r.step();
    EXPECT_NEAR(std::hypot(r.x() - 10, r.y()), 10.0, 1e-9 * 10);
    ymin = std::min(ymin, r.y());
  }
  EXPECT_NEAR(ymin, -10.0, 1e-3);  // CCW from (0,0) around (10,0) passes below
  EXPECT_EQ(r.x(), 20.0);
  EXPECT_EQ(r.y(), 0.0);
}

TEST(CoordInstr, MccmGeometryErrors) {
  CoordRig r;
  r.set("p1", 20, 0);
  r.set("ctr", 10, 0);
  auto mccm = [&](const std::string& type, const std::string& dir) {
    return r.exec("MCCM(cs, c1, absolute, p1, " + type + ", ctr, " + dir +
                  ", 50, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0, unitspersec3, nosettle,"
                  " disabled, programmed, 0, 0, none, 0, 0);");
  };
  EXPECT_EQ(mccm("via", "clockwise"), Err::CircularCollinearity);  // via (10,0) on the line (0,0)-(20,0)
  r.set("ctr", 10, 3);
  r.set("p1", 0, 0);
  EXPECT_EQ(mccm("center", "clockwise"), Err::CircularStartEnd);
  EXPECT_EQ(r.tag("c1").err, 45);
  r.set("p1", 20, 0);
  r.set("ctr", 12, 3);
  EXPECT_EQ(mccm("center", "clockwise"), Err::CircularR1R2Mismatch);
}

TEST(CoordInstr, SuperposedIncrementalMamShiftsTheEndPoint) {
  CoordRig r;
  r.set("p1", 50, 0);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 50)), Err::None);
  r.step(10);
  ASSERT_EQ(r.exec(mam("Y", "am", 1, 5, 20)), Err::None);
  r.step_until([&] { return r.tag("m1").pc() && r.tag("am").pc(); }, 10000);
  EXPECT_EQ(r.x(), 50.0);
  EXPECT_NEAR(r.y(), 5.0, 1e-12);
}

TEST(CoordInstr, McsdShutsTheMembersDownAndEndsEverything) {
  CoordRig r;
  r.set("p1", 50, 50);
  ASSERT_EQ(r.exec("MAJ(M, jm, forward, 10, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none);"), Err::None);
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 50)), Err::None);
  r.step(20);
  ASSERT_EQ(r.exec("MCSD(cs, sd);"), Err::None);
  EXPECT_TRUE(r.tag("sd").dn());
  EXPECT_FALSE(r.tag("m1").ip());
  EXPECT_FALSE(r.tag("md1").ip());
  EXPECT_EQ(r.axis("X").state, AxisState::Shutdown);
  EXPECT_EQ(r.axis("Y").state, AxisState::Shutdown);
  r.step();
  EXPECT_TRUE((r.cs().system_status >> coordinate_system_status::ShutdownStatus) & 1u);
  EXPECT_EQ(r.exec(mclm("m2", "p1", 50)), Err::ShutdownState);
}

TEST(CoordInstr, MemberServoOffStopsTheOtherMemberAlongThePath) {
  CoordRig r;  // max decel 1000
  r.set("p1", 50, 50);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 50)), Err::None);
  r.step(100);
  ASSERT_EQ(r.exec("MSF(X, f);"), Err::None);
  EXPECT_FALSE(r.tag("m1").ip());
  const double y = r.y(), x = r.x();
  r.step(100);
  // the other member stops along the path: 50^2 / (2 * 1000) of travel, Y's share 1/sqrt(2) of it
  EXPECT_NEAR(r.y() - y, 1.25 / std::sqrt(2.0), 0.05);
  EXPECT_EQ(r.x(), x);  // the member that left holds
  EXPECT_EQ(r.exec(mclm("m2", "p1", 50)), Err::ServoOffState);
}

TEST(CoordInstr, McCdChangesTheSpeedWithoutAStep) {
  CoordRig r;
  r.set("p1", 100, 0);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 100)), Err::None);
  r.step(200);
  const double x0 = r.x();
  ASSERT_EQ(r.exec("MCCD(cs, cd, coordinatedmove, yes, 20, unitspersec, no, 0, unitspersec2, no, 0, unitspersec2,"
                   " no, 0, no, 0, unitspersec3, activemotion);"), Err::None);
  EXPECT_TRUE(r.tag("cd").dn());
  r.step();
  EXPECT_LT(r.x() - x0, 0.101);
  r.step(500);
  EXPECT_NEAR(r.cs().speed, 20, 1e-9);
  r.step_until([&] { return r.tag("m1").pc(); }, 20000);
  EXPECT_EQ(r.x(), 100.0);
}

// ------------------------------------------------------------- seed 001 (MDCC)
/// M jogs forward at `v` units/s; cs follows it (MDCC md1, command).
void jog_master(CoordRig& r, const std::string& axis, double v, const std::string& ctl) {
  ASSERT_EQ(r.exec("MAJ(" + axis + ", " + ctl + ", forward, " + std::to_string(v) +
                   ", unitspersec, 10000, unitspersec2, 10000, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled,"
                   " programmed, 0, none);"),
            Err::None);
  r.step(5);
}

std::string mdmove(const std::string& c, const std::string& pos, double speed_per_master) {
  return mclm(c, pos, speed_per_master, "nosettle", "unitspermasterunit", "unitspermasterunit2", "immediateforwardonly",
              0, "disabled", 100);
}

TEST(CoordSeed001, ModeComesFromTheSpeedUnits) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  EXPECT_TRUE(r.tag("md1").ip());
  r.set("p1", 60, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::None);  // 2 units per master unit
  r.step(600);  // the master runs at 10/s: the path at 20/s once accelerated
  EXPECT_NEAR(r.cs().speed, 20.0, 1e-6);
  EXPECT_TRUE(r.tag("md1").ac());  // AC while a master-driven move on the slave system is active
  EXPECT_TRUE(cs_bit(r.cs(), coordinate_motion_status::CoordinateSystemLockStatus));
  r.step_until([&] { return r.tag("m1").pc(); }, 20000);
  EXPECT_EQ(r.x(), 60.0);
  r.step();
  EXPECT_FALSE(r.tag("md1").ac());
  EXPECT_TRUE(r.tag("md1").ip());  // the link holds
  // the next move in time-driven units runs time-driven (mode change at its activation)
  r.set("p2", 0, 0);
  ASSERT_EQ(r.exec(mclm("m2", "p2", 100)), Err::None);
  r.step(300);
  EXPECT_NEAR(r.cs().speed, 100.0, 1e-6);
  EXPECT_FALSE(r.tag("md1").ac());
}

TEST(CoordSeed001, MasterDrivenHoldsWhileTheMasterStands) {
  CoordRig r;
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 60, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::None);  // master idle, system idle: allowed
  r.step(100);
  EXPECT_EQ(r.x(), 0.0);
  jog_master(r, "M", 10, "jm");
  r.step(100);
  EXPECT_GT(r.x(), 0.0);
}

TEST(CoordSeed001, UnitsConflict) {
  CoordRig r;
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 60, 0);
  EXPECT_EQ(r.exec(mclm("m1", "p1", 2, "nosettle", "unitspermasterunit", "unitspersec2", "immediateforwardonly")),
            Err::MdscUnitsConflict);
  EXPECT_EQ(r.tag("m1").err, 94);
  EXPECT_EQ(r.exec(mclm("m2", "p1", 2, "nosettle", "unitspersec", "unitspermasterunit2", "none")), Err::MdscUnitsConflict);
}

TEST(CoordSeed001, MasterDrivenNeedsMdccAndALockDirection) {
  CoordRig r;
  r.set("p1", 60, 0);
  EXPECT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::MdscNotActivated);
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  EXPECT_EQ(r.exec(mclm("m1", "p1", 2, "nosettle", "unitspermasterunit", "unitspermasterunit2", "none")),
            Err::MdscLockDirConflict);
  EXPECT_EQ(r.exec(mclm("m1", "p1", 2, "nosettle", "unitspersec", "unitspersec2", "immediateforwardonly")),
            Err::MdscLockDirConflict);
}

TEST(CoordSeed001, MccdCannotChangeTheMode) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 60, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::None);
  r.step(50);
  EXPECT_EQ(r.exec("MCCD(cs, cd, coordinatedmove, yes, 20, unitspersec, no, 0, unitspersec2, no, 0, unitspersec2,"
                   " no, 0, no, 0, unitspersec3, activemotion);"),
            Err::MdscInvalidModeOrMasterChange);
  EXPECT_EQ(r.tag("cd").err, 105);
  EXPECT_EQ(r.exec("MCCD(cs, cd2, coordinatedmove, yes, 1, unitspermasterunit, no, 0, unitspermasterunit2, no, 0,"
                   " unitspermasterunit2, no, 0, no, 0, unitspermasterunit3, activemotion);"),
            Err::None);
}

TEST(CoordSeed001, IdleMasterWithAMovingSlaveSystem) {
  CoordRig r;
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 100, 0);
  ASSERT_EQ(r.exec(mclm("m1", "p1", 50)), Err::None);  // time-driven, moving
  r.step(100);
  r.set("p2", 0, 0);
  // master-driven, merging now while the system moves and the master is idle
  EXPECT_EQ(r.exec(mclm("m2", "p2", 2, "nosettle", "unitspermasterunit", "unitspermasterunit2", "immediateforwardonly",
                        0, "coordinatedmotion", 100)),
            Err::MdscIdleMasterSlaveMoving);
  EXPECT_EQ(r.tag("m2").err, 97);
  EXPECT_TRUE(r.tag("m1").ip());  // nothing changed
}

TEST(CoordSeed001, MasterChangeIsPendingUntilTheNextMove) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  jog_master(r, "M2", 20, "jm2");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 200, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::None);
  r.step(200);
  ASSERT_EQ(r.exec("MDCC(cs, M2, md2, command, 20);"), Err::None);
  EXPECT_TRUE(r.tag("md2").ip());  // the reassignment is pending
  EXPECT_TRUE(r.tag("md1").ip());  // the first master still drives
  r.step(200);
  EXPECT_NEAR(r.cs().speed, 20.0, 1e-6);  // still M's 10/s x 2
  r.set("p2", 0, 0);
  ASSERT_EQ(r.exec(mdmove("m2", "p2", 2.0)), Err::None);  // goes IP: the switch happens
  EXPECT_FALSE(r.tag("md1").ip());
  EXPECT_TRUE(r.tag("md2").ip());
  r.step_until([&] { return r.tag("m1").pc(); }, 50000);
  r.step(600);
  EXPECT_NEAR(r.cs().speed, 40.0, 1e-6);  // M2's 20/s x 2
  EXPECT_TRUE(r.tag("md2").ac());
}

TEST(CoordSeed001, MasterChangeBelowTenPercentIsRefused) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  jog_master(r, "M2", 0.5, "jm2");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 200, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::None);
  r.step(400);
  ASSERT_NEAR(r.cs().speed, 20.0, 1e-6);
  ASSERT_EQ(r.exec("MDCC(cs, M2, md2, command, 1);"), Err::None);
  r.set("p2", 0, 0);
  // 0.5/s x 2 = 1/s < 10 % of 20/s
  EXPECT_EQ(r.exec(mdmove("m2", "p2", 2.0)), Err::MdscInvalidSlaveSpeedReduction);
  EXPECT_EQ(r.tag("m2").err, 103);
  EXPECT_TRUE(r.tag("md1").ip());  // no switch
  // 0.5/s x 5 = 2.5/s >= 2/s: allowed
  EXPECT_EQ(r.exec(mdmove("m3", "p2", 5.0)), Err::None);
  EXPECT_FALSE(r.tag("md1").ip());
}

TEST(CoordSeed001, MasterChangeToAnIdleMaster) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 200, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 2.0)), Err::None);
  r.step(200);
  ASSERT_EQ(r.exec("MDCC(cs, M2, md2, command, 10);"), Err::None);  // M2 stands
  r.set("p2", 0, 0);
  EXPECT_EQ(r.exec(mdmove("m2", "p2", 2.0)), Err::MdscIdleMasterSlaveMoving);
}

TEST(CoordSeed001, MasterInTheSlaveSystemIsRefused) {
  CoordRig r;
  EXPECT_EQ(r.exec("MDCC(cs, X, md1, command, 10);"), Err::MasterAxisConflict);
}

TEST(CoordSeed001, TimeDrivenMamSuperposedOnAMasterDrivenPath) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  r.set("p1", 40, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 1.0)), Err::None);
  ASSERT_EQ(r.exec(mam("Y", "am", 1, 3, 10)), Err::None);
  r.step_until([&] { return r.tag("m1").pc() && r.tag("am").pc(); }, 20000);
  EXPECT_EQ(r.x(), 40.0);
  EXPECT_NEAR(r.y(), 3.0, 1e-12);
}

TEST(CoordInstr, McsAllBreaksTheMdccLinkAndStopsMemberMotion) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  ASSERT_EQ(r.exec("MDCC(cs, M, md1, command, 10);"), Err::None);
  ASSERT_EQ(r.exec(maj("Y", "jy", 0, 5)), Err::None);
  r.set("p1", 100, 0);
  ASSERT_EQ(r.exec(mdmove("m1", "p1", 1.0)), Err::None);
  r.step(100);
  ASSERT_EQ(r.exec("MCS(cs, s1, all, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(r.tag("md1").ip());
  EXPECT_FALSE(r.tag("jy").ip());
  r.step_until([&] { return r.tag("s1").pc(); }, 10000);
  r.step(100);
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  EXPECT_EQ(r.axis("Y").command_velocity, 0.0);
}

TEST(CoordInstr, NoAllocationInTheCycleOrTheInstructions) {
  CoordRig r;
  jog_master(r, "M", 10, "jm");
  r.set("p1", 40, 0);
  r.set("p2", 40, 30);
  r.set("p3", 0, 0);
  r.set("ctr", 20, 0);
  // requests parsed before counting; executed and stepped while counting
  const std::vector<Request> rq = {
      r.req(mclm("m1", "p1", 100, "commandtolerance")),
      r.req(mclm("m2", "p2", 100, "nodecel")),
      r.req("MCCD(cs, cd, coordinatedmove, yes, 50, unitspersec, no, 0, unitspersec2, no, 0, unitspersec2,"
            " no, 0, no, 0, unitspersec3, activeandpendingmotion);"),
      r.req("MCCM(cs, c1, absolute, p3, center, ctr, clockwise, 50, unitspersec, 1000, unitspersec2, 1000, unitspersec2,"
            " scurve, 1e5, 1e5, unitspersec3, nosettle, coordinatedmotion, current, 0, 0, none, 0, 0);"),
      r.req("MDCC(cs, M, md1, command, 10);"),
      r.req(mdmove("m3", "p1", 1.0)),
      r.req("MCS(cs, s1, all, no, 0, unitspersec2, no, 0, unitspersec3);"),
      r.req(mclm("m4", "p3", 100)),
      r.req("MAS(X, sx, all, no, 0, unitspersec2, no, 0, unitspersec3);"),  // the path stops along itself
      r.req(mclm("m5", "p1", 100)),
      r.req("MSF(Y, fy);"),  // a member leaves: the other stops along the path
      r.req("MCSD(cs, sd);"),
  };
  canmotion::test::reset_allocation_count();
  canmotion::test::count_allocations_on_this_thread(true);
  for (const Request& q : rq) {
    r.p->execute(q);
    for (int i = 0; i < 300; ++i) r.step();
  }
  canmotion::test::count_allocations_on_this_thread(false);
  EXPECT_EQ(canmotion::test::counted_allocations(), 0u);
  EXPECT_TRUE(r.tag("sd").dn());
  EXPECT_TRUE(r.tag("sx").pc());
  EXPECT_TRUE(r.tag("fy").dn());
  EXPECT_TRUE(r.p->check_incremental_state());
}

TEST(CoordInstr, EventDistanceGivesCalculatedData) {
  CoordRig r;
  r.add_array("ed", 2);
  r.add_array("cd", 2);
  r.set("ed", 0, 10);  // the whole move; 10 units before its end
  r.set("p1", 100, 0);
  ASSERT_EQ(r.exec("MCLM(cs, m1, 0, p1, 100, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0,"
                   " unitspersec3, nosettle, disabled, programmed, 0, 0, none, ed, cd);"),
            Err::None);
  EXPECT_TRUE(r.tag("m1").get(flag::CalculatedDataAvailable));
  const auto& cd = r.arrays[r.sym.real_arrays.at("cd")];
  EXPECT_NEAR(cd[0], 1.1, 1e-9);  // 100 units at 100/s with 0.1 s ramps: 1.1 s
  EXPECT_NEAR(cd[1], 0.95, 1e-9);  // 10 units before the end: 5 of cruise (0.05 s) before the 0.1 s decel ramp
}

TEST(CoordInstr, UnconfiguredSystemGivesErr11) {
  CoordRig r;
  r.sym.coordinate_systems["nocs"] = 5;
  EXPECT_EQ(r.exec("MCSD(nocs, t);"), Err::AxisNotConfigured);
}

}  // namespace
}  // namespace canmotion::motion::test
