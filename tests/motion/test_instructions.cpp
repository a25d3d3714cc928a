// Per-instruction tests: EN/DN/ER/IP/PC sequences and the error cases the
// reference names for each instruction (ERR numbers, EXERR operand index).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::maj;
using canmotion::motion::test::Rig;

namespace {

AxisConfig virt() {
  AxisConfig c;
  c.max_speed = 100;
  c.max_accel = 1000;
  c.max_decel = 1000;
  c.max_accel_jerk = 1e5;
  c.max_decel_jerk = 1e5;
  return c;
}

struct Bits {
  bool en, dn, er, ip, pc;
};
Bits bits(const ControlTag& t) { return {t.en(), t.dn(), t.er(), t.ip(), t.pc()}; }
#define EXPECT_BITS(tag, EN, DN, ER, IP, PC)                                          \
  do {                                                                                \
    const Bits b_ = bits(tag);                                                        \
    EXPECT_EQ(b_.en, EN) << "EN";                                                     \
    EXPECT_EQ(b_.dn, DN) << "DN";                                                     \
    EXPECT_EQ(b_.er, ER) << "ER";                                                     \
    EXPECT_EQ(b_.ip, IP) << "IP";                                                     \
    EXPECT_EQ(b_.pc, PC) << "PC";                                                     \
  } while (0)

Rig servo_rig(AxisConfig c = virt()) {
  Rig r;
  r.add_axis("X", c);
  EXPECT_EQ(r.exec("MSO(X, mso1);"), Err::None);
  r.step();
  return r;
}

}  // namespace

// ------------------------------------------------------------------ MSO/MSF
TEST(Mso, VirtualAxisEnablesImmediately) {
  Rig r;
  r.add_axis("X", virt());
  EXPECT_EQ(r.axis("X").state, AxisState::Ready);
  EXPECT_EQ(r.exec("MSO(X, mso1);"), Err::None);
  EXPECT_BITS(r.tag("mso1"), true, true, false, false, false);
  EXPECT_TRUE(r.axis("X").status(axis_status::ServoActionStatus));
  EXPECT_TRUE(r.axis("X").status(axis_status::DriveEnableStatus));
  EXPECT_EQ(r.axis("X").state, AxisState::ServoControl);
}

TEST(Mso, Errors) {
  Rig r;
  AxisConfig nc = virt();
  nc.configured = false;
  r.add_axis("U", nc);
  AxisConfig inh = virt();
  inh.inhibited = true;
  r.add_axis("I", inh);
  r.add_axis("X", virt());
  EXPECT_EQ(r.exec("MSO(U, m1);"), Err::AxisNotConfigured);
  EXPECT_BITS(r.tag("m1"), true, false, true, false, false);
  EXPECT_EQ(r.tag("m1").err, 11);
  EXPECT_EQ(r.exec("MSO(I, m2);"), Err::AxisIsInhibited);
  EXPECT_EQ(r.exec("MASD(X, sd);"), Err::None);
  EXPECT_EQ(r.exec("MSO(X, m3);"), Err::ShutdownState);
  EXPECT_EQ(r.tag("m3").err, 7);
  EXPECT_FALSE(r.axis("X").status(axis_status::ServoActionStatus));
}

TEST(Mso, CipDriveWaitsForOperationEnabled) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  r.add_axis("D", c);
  r.fb[0].position = 12.5;
  r.fb[0].drive = DriveState::SwitchedOn;
  EXPECT_EQ(r.exec("MSO(D, mso1);"), Err::None);
  EXPECT_BITS(r.tag("mso1"), true, false, false, false, false);
  EXPECT_EQ(r.tag("mso1").state, 0);  // sending the request
  r.step();
  EXPECT_TRUE(r.out[0].enable);
  EXPECT_FALSE(r.tag("mso1").dn());
  EXPECT_EQ(r.tag("mso1").state, 1);  // waiting for enable
  EXPECT_EQ(r.axis("D").cip_state, CipAxisState::Starting);
  r.fb[0].drive = DriveState::Enabled;
  r.step();
  EXPECT_BITS(r.tag("mso1"), true, true, false, false, false);
  EXPECT_EQ(r.axis("D").cip_state, CipAxisState::Running);
  EXPECT_DOUBLE_EQ(r.out[0].position, 12.5);  // loop closed at the actual position
}

TEST(Mso, CipDriveFaultWhileEnablingIsServoMessageFailure) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  c.exception_actions.fill(ExceptionAction::Ignore);
  r.add_axis("D", c);
  r.exec("MSO(D, mso1);");
  r.fb[0].drive = DriveState::Fault;
  r.step();
  EXPECT_BITS(r.tag("mso1"), true, false, true, false, false);
  EXPECT_EQ(r.tag("mso1").err, 12);
  EXPECT_EQ(r.tag("mso1").exerr, 16);
}

TEST(Mso, CipAxisCoastingIsAxisInMotion) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  r.add_axis("D", c);
  r.fb[0].velocity = 5.0;  // coasting, servo off
  r.step();
  EXPECT_EQ(r.exec("MSO(D, m);"), Err::AxisInMotion);
  EXPECT_EQ(r.tag("m").err, 22);
  EXPECT_FALSE(r.out[0].enable);
  r.fb[0].velocity = 0.0;
  r.step();
  EXPECT_EQ(r.exec("MSO(D, m);"), Err::None);
}

TEST(Msf, CancelsMotionAndDisables) {
  Rig r = servo_rig();
  r.exec(maj("X", "j1", 0, 10));
  r.step(5);
  EXPECT_TRUE(r.tag("j1").ip());
  EXPECT_EQ(r.exec("MSF(X, msf1);"), Err::None);
  EXPECT_BITS(r.tag("msf1"), true, true, false, false, false);
  EXPECT_FALSE(r.tag("j1").ip());
  EXPECT_FALSE(r.axis("X").status(axis_status::ServoActionStatus));
  EXPECT_EQ(r.exec(maj("X", "j2", 0, 10)), Err::ServoOffState);
  EXPECT_EQ(r.tag("j2").err, 5);
}

// ------------------------------------------------------------------- MAM
TEST(Mam, BitSequenceAndExactTarget) {
  Rig r = servo_rig();
  EXPECT_EQ(r.exec(mam("X", "mam1", 0, 12.345, 50, 500, 400)), Err::None);
  EXPECT_BITS(r.tag("mam1"), true, true, false, true, false);
  r.step();
  EXPECT_TRUE(r.axis("X").motion(motion_status::MoveStatus));
  EXPECT_TRUE(r.tag("mam1").accel());
  EXPECT_TRUE(r.axis("X").motion(motion_status::AccelStatus));
  const int n = r.step_until([&] { return r.tag("mam1").pc(); });
  EXPECT_GT(n, 100);
  EXPECT_BITS(r.tag("mam1"), true, true, false, false, true);
  EXPECT_EQ(r.axis("X").command_position, 12.345);
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  EXPECT_FALSE(r.axis("X").motion(motion_status::MoveStatus));
  EXPECT_FALSE(r.tag("mam1").accel());
}

TEST(Mam, DecelBitWhileDecelerating) {
  Rig r = servo_rig();
  r.exec(mam("X", "mam1", 0, 10, 50, 500, 500));
  bool saw_decel = false;
  r.step_until([&] {
    saw_decel = saw_decel || (r.tag("mam1").decel() && r.axis("X").motion(motion_status::DecelStatus));
    return r.tag("mam1").pc();
  });
  EXPECT_TRUE(saw_decel);
}

TEST(Mam, ErrorCasesChangeNothing) {
  Rig r = servo_rig();
  r.exec(mam("X", "run", 0, 1000, 10));
  r.step(3);
  const double p0 = r.axis("X").command_position;
  struct Case { std::string text; Err err; int exerr; };
  const std::vector<Case> cases = {
      {mam("X", "e", 0, 5, -1), Err::ParameterOutOfRange, 4},   // Speed < 0
      {mam("X", "e", 0, 5, 10, 0), Err::ParameterOutOfRange, 6},  // AccelRate 0
      {mam("X", "e", 0, 5, 10, 100, -3), Err::ParameterOutOfRange, 8},
      {mam("X", "e", 0, 5, 10, 100, 100, "scurve", 0, 10, "unitspersec3"), Err::ParameterOutOfRange, 11},
      {mam("X", "e", 0, 5, 10, 100, 100, "scurve", 10, -1, "unitspersec3"), Err::ParameterOutOfRange, 12},
      {mam("X", "e", 0, 5, 10, 100, 100, "scurve", 150, 10, "%oftime"), Err::ParameterOutOfRange, 11},
      {mam("X", "e", 2, 5, 10), Err::AxisModeNotRotary, 0},
      {mam("X", "e", 5, 5, 10), Err::PositionCamNotEnabled, 0},  // master offset without a position cam
      {"MAM(X,e,0,5,1,unitspermasterunit,1,unitspermasterunit2,1,unitspermasterunit2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,immediateforwardonly,0,0);",
       Err::MdscNotActivated, 0},
      {"MAM(X,e,0,5,1,unitspermasterunit,1,unitspersec2,1,unitspermasterunit2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none,0,0);",
       Err::MdscUnitsConflict, 0},
      {"MAM(X,e,0,5,1,unitspersec,1,unitspersec2,1,unitspersec2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,immediateforwardonly,0,0);",
       Err::MdscLockDirConflict, 0},
      {"MAM(X,e,0,5,2,seconds,0.5,seconds,0.5,seconds,trapezoidal,0,0,seconds,disabled,programmed,0,none,0,0);",
       Err::AxisNotAtRest, 0},
      {"MAM(X,e,0,5,2,seconds,0.5,unitspersec2,0.5,seconds,trapezoidal,0,0,seconds,disabled,programmed,0,none,0,0);",
       Err::ParameterOutOfRange, 7},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.text);
    EXPECT_EQ(r.exec(c.text), c.err);
    EXPECT_BITS(r.tag("e"), true, false, true, false, false);
    EXPECT_EQ(r.tag("e").err, static_cast<int>(c.err));
    EXPECT_EQ(r.tag("e").exerr, c.exerr);
    EXPECT_TRUE(r.tag("run").ip());  // the running move is untouched
    EXPECT_EQ(r.axis("X").command_position, p0);
  }
  r.step();
  EXPECT_GT(r.axis("X").command_position, p0);
}

TEST(Mam, ZeroMaxDecelWithPercentOfMaximum) {
  AxisConfig c = virt();
  c.max_decel = 0;
  Rig r = servo_rig(c);
  EXPECT_EQ(r.exec("MAM(X,e,0,5,10,unitspersec,50,%ofmaximum,50,%ofmaximum,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none,0,0);"),
            Err::ZeroMaxDecel);
  EXPECT_EQ(r.tag("e").err, 54);
}

TEST(Mam, PercentOfMaximumUsesAxisLimits) {
  Rig r = servo_rig();
  r.exec("MAM(X,m,1,1000,50,%ofmaximum,100,%ofmaximum,100,%ofmaximum,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none,0,0);");
  r.step(500);
  EXPECT_DOUBLE_EQ(r.axis("X").command_velocity, 50.0);  // 50 % of 100
}

TEST(Mam, SecondsMoveTakesExactlyTheProgrammedTime) {
  Rig r = servo_rig();
  r.exec("MAM(X,m,1,10,2,seconds,0.5,seconds,0.5,seconds,scurve,0.1,0.1,seconds,disabled,programmed,0,none,0,0);");
  const int n = r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_NEAR(n, 2000, 1);
  EXPECT_NEAR(r.axis("X").command_position, 10.0, 1e-9);
  // MCD is an illegal dynamic change on a move programmed in seconds
  r.exec("MAM(X,m2,1,10,2,seconds,0.5,seconds,0.5,seconds,trapezoidal,0,0,seconds,disabled,programmed,0,none,0,0);");
  EXPECT_EQ(r.exec("MCD(X,mcd1,move,yes,5,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);"),
            Err::IllegalDynamicChange);
  EXPECT_EQ(r.tag("mcd1").err, 23);
}

TEST(Mam, ReplacementKeepsVelocityContinuous) {
  Rig r = servo_rig();
  r.exec(mam("X", "m1", 0, 100, 50, 200, 200, "scurve", 50, 50));
  r.step(200);
  const double v0 = r.axis("X").command_velocity;
  EXPECT_EQ(r.exec(mam("X", "m2", 0, 20, 50, 200, 200, "scurve", 50, 50)), Err::None);
  EXPECT_FALSE(r.tag("m1").ip());  // superseded, no PC
  EXPECT_FALSE(r.tag("m1").pc());
  r.step();
  EXPECT_NEAR(r.axis("X").command_velocity, v0, 0.5);  // no jump (S-curve: jerk-limited)
  r.step_until([&] { return r.tag("m2").pc(); });
  EXPECT_EQ(r.axis("X").command_position, 20.0);
}

TEST(Mam, IncrementalOnIncrementalAddsToTheTarget) {
  Rig r = servo_rig();
  r.exec(mam("X", "m1", 1, 10, 20));
  r.step(100);
  r.exec(mam("X", "m2", 1, 5, 20));
  r.step_until([&] { return r.tag("m2").pc(); });
  EXPECT_NEAR(r.axis("X").command_position, 15.0, 1e-9);
}

TEST(Mam, MergeFromJogIsContinuousAndCancelsTheJog) {
  Rig r = servo_rig();
  r.exec(maj("X", "j", 0, 20));
  r.step(300);
  const double v0 = r.axis("X").command_velocity;
  ASSERT_DOUBLE_EQ(v0, 20.0);
  EXPECT_EQ(r.exec(mam("X", "m", 0, 50, 20, 1000, 1000, "trapezoidal", 100, 100, "%oftime", "enabled")), Err::None);
  EXPECT_FALSE(r.tag("j").ip());
  r.step();
  EXPECT_NEAR(r.axis("X").command_velocity, 20.0, 1e-9);
  EXPECT_FALSE(r.axis("X").motion(motion_status::JogStatus));
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_EQ(r.axis("X").command_position, 50.0);
}

TEST(Mam, SuperposesOnJog) {
  Rig r = servo_rig();
  r.exec(maj("X", "j", 0, 10));
  r.step(100);
  r.exec(mam("X", "m", 1, 5, 5));
  r.step(200);
  EXPECT_NEAR(r.axis("X").command_velocity, 15.0, 1e-9);
  EXPECT_TRUE(r.axis("X").motion(motion_status::MoveStatus));
  EXPECT_TRUE(r.axis("X").motion(motion_status::JogStatus));
}

TEST(Mam, RotaryMoveTypes) {
  AxisConfig c = virt();
  c.rotary = true;
  c.unwind = 360;
  Rig r = servo_rig(c);
  r.exec("MRP(X, mrp, absolute, command, 350);");
  // shortest path 350 -> 10 goes forward through 0
  r.exec(mam("X", "m", 2, 10, 50));
  r.step();
  EXPECT_GT(r.axis("X").command_velocity, 0);
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_NEAR(r.axis("X").command_position, 10, 1e-9);
  // negative 10 -> 20 goes backwards 350 degrees
  r.exec(mam("X", "m2", 4, 20, 50));
  r.step();
  EXPECT_LT(r.axis("X").command_velocity, 0);
  r.step_until([&] { return r.tag("m2").pc(); });
  EXPECT_NEAR(r.axis("X").command_position, 20, 1e-9);
  // positive 20 -> 10 goes forward 350 degrees
  r.exec(mam("X", "m3", 3, 10, 50));
  r.step();
  EXPECT_GT(r.axis("X").command_velocity, 0);
  r.step_until([&] { return r.tag("m3").pc(); });
  EXPECT_NEAR(r.axis("X").command_position, 10, 1e-9);
  EXPECT_EQ(r.exec(mam("X", "m4", 2, 360, 50)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("m4").exerr, 3);
}

// ------------------------------------------------------------------- MAJ / MAS
TEST(Maj, JogRunsUntilStoppedThenMasPc) {
  Rig r = servo_rig();
  EXPECT_EQ(r.exec(maj("X", "j", 1, 10)), Err::None);
  EXPECT_BITS(r.tag("j"), true, true, false, true, false);
  r.step(100);
  EXPECT_DOUBLE_EQ(r.axis("X").command_velocity, -10.0);
  EXPECT_TRUE(r.axis("X").motion(motion_status::JogStatus));
  EXPECT_EQ(r.exec("MAS(X, mas1, jog, yes, 100, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_BITS(r.tag("mas1"), true, true, false, true, false);
  EXPECT_BITS(r.tag("j"), true, true, false, false, false);
  r.step();
  EXPECT_TRUE(r.axis("X").motion(motion_status::StoppingStatus));
  const int n = r.step_until([&] { return r.tag("mas1").pc(); });
  EXPECT_NEAR(n, 100, 2);  // 10 u/s at 100 u/s^2
  EXPECT_BITS(r.tag("mas1"), true, true, false, false, true);
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  EXPECT_FALSE(r.axis("X").motion(motion_status::StoppingStatus));
}

TEST(Maj, ReplacementAndErrors) {
  Rig r = servo_rig();
  r.exec(maj("X", "j1", 0, 10));
  r.step(50);
  r.exec(maj("X", "j2", 0, 30));
  EXPECT_FALSE(r.tag("j1").ip());
  r.step(100);
  EXPECT_DOUBLE_EQ(r.axis("X").command_velocity, 30.0);
  EXPECT_EQ(r.exec(maj("X", "e", 0, -5)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("e").exerr, 3);
  EXPECT_EQ(r.exec(maj("X", "e", 0, 5, 0)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("e").exerr, 5);
}

TEST(Mas, StopTypesOnlyStopTheirMotion) {
  Rig r = servo_rig();
  r.exec(maj("X", "j", 0, 10));
  r.exec(mam("X", "m", 1, 1000, 10));
  r.step(100);
  r.exec("MAS(X, s1, move, no, 0, unitspersec2, no, 0, unitspersec3);");
  EXPECT_FALSE(r.tag("m").ip());
  EXPECT_TRUE(r.tag("j").ip());
  r.step_until([&] { return r.tag("s1").pc(); });
  EXPECT_DOUBLE_EQ(r.axis("X").command_velocity, 10.0);
  // a stop type with nothing running: DN and PC at once
  r.exec("MAS(X, s2, gear, no, 0, unitspersec2, no, 0, unitspersec3);");
  EXPECT_BITS(r.tag("s2"), true, true, false, false, true);
  // all
  r.exec("MAS(X, s3, all, no, 0, unitspersec2, no, 0, unitspersec3);");
  EXPECT_FALSE(r.tag("j").ip());
  r.step_until([&] { return r.tag("s3").pc(); });
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  // new motion while stopping is refused (78)
  r.exec(maj("X", "j2", 0, 10));
  r.step(50);
  r.exec("MAS(X, s4, all, yes, 1, unitspersec2, no, 0, unitspersec3);");
  EXPECT_EQ(r.exec(maj("X", "j3", 0, 10)), Err::NotAllowedWhileStopping);
  EXPECT_EQ(r.tag("j3").err, 78);
  // a second MAS supersedes the first (IP cleared, no PC)
  r.exec("MAS(X, s5, all, yes, 1000, unitspersec2, no, 0, unitspersec3);");
  EXPECT_FALSE(r.tag("s4").ip());
  EXPECT_FALSE(r.tag("s4").pc());
  r.step_until([&] { return r.tag("s5").pc(); });
}

TEST(Mas, Errors) {
  AxisConfig c = virt();
  c.max_decel = 0;
  c.max_decel_jerk = 0;
  Rig r = servo_rig(c);
  EXPECT_EQ(r.exec("MAS(X, s, all, yes, 0, unitspersec2, no, 0, unitspersec3);"), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("s").exerr, 4);
  EXPECT_EQ(r.exec("MAS(X, s, all, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::ZeroMaxDecel);
  r.exec(maj("X", "j", 0, 10, 100, 100, "scurve"));
  r.step(10);
  EXPECT_EQ(r.exec("MAS(X, s, all, yes, 10, unitspersec2, no, 0, unitspersec3);"), Err::ZeroMaxDecelJerk);
  EXPECT_EQ(r.tag("s").err, 76);
  EXPECT_EQ(r.exec("MAS(X, s, all, yes, 10, unitspersec2, yes, -1, unitspersec3);"), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("s").exerr, 7);
  EXPECT_TRUE(r.tag("j").ip());
}

TEST(Mas, SCurveStopPercentOfTime) {
  Rig r = servo_rig();
  r.exec(maj("X", "j", 0, 10, 100, 100, "scurve"));
  r.step(1000);
  r.exec("MAS(X, s, jog, yes, 100, unitspersec2, yes, 100, %oftime);");
  // P=100: triangular decel, j = d^2/v = 1000, t = 2*sqrt(v/j) = 0.2 s
  const int n = r.step_until([&] { return r.tag("s").pc(); });
  EXPECT_NEAR(n, 200, 2);
}

// ------------------------------------------------------------------- MCD
TEST(Mcd, ChangesJogSpeed) {
  Rig r = servo_rig();
  r.exec(maj("X", "j", 0, 10));
  r.step(100);
  EXPECT_EQ(r.exec("MCD(X,c,jog,yes,25,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);"), Err::None);
  EXPECT_BITS(r.tag("c"), true, true, false, false, false);
  r.step(100);
  EXPECT_DOUBLE_EQ(r.axis("X").command_velocity, 25.0);
}

TEST(Mcd, LimitsDropMidMoveNeverOvershootTheTarget) {
  Rig r = servo_rig();
  r.exec(mam("X", "m", 0, 10, 50, 500, 500, "scurve", 5000, 5000, "unitspersec3"));
  r.step_until([&] { return r.axis("X").command_position > 8.5; });
  // decel drops to 1 u/s^2: stopping would need > 1000 units
  EXPECT_EQ(r.exec("MCD(X,c,move,no,0,no,0,yes,1,no,0,yes,1,unitspersec,unitspersec2,unitspersec2,unitspersec3);"), Err::None);
  double maxp = 0;
  r.step_until([&] {
    maxp = std::max(maxp, r.axis("X").command_position);
    return r.tag("m").pc();
  });
  EXPECT_LE(maxp, 10.0);
  EXPECT_EQ(r.axis("X").command_position, 10.0);
}

TEST(Mcd, SpeedZeroPausesAndResumes) {
  Rig r = servo_rig();
  r.exec(mam("X", "m", 0, 100, 20));
  r.step(500);
  r.exec("MCD(X,c,move,yes,0,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);");
  r.step(200);
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  EXPECT_TRUE(r.tag("m").ip());
  r.exec("MCD(X,c2,move,yes,40,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);");
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_EQ(r.axis("X").command_position, 100.0);
}

TEST(Mcd, Errors) {
  Rig r = servo_rig();
  r.exec(mam("X", "m", 0, 100, 20));
  EXPECT_EQ(r.exec("MCD(X,c,move,no,0,yes,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);"), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("c").exerr, 6);
  EXPECT_EQ(r.exec("MCD(X,c,move,yes,-1,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);"), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("c").exerr, 4);
  // master-driven units on a time-driven move: a mode change, ERR 105 (issue 16, seed 001)
  EXPECT_EQ(r.exec("MCD(X,c,move,yes,1,no,0,no,0,no,0,no,0,unitspermasterunit,unitspersec2,unitspersec2,unitspersec3);"), Err::MdscInvalidModeOrMasterChange);
  // and with no jog to change and no MDAC link for jogs: ERR 93
  EXPECT_EQ(r.exec("MCD(X,c,jog,yes,1,no,0,no,0,no,0,no,0,unitspermasterunit,unitspersec2,unitspersec2,unitspersec3);"), Err::MdscNotActivated);
  r.exec("MSF(X, f);");
  EXPECT_EQ(r.exec("MCD(X,c,move,yes,1,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);"), Err::ServoOffState);
}

// ------------------------------------------------------------------- MRP / MAH
TEST(Mrp, AbsoluteAndRelative) {
  Rig r = servo_rig();
  r.exec(mam("X", "m", 0, 5, 50));
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_EQ(r.exec("MRP(X, mrp, absolute, command, 100);"), Err::None);
  EXPECT_BITS(r.tag("mrp"), true, true, false, false, false);
  EXPECT_DOUBLE_EQ(r.axis("X").command_position, 100.0);
  EXPECT_DOUBLE_EQ(r.axis("X").actual_position, 100.0);
  r.exec("MRP(X, mrp2, relative, actual, -30);");
  EXPECT_DOUBLE_EQ(r.axis("X").command_position, 70.0);
}

TEST(Mah, VirtualIsImmediate) {
  AxisConfig c = virt();
  c.homing.home_position = 42;
  Rig r = servo_rig(c);
  EXPECT_FALSE(r.axis("X").motion(motion_status::AxisHomedStatus));
  EXPECT_EQ(r.exec("MAH(X, mah1);"), Err::None);
  EXPECT_BITS(r.tag("mah1"), true, true, false, false, true);
  EXPECT_TRUE(r.axis("X").motion(motion_status::AxisHomedStatus));
  EXPECT_DOUBLE_EQ(r.axis("X").command_position, 42.0);
}

TEST(Mah, CipDriveHomingMode6) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  c.homing.sequence = HomingConfig::Sequence::Switch;
  c.homing.cia_method = 19;
  c.homing.speed_search = 5;
  c.homing.speed_zero = 0.5;
  c.homing.accel = 50;
  c.homing.home_position = 7;
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  r.fb[0].position = 3;
  r.exec("MSO(D, mso);");
  r.step();
  EXPECT_EQ(r.exec("MAH(D, mah);"), Err::None);
  EXPECT_BITS(r.tag("mah"), true, true, false, true, false);
  r.step();
  EXPECT_EQ(r.out[0].mode, DriveMode::Homing);
  EXPECT_TRUE(r.out[0].homing_start);
  EXPECT_EQ(r.out[0].homing.method, 19);
  EXPECT_DOUBLE_EQ(r.out[0].homing.speed_search, 5);
  EXPECT_DOUBLE_EQ(r.out[0].homing.speed_zero, 0.5);
  EXPECT_DOUBLE_EQ(r.out[0].homing.accel, 50);
  EXPECT_TRUE(r.axis("D").motion(motion_status::HomingStatus));
  EXPECT_EQ(r.exec(mam("D", "m", 0, 1, 1)), Err::HomeInProcess);
  EXPECT_EQ(r.exec("MAH(D, mah2);"), Err::HomeInProcess);
  r.step();  // the drive shows this homing in progress
  r.fb[0].position = -2;  // drive moved while homing
  r.fb[0].homing_attained = true;
  r.step();
  EXPECT_BITS(r.tag("mah"), true, true, false, false, true);
  EXPECT_EQ(r.out[0].mode, DriveMode::CyclicPosition);
  EXPECT_TRUE(r.axis("D").motion(motion_status::AxisHomedStatus));
  EXPECT_DOUBLE_EQ(r.axis("D").actual_position, 7.0);
  EXPECT_DOUBLE_EQ(r.out[0].position, -2.0);  // drive frame unchanged: no jump
}

// "Homing attained" still set from an earlier homing when MAH starts is not
// this homing's completion: it counts only after the feedback showed it
// clear once since the start (on main MAH was PC in the next cycle).
TEST(Mah, StaleHomingAttainedDoesNotCompleteANewHoming) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  c.homing.sequence = HomingConfig::Sequence::Switch;
  c.homing.home_position = 7;
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  r.fb[0].homing_attained = true;  // left from a previous homing
  r.exec("MSO(D, mso);");
  r.step();
  EXPECT_EQ(r.exec("MAH(D, mah);"), Err::None);
  for (int i = 0; i < 5; ++i) r.step();
  EXPECT_BITS(r.tag("mah"), true, true, false, true, false);  // still IP
  EXPECT_FALSE(r.axis("D").motion(motion_status::AxisHomedStatus));
  r.fb[0].homing_attained = false;  // the drive started this homing
  r.step();
  EXPECT_BITS(r.tag("mah"), true, true, false, true, false);
  r.fb[0].homing_attained = true;
  r.step();
  EXPECT_BITS(r.tag("mah"), true, true, false, false, true);
  EXPECT_TRUE(r.axis("D").motion(motion_status::AxisHomedStatus));
}

// A homing error (or the runtime's homing timeout) ends MAH with ERR 12 and
// the EXERR the feedback gives (3: a homing parameter refused).
TEST(Mah, HomingErrorEndsWithErr12AndTheFeedbacksExerr) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  c.homing.sequence = HomingConfig::Sequence::Switch;
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(D, mso);");
  r.step();
  EXPECT_EQ(r.exec("MAH(D, mah);"), Err::None);
  r.step();
  r.fb[0].homing_error = true;
  r.fb[0].homing_exerr = 3;
  r.step();
  EXPECT_TRUE(r.tag("mah").er());
  EXPECT_EQ(r.tag("mah").err, 12);
  EXPECT_EQ(r.tag("mah").exerr, 3);
  EXPECT_FALSE(r.axis("D").motion(motion_status::HomingStatus));
}

TEST(Mah, Errors) {
  AxisConfig c = virt();
  c.rotary = true;
  c.unwind = 360;
  c.homing.home_position = 400;
  Rig r = servo_rig(c);
  EXPECT_EQ(r.exec("MAH(X, h);"), Err::IllegalHomingConfig);
  EXPECT_EQ(r.tag("h").err, 41);
  Rig r2;
  r2.add_axis("X", virt());
  EXPECT_EQ(r2.exec("MAH(X, h);"), Err::ServoOffState);  // active homing, servo off
}

// ------------------------------------------------------------------- shutdown / faults
TEST(Masd, ShutdownAndReset) {
  Rig r = servo_rig();
  r.exec(maj("X", "j", 0, 10));
  r.step(10);
  EXPECT_EQ(r.exec("MASD(X, sd);"), Err::None);
  EXPECT_BITS(r.tag("sd"), true, true, false, false, false);
  EXPECT_FALSE(r.tag("j").ip());
  EXPECT_EQ(r.axis("X").state, AxisState::Shutdown);
  EXPECT_TRUE(r.axis("X").status(axis_status::ShutdownStatus));
  EXPECT_EQ(r.exec(maj("X", "j2", 0, 10)), Err::ShutdownState);
  EXPECT_EQ(r.exec("MASR(X, sr);"), Err::None);
  EXPECT_EQ(r.axis("X").state, AxisState::Ready);
  EXPECT_EQ(r.exec("MSO(X, m);"), Err::None);
}

TEST(Exceptions, SoftOvertravelStopsThePlannerAndBlocksThatDirection) {
  AxisConfig c = virt();
  c.soft_limits_enabled = true;
  c.soft_limit_pos = 5;
  c.soft_limit_neg = -5;
  Rig r = servo_rig(c);
  r.exec(maj("X", "j", 0, 10));
  r.step_until([&] { return r.axis("X").motion_fault_status != 0; }, 5000);
  EXPECT_TRUE(r.axis("X").fault(axis_fault::MotionFault));
  EXPECT_TRUE((r.axis("X").motion_fault_status >> motion_fault::SoftTravelLimitPositive) & 1u);
  EXPECT_FALSE(r.tag("j").ip());
  r.step(200);
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  EXPECT_EQ(r.axis("X").state, AxisState::ServoControl);  // stop planner keeps the servo on
  EXPECT_EQ(r.exec(maj("X", "j2", 0, 1)), Err::OvertravelCondition);
  EXPECT_EQ(r.exec(maj("X", "j3", 1, 1)), Err::None);  // moving back out is allowed
}

TEST(Exceptions, MostSevereActionWins) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  c.exception_actions[static_cast<std::size_t>(ExceptionKind::DriveFault)] = ExceptionAction::Alarm;
  c.exception_actions[static_cast<std::size_t>(ExceptionKind::NodeLost)] = ExceptionAction::Shutdown;
  c.exception_actions[static_cast<std::size_t>(ExceptionKind::BusOff)] = ExceptionAction::StopDrive;
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(D, mso);");
  r.step();
  r.fb[0].drive_fault = true;
  r.fb[0].node_lost = true;
  r.fb[0].bus_off = true;
  r.step();
  EXPECT_EQ(r.axis("D").state, AxisState::Shutdown);
  EXPECT_TRUE(r.axis("D").fault(axis_fault::ModuleFault));
  EXPECT_FALSE(r.out[0].enable);
  EXPECT_EQ(r.exec("MSO(D, m2);"), Err::ShutdownState);
}

TEST(Exceptions, PositionErrorStopDriveFaultsUntilMafr) {
  Rig r;
  AxisConfig c = virt();
  c.type = AxisType::CipDrive;
  c.position_error_tolerance = 0.5;
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(D, mso);");
  r.step();
  r.exec(maj("D", "j", 0, 10));
  r.step(200);  // the drive does not move: following error grows
  EXPECT_EQ(r.axis("D").state, AxisState::Faulted);
  EXPECT_TRUE(r.axis("D").fault(axis_fault::PhysicalAxisFault));
  EXPECT_FALSE(r.tag("j").ip());
  EXPECT_EQ(r.exec(maj("D", "j2", 0, 10)), Err::AxisInFaultedState);
  EXPECT_EQ(r.tag("j2").err, 20);
  EXPECT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  EXPECT_TRUE(r.out[0].enable == false);
  r.step();
  EXPECT_EQ(r.axis("D").state, AxisState::Ready);
  EXPECT_EQ(r.axis("D").axis_fault, 0u);
}

// ------------------------------------------------------------------- group
TEST(Group, MgsFastStopPcWhenAllStopped) {
  Rig r;
  r.add_axis("X", virt());
  r.add_axis("Y", virt());
  r.exec("MSO(X, a);");
  r.exec("MSO(Y, b);");
  r.exec(maj("X", "jx", 0, 10));
  r.exec(maj("Y", "jy", 0, 50));
  r.step(200);
  EXPECT_EQ(r.exec("MGS(g, mgs, faststop);"), Err::None);
  EXPECT_BITS(r.tag("mgs"), true, true, false, true, false);
  r.step(15);  // X (10 u/s) stopped after 10 ms, Y (50 u/s) needs 50 ms
  EXPECT_FALSE(r.tag("mgs").pc());
  r.step_until([&] { return r.tag("mgs").pc(); });
  EXPECT_FALSE(r.tag("mgs").ip());
  EXPECT_EQ(r.axis("X").command_velocity, 0.0);
  EXPECT_EQ(r.axis("Y").command_velocity, 0.0);
  EXPECT_EQ(r.axis("Y").state, AxisState::ServoControl);
}

TEST(Group, FastDisableAndShutdownReset) {
  Rig r;
  r.add_axis("X", virt());
  r.exec("MSO(X, a);");
  r.exec(maj("X", "jx", 0, 10));
  r.step(100);
  r.exec("MGS(g, mgs, 2);");
  r.step_until([&] { return r.tag("mgs").pc(); });
  EXPECT_EQ(r.axis("X").state, AxisState::Ready);  // disabled after the stop
  EXPECT_EQ(r.exec("MGSD(g, sd);"), Err::None);
  EXPECT_EQ(r.axis("X").state, AxisState::Shutdown);
  EXPECT_EQ(r.exec("MGSR(g, sr);"), Err::None);
  EXPECT_EQ(r.axis("X").state, AxisState::Ready);
}

// ------------------------------------------------------------------- model rules
TEST(Model, CoordinatedInstructionOnAnUnconfiguredSystemGivesErr11) {
  Rig r = servo_rig();
  r.add_axis("M", virt());
  r.sym.coordinate_systems["cs"] = 0;
  EXPECT_EQ(r.exec("MCSD(cs, t);"), Err::AxisNotConfigured);
  EXPECT_EQ(r.tag("t").err, 11);
}

TEST(Model, EachExecutionIsARisingEdge) {
  Rig r = servo_rig();
  r.exec(mam("X", "m", 0, 1, 50));
  r.step_until([&] { return r.tag("m").pc(); });
  const auto g0 = r.tag("m").generation;
  r.exec(mam("X", "m", 0, 2, 50));  // the same statement executed again: a new transition
  EXPECT_EQ(r.tag("m").generation, g0 + 1);
  EXPECT_BITS(r.tag("m"), true, true, false, true, false);  // PC cleared by the new execution
}

TEST(Determinism, SameSequenceTwiceIsBitIdentical) {
  auto run = [] {
    Rig r = servo_rig();
    std::vector<double> trace;
    r.exec(mam("X", "m", 0, 37.5, 40, 300, 200, "scurve", 60, 40));
    for (int i = 0; i < 3000; ++i) {
      if (i == 400) r.exec(maj("X", "j", 1, 15, 100, 100, "scurve"));
      if (i == 900) r.exec("MCD(X,c,jog,yes,30,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);");
      if (i == 1500) r.exec(mam("X", "m2", 0, -3, 20, 100, 100, "scurve", 50, 50, "%oftime", "enabled"));
      if (i == 2000) r.exec("MAS(X, s, all, yes, 80, unitspersec2, yes, 90, %oftime);");
      r.step();
      trace.push_back(r.out[0].position);
      trace.push_back(r.out[0].velocity);
    }
    return trace;
  };
  const auto a = run();
  const auto b = run();
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
}

TEST(Model, FirstCycleIndexCanBeAnything) {
  Rig r;
  r.add_axis("X", virt());
  r.cycle = 123456;  // the runtime starts counting wherever it likes
  r.submit("MSO(X, on);");
  r.submit(mam("X", "m", 0, 10, 50, 1000, 1000));
  r.step();
  // one period of a 1000 u/s^2 ramp: v = 1 u/s, not a jump into the profile
  EXPECT_NEAR(r.axis("X").command_velocity, 1.0, 1e-9);
  Output none{};
  EXPECT_EQ(r.p->update(Input{r.cycle, {}, {}}, none), Result::ErrorCycleNotIncreasing);
}
