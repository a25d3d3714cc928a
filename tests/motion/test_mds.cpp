// MDS (Motion Drive Start), issue 5, from seed 002: CIP only, drive enable
// with STATE 0/1, CSV/CST per configuration, live command, status bits,
// planner instructions refused, cancel paths (MAS, MASD, MGSD, MSF, faults).
#include <gtest/gtest.h>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::maj;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cip(AxisConfig::DirectMode mode = AxisConfig::DirectMode::Velocity) {
  return canmotion::motion::test::cip_direct(mode);
}

}  // namespace

TEST(Mds, OnlyOnCipDriveAxes) {
  Rig r;
  r.add_axis("V", AxisConfig{});
  EXPECT_EQ(r.exec("MDS(V, m, 10, unitspersec);"), Err::WrongAxisType);
  EXPECT_EQ(r.tag("m").err, 8);
}

TEST(Mds, EnablesTheDriveThenRunsCsvWithLiveCommand) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::SwitchedOn;
  ASSERT_EQ(r.exec("MDS(D, m, 50, %ofmaximum);"), Err::None);  // seed: 0 = % of maximum
  EXPECT_TRUE(r.tag("m").ip());
  EXPECT_FALSE(r.tag("m").dn());
  EXPECT_EQ(r.tag("m").state, 0);  // sending the enable request
  r.step();
  EXPECT_TRUE(r.out[0].enable);
  EXPECT_EQ(r.tag("m").state, 1);  // waiting for drive enable
  r.fb[0].drive = DriveState::Enabled;
  r.step();
  EXPECT_TRUE(r.tag("m").dn());
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicVelocity);
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 100.0);
  EXPECT_TRUE(r.axis("D").status(axis_status::DirectControlStatus));
  EXPECT_TRUE(r.axis("D").motion(motion_status::DirectVelocityControlStatus));
  EXPECT_FALSE(r.axis("D").motion(motion_status::DirectTorqueControlStatus));
  // the command tag can be written live
  EXPECT_TRUE(r.p->set_direct_command(0, -30.0));
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].velocity, -30.0);
  // planner instructions, MAH and MRP are refused while in direct control
  EXPECT_EQ(r.exec(mam("D", "mm", 0, 1, 1)), Err::NotAllowedWhileInDirectMotion);
  EXPECT_EQ(r.tag("mm").err, 87);
  EXPECT_EQ(r.exec(maj("D", "jj", 0, 1)), Err::NotAllowedWhileInDirectMotion);
  EXPECT_EQ(r.exec("MAH(D, h);"), Err::NotAllowedWhileInDirectMotion);
  EXPECT_EQ(r.exec("MRP(D, p, absolute, actual, 0);"), Err::NotAllowedWhileInDirectMotion);
  // a second MDS supersedes the first
  ASSERT_EQ(r.exec("MDS(D, m2, 20, unitspersec);"), Err::None);
  EXPECT_FALSE(r.tag("m").ip());
  EXPECT_TRUE(r.tag("m2").ip() && r.tag("m2").dn());
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 20.0);
}

TEST(Mds, TorqueModeRunsCst) {
  Rig r;
  r.add_axis("D", cip(AxisConfig::DirectMode::Torque));
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(D, on);");
  r.step();
  ASSERT_EQ(r.exec("MDS(D, m, 25, %ofmaximum);"), Err::None);
  EXPECT_TRUE(r.tag("m").dn());  // drive already enabled
  r.step();
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicTorque);
  EXPECT_DOUBLE_EQ(r.out[0].torque, 250.0);
  EXPECT_TRUE(r.axis("D").motion(motion_status::DirectTorqueControlStatus));
}

TEST(Mds, RefusedWhileThePlannerMovesTheAxis) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(D, on);");
  r.step();
  r.exec(maj("D", "j", 0, 1));
  EXPECT_EQ(r.exec("MDS(D, m, 10, unitspersec);"), Err::NotAllowedWhilePlannerActive);
}

TEST(Mds, MasStopsDirectMotionAndMsoLeavesDirectControl) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(D, on);");
  r.step();
  r.exec("MDS(D, m, 40, unitspersec);");
  r.fb[0].velocity = 40;
  r.step();
  ASSERT_EQ(r.exec("MAS(D, s, directcontrol, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(r.tag("m").ip());
  EXPECT_TRUE(r.tag("s").ip());
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 0.0);  // the drive ramps down with its own limits
  EXPECT_FALSE(r.axis("D").motion(motion_status::DirectVelocityControlStatus));
  EXPECT_TRUE(r.axis("D").status(axis_status::DirectControlStatus));  // only MSO clears it
  r.fb[0].velocity = 0;
  r.step();
  EXPECT_TRUE(r.tag("s").pc());
  EXPECT_EQ(r.exec(maj("D", "j", 0, 1)), Err::NotAllowedWhileInDirectMotion);
  ASSERT_EQ(r.exec("MSO(D, on2);"), Err::None);
  EXPECT_FALSE(r.axis("D").status(axis_status::DirectControlStatus));
  r.step();
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicPosition);
  EXPECT_EQ(r.exec(maj("D", "j2", 0, 1)), Err::None);
}

TEST(Mds, CancelledByMsfMasdMgsdAndFaults) {
  auto running = [](Rig& r) {
    r.add_axis("D", cip());
    r.fb[0].drive = DriveState::Enabled;
    r.exec("MSO(D, on);");
    r.step();
    EXPECT_EQ(r.exec("MDS(D, m, 10, unitspersec);"), Err::None);
    r.step();
  };
  {
    Rig r;
    running(r);
    r.exec("MSF(D, f);");
    EXPECT_FALSE(r.tag("m").ip());
    EXPECT_FALSE(r.axis("D").status(axis_status::DirectControlStatus));
  }
  {
    Rig r;
    running(r);
    r.exec("MASD(D, sd);");
    EXPECT_FALSE(r.tag("m").ip());
    r.step();
    EXPECT_FALSE(r.out[0].enable);
  }
  {
    Rig r;
    running(r);
    r.exec("MGSD(g, sd);");
    EXPECT_FALSE(r.tag("m").ip());
  }
  {  // drive fault with the default Stop Drive action
    Rig r;
    running(r);
    r.fb[0].drive_fault = true;
    r.step();
    EXPECT_FALSE(r.tag("m").ip());
    EXPECT_FALSE(r.axis("D").motion(motion_status::DirectVelocityControlStatus));
  }
}
