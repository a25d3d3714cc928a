// MDS (seed 002) audit, issue 5: the cancel paths the seed lists (MAS All and
// DirectControl, MASD, MGSD, MSF; MCSD is not supported here and answers
// ERR 75), faults per each configured exception action, the status bits
// (DirectVelocity/TorqueControlStatus, AxisStatus.DirectControlStatus), STATE
// 0/1 while enabling, WrongAxisType on a virtual axis, operand checks, and the
// torque-mode velocity command (the drive's SLAT speed reference).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cip(AxisConfig::DirectMode mode = AxisConfig::DirectMode::Velocity) {
  return canmotion::motion::test::cip_direct(mode, 25);
}

/// An enabled CIP axis "D" under MDS (control tag "m"), one cycle stepped.
void running(Rig& r, AxisConfig c = cip(), const std::string& mds = "MDS(D, m, 10, unitspersec);") {
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  ASSERT_EQ(r.exec("MSO(D, on);"), Err::None);
  r.step();
  ASSERT_EQ(r.exec(mds), Err::None);
  r.step();
  ASSERT_TRUE(r.tag("m").ip());
}

bool vel_status(Rig& r) { return r.axis("D").motion(motion_status::DirectVelocityControlStatus); }
bool trq_status(Rig& r) { return r.axis("D").motion(motion_status::DirectTorqueControlStatus); }
bool direct_status(Rig& r) { return r.axis("D").status(axis_status::DirectControlStatus); }

}  // namespace

TEST(MdsAudit, WrongAxisTypeOnAVirtualAxisAndNothingApplied) {
  Rig r;
  r.add_axis("V", AxisConfig{});
  EXPECT_EQ(r.exec("MDS(V, m, 10, unitspersec);"), Err::WrongAxisType);
  EXPECT_TRUE(r.tag("m").er());
  EXPECT_FALSE(r.tag("m").ip());
  EXPECT_FALSE(r.axis("V").status(axis_status::DirectControlStatus));
  EXPECT_FALSE(r.axis("V").motion(motion_status::DirectVelocityControlStatus));
}

TEST(MdsAudit, StateZeroThenOneWhileEnablingThenDone) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::SwitchedOn;
  ASSERT_EQ(r.exec("MDS(D, m, 30, unitspersec);"), Err::None);
  EXPECT_EQ(r.tag("m").state, 0);  // 0 = sending the request to turn the drive on
  EXPECT_TRUE(r.tag("m").ip());
  EXPECT_FALSE(r.tag("m").dn());
  // initiated without errors: the direct control bits are set at once [seed 002]
  EXPECT_TRUE(vel_status(r));
  EXPECT_TRUE(direct_status(r));
  for (int i = 0; i < 20; ++i) {
    r.step();
    EXPECT_EQ(r.tag("m").state, 1);  // 1 = waiting for drive enable and servo action
    EXPECT_TRUE(r.out[0].enable);
    EXPECT_FALSE(r.tag("m").dn());
    EXPECT_FALSE(r.axis("D").status(axis_status::ServoActionStatus));
  }
  r.fb[0].drive = DriveState::Enabled;
  r.step();
  EXPECT_TRUE(r.tag("m").dn());
  EXPECT_TRUE(r.tag("m").ip());
  EXPECT_TRUE(r.axis("D").status(axis_status::ServoActionStatus));
  EXPECT_TRUE(r.axis("D").status(axis_status::DriveEnableStatus));
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicVelocity);
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 30.0);
}

TEST(MdsAudit, DriveFaultWhileEnablingErrorsAndClearsTheBits) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::SwitchedOn;
  ASSERT_EQ(r.exec("MDS(D, m, 30, unitspersec);"), Err::None);
  r.step();
  r.fb[0].drive = DriveState::Fault;
  r.step();
  EXPECT_TRUE(r.tag("m").er());
  EXPECT_EQ(r.tag("m").err, static_cast<int>(Err::ServoMessageFailure));
  EXPECT_FALSE(r.tag("m").ip());
  EXPECT_FALSE(vel_status(r));
  EXPECT_FALSE(direct_status(r));
  EXPECT_FALSE(r.out[0].enable);
}

TEST(MdsAudit, MasAllAndDirectControlStopTheDirectCommandMasMoveDoesNot) {
  for (const char* type : {"all", "directcontrol"}) {
    SCOPED_TRACE(type);
    Rig r;
    running(r);
    r.fb[0].velocity = 10;
    ASSERT_EQ(r.exec(std::string("MAS(D, s, ") + type + ", no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
    EXPECT_FALSE(r.tag("m").ip());  // MDS cancelled
    EXPECT_TRUE(r.tag("s").dn());
    EXPECT_TRUE(r.tag("s").ip());   // until the drive has ramped down
    r.step();
    EXPECT_DOUBLE_EQ(r.out[0].velocity, 0.0);
    EXPECT_EQ(r.out[0].mode, DriveMode::CyclicVelocity);  // the drive ramps with its RampDeceleration
    EXPECT_FALSE(vel_status(r));
    EXPECT_TRUE(direct_status(r));
    EXPECT_FALSE(r.tag("s").pc());
    r.fb[0].velocity = 0;
    r.step();
    EXPECT_TRUE(r.tag("s").pc());
    EXPECT_FALSE(r.tag("s").ip());
    EXPECT_FALSE(r.p->set_direct_command(0, 5.0));  // no MDS active any more
  }
  Rig r;
  running(r);
  ASSERT_EQ(r.exec("MAS(D, s, move, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  r.step();
  EXPECT_TRUE(r.tag("m").ip());
  EXPECT_TRUE(vel_status(r));
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 10.0);
}

TEST(MdsAudit, MasdMgsdAndMsfCancelAndClearDirectControl) {
  {
    Rig r;
    running(r);
    ASSERT_EQ(r.exec("MASD(D, sd);"), Err::None);
    EXPECT_FALSE(r.tag("m").ip());
    r.step();
    EXPECT_FALSE(r.out[0].enable);
    EXPECT_TRUE(r.out[0].shutdown);
    EXPECT_TRUE(r.axis("D").status(axis_status::ShutdownStatus));
    EXPECT_FALSE(vel_status(r));
    EXPECT_FALSE(direct_status(r));
  }
  {
    Rig r;
    running(r);
    r.add_axis("E", cip());
    ASSERT_EQ(r.exec("MGSD(g, gsd);"), Err::None);
    EXPECT_FALSE(r.tag("m").ip());
    r.step();
    EXPECT_FALSE(r.out[0].enable);
    EXPECT_FALSE(vel_status(r));
    EXPECT_FALSE(direct_status(r));
  }
  {
    Rig r;
    running(r);
    ASSERT_EQ(r.exec("MSF(D, f);"), Err::None);
    EXPECT_FALSE(r.tag("m").ip());
    r.step();
    EXPECT_FALSE(r.out[0].enable);
    EXPECT_FALSE(r.out[0].shutdown);
    EXPECT_FALSE(vel_status(r));
    EXPECT_FALSE(direct_status(r));
    EXPECT_EQ(r.out[0].mode, DriveMode::CyclicPosition);
  }
}

TEST(MdsAudit, McsdCancelsMdsOnAMember) {
  // Coordinated motion (issue 14): MCSD shuts every member of the coordinate
  // system down (MASD on each), which cancels an MDS on a member.
  Rig r;
  running(r);
  CoordSystemConfig c;
  c.dim = 1;
  c.axes = {r.sym.axes.at("D"), kNoAxis, kNoAxis};
  c.max_speed = c.max_accel = c.max_decel = 100;
  ASSERT_TRUE(r.p->configure_coordinate_system(0, c));
  r.sym.coordinate_systems["cs"] = 0;
  EXPECT_EQ(r.exec("MCSD(cs, csd);"), Err::None);
  EXPECT_TRUE(r.tag("csd").dn());
  EXPECT_FALSE(r.tag("csd").ip());  // the shutdown instructions never go IP
  EXPECT_FALSE(r.tag("m").ip());
  r.step();
  EXPECT_FALSE(vel_status(r));
  EXPECT_FALSE(direct_status(r));
  EXPECT_TRUE(r.out[0].shutdown);
}

TEST(MdsAudit, DriveFaultPerExceptionAction) {
  struct Case {
    ExceptionAction action;
    bool cancels;
    bool shutdown;
  };
  for (const Case& k : {Case{ExceptionAction::Ignore, false, false}, Case{ExceptionAction::Alarm, false, false},
                        Case{ExceptionAction::FaultStatusOnly, false, false},
                        Case{ExceptionAction::StopPlanner, false, false},  // direct control is not planned motion
                        Case{ExceptionAction::StopDrive, true, false}, Case{ExceptionAction::Shutdown, true, true}}) {
    SCOPED_TRACE(static_cast<int>(k.action));
    Rig r;
    AxisConfig c = cip();
    c.exception_actions[static_cast<std::size_t>(ExceptionKind::DriveFault)] = k.action;
    running(r, c);
    r.fb[0].drive_fault = true;  // e.g. an EMCY, or a refused mode switch (drive.timeouts.mode_switch_ms)
    r.step();
    EXPECT_EQ(r.tag("m").ip(), !k.cancels);
    EXPECT_EQ(vel_status(r), !k.cancels);
    EXPECT_EQ(direct_status(r), !k.cancels);
    EXPECT_EQ(r.out[0].enable, !k.cancels);
    EXPECT_EQ(r.out[0].shutdown, k.shutdown);
    const bool fault_bit = (r.axis("D").exception_faults >> static_cast<unsigned>(ExceptionKind::DriveFault)) & 1u;
    const bool alarm_bit = (r.axis("D").exception_alarms >> static_cast<unsigned>(ExceptionKind::DriveFault)) & 1u;
    EXPECT_EQ(fault_bit, k.action >= ExceptionAction::FaultStatusOnly);
    EXPECT_EQ(alarm_bit, k.action == ExceptionAction::Alarm);
    if (!k.cancels) {
      EXPECT_DOUBLE_EQ(r.out[0].velocity, 10.0);
    }
  }
}

TEST(MdsAudit, TorqueModeSendsTheVelocityCommandForSlatAndItIsWritableLive) {
  Rig r;
  running(r, cip(AxisConfig::DirectMode::Torque), "MDS(D, m, 40, %ofmaximum);");
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicTorque);
  EXPECT_DOUBLE_EQ(r.out[0].torque, 400.0);
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 25.0);  // AxisConfig::direct_velocity_command
  EXPECT_TRUE(trq_status(r));
  EXPECT_FALSE(vel_status(r));
  EXPECT_TRUE(r.p->set_direct_velocity_command(0, -12.5));
  EXPECT_TRUE(r.p->set_direct_command(0, 150.0));
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].velocity, -12.5);
  EXPECT_DOUBLE_EQ(r.out[0].torque, 150.0);
  EXPECT_FALSE(r.p->set_direct_velocity_command(0, std::numeric_limits<double>::quiet_NaN()));
  // a superseding MDS changes the torque and keeps the velocity command
  ASSERT_EQ(r.exec("MDS(D, m2, 20, unitspersec);"), Err::None);
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].torque, 20.0);
  EXPECT_DOUBLE_EQ(r.out[0].velocity, -12.5);
  ASSERT_EQ(r.exec("MAS(D, s, directcontrol, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].torque, 0.0);
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 0.0);
  EXPECT_FALSE(trq_status(r));
  EXPECT_FALSE(r.p->set_direct_velocity_command(0, 1.0));
}

TEST(MdsAudit, VelocityCommandSetterIsForTorqueModeOnly) {
  Rig r;
  running(r);
  EXPECT_FALSE(r.p->set_direct_velocity_command(0, 5.0));
  EXPECT_TRUE(r.p->set_direct_command(0, 5.0));
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 5.0);
  EXPECT_DOUBLE_EQ(r.out[0].torque, 0.0);
}

// Issue 16 item 2. "The MDS instruction is validated if the CIP drive device
// supports the ramp attributes, including RampAcceleration, RampDeceleration,
// RampVelocity - Positive, RampVelocity - Negative, RampJerk - Control"
// [seed 002]. The ramps are the axis' direct_control: in the configuration
// (written to the drive at boot); without it MDS is refused with ERR 86
// Optional Attribute Not Supported, whose text names what to configure, and
// nothing is applied (the drive stays in CSP, no status bit).
TEST(MdsAudit, RefusedOnACipAxisWithoutDirectControlConfigured) {
  Rig r;
  AxisConfig c = cip();
  c.direct_control = false;  // a CIP axis without direct_control:
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  ASSERT_EQ(r.exec("MSO(D, on);"), Err::None);
  r.step();
  EXPECT_EQ(r.exec("MDS(D, m, 10, unitspersec);"), Err::OptionalAttributeNotSupported);
  EXPECT_EQ(r.tag("m").err, 86);
  EXPECT_FALSE(r.tag("m").ip());
  EXPECT_NE(err_name(Err::OptionalAttributeNotSupported).find("direct_control:"), std::string_view::npos);
  r.step();
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicPosition);
  EXPECT_FALSE(direct_status(r));
  EXPECT_FALSE(vel_status(r));
}

// Issue 16 item 3. "A combination of the DirectVelocityControlStatus Command
// attribute and the DirectTorqueControlStatus Command attribute can be applied
// in applications that require Speed-limited Adjustable Torque (SLAT) modes";
// "The DirectVelocityControlStatus Command attribute is applied by taking the
// value in the speed field in the instruction configuration"; on MDS "the
// DirectVelocityControlStatus bit ... is set" and "Also ... the
// DirectTorqueControlStatus bit ... is set" [seed 002]. With SLAT configured
// the instruction's Speed is the velocity command (the SLAT speed, % of the
// maximum speed), the torque command is written live, and both bits are set.
TEST(MdsAudit, SlatTakesTheVelocityCommandFromTheInstructionAndSetsBothBits) {
  Rig r;
  AxisConfig c = cip(AxisConfig::DirectMode::Torque);
  c.direct_slat = true;  // direct_control.slat.configuration: SLAT Min Speed/Torque
  running(r, c, "MDS(D, m, 40, %ofmaximum);");
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicTorque);
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 80.0);  // 40 % of max_speed 200, not the configured 25
  EXPECT_DOUBLE_EQ(r.out[0].torque, 0.0);     // until the program writes the torque command
  EXPECT_TRUE(vel_status(r));
  EXPECT_TRUE(trq_status(r));
  EXPECT_TRUE(r.p->set_direct_command(0, 150.0));
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].torque, 150.0);
  // a superseding MDS changes the speed and keeps the torque command
  ASSERT_EQ(r.exec("MDS(D, m2, 12.5, unitspersec);"), Err::None);
  r.step();
  EXPECT_DOUBLE_EQ(r.out[0].velocity, 12.5);
  EXPECT_DOUBLE_EQ(r.out[0].torque, 150.0);
  ASSERT_EQ(r.exec("MAS(D, s, directcontrol, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  r.step();
  EXPECT_FALSE(vel_status(r));
  EXPECT_FALSE(trq_status(r));
}
