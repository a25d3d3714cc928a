// MDAC (Master Driven Axis Control) and master-driven MAM/MAJ, issue 5, from
// seed 000: All conflicts, pending master queue, what breaks the link, AC bit,
// lock directions, units per master unit and master units.
#include <gtest/gtest.h>

#include <cmath>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::maj;
using canmotion::motion::test::mam;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cfg() { return canmotion::motion::test::axis_cfg(1000, 10000); }

Rig rig3() {
  Rig r;
  r.add_axis("X", cfg());
  r.add_axis("Y", cfg());
  r.add_axis("Z", cfg());
  for (const char* a : {"X", "Y", "Z"}) EXPECT_EQ(r.exec(std::string("MSO(") + a + ", on" + a + ");"), Err::None);
  r.step();
  return r;
}

/// Master-driven incremental MAM: speed in units per master unit.
std::string md_mam(const std::string& ax, const std::string& c, double dist, double ratio, double acc,
                   const std::string& lock = "immediateforwardonly", double lockpos = 0) {
  return "MAM(" + ax + "," + c + ",incremental," + std::to_string(dist) + "," + std::to_string(ratio) +
         ",unitspermasterunit," + std::to_string(acc) + ",unitspermasterunit2," + std::to_string(acc) +
         ",unitspermasterunit2,trapezoidal,0,0,unitspermasterunit3,disabled,programmed," + std::to_string(lockpos) +
         "," + lock + ",0,0);";
}

/// For `cycles` cycles, the axis moves between lo and hi per cycle (no jump,
/// no stop).
void expect_steps_between(Rig& r, const char* ax, int cycles, double lo, double hi) {
  double prev = r.axis(ax).command_position;
  for (int i = 0; i < cycles; ++i) {
    r.step();
    const double p = r.axis(ax).command_position;
    EXPECT_GE(p - prev, lo - 1e-9) << ax << " cycle " << i;
    EXPECT_LE(p - prev, hi + 1e-9) << ax << " cycle " << i;
    prev = p;
  }
}

}  // namespace

TEST(Mdac, LinkBitsAndMasterDrivenMoveFollowsMasterTravel) {
  Rig r = rig3();
  EXPECT_EQ(r.exec("MDAC(Z, X, mdac1, move, command);"), Err::None);
  EXPECT_TRUE(r.tag("mdac1").dn());
  EXPECT_TRUE(r.tag("mdac1").ip());
  EXPECT_FALSE(r.tag("mdac1").ac());
  r.step();
  EXPECT_TRUE(r.axis("Z").motion(motion_status::CoordinatedMotionStatus));
  // slave: 10 units at 0.5 units per master unit, accel 1 unit/mu^2
  ASSERT_EQ(r.exec(md_mam("Z", "m", 10, 0.5, 1)), Err::None);
  EXPECT_TRUE(r.tag("mdac1").ac());  // AC: a move went IP in master-driven mode
  EXPECT_TRUE(r.tag("m").ip());
  r.step(100);
  EXPECT_EQ(r.axis("Z").command_position, 0.0);  // master at rest: slave waits
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.step(1);
  r.step(300);  // master travels 3 units
  EXPECT_TRUE(r.axis("Z").motion(motion_status::MoveLockStatus));
  // trapezoid over master travel: 0.5 u/mu reached after 0.5 mu of master travel
  EXPECT_NEAR(r.axis("Z").command_velocity, 0.5 * 10, 1e-6);
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_NEAR(r.axis("Z").command_position, 10.0, 1e-9);
  EXPECT_FALSE(r.tag("mdac1").ac());  // the master-driven motion ended
  EXPECT_TRUE(r.tag("mdac1").ip());   // the link stays
  // 10 units at 0.5 u/mu with 0.5 mu ramps each side: 20.5 master units
  EXPECT_NEAR(r.axis("X").command_position, 20.5, 0.02);
}

TEST(Mdac, ForwardOnlySlaveStopsWhenTheMasterReverses) {
  Rig r = rig3();
  r.exec("MDAC(Z, X, l, jog, command);");
  r.exec("MAJ(Z, j, forward, 1, unitspermasterunit, 100, unitspermasterunit2, 100, unitspermasterunit2, trapezoidal, 0, 0, unitspermasterunit3, disabled, programmed, 0, immediateforwardonly);");
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.step(200);
  EXPECT_TRUE(r.axis("Z").motion(motion_status::JogLockStatus));
  EXPECT_NEAR(r.axis("Z").command_velocity, 10.0, 1e-6);
  r.exec(maj("X", "jx2", 1, 10, 1e6, 1e6));  // master reverses
  r.step(5);
  const double z = r.axis("Z").command_position;
  r.step(100);
  EXPECT_EQ(r.axis("Z").command_position, z);  // does not back up
  EXPECT_FALSE(r.axis("Z").motion(motion_status::JogLockStatus));
  r.exec(maj("X", "jx3", 0, 10, 1e6, 1e6));  // forward again: resumes
  r.step(50);
  EXPECT_GT(r.axis("Z").command_position, z);
  EXPECT_TRUE(r.axis("Z").motion(motion_status::JogLockStatus));
}

TEST(Mdac, PositionLockStartsWhenTheMasterCrossesIt) {
  Rig r = rig3();
  r.exec("MDAC(Z, X, l, move, command);");
  r.exec(md_mam("Z", "m", 5, 1, 100, "positionforwardonly", 2.0));
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.step(150);  // master at ~1.5
  EXPECT_EQ(r.axis("Z").command_position, 0.0);
  EXPECT_FALSE(r.axis("Z").motion(motion_status::MoveLockStatus));
  r.step(100);  // master at ~2.5: 0.5 units past the lock
  EXPECT_TRUE(r.axis("Z").motion(motion_status::MoveLockStatus));
  EXPECT_GT(r.axis("Z").command_position, 0.3);
}

TEST(Mdac, MasterUnitsMoveCoversItsDistanceOverTheGivenMasterTravel) {
  Rig r = rig3();
  r.exec("MDAC(Z, X, l, move, command);");
  // 6 units over 12 master units, with 2 master units of accel and decel
  ASSERT_EQ(r.exec("MAM(Z,m,incremental,6,12,masterunits,2,masterunits,2,masterunits,trapezoidal,0,0,masterunits,disabled,programmed,0,immediateforwardonly,0,0);"),
            Err::None);
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_NEAR(r.axis("Z").command_position, 6.0, 1e-9);
  EXPECT_NEAR(r.axis("X").command_position, 12.0, 0.02);
}

TEST(Mdac, AllConflictsAndErrors) {
  Rig r = rig3();
  ASSERT_EQ(r.exec("MDAC(Y, X, a1, move, command);"), Err::None);
  // MDAC Move=MAM Master=X Slave=Y, then MDAC All Master=Z Slave=Y: error [seed 000]
  EXPECT_EQ(r.exec("MDAC(Y, Z, a2, all, command);"), Err::MdscMdacAllConflict);
  EXPECT_EQ(r.tag("a2").err, 96);
  EXPECT_TRUE(r.tag("a1").ip());
  Rig r2 = rig3();
  ASSERT_EQ(r2.exec("MDAC(Y, X, b1, all, command);"), Err::None);
  EXPECT_EQ(r2.exec("MDAC(Y, X, b2, jog, command);"), Err::MdscMdacAllConflict);
  EXPECT_EQ(r2.exec("MDAC(Y, Y, b3, move, command);"), Err::MasterAxisConflict);
  // master-driven units without a link for that motion type
  Rig r3 = rig3();
  r3.exec("MDAC(Y, X, c1, jog, command);");
  EXPECT_EQ(r3.exec(md_mam("Y", "m", 1, 1, 1)), Err::MdscNotActivated);
  // lock direction none in master-driven mode
  r3.exec("MDAC(Y, X, c2, move, command);");
  EXPECT_EQ(r3.exec(md_mam("Y", "m", 1, 1, 1, "none")), Err::MdscLockDirConflict);
  EXPECT_EQ(r3.tag("m").err, 95);
}

TEST(Mdac, PendingMasterTakesOverAtTheNextMotion) {
  // [seed 000] MDAC Move Master=X Slave=Z; MAM Z; MDAC Move Master=Y Slave=Z -> pending; MAM Z uses Y
  Rig r = rig3();
  r.exec("MDAC(Z, X, d1, move, command);");
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.exec(md_mam("Z", "m1", 2, 1, 100));
  r.step(100);
  EXPECT_GT(r.axis("Z").command_position, 0.5);
  ASSERT_EQ(r.exec("MDAC(Z, Y, d2, move, command);"), Err::None);
  EXPECT_TRUE(r.tag("d1").ip());  // both in process,
  EXPECT_TRUE(r.tag("d2").ip());
  EXPECT_TRUE(r.tag("d1").ac());  // only the active one is AC
  EXPECT_FALSE(r.tag("d2").ac());
  r.step_until([&] { return r.tag("m1").pc(); });
  ASSERT_EQ(r.exec(md_mam("Z", "m2", 2, 1, 100)), Err::None);  // goes IP: Y becomes the master
  EXPECT_FALSE(r.tag("d1").ip());
  EXPECT_TRUE(r.tag("d2").ac());
  const double z = r.axis("Z").command_position;
  r.step(100);  // X moves, Y does not: the slave waits for Y
  EXPECT_EQ(r.axis("Z").command_position, z);
  r.exec(maj("Y", "jy", 0, 10, 1e6, 1e6));
  r.step(100);
  EXPECT_GT(r.axis("Z").command_position, z);
}

TEST(Mdac, WhatBreaksTheLink) {
  {  // MAS All on the slave breaks it; MAS Move only clears AC
    Rig r = rig3();
    r.exec("MDAC(Z, X, l, move, command);");
    r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
    r.exec(md_mam("Z", "m", 100, 1, 100));
    r.step(50);
    r.exec("MAS(Z, s1, move, no, 0, unitspersec2, no, 0, unitspersec3);");
    EXPECT_FALSE(r.tag("l").ac());
    EXPECT_TRUE(r.tag("l").ip());
    r.step_until([&] { return r.tag("s1").pc(); });
    r.exec("MAS(Z, s2, all, no, 0, unitspersec2, no, 0, unitspersec3);");
    EXPECT_FALSE(r.tag("l").ip());
    EXPECT_FALSE(r.axis("Z").motion(motion_status::CoordinatedMotionStatus));
  }
  {  // MAS of any type on the master does not; MASD on the master does
    Rig r = rig3();
    r.exec("MDAC(Z, X, l, all, command);");
    r.exec("MAS(X, s, all, no, 0, unitspersec2, no, 0, unitspersec3);");
    EXPECT_TRUE(r.tag("l").ip());
    r.exec("MASD(X, sd);");
    EXPECT_FALSE(r.tag("l").ip());
  }
  {  // MGS on the slave's group
    Rig r = rig3();
    r.exec("MDAC(Z, X, l, jog, command);");
    r.exec("MGS(g, gs, faststop);");
    EXPECT_FALSE(r.tag("l").ip());
  }
}

TEST(Mdac, MasterReferenceChangeOfAMovingSlaveErrs) {
  Rig r;
  AxisConfig m = cfg();
  m.type = AxisType::CipDrive;
  r.add_axis("M", m);
  r.add_axis("S", cfg());
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(M, a);");
  r.exec("MSO(S, b);");
  r.step();
  ASSERT_EQ(r.exec("MDAC(S, M, l1, jog, command);"), Err::None);
  r.exec(maj("S", "j", 0, 10));  // slave moving (time driven)
  r.step(10);
  EXPECT_EQ(r.exec("MDAC(S, M, l2, jog, actual);"), Err::MdscInvalidModeOrMasterChange);
  EXPECT_TRUE(r.tag("l1").ip());  // the original stays
}

// Issue 16 item 1. MCD changes the dynamics of "the active jog or move on the
// fly" [RM002H p.142]; in Master Driven mode the speed of a move is in units
// per master unit, so an MCD in those units re-plans it over master travel.
// Switching modes with a change-dynamics instruction is refused: "A runtime
// MDSC_INVALID_MODE_OR_MASTER_CHANGE error will occur if you attempt to change
// from Master Driven Mode to Time Driven Mode or vice versa with an MCCD
// instruction" [seed 001]: MCD follows its coordinated counterpart (ERR 105).
TEST(Mdac, McdOnAMasterDrivenMoveReplansPerMasterUnitWithoutAJump) {
  Rig r = rig3();
  ASSERT_EQ(r.exec("MDAC(Z, X, l, move, command);"), Err::None);
  ASSERT_EQ(r.exec(md_mam("Z", "m", 1000, 0.5, 10)), Err::None);
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.step(500);  // the master runs at 10 u/s, the slave at 0.5 u/mu = 5 u/s
  ASSERT_NEAR(r.axis("Z").command_velocity, 5.0, 1e-6);
  const std::string mcd =
      "MCD(Z, c1, move, yes, 1.0, no, 0, no, 0, no, 0, no, 0, unitspermasterunit, unitspermasterunit2, "
      "unitspermasterunit2, unitspermasterunit3);";
  ASSERT_EQ(r.exec(mcd), Err::None) << r.tag("c1").err;
  EXPECT_TRUE(r.tag("c1").dn());
  // 0.5 -> 1.0 u/mu at 10 u/mu^2: 0.05 mu = 5 ms of master travel; no jump:
  // the slave moves at most what 1.0 u/mu of the master's 0.01 u per cycle gives
  expect_steps_between(r, "Z", 100, 0.005, 0.010);
  EXPECT_NEAR(r.axis("Z").command_velocity, 10.0, 1e-6);  // 1.0 u/mu x 10 u/s
  EXPECT_TRUE(r.tag("m").ip());
  // time-driven units on the master-driven move: a mode change, refused; the
  // move keeps its speed
  ASSERT_EQ(r.exec("MCD(Z, c2, move, yes, 3, no, 0, no, 0, no, 0, no, 0, unitspersec, unitspersec2, unitspersec2, "
                   "unitspersec3);"),
            Err::MdscInvalidModeOrMasterChange);
  EXPECT_EQ(r.tag("c2").err, 105);
  r.step(10);
  EXPECT_NEAR(r.axis("Z").command_velocity, 10.0, 1e-6);
  // and the reverse: master-driven units on a time-driven jog
  ASSERT_EQ(r.exec(maj("Y", "jy", 0, 10, 1e6, 1e6)), Err::None);
  ASSERT_EQ(r.exec("MCD(Y, c3, jog, yes, 1.0, no, 0, no, 0, no, 0, no, 0, unitspermasterunit, unitspermasterunit2, "
                   "unitspermasterunit2, unitspermasterunit3);"),
            Err::MdscInvalidModeOrMasterChange);
}

// Issue 16 item 1, the jog: MCD changes "the active jog or move on the fly"
// [RM002H p.142]; a master-driven jog (MDAC ... jog, MAJ in units per master
// unit) is re-planned in units per master unit, without a jump, and
// time-driven units on it are a mode change (ERR 105, as MCCD [seed 001]).
TEST(Mdac, McdOnAMasterDrivenJogReplansPerMasterUnitWithoutAJump) {
  Rig r = rig3();
  ASSERT_EQ(r.exec("MDAC(Z, X, l, jog, command);"), Err::None);
  ASSERT_EQ(r.exec("MAJ(Z, j, forward, 0.5, unitspermasterunit, 10, unitspermasterunit2, 10, unitspermasterunit2, "
                   "trapezoidal, 0, 0, unitspermasterunit3, disabled, programmed, 0, immediateforwardonly);"),
            Err::None)
      << r.tag("j").err;
  r.exec(maj("X", "jx", 0, 10, 1e6, 1e6));
  r.step(500);  // the master runs at 10 u/s, the slave jogs at 0.5 u/mu = 5 u/s
  ASSERT_NEAR(r.axis("Z").command_velocity, 5.0, 1e-6);
  ASSERT_EQ(r.exec("MCD(Z, c1, jog, yes, 1.0, no, 0, no, 0, no, 0, no, 0, unitspermasterunit, unitspermasterunit2, "
                   "unitspermasterunit2, unitspermasterunit3);"),
            Err::None)
      << r.tag("c1").err;
  EXPECT_TRUE(r.tag("c1").dn());
  // 0.5 -> 1.0 u/mu at 10 u/mu^2 over the master's 0.01 u per cycle: no jump
  expect_steps_between(r, "Z", 100, 0.005, 0.010);
  EXPECT_NEAR(r.axis("Z").command_velocity, 10.0, 1e-6);  // 1.0 u/mu x 10 u/s
  EXPECT_TRUE(r.tag("j").ip());
  ASSERT_EQ(r.exec("MCD(Z, c2, jog, yes, 3, no, 0, no, 0, no, 0, no, 0, unitspersec, unitspersec2, unitspersec2, "
                   "unitspersec3);"),
            Err::MdscInvalidModeOrMasterChange);
  EXPECT_EQ(r.tag("c2").err, 105);
  r.step(10);
  EXPECT_NEAR(r.axis("Z").command_velocity, 10.0, 1e-6);
}

// Issue 16 item 4. "A mode change (Rem Run to Rem Prog or Rem Prog to Rem Run)
// or an axis fault also breaks the MDAC link"; on the master "MASD, MCSD, and
// MGSD ... MAS and MCS for any Stop Type, including All, do NOT break the MDAC
// link" [seed 000]. An axis fault here is an exception whose action faults or
// stops the axis: on the slave Stop Planner (a stop of all planned motion, as
// MAS All), Stop Drive and Shutdown break its links; on the master Stop Drive
// and Shutdown (the axis is faulted, as MASD) break its slaves' links, Stop
// Planner (a stop, as MAS on the master) does not. Fault Status Only "set[s]
// the associated bit ... but [does] otherwise not affect axis behavior"
// [seed 002]: no link is broken. Triggered by a soft overtravel of the slave Y
// or the master X, with each action configured for it.
TEST(Mdac, FaultsBreakTheLinksByActionAndSide) {
  struct Case {
    const char* axis;
    ExceptionAction action;
    bool breaks;
  };
  const Case cases[] = {
      {"Y", ExceptionAction::FaultStatusOnly, false}, {"Y", ExceptionAction::StopPlanner, true},
      {"Y", ExceptionAction::StopDrive, true},        {"Y", ExceptionAction::Shutdown, true},
      {"X", ExceptionAction::FaultStatusOnly, false}, {"X", ExceptionAction::StopPlanner, false},
      {"X", ExceptionAction::StopDrive, true},        {"X", ExceptionAction::Shutdown, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.axis) + " action " + std::to_string(static_cast<int>(c.action)));
    Rig r;
    for (const char* a : {"X", "Y"}) {
      AxisConfig k = cfg();
      if (std::string(a) == c.axis) {
        k.soft_limits_enabled = true;
        k.soft_limit_pos = 0.5;
        k.soft_limit_neg = -1e6;
        k.exception_actions[static_cast<std::size_t>(ExceptionKind::SoftOvertravelPos)] = c.action;
      }
      r.add_axis(a, k);
      ASSERT_EQ(r.exec(std::string("MSO(") + a + ", on" + a + ");"), Err::None);
    }
    r.step();
    ASSERT_EQ(r.exec("MDAC(Y, X, l, all, command);"), Err::None);
    ASSERT_EQ(r.exec(maj(c.axis, "j", 0, 10, 1e6, 1e6)), Err::None);
    r.step(200);  // 2 units: past the soft limit
    ASSERT_NE(r.axis(c.axis).axis_fault, 0u);  // the exception happened
    EXPECT_EQ(r.tag("l").ip(), !c.breaks);
    // a broken link can be given to another master at once; a kept one is an All conflict
    r.add_axis("Z", cfg());
    const bool y_shut_down = std::string(c.axis) == "Y" && c.action == ExceptionAction::Shutdown;  // ERR 7 first
    if (!y_shut_down) {
      EXPECT_EQ(r.exec("MDAC(Y, Z, l2, move, command);"), c.breaks ? Err::None : Err::MdscMdacAllConflict);
    }
  }
}

// Issue 16 item 5. "An error is generated if a MDAC instruction is executed
// that changes the Master Reference of a slave axis that is in motion. The new
// MDAC instruction will error and the original one will remain active"
// [seed 000]: also when the new MDAC names another master (it would otherwise
// be queued silently with the other reference). The same reference with
// another master is queued as before.
TEST(Mdac, MasterReferenceChangeWithAnotherMasterOfAMovingSlaveErrs) {
  Rig r;
  AxisConfig m = cfg();
  m.type = AxisType::CipDrive;
  r.add_axis("M", m);
  r.add_axis("N", m);
  r.add_axis("S", cfg());
  r.fb[0].drive = r.fb[1].drive = DriveState::Enabled;
  for (const char* a : {"M", "N", "S"}) ASSERT_EQ(r.exec(std::string("MSO(") + a + ", on" + a + ");"), Err::None);
  r.step();
  ASSERT_EQ(r.exec("MDAC(S, M, l1, jog, command);"), Err::None);
  r.exec(maj("S", "j", 0, 10));  // slave moving (time driven)
  r.step(10);
  EXPECT_EQ(r.exec("MDAC(S, N, l2, jog, actual);"), Err::MdscInvalidModeOrMasterChange);
  EXPECT_EQ(r.tag("l2").err, 105);
  EXPECT_FALSE(r.tag("l2").ip());
  EXPECT_TRUE(r.tag("l1").ip());  // the original stays
  // the same reference with another master: queued (both IP) [seed 000]
  EXPECT_EQ(r.exec("MDAC(S, N, l3, jog, command);"), Err::None);
  EXPECT_TRUE(r.tag("l3").ip() && r.tag("l1").ip());
}
