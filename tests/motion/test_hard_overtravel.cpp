// Hardware overtravel (issue 30 part 1, item 4): the drive's limit switches
// (0x60FD bits 1 / 0, CiA 402 digital inputs) latch PositiveOvertravelFault /
// NegativeOvertravelFault with the axis's configured exception action.
#include <gtest/gtest.h>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::Rig;

namespace {

/// An enabled CIP axis "D" under MDS (control tag "m"), one cycle stepped.
void running(Rig& r, const AxisConfig& c) {
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  ASSERT_EQ(r.exec("MSO(D, on);"), Err::None);
  r.step();
  ASSERT_EQ(r.exec("MDS(D, m, 10, unitspersec);"), Err::None);
  r.step();
  ASSERT_TRUE(r.tag("m").ip());
}

bool latched(Rig& r, ExceptionKind k) { return (r.axis("D").exception_faults >> static_cast<unsigned>(k)) & 1u; }

}  // namespace

TEST(HardOvertravel, LimitSwitchFaultsPerExceptionAction) {
  struct Case {
    ExceptionAction action;
    bool servo_off;
    bool shutdown;
  };
  for (const bool positive : {true, false}) {
    const ExceptionKind kind = positive ? ExceptionKind::HardOvertravelPos : ExceptionKind::HardOvertravelNeg;
    const ExceptionKind other = positive ? ExceptionKind::HardOvertravelNeg : ExceptionKind::HardOvertravelPos;
    for (const Case& k : {Case{ExceptionAction::FaultStatusOnly, false, false},
                          Case{ExceptionAction::StopDrive, true, false}, Case{ExceptionAction::Shutdown, true, true}}) {
      SCOPED_TRACE(testing::Message() << (positive ? "positive " : "negative ") << static_cast<int>(k.action));
      Rig r;
      AxisConfig c = canmotion::motion::test::cip_direct(AxisConfig::DirectMode::Velocity, 25);
      c.exception_actions[static_cast<std::size_t>(kind)] = k.action;
      running(r, c);
      EXPECT_FALSE(latched(r, kind));
      (positive ? r.fb[0].limit_positive : r.fb[0].limit_negative) = true;
      r.step();
      EXPECT_TRUE(latched(r, kind));
      EXPECT_FALSE(latched(r, other));
      EXPECT_TRUE((r.axis("D").axis_fault >> axis_fault::PhysicalAxisFault) & 1u);
      EXPECT_EQ(r.out[0].enable, !k.servo_off);
      EXPECT_EQ(r.out[0].shutdown, k.shutdown);
      // latched: it stays after the switch is released, until MAFR
      (positive ? r.fb[0].limit_positive : r.fb[0].limit_negative) = false;
      r.step();
      EXPECT_TRUE(latched(r, kind));
      ASSERT_EQ(r.exec("MAFR(D, f);"), Err::None);
      r.step(3);
      EXPECT_FALSE(latched(r, kind));
    }
  }
}

TEST(HardOvertravel, StopPlannerStopsTheMotionAndKeepsTheServoOn) {
  Rig r;
  AxisConfig c = canmotion::motion::test::cip_direct(AxisConfig::DirectMode::Velocity, 25);
  c.exception_actions[static_cast<std::size_t>(ExceptionKind::HardOvertravelPos)] = ExceptionAction::StopPlanner;
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::Enabled;
  ASSERT_EQ(r.exec("MSO(D, on);"), Err::None);
  r.step();
  ASSERT_EQ(r.exec("MAJ(D, j, 0, 10, unitspersec, 100, unitspersec2, 100, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none);"), Err::None);
  r.step(5);
  ASSERT_TRUE(r.tag("j").ip());
  r.fb[0].limit_positive = true;
  r.step();
  EXPECT_TRUE(latched(r, ExceptionKind::HardOvertravelPos));
  EXPECT_FALSE(r.tag("j").ip());
  EXPECT_TRUE(r.out[0].enable);
}

TEST(HardOvertravel, DefaultActionIsStopDrive) {
  const AxisConfig c{};
  EXPECT_EQ(c.action(ExceptionKind::HardOvertravelPos), ExceptionAction::StopDrive);
  EXPECT_EQ(c.action(ExceptionKind::HardOvertravelNeg), ExceptionAction::StopDrive);
  EXPECT_EQ(exception_key(ExceptionKind::HardOvertravelPos), "hard_overtravel_positive");
  EXPECT_EQ(exception_key(ExceptionKind::HardOvertravelNeg), "hard_overtravel_negative");
}
