// MAPC (Motion Axis Position Cam, issue 5, reference 2.14): every operand
// value (Direction, scaling, ExecutionMode, ExecutionSchedule, lock
// positions, MasterReference, MasterDirection), the MotionStatus and
// MOTION_INSTRUCTION bits, CAM_PROFILE[0].Status use counting, pending
// takeover continuity, the stops that end a position cam, the ERR codes, and a
// seeded property test: the slave equals the scaled profile of the master
// over random master trajectories.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <random>
#include <utility>
#include <string>

#include "motion/cam/cam_profile.hpp"
#include "poscam_rig.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::maj;
using canmotion::motion::test::Rig;

namespace {

using namespace motion_status;

using canmotion::motion::test::PcRig;

}  // namespace

// ------------------------------------------------------------- immediate / once
TEST(Mapc, ImmediateOnceFollowsTheProfileAndCompletes) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "immediate")), Err::None);
  const ControlTag& t = c.r.tag("pc");
  EXPECT_TRUE(t.dn() && t.ip() && t.ac());
  EXPECT_FALSE(t.pc());
  EXPECT_TRUE(c.bit(PositionCamStatus));
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
  EXPECT_FALSE(c.bit(PositionCamPendingStatus));
  EXPECT_EQ(c.lin.status(), 3);  // calculated and in use by one cam
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 5, 1e6, 1e6)), Err::None);
  c.r.step(1000);
  EXPECT_NEAR(c.m(), 5.0, 1e-4);
  EXPECT_NEAR(c.s(), 2 * c.m(), 1e-9);
  EXPECT_NEAR(c.r.axis("S").command_velocity, 10.0, 1e-9);  // slope 2 x master 5 units/s
  EXPECT_EQ(t.segment, 0);
  c.r.step_until([&] { return t.pc(); }, 2000);
  EXPECT_TRUE(t.pc());
  EXPECT_FALSE(t.ip());
  EXPECT_FALSE(t.ac());
  EXPECT_FALSE(c.bit(PositionCamStatus));
  EXPECT_FALSE(c.bit(PositionCamLockStatus));
  EXPECT_NEAR(c.s(), 20.0, 1e-9);  // holds the end of the profile
  EXPECT_EQ(c.r.axis("S").command_velocity, 0.0);
  EXPECT_EQ(c.lin.status(), 2);
  c.r.step(500);
  EXPECT_NEAR(c.s(), 20.0, 1e-9);  // the master runs on, the slave stays
}

TEST(Mapc, OnceCompletesWhenTheMasterLeavesBackwards) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "immediate", 0, 3)), Err::None);
  c.move_master(-5);
  EXPECT_TRUE(c.r.tag("pc").pc());
  EXPECT_NEAR(c.s(), -6.0, 1e-9);  // P(0) - P(3) = -6
}

TEST(Mapc, ScalingDirectionAndCamLockPosition) {
  PcRig c;
  // opposite, slave x3, master x2, start at profile master 4 (slave 8 on the profile)
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "cub", 3, 2, "once", "immediate", 0, 4, "command", "bidirectional",
                                 "opposite")),
            Err::None);
  c.move_master(5);
  const double expect = -3 * (c.cub.evaluate(4 + 5.0 / 2).position - c.cub.evaluate(4).position);
  EXPECT_NEAR(c.s(), expect, 1e-9);
  EXPECT_EQ(c.r.tag("pc").segment, 2);  // 6.5 lies in [5, 8)
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 1, 1e6, 1e6)), Err::None);
  c.r.step(10);
  const double v = -3 * c.cub.evaluate(4 + c.m() / 2).velocity / 2 * 1.0;
  EXPECT_NEAR(c.r.axis("S").command_velocity, v, 1e-9);
}

TEST(Mapc, ReverseAndUnchangedDirections) {
  PcRig c;
  // reverse on first use = opposite
  ASSERT_EQ(c.r.exec(PcRig::mapc("a", "lin", 1, 1, "once", "immediate", 0, 0, "command", "bidirectional", "reverse")),
            Err::None);
  c.move_master(2);
  EXPECT_NEAR(c.s(), -4.0, 1e-9);
  ASSERT_EQ(c.r.exec("MAS(S, st, positioncam, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  c.r.step(10);
  const double s0 = c.s();
  ASSERT_EQ(c.r.exec(PcRig::mapc("b", "lin", 1, 1, "once", "immediate", 0, 0, "command", "bidirectional", "unchanged")),
            Err::None);
  c.move_master(3);
  EXPECT_NEAR(c.s() - s0, -2.0, 1e-9);  // unchanged keeps opposite
  ASSERT_EQ(c.r.exec("MAS(S, st2, positioncam, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  c.r.step(10);
  const double s1 = c.s();
  ASSERT_EQ(c.r.exec(PcRig::mapc("d", "lin", 1, 1, "once", "immediate", 0, 0, "command", "bidirectional", "reverse")),
            Err::None);
  c.move_master(4);
  EXPECT_NEAR(c.s() - s1, 2.0, 1e-9);  // reverse flips back to same
  // numbers work as well as keywords: 1 = opposite
  ASSERT_EQ(c.r.exec("MAS(S, st3, positioncam, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  c.r.step(10);
  const double s2 = c.s();
  ASSERT_EQ(c.r.exec("MAPC(S, M, e, 1, lin[0], 1, 1, 0, 0, 0, 0, 1, 0);"), Err::None);
  c.move_master(5);
  EXPECT_NEAR(c.s() - s2, -2.0, 1e-9);
}

// --------------------------------------------------------- execution modes
TEST(Mapc, ContinuousWrapsOverTheProfileLength) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "continuous", "immediate")), Err::None);
  c.move_master(25);
  EXPECT_NEAR(c.s(), 50.0, 1e-9);  // two and a half passes of 20
  EXPECT_TRUE(c.r.tag("pc").ip());
  EXPECT_FALSE(c.r.tag("pc").pc());
  c.move_master(-12);  // and backwards through the start
  EXPECT_NEAR(c.s(), -24.0, 1e-9);
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
}

TEST(Mapc, PersistentUnlocksOutsideAndRelocksOnReentry) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "persistent", "immediate", 0, 5)), Err::None);
  c.move_master(8);  // past the end (profile 13 > 10)
  EXPECT_NEAR(c.s(), 10.0, 1e-9);
  EXPECT_TRUE(c.bit(PositionCamStatus));
  EXPECT_FALSE(c.bit(PositionCamLockStatus));
  EXPECT_TRUE(c.r.tag("pc").ip());
  EXPECT_FALSE(c.r.tag("pc").pc());
  c.move_master(3);  // back inside: profile 8
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
  EXPECT_NEAR(c.s(), 6.0, 1e-9);
}

// ------------------------------------------------------- execution schedules
TEST(Mapc, ForwardOnlyScheduleLocksWhenTheMasterCrossesForward) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "forwardonly", 3, 0)), Err::None);
  EXPECT_TRUE(c.bit(PositionCamStatus));
  EXPECT_FALSE(c.bit(PositionCamLockStatus));
  EXPECT_TRUE(c.r.tag("pc").ip());
  c.move_master(2.5);
  EXPECT_EQ(c.s(), 0.0);
  EXPECT_FALSE(c.bit(PositionCamLockStatus));
  c.move_master(4.25);  // crosses 3 going forward
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
  EXPECT_NEAR(c.s(), 2 * 1.25, 1e-9);  // counted from the lock position exactly
}

TEST(Mapc, ReverseOnlyScheduleIgnoresForwardCrossings) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "reverseonly", 3, 10)), Err::None);
  c.move_master(5);  // forward across 3: no lock
  EXPECT_FALSE(c.bit(PositionCamLockStatus));
  EXPECT_EQ(c.s(), 0.0);
  c.move_master(1);  // backwards across 3: lock, runs down the profile from 10
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
  EXPECT_NEAR(c.s(), -4.0, 1e-9);
}

TEST(Mapc, BidirectionalScheduleLocksInEitherDirection) {
  for (const auto& [from, to] : {std::pair{2.0, 6.0}, std::pair{4.0, -2.0}}) {
    PcRig c;
    c.move_master(from);
    ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "persistent", "bidirectional", 2.5, 5)), Err::None);
    c.r.step(5);
    EXPECT_FALSE(c.bit(PositionCamLockStatus));
    c.move_master(to);  // across 2.5, forward or backwards
    EXPECT_TRUE(c.bit(PositionCamLockStatus)) << from;
    EXPECT_NEAR(c.s(), 2 * (to - 2.5), 1e-9) << from;
  }
}

TEST(Mapc, RotaryMasterLocksAtEveryTurnOfTheLockPosition) {
  PcRig c(AxisType::Virtual, true);
  c.move_master(700);  // 340 in the unwound frame
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "continuous", "forwardonly", 10, 0)), Err::None);
  ASSERT_EQ(c.r.exec(mam("M", "inc", 1, 35, 50, 1e5, 1e5)), Err::None);  // to 735 = 2 * 360 + 15: crosses 730
  c.r.step_until([&] { return c.r.tag("inc").pc(); });
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
  EXPECT_NEAR(c.s(), 10.0, 1e-9);
}

TEST(Mapc, PendingTakesOverAtThePassEndWithoutAJump) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("a", "lin", 1, 1, "continuous", "immediate")), Err::None);
  c.move_master(3);
  ASSERT_EQ(c.r.exec(PcRig::mapc("b", "step", 1, 1, "once", "pending")), Err::None);
  EXPECT_TRUE(c.bit(PositionCamPendingStatus));
  EXPECT_TRUE(c.r.tag("b").dn() && c.r.tag("b").ip());
  EXPECT_FALSE(c.r.tag("b").ac());  // not the active cam yet
  EXPECT_EQ(c.step.status(), 2);     // counted when it becomes active
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 2, 1e6, 1e6)), Err::None);
  double prev = c.s(), worst = 0;
  for (int i = 0; i < 5000; ++i) {
    c.r.step();
    worst = std::max(worst, std::fabs(c.s() - prev));
    prev = c.s();
  }
  EXPECT_LE(worst, 2 * 2 * 0.001 + 1e-9);  // never faster than slope 2 x 2 units/s: no jump
  EXPECT_FALSE(c.r.tag("a").ip());          // continuous cam superseded: IP cleared, no PC
  EXPECT_FALSE(c.r.tag("a").pc());
  EXPECT_FALSE(c.r.tag("a").ac());
  EXPECT_FALSE(c.bit(PositionCamPendingStatus));
  // master at 3 + 10 = 13: the pending cam took over at 10 (slave 20) and ran 3 of its 4
  EXPECT_NEAR(c.m(), 13.0, 1e-4);
  EXPECT_NEAR(c.s(), 20.0 + (c.m() - 10.0), 1e-9);
  EXPECT_TRUE(c.r.tag("b").ac());
  EXPECT_EQ(c.lin.status(), 2);
  EXPECT_EQ(c.step.status(), 3);
  c.r.step_until([&] { return c.r.tag("b").pc(); });
  EXPECT_NEAR(c.s(), 24.0, 1e-9);
  EXPECT_EQ(c.step.status(), 2);
}

TEST(Mapc, PendingAfterAOnceCamSetsItsPc) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("a", "step", 1, 1, "once", "immediate")), Err::None);
  ASSERT_EQ(c.r.exec(PcRig::mapc("b", "lin", 1, 1, "once", "pending")), Err::None);
  c.move_master(6);
  EXPECT_TRUE(c.r.tag("a").pc());
  EXPECT_FALSE(c.r.tag("a").ip());
  EXPECT_TRUE(c.r.tag("b").ip());
  EXPECT_NEAR(c.s(), 4.0 + 2 * 2.0, 1e-9);
}

TEST(Mapc, PendingWithoutAnActiveCamWaitsForANonPendingOne) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("p", "lin", 1, 1, "once", "pending")), Err::None);
  EXPECT_TRUE(c.bit(PositionCamPendingStatus));
  EXPECT_FALSE(c.bit(PositionCamStatus));
  c.move_master(3);
  EXPECT_EQ(c.s(), 0.0);
  ASSERT_EQ(c.r.exec(PcRig::mapc("i", "step", 1, 1, "once", "immediate")), Err::None);
  c.move_master(10);
  EXPECT_TRUE(c.r.tag("i").pc());
  EXPECT_NEAR(c.s(), 4.0 + 2 * 3.0, 1e-9);
}

TEST(Mapc, PendingAfterAPersistentCamOutsideItsRangeWaitsForTheNextExit) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("a", "lin", 1, 1, "persistent", "immediate", 0, 5)), Err::None);
  c.move_master(8);  // outside (profile 13)
  ASSERT_EQ(c.r.exec(PcRig::mapc("b", "step", 1, 1, "once", "pending")), Err::None);
  c.r.step(10);
  EXPECT_TRUE(c.r.tag("a").ip());  // no takeover while it stays outside
  EXPECT_TRUE(c.bit(PositionCamPendingStatus));
  c.move_master(3);  // back inside (profile 8)
  EXPECT_NEAR(c.s(), 6.0, 1e-9);
  c.move_master(6);  // leaves at profile 10 (master 5): the pending cam takes over there
  EXPECT_FALSE(c.r.tag("a").ip());
  EXPECT_TRUE(c.r.tag("a").pc());
  EXPECT_TRUE(c.r.tag("b").ac());
  EXPECT_NEAR(c.s(), 10.0 + 1.0, 1e-9);
}

TEST(Mapc, SecondPendingOverlaysTheFirst) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("a", "step", 1, 1, "once", "immediate")), Err::None);
  ASSERT_EQ(c.r.exec(PcRig::mapc("p1", "lin", 1, 1, "once", "pending")), Err::None);
  ASSERT_EQ(c.r.exec(PcRig::mapc("p2", "step", 1, 1, "once", "pending")), Err::None);
  EXPECT_FALSE(c.r.tag("p1").ip());
  c.move_master(9);
  EXPECT_TRUE(c.r.tag("p2").pc());
  EXPECT_NEAR(c.s(), 8.0, 1e-9);
}

// ------------------------------------------------------------ master direction
TEST(Mapc, ForwardOnlyMasterDirectionIsASlipClutch) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "immediate", 0, 0, "command", "forwardonly")), Err::None);
  c.move_master(3);
  ASSERT_EQ(c.r.exec(mam("M", "back", 0, 1, 2, 1e5, 1e5)), Err::None);
  c.r.step(100);
  EXPECT_FALSE(c.bit(PositionCamLockStatus));  // slipping
  EXPECT_EQ(c.r.axis("S").command_velocity, 0.0);
  c.r.step_until([&] { return c.r.tag("back").pc(); });
  EXPECT_NEAR(c.s(), 6.0, 1e-9);  // did not back up
  c.move_master(3);
  EXPECT_TRUE(c.bit(PositionCamLockStatus));
  EXPECT_NEAR(c.s(), 2 * (3 + 2), 1e-9);
}

TEST(Mapc, ReverseOnlyMasterDirectionFollowsOnlyReverseMotion) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "immediate", 0, 10, "command", "reverseonly")), Err::None);
  c.move_master(4);
  EXPECT_EQ(c.s(), 0.0);
  c.move_master(1);
  EXPECT_NEAR(c.s(), -6.0, 1e-9);
}

// ------------------------------------------------------------ master reference
TEST(Mapc, MasterReferenceActualFollowsTheDriveFeedback) {
  PcRig c(AxisType::CipDrive);
  c.r.fb[1].position = 1.0;
  c.r.step();
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "immediate", 0, 0, "actual")), Err::None);
  for (int i = 1; i <= 100; ++i) {
    c.r.fb[1].position = 1.0 + 0.02 * i;
    c.r.fb[1].velocity = 20.0;
    c.r.step();
  }
  EXPECT_NEAR(c.s(), 2 * 2.0, 1e-9);
  EXPECT_NEAR(c.r.axis("S").command_velocity, 40.0, 1e-9);
}

TEST(Mapc, VirtualMasterAlwaysGivesCommandPosition) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "once", "immediate", 0, 0, "actual")), Err::None);
  c.move_master(2);
  EXPECT_NEAR(c.s(), 4.0, 1e-9);
}

// --------------------------------------------------------------------- stops
TEST(Mapc, MasPositionCamStopsItAndReleasesTheProfile) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "continuous", "immediate")), Err::None);
  ASSERT_EQ(c.r.exec(PcRig::mapc("pp", "lin", 1, 1, "once", "pending")), Err::None);
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 5, 1e6, 1e6)), Err::None);
  c.r.step(200);
  // other stop types leave the cam alone
  ASSERT_EQ(c.r.exec("MAS(S, sj, jog, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_TRUE(c.r.tag("pc").ip());
  ASSERT_EQ(c.r.exec("MAS(S, s, positioncam, yes, 100, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(c.r.tag("pc").ip());
  EXPECT_FALSE(c.r.tag("pp").ip());  // the pending cam goes too
  EXPECT_FALSE(c.bit(PositionCamStatus));
  EXPECT_FALSE(c.bit(PositionCamPendingStatus));
  EXPECT_TRUE(c.bit(StoppingStatus));
  EXPECT_EQ(c.lin.status(), 2);
  c.r.step_until([&] { return c.r.tag("s").pc(); });
  EXPECT_EQ(c.r.axis("S").command_velocity, 0.0);
  EXPECT_NEAR(c.s(), 2.0 + 10.0 * 10.0 / (2 * 100), 1e-3);  // 10 u/s at 100 u/s^2 stops in 0.5
}

TEST(Mapc, MasAllMgsMasdAndServoOffEndIt) {
  const char* stops[] = {"MAS(S, s, all, no, 0, unitspersec2, no, 0, unitspersec3);", "MGS(g, s, faststop);",
                         "MASD(S, s);", "MSF(S, s);"};
  for (const char* stop : stops) {
    PcRig c;
    ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "continuous", "immediate")), Err::None);
    ASSERT_EQ(c.r.exec(maj("M", "j", 0, 5, 1e6, 1e6)), Err::None);
    c.r.step(100);
    ASSERT_EQ(c.r.exec(stop), Err::None) << stop;
    EXPECT_FALSE(c.r.tag("pc").ip()) << stop;
    EXPECT_FALSE(c.r.tag("pc").ac()) << stop;
    EXPECT_FALSE(c.bit(PositionCamStatus)) << stop;
    EXPECT_EQ(c.lin.status(), 2) << stop;
  }
}

TEST(Mapc, MergingMoveEndsTheCam) {
  PcRig c;
  ASSERT_EQ(c.r.exec(PcRig::mapc("pc", "lin", 1, 1, "continuous", "immediate")), Err::None);
  c.move_master(1);
  ASSERT_EQ(c.r.exec(mam("S", "mv", 1, 1, 10, 1000, 1000, "trapezoidal", 100, 100, "%oftime", "enabled")), Err::None);
  EXPECT_FALSE(c.r.tag("pc").ip());
  EXPECT_EQ(c.lin.status(), 2);
}

// -------------------------------------------------------------------- errors
TEST(Mapc, Errors) {
  PcRig c;
  EXPECT_EQ(c.r.exec(PcRig::mapc("e", "uncalc", 1, 1, "once", "immediate")), Err::CamProfileNotCalculated);
  EXPECT_EQ(c.r.tag("e").err, 32);
  EXPECT_TRUE(c.r.tag("e").er());
  EXPECT_EQ(c.uncalc.status(), 0);
  EXPECT_EQ(c.r.exec(PcRig::mapc("e", "lin", 1, 1, "once", "immediate", 0, 0, "command", "bidirectional", "same", "S",
                                 "S")),
            Err::MasterAxisConflict);
  EXPECT_EQ(c.r.tag("e").err, 10);
  // operand values (ERR 13, EXERR = ST operand index)
  const struct { std::string text; int exerr; } bad[] = {
      {PcRig::mapc("e", "lin", 1, 0, "once", "immediate"), 6},     // MasterScaling 0
      {PcRig::mapc("e", "lin", 1, -2, "once", "immediate"), 6},    // MasterScaling < 0
      {PcRig::mapc("e", "lin", 1, 1, "once", "immediate", 0, 11), 10},   // CamLockPosition past the end
      {PcRig::mapc("e", "lin", 1, 1, "once", "immediate", 0, -1), 10},   // before the start
  };
  for (const auto& b : bad) {
    EXPECT_EQ(c.r.exec(b.text), Err::ParameterOutOfRange) << b.text;
    EXPECT_EQ(c.r.tag("e").exerr, b.exerr) << b.text;
  }
  // enumeration numbers out of range (the ST parser refuses them in text; a
  // numeric tag or a request built elsewhere can still carry them)
  const struct { int operand; double value; } bad_enum[] = {
      {3, 4}, {3, -1}, {7, 3}, {8, 5}, {11, 2}, {12, 3}, {12, 0.5}};
  for (const auto& b : bad_enum) {
    Request q = c.r.req(PcRig::mapc("e", "lin", 1, 1, "once", "immediate"));
    q.op[static_cast<std::size_t>(b.operand)].value = b.value;
    EXPECT_EQ(c.r.p->execute(q), Err::ParameterOutOfRange) << b.operand;
    EXPECT_EQ(c.r.tag("e").exerr, b.operand);
  }
  // Direction may be a numeric tag
  c.r.sym.numeric_tags["dirtag"] = 7;
  EXPECT_EQ(c.r.exec("MAPC(S, M, e, dirtag, lin[0], 1, 1, once, immediate, 0, 0, command, bidirectional);"),
            Err::ParameterOutOfRange);
  EXPECT_EQ(c.r.tag("e").exerr, 3);
  EXPECT_EQ(c.lin.status(), 2);  // nothing acquired by a refused MAPC
  // slave scaling 0 is allowed (no motion)
  EXPECT_EQ(c.r.exec(PcRig::mapc("z", "lin", 0, 1, "once", "immediate")), Err::None);
  // immediate (and the lock schedules) on an axis already position camming
  EXPECT_EQ(c.r.exec(PcRig::mapc("e", "lin", 1, 1, "once", "immediate")), Err::IllegalDynamicChange);
  EXPECT_EQ(c.r.exec(PcRig::mapc("e", "lin", 1, 1, "once", "forwardonly")), Err::IllegalDynamicChange);
  EXPECT_EQ(c.r.tag("e").err, 23);
  EXPECT_TRUE(c.r.tag("z").ip());  // the active cam is untouched
  // a pending cam must continue the active cam's master
  AxisConfig v;
  c.r.add_axis("N", v);
  EXPECT_EQ(c.r.exec(PcRig::mapc("e", "lin", 1, 1, "once", "pending", 0, 0, "command", "bidirectional", "same", "S",
                                 "N")),
            Err::MasterAxisConflict);
}

TEST(Mapc, AxisStateErrors) {
  PcRig c;
  AxisConfig off;
  off.configured = false;
  c.r.add_axis("U", off);
  AxisConfig inh;
  inh.inhibited = true;
  c.r.add_axis("I", inh);
  AxisConfig v;
  c.r.add_axis("Q", v);  // servo off
  auto m = [](const std::string& slave, const std::string& master) {
    return PcRig::mapc("e", "lin", 1, 1, "once", "immediate", 0, 0, "command", "bidirectional", "same", slave, master);
  };
  EXPECT_EQ(c.r.exec(m("S", "U")), Err::AxisNotConfigured);  // master not configured
  EXPECT_EQ(c.r.tag("e").err, 11);
  EXPECT_EQ(c.r.exec(m("S", "I")), Err::AxisIsInhibited);
  EXPECT_EQ(c.r.exec(m("U", "M")), Err::AxisNotConfigured);
  EXPECT_EQ(c.r.exec(m("Q", "M")), Err::ServoOffState);
  EXPECT_EQ(c.r.tag("e").err, 5);
  // circular: M already follows S (gear), so S may not cam on M
  ASSERT_EQ(c.r.exec("MAG(M, S, g1, same, 1, 1, 1, command, real, disabled, 0, unitspersec2);"), Err::None);
  EXPECT_EQ(c.r.exec(m("S", "M")), Err::MasterAxisConflict);
  // while stopping
  ASSERT_EQ(c.r.exec("MAS(M, sg, gear, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  ASSERT_EQ(c.r.exec(maj("S", "js", 0, 50)), Err::None);
  c.r.step(100);
  ASSERT_EQ(c.r.exec("MAS(S, sj, jog, yes, 10, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_EQ(c.r.exec(m("S", "M")), Err::NotAllowedWhileStopping);
}

// ----------------------------------------------------------------- property
// slave == base + dir * SlaveScaling * (P(unwound cam coordinate) - P(CamLockPosition) + passes * slave span)
// for random master trajectories (actual feedback of a CIP master), random
// scaling, lock position, direction and profile, bidirectional continuous.
TEST(MapcProperty, SlaveEqualsScaledProfileOfTheMaster) {
  const char* env_seed = std::getenv("MAPC_SEED");
  const char* env_count = std::getenv("MAPC_COUNT");
  const unsigned seed = env_seed ? static_cast<unsigned>(std::strtoul(env_seed, nullptr, 10)) : 20261121u;
  const int count = env_count ? std::atoi(env_count) : 30;
  std::mt19937 rng(seed);
  for (int n = 0; n < count; ++n) {
    SCOPED_TRACE("MAPC_SEED=" + std::to_string(seed) + " case " + std::to_string(n));
    PcRig c(AxisType::CipDrive);
    std::uniform_real_distribution<double> U(0, 1);
    const bool cubic = U(rng) < 0.5;
    const cam::CamProfile& prof = cubic ? c.cub : c.lin;
    // three decimals: the ST text carries them exactly
    auto r3 = [&](double v) { return std::round(v * 1000) / 1000; };
    const double ss = r3(-3 + 6 * U(rng)), ms = r3(0.2 + 3 * U(rng)), clp = r3(10 * U(rng));
    const bool opposite = U(rng) < 0.5;
    const bool once = U(rng) < 0.3;
    double mpos = -5 + 10 * U(rng);
    c.r.fb[1].position = mpos;
    c.r.step();
    const double s0 = c.s();
    ASSERT_EQ(c.r.exec(PcRig::mapc("pc", cubic ? "cub" : "lin", ss, ms, once ? "once" : "continuous", "immediate", 0,
                                   clp, "actual", "bidirectional", opposite ? "opposite" : "same")),
              Err::None);
    const double m0 = mpos;
    const double L = prof.master_span(), D = prof.slave_span();
    double worst = 0;
    for (int i = 0; i < 2000 && !c.r.tag("pc").pc(); ++i) {
      mpos += (U(rng) - 0.45) * 0.05 * ms;  // a random walk, drifting forward
      c.r.fb[1].position = mpos;
      c.r.step();
      if (c.r.tag("pc").pc()) break;
      const double v = clp + (mpos - m0) / ms;
      const double p = std::floor(v / L);
      const double y = prof.evaluate(v - p * L).position - prof.evaluate(clp).position + p * D;
      const double expect = s0 + (opposite ? -1 : 1) * ss * y;
      worst = std::max(worst, std::fabs(c.s() - expect));
    }
    EXPECT_LE(worst, 1e-9);
  }
}

// --------------------------------------------------------------- ST binding
// Every MAPC enumeration keyword binds to its number, case-insensitively, and
// the numbers bind to the same request.
TEST(MapcParse, KeywordsAndNumbersBindAlike) {
  PcRig c;
  const struct { const char* kw; const char* num; } forms[] = {
      {"MAPC(S, M, k, same, lin[0], 1.5, 2, once, immediate, 1, 2, actual, bidirectional);",
       "MAPC(S, M, k, 0, lin[0], 1.5, 2, 0, 0, 1, 2, 0, 0);"},
      {"mapc(S, M, k, Opposite, lin[0], -1, 0.5, Continuous, Pending, -3, 4, Command, ForwardOnly);",
       "MAPC(S, M, k, 1, lin[0], -1, 0.5, 1, 1, -3, 4, 1, 1);"},
      {"MAPC(S, M, k, REVERSE, lin[0], 1, 1, PERSISTENT, FORWARDONLY, 0, 0, command, REVERSEONLY);",
       "MAPC(S, M, k, 2, lin[0], 1, 1, 2, 2, 0, 0, 1, 2);"},
      {"MAPC(S, M, k, unchanged, lin[0], 1, 1, once, reverseonly, 0, 0, command, bidirectional);",
       "MAPC(S, M, k, 3, lin[0], 1, 1, 0, 3, 0, 0, 1, 0);"},
      {"MAPC(S, M, k, same, lin[0], 1, 1, once, bidirectional, 0, 0, command, bidirectional);",
       "MAPC(S, M, k, 0, lin[0], 1, 1, 0, 4, 0, 0, 1, 0);"},
  };
  for (const auto& f : forms) {
    const Request a = c.r.req(f.kw), b = c.r.req(f.num);
    ASSERT_EQ(a.instr, Instr::MAPC) << f.kw;
    ASSERT_EQ(a.count, 13) << f.kw;
    ASSERT_EQ(b.count, 13) << f.num;
    for (std::size_t i = 0; i < 13; ++i) {
      EXPECT_EQ(a.op[i].value, b.op[i].value) << f.kw << " operand " << i;
      EXPECT_EQ(a.op[i].ref, b.op[i].ref) << f.kw << " operand " << i;
    }
  }
  // wrong operand counts and unknown keywords are refused by the parser/binder
  Request q;
  EXPECT_TRUE(parse_and_bind("MAPC(S, M, k, same, lin[0], 1, 1, twice, immediate, 0, 0, command, bidirectional);",
                             c.r.sym, q)
                  .has_value());
  EXPECT_TRUE(parse_and_bind("MAPC(S, M, k, same, lin[0], 1, 1, once, immediate, 0, 0, command);", c.r.sym, q)
                  .has_value());
}

// Circular through a master-driven time cam: M cams on S's travel (MDAC Time
// Cam link + MATC master driven), so S may not position-cam on M.
TEST(Mapc, MasterFollowingTheSlaveThroughAMasterDrivenCamIsAConflict) {
  PcRig c;
  ASSERT_EQ(c.r.exec("MDAC(M, S, md1, timecam, command);"), Err::None);
  ASSERT_EQ(c.r.exec("MATC(M, mt1, same, lin[0], 1, 1, continuous, immediate, 0, immediateforwardonly, "
                     "masterdrivenmode);"),
            Err::None);
  ASSERT_TRUE(c.r.tag("mt1").ip());
  EXPECT_EQ(c.r.exec(PcRig::mapc("e", "lin", 1, 1, "once", "immediate")), Err::MasterAxisConflict);
  EXPECT_EQ(c.lin.status(), 3) << "only the MATC uses the profile: the refused MAPC acquired nothing";
}
