// The worked examples and rules of the seeds, one test per example or rule,
// named after the seed and its section: 000 MDAC, 001 master-driven modes and
// units, 003 MAG, 004 MATC. Each test follows the seed's text step by step.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "motion/cam/cam_profile.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::maj;
using canmotion::motion::test::mam;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cfg() { return canmotion::motion::test::axis_cfg(1000, 1e6); }

/// Virtual axes, servo on, the standard group "g".
Rig rig(std::initializer_list<const char*> axes) {
  Rig r;
  for (const char* a : axes) r.add_axis(a, cfg());
  for (const char* a : axes) EXPECT_EQ(r.exec(std::string("MSO(") + a + ", on" + a + ");"), Err::None);
  r.step();
  return r;
}

/// A jog at `v` units/s with (almost) instant accel; `v` < 0 jogs in reverse.
void jog(Rig& r, const std::string& ax, const std::string& c, double v) {
  ASSERT_EQ(r.exec(maj(ax, c, v < 0 ? 1 : 0, std::fabs(v), 1e6, 1e6)), Err::None);
}

/// A master-driven incremental MAM (ratio in units per master unit).
std::string md_mam(const std::string& ax, const std::string& c, double dist, double ratio, double acc = 1e3) {
  return "MAM(" + ax + "," + c + ",incremental," + std::to_string(dist) + "," + std::to_string(ratio) +
         ",unitspermasterunit," + std::to_string(acc) + ",unitspermasterunit2," + std::to_string(acc) +
         ",unitspermasterunit2,trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0,immediateforwardonly,0,0);";
}
std::string md_maj(const std::string& ax, const std::string& c, double ratio, double acc = 1e3) {
  return "MAJ(" + ax + "," + c + ",forward," + std::to_string(ratio) + ",unitspermasterunit," + std::to_string(acc) +
         ",unitspermasterunit2," + std::to_string(acc) +
         ",unitspermasterunit2,trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0,immediateforwardonly);";
}
std::string matc(const std::string& ax, const std::string& c, const std::string& prof, const std::string& sched,
                 const std::string& mode = "continuous", const std::string& im = "masterdrivenmode",
                 const std::string& lock = "immediateforwardonly", const std::string& dir = "same", double ds = 1,
                 double ts = 1) {
  return "MATC(" + ax + ", " + c + ", " + dir + ", " + prof + "[0], " + std::to_string(ds) + ", " + std::to_string(ts) +
         ", " + mode + ", " + sched + ", 0, " + lock + ", " + im + ");";
}

void calc(cam::CamProfile& p, double rise) {  // linear: 0..1 -> 0..rise
  const std::array<cam::CamPoint, 2> pts{{{0.0, 0.0, 0}, {1.0, rise, 0}}};
  ASSERT_TRUE(cam::mccp(cam::MccpRequest{pts, 0, 2, 0.0, 0.0}, p).ok());
}

double pos(Rig& r, const char* a) { return r.axis(a).command_position; }
double vel(Rig& r, const char* a) { return r.axis(a).command_velocity; }

}  // namespace

// ============================================================ seed 000 MDAC

// "MDAC Move=MAM Master=X Slave=Y ... MDAC Move=ALL Master=Z Slave=Y - Causes an
// error ... assigning the Slave Y axis to any other Master axis causes the same error"
TEST(Seed000Mdac, MotionTypeAllExample) {
  Rig r = rig({"X", "Y", "Z"});
  ASSERT_EQ(r.exec("MDAC(Y, X, a1, move, command);"), Err::None);
  EXPECT_EQ(r.exec("MDAC(Y, Z, a2, all, command);"), Err::MdscMdacAllConflict);
  EXPECT_EQ(r.tag("a2").err, 96);
  EXPECT_EQ(r.exec("MDAC(Y, X, a3, all, command);"), Err::MdscMdacAllConflict);
  EXPECT_TRUE(r.tag("a1").ip());
  // "If there is an active MDAC (All) on a Slave, then setting the MDAC
  // instruction to a Motion Type other than All causes a runtime error."
  Rig s = rig({"X", "Y", "Z"});
  ASSERT_EQ(s.exec("MDAC(Y, X, b1, all, command);"), Err::None);
  for (const char* t : {"move", "jog", "timecam", "masteroffsetmove"}) {
    SCOPED_TRACE(t);
    EXPECT_EQ(s.exec(std::string("MDAC(Y, Z, b2, ") + t + ", command);"), Err::MdscMdacAllConflict);
  }
}

// "To be able to reassign the Master once the All option is used, it is
// sufficient to execute one of the following for either the Slave Axis or the
// Master Axis: Slave MAS (All), MCS (All), MGS, MASD, MCSD, or MGSD; Master
// MASD, MCSD, or MGSD" -- and "MAS (anything other than All) ... do NOT break
// the MDAC link"; "MAS and MCS [on the master] for any Stop Type, including
// All, do NOT break the MDAC link."
TEST(Seed000Mdac, ReassignAfterAllNeedsABreakingInstruction) {
  struct Case {
    const char* what;
    std::vector<std::string> steps;
    bool breaks;
  };
  const std::vector<Case> cases = {
      {"slave MAS all", {"MAS(Y, s, all, no, 0, unitspersec2, no, 0, unitspersec3);"}, true},
      {"slave MGS", {"MGS(g, s, faststop);"}, true},
      {"slave MASD", {"MASD(Y, s);", "MASR(Y, s2);"}, true},
      {"slave MGSD", {"MGSD(g, s);", "MGSR(g, s2);"}, true},
      {"master MASD", {"MASD(X, s);"}, true},
      {"slave MAS move", {"MAS(Y, s, move, no, 0, unitspersec2, no, 0, unitspersec3);"}, false},
      {"slave MAS timecam", {"MAS(Y, s, timecam, no, 0, unitspersec2, no, 0, unitspersec3);"}, false},
      {"master MAS all", {"MAS(X, s, all, no, 0, unitspersec2, no, 0, unitspersec3);"}, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    Rig r = rig({"X", "Y", "Z"});
    ASSERT_EQ(r.exec("MDAC(Y, X, l, all, command);"), Err::None);
    for (const auto& s : c.steps) ASSERT_EQ(r.exec(s), Err::None) << s;
    EXPECT_EQ(r.tag("l").ip(), !c.breaks);
    EXPECT_EQ(r.exec("MDAC(Y, Z, l2, move, command);"), c.breaks ? Err::None : Err::MdscMdacAllConflict);
  }
}

// "The Shutdown instructions (MGSD, MASD, MCSD) never go IP." Issue 16 item
// 10: on moving axes (a stop could have a ramp in process), checked in the
// executing scan and over the cycles after it, and the shutdown must have
// happened (ShutdownStatus, the link broken, the motion ended) so that a
// no-op instruction fails too.
TEST(Seed000Mdac, ShutdownInstructionsNeverGoIp) {
  Rig r = rig({"X", "Y", "Z"});
  ASSERT_EQ(r.exec("MDAC(Y, X, l, all, command);"), Err::None);
  for (const char* a : {"X", "Y", "Z"}) jog(r, a, std::string("j") + a, 10);
  r.step(50);
  ASSERT_NE(vel(r, "Y"), 0.0);
  ASSERT_EQ(r.exec("MASD(Y, sd);"), Err::None);
  EXPECT_TRUE(r.tag("sd").dn());
  EXPECT_FALSE(r.tag("sd").ip());
  EXPECT_FALSE(r.tag("l").ip());  // the link is broken
  EXPECT_FALSE(r.tag("jY").ip());  // the jog ended at once
  for (int i = 0; i < 20; ++i) {
    r.step();
    EXPECT_FALSE(r.tag("sd").ip()) << "cycle " << i;
  }
  EXPECT_TRUE(r.axis("Y").status(axis_status::ShutdownStatus));
  EXPECT_EQ(vel(r, "Y"), 0.0);
  ASSERT_NE(vel(r, "X"), 0.0);
  ASSERT_EQ(r.exec("MGSD(g, gsd);"), Err::None);
  EXPECT_TRUE(r.tag("gsd").dn());
  EXPECT_FALSE(r.tag("gsd").ip());
  for (int i = 0; i < 20; ++i) {
    r.step();
    EXPECT_FALSE(r.tag("gsd").ip()) << "cycle " << i;
  }
  for (const char* a : {"X", "Z"}) {
    EXPECT_TRUE(r.axis(a).status(axis_status::ShutdownStatus)) << a;
    EXPECT_EQ(vel(r, a), 0.0) << a;
  }
}

// "The same Slave axis can be assigned to 2 different Master axes ... X can be
// the Master axis for MAM instructions for Z and Y is the Master axis for MAJ
// instructions for Slave Z."
TEST(Seed000Mdac, SameSlaveTwoMastersPerMotionType) {
  Rig r = rig({"X", "Y", "Z"});
  ASSERT_EQ(r.exec("MDAC(Z, X, lx, move, command);"), Err::None);
  ASSERT_EQ(r.exec("MDAC(Z, Y, ly, jog, command);"), Err::None);
  ASSERT_EQ(r.exec(md_mam("Z", "m", 1000, 1.0)), Err::None);
  ASSERT_EQ(r.exec(md_maj("Z", "j", 0.5)), Err::None);
  EXPECT_TRUE(r.tag("lx").ac() && r.tag("ly").ac());
  jog(r, "X", "jx", 10);
  r.step(100);
  EXPECT_NEAR(vel(r, "Z"), 10.0, 1e-6);  // only the move runs: X moves
  jog(r, "Y", "jy", 4);
  r.step(100);
  EXPECT_NEAR(vel(r, "Z"), 10.0 + 0.5 * 4.0, 1e-6);  // move on X plus jog on Y
}

// "In this example, the masters are already running.
//  MDAC Move=MAM Master=X Slave=Z   Assigns master and slave axis
//  MAM X   Start MAM motion on the master 1
//  MAM Z   Start MAM motion on the slave
//  MAM Y   Start MAM motion on the Y master 2
//  MDAC Move=MAM Master=Y Slave=Z   Y is pending to be the new master
//  MAM Z   Start new MAM motion on the slave using new master 2"
TEST(Seed000Mdac, PendingMasterExample) {
  Rig r = rig({"X", "Y", "Z"});
  ASSERT_EQ(r.exec("MDAC(Z, X, mdac1, move, command);"), Err::None);
  ASSERT_EQ(r.exec(mam("X", "mamx", 1, 1e6, 10, 1e6, 1e6)), Err::None);
  r.step(10);
  ASSERT_EQ(r.exec(md_mam("Z", "mamz1", 1e4, 1.0)), Err::None);
  r.step(10);
  ASSERT_EQ(r.exec(mam("Y", "mamy", 1, 1e6, 4, 1e6, 1e6)), Err::None);
  r.step(50);
  EXPECT_NEAR(vel(r, "Z"), 10.0, 1e-6);  // follows master 1
  ASSERT_EQ(r.exec("MDAC(Z, Y, mdac2, move, command);"), Err::None);
  // "the active and the pending MDAC will both have their IP bits set. However,
  // only the active MDAC will have its AC bit set."
  EXPECT_TRUE(r.tag("mdac1").ip() && r.tag("mdac2").ip());
  EXPECT_TRUE(r.tag("mdac1").ac());
  EXPECT_FALSE(r.tag("mdac2").ac());
  r.step(50);
  EXPECT_NEAR(vel(r, "Z"), 10.0, 1e-6);  // "no changes in any active motion"
  ASSERT_EQ(r.exec(md_mam("Z", "mamz2", 1e4, 1.0)), Err::None);  // goes IP: Y becomes the master
  EXPECT_FALSE(r.tag("mdac1").ip());
  EXPECT_TRUE(r.tag("mdac2").ip() && r.tag("mdac2").ac());
  r.step(100);
  EXPECT_NEAR(vel(r, "Z"), 4.0, 1e-6);  // follows master 2
}

// "The parameters in the pending MDAC instruction are overridden if you execute
// a succeeding MDAC before a new single axis motion instruction ... is
// activated on the slave axis. The most recent values ... are used"
TEST(Seed000Mdac, SucceedingPendingMdacOverridesThePendingOne) {
  Rig r = rig({"X", "Y", "Z", "W"});
  r.exec("MDAC(Z, X, d1, jog, command);");
  r.exec(md_maj("Z", "j1", 1.0));
  ASSERT_EQ(r.exec("MDAC(Z, Y, d2, jog, command);"), Err::None);
  ASSERT_EQ(r.exec("MDAC(Z, W, d3, jog, command);"), Err::None);
  EXPECT_FALSE(r.tag("d2").ip());  // overridden
  EXPECT_TRUE(r.tag("d3").ip());
  ASSERT_EQ(r.exec(md_maj("Z", "j2", 1.0)), Err::None);
  jog(r, "Y", "jy", 5);
  r.step(50);
  EXPECT_EQ(vel(r, "Z"), 0.0);  // not Y
  jog(r, "W", "jw", 3);
  r.step(50);
  EXPECT_NEAR(vel(r, "Z"), 3.0, 1e-6);  // W
  EXPECT_TRUE(r.tag("d3").ac());
}

// ".AC (Active) Bit 23: set when a move (MAJ, MAM or MATC) goes IP in Master
// Driven mode ... If the Slave Axis is started in Time Driven mode, then the AC
// bit of the MDAC does not go active. The IP bit of the MDAC does not change."
TEST(Seed000Mdac, AcBitOnlyForMasterDrivenMotion) {
  Rig r = rig({"X", "Y"});
  cam::CamProfile prof(4);
  calc(prof, 1.0);
  r.p->attach_cam_profile(0, &prof);
  r.sym.cam_profiles["p"] = 0;
  ASSERT_EQ(r.exec("MDAC(Y, X, l, all, command);"), Err::None);
  ASSERT_EQ(r.exec(mam("Y", "t", 1, 5, 10)), Err::None);  // time driven
  ASSERT_EQ(r.exec(maj("Y", "tj", 0, 5)), Err::None);
  ASSERT_EQ(r.exec(matc("Y", "tc", "p", "immediate", "continuous", "timedrivenmode", "none")), Err::None);
  EXPECT_FALSE(r.tag("l").ac());
  EXPECT_TRUE(r.tag("l").ip());
  for (const char* instr : {"mam", "maj", "matc"}) {
    SCOPED_TRACE(instr);
    Rig s = rig({"X", "Y"});
    s.p->attach_cam_profile(0, &prof);
    s.sym.cam_profiles["p"] = 0;
    ASSERT_EQ(s.exec("MDAC(Y, X, l, all, command);"), Err::None);
    const std::string i = instr;
    const std::string call = i == "mam" ? md_mam("Y", "m", 5, 1) : i == "maj" ? md_maj("Y", "m", 1) : matc("Y", "m", "p", "immediate");
    ASSERT_EQ(s.exec(call), Err::None);
    EXPECT_TRUE(s.tag("l").ac());
    EXPECT_TRUE(s.tag("m").ac());
    EXPECT_TRUE(s.tag("l").ip());
  }
}

// "Because there is no Actual Position for a Virtual axis, if you select either
// Actual or Command for Master Reference, the Command Position is used. No error."
TEST(Seed000Mdac, VirtualMasterAlwaysUsesCommandPosition) {
  Rig r = rig({"X", "Y"});
  ASSERT_EQ(r.exec("MDAC(Y, X, l, jog, actual);"), Err::None);
  ASSERT_EQ(r.exec(md_maj("Y", "j", 1.0)), Err::None);
  jog(r, "X", "jx", 10);
  for (int i = 0; i < 50; ++i) {
    r.fb[0].position = 1000.0 + i;  // ignored for a virtual axis
    r.step();
  }
  EXPECT_NEAR(vel(r, "Y"), 10.0, 1e-6);
}

// "An error is generated if a MDAC instruction is executed that changes the
// Master Reference of a slave axis that is in motion. The new MDAC instruction
// will error and the original one will remain active."
TEST(Seed000Mdac, MasterReferenceChangeOfAMovingSlaveErrsAndKeepsTheOriginal) {
  Rig r;
  AxisConfig m = cfg();
  m.type = AxisType::CipDrive;
  m.position_error_tolerance = 1e9;
  r.add_axis("M", m);
  r.add_axis("S", cfg());
  cam::CamProfile prof(4);
  calc(prof, 10.0);
  r.p->attach_cam_profile(0, &prof);
  r.sym.cam_profiles["p"] = 0;
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(M, a);");
  r.exec("MSO(S, b);");
  r.step();
  // at rest the reference may change: l1 is queued and takes effect when the MATC goes IP
  ASSERT_EQ(r.exec("MDAC(S, M, l0, timecam, actual);"), Err::None);
  ASSERT_EQ(r.exec("MDAC(S, M, l1, timecam, command);"), Err::None);
  ASSERT_EQ(r.exec(matc("S", "c", "p", "immediate")), Err::None);
  // the drive feedback moves, the command does not: the slave follows the command (still)
  r.exec(maj("M", "jm", 0, 10, 1e6, 1e6));
  for (int i = 1; i <= 30; ++i) {
    r.fb[0].position = 0.5 * 0.01 * i;  // drive lags its command
    r.step();
  }
  ASSERT_GT(vel(r, "S"), 0);
  EXPECT_EQ(r.exec("MDAC(S, M, l2, timecam, actual);"), Err::MdscInvalidModeOrMasterChange);
  EXPECT_EQ(r.tag("l2").err, 105);
  EXPECT_TRUE(r.tag("l1").ip());
  EXPECT_TRUE(r.tag("l1").ac());
  const double m0 = r.axis("M").command_position, s0 = pos(r, "S");
  r.step(10);
  EXPECT_NEAR(pos(r, "S") - s0, 10.0 * (r.axis("M").command_position - m0), 1e-9);  // still the command
}

// "Verification Errors: The Master and Slave Axis are the same. Master or Slave
// Axis is not configured. Master or Slave Axis is inhibited. Redefine position
// is in progress. Home of an axis is in progress." (runtime errors here)
TEST(Seed000Mdac, VerificationErrorsAreRuntimeErrors) {
  Rig r;
  r.add_axis("X", cfg());
  r.add_axis("Y", cfg());
  AxisConfig un = cfg();
  un.configured = false;
  r.add_axis("U", un);
  AxisConfig inh = cfg();
  inh.inhibited = true;
  r.add_axis("I", inh);
  AxisConfig h = cfg();
  h.type = AxisType::CipDrive;
  h.homing.sequence = HomingConfig::Sequence::Switch;
  h.homing.cia_method = 19;
  h.position_error_tolerance = 1e9;
  r.add_axis("H", h);
  r.fb[4].drive = DriveState::Enabled;
  r.exec("MSO(X, a);");
  r.exec("MSO(Y, b);");
  r.exec("MSO(H, c);");
  r.step();
  EXPECT_EQ(r.exec("MDAC(Y, Y, e, move, command);"), Err::MasterAxisConflict);
  EXPECT_EQ(r.exec("MDAC(Y, U, e, move, command);"), Err::AxisNotConfigured);
  EXPECT_EQ(r.exec("MDAC(U, Y, e, move, command);"), Err::AxisNotConfigured);
  EXPECT_EQ(r.exec("MDAC(Y, I, e, move, command);"), Err::AxisIsInhibited);
  EXPECT_EQ(r.exec("MDAC(I, Y, e, move, command);"), Err::AxisIsInhibited);
  ASSERT_EQ(r.exec("MAH(H, home);"), Err::None);
  ASSERT_TRUE(r.tag("home").ip());  // drive homing in progress
  EXPECT_EQ(r.exec("MDAC(Y, H, e, move, command);"), Err::HomeInProcess);
  EXPECT_EQ(r.exec("MDAC(H, Y, e, move, command);"), Err::HomeInProcess);
  // MRP completes in the scan it runs in (DN, no IP, the position already
  // redefined before any cycle ran): a redefine is never "in progress" when
  // the next instruction runs, so MDAC after MRP succeeds. Issue 16 item 10:
  // the redefinition itself is checked, so an MRP that did nothing or only
  // later would fail here.
  const double before = r.axis("X").command_position;
  ASSERT_EQ(r.exec("MRP(X, mrp, relative, command, 3);"), Err::None);
  EXPECT_TRUE(r.tag("mrp").dn());
  EXPECT_FALSE(r.tag("mrp").ip());
  EXPECT_EQ(r.axis("X").command_position, before + 3.0);
  EXPECT_EQ(r.exec("MDAC(Y, X, ok, move, command);"), Err::None);
  EXPECT_TRUE(r.tag("ok").ip());
}

// The MDAC1/MATC1/MDAC2/MATC2 example of seed 000:
//  - MDAC1: Master=X, Slave=Y
//  - MATC1: Slave Y, Immediate
//  - MDAC2: Master=Z Slave=Y, executed while MATC1 is moving
//  - MATC2: Slave=Y, Pending
//  - MATC2 uses the parameters from MDAC1 because MATC1 was active when MDAC2
//    was executed. "If MATC2 and MDAC2 were executed in the reverse order, you
//    get the same results."
namespace {
void mdac_matc_example(bool reverse_order) {
  Rig r = rig({"X", "Y", "Z"});
  cam::CamProfile c1(4), c2(4);
  calc(c1, 10.0);
  calc(c2, 5.0);
  r.p->attach_cam_profile(0, &c1);
  r.p->attach_cam_profile(1, &c2);
  r.sym.cam_profiles["c1"] = 0;
  r.sym.cam_profiles["c2"] = 1;
  ASSERT_EQ(r.exec("MDAC(Y, X, mdac1, timecam, command);"), Err::None);              // MDAC1
  ASSERT_EQ(r.exec(matc("Y", "matc1", "c1", "immediate", "once")), Err::None);       // MATC1
  jog(r, "X", "jx", 10);
  jog(r, "Z", "jz", 3);  // the other master also runs, more slowly
  r.step(20);
  ASSERT_GT(pos(r, "Y"), 0.0);  // MATC1 is moving
  if (!reverse_order) {
    ASSERT_EQ(r.exec("MDAC(Y, Z, mdac2, timecam, command);"), Err::None);           // MDAC2
    ASSERT_EQ(r.exec(matc("Y", "matc2", "c2", "pending", "once")), Err::None);      // MATC2
  } else {
    ASSERT_EQ(r.exec(matc("Y", "matc2", "c2", "pending", "once")), Err::None);
    ASSERT_EQ(r.exec("MDAC(Y, Z, mdac2, timecam, command);"), Err::None);
  }
  EXPECT_TRUE(r.tag("mdac1").ip() && r.tag("mdac1").ac());
  EXPECT_TRUE(r.tag("mdac2").ip());
  EXPECT_FALSE(r.tag("mdac2").ac());
  EXPECT_TRUE(r.tag("matc2").ip());
  EXPECT_FALSE(r.tag("matc2").ac());
  EXPECT_TRUE(r.axis("Y").motion(motion_status::TimeCamPendingStatus));
  // MATC1 ends after 1 unit of X travel; MATC2 continues on X (not Z)
  r.step_until([&] { return !r.tag("matc1").ip(); });
  EXPECT_TRUE(r.tag("matc1").pc());  // Once cam superseded by the pending one: PC
  EXPECT_TRUE(r.tag("matc2").ac());
  EXPECT_FALSE(r.axis("Y").motion(motion_status::TimeCamPendingStatus));
  const double x0 = pos(r, "X"), y0 = pos(r, "Y");
  r.step(30);
  EXPECT_NEAR(pos(r, "Y") - y0, 5.0 * (pos(r, "X") - x0), 1e-9);  // MDAC1's master X
  EXPECT_NEAR(vel(r, "Y"), 5.0 * 10.0, 1e-6);
  EXPECT_TRUE(r.tag("mdac1").ac());
  EXPECT_FALSE(r.tag("mdac2").ac());  // still pending: the next immediate motion takes it
  r.step_until([&] { return r.tag("matc2").pc(); });
  EXPECT_FALSE(r.tag("mdac1").ac());
  // the next single-axis motion that goes IP uses MDAC2's master Z
  ASSERT_EQ(r.exec(matc("Y", "matc3", "c1", "immediate", "continuous")), Err::None);
  EXPECT_FALSE(r.tag("mdac1").ip());
  EXPECT_TRUE(r.tag("mdac2").ac());
  r.step(20);
  EXPECT_NEAR(vel(r, "Y"), 10.0 * 3.0, 1e-6);  // Z at 3 units/s
}
}  // namespace

TEST(Seed000Mdac, Mdac1Matc1Mdac2Matc2Example) { mdac_matc_example(false); }
TEST(Seed000Mdac, Mdac1Matc1Matc2Mdac2ReverseOrderSameResult) { mdac_matc_example(true); }

// "A MATC with an Execution Schedule of Pending always uses the Instruction
// mode of the active MATC; Lock Position and Lock Direction are ignored."
TEST(Seed000Mdac, PendingMatcIgnoresItsLockDirection) {
  Rig r = rig({"X", "Y"});
  cam::CamProfile c1(4), c2(4);
  calc(c1, 10.0);
  calc(c2, 5.0);
  r.p->attach_cam_profile(0, &c1);
  r.p->attach_cam_profile(1, &c2);
  r.sym.cam_profiles["c1"] = 0;
  r.sym.cam_profiles["c2"] = 1;
  r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(r.exec(matc("Y", "a", "c1", "immediate", "once", "masterdrivenmode", "immediateforwardonly")), Err::None);
  ASSERT_EQ(r.exec(matc("Y", "b", "c2", "pending", "continuous", "masterdrivenmode", "immediatereverseonly")),
            Err::None);
  jog(r, "X", "jx", 10);
  r.step_until([&] { return r.tag("b").ac(); });
  r.step(20);
  EXPECT_NEAR(vel(r, "Y"), 50.0, 1e-6);  // follows forward travel (the active cam's lock)
  jog(r, "X", "jx2", -10);
  r.step(3);
  const double y = pos(r, "Y");
  r.step(20);
  EXPECT_EQ(pos(r, "Y"), y);  // and holds on reverse travel
}

// ================================================ seed 001 modes and units

// "the system will assume that the desired mode for the new instruction is the
// mode ... as specified in the programmed units of the speed parameter"
TEST(Seed001Modes, ModeFollowsTheSpeedUnitsBothWays) {
  Rig r = rig({"X", "Y"});
  r.exec("MDAC(Y, X, l, jog, command);");
  jog(r, "X", "jx", 10);
  ASSERT_EQ(r.exec(maj("Y", "t1", 0, 5, 1e6, 1e6)), Err::None);  // time driven
  r.step(20);
  EXPECT_NEAR(vel(r, "Y"), 5.0, 1e-9);
  // time -> master driven: starts from the present 5 u/s (= 0.5 u/mu), ramps to 2 u/mu
  ASSERT_EQ(r.exec(md_maj("Y", "m1", 2.0, 10.0)), Err::None);
  EXPECT_TRUE(r.tag("l").ac());
  double prev = vel(r, "Y");
  for (int i = 0; i < 100; ++i) {
    r.step();
    EXPECT_LE(std::fabs(vel(r, "Y") - prev), 10.0 * 10.0 * 10.0 * 0.001 + 1e-6);  // ramps, no step
    prev = vel(r, "Y");
  }
  EXPECT_NEAR(vel(r, "Y"), 20.0, 1e-6);
  // master -> time driven: starts from the present 20 u/s
  ASSERT_EQ(r.exec(maj("Y", "t2", 0, 3, 100, 100)), Err::None);
  EXPECT_FALSE(r.tag("l").ac());
  r.step();
  EXPECT_NEAR(vel(r, "Y"), 20.0 - 100 * 0.001, 1e-9);
  r.step(300);
  EXPECT_NEAR(vel(r, "Y"), 3.0, 1e-9);
}

// "the Accel, Decel, and Jerk must be programmed in the same units as the Speed
// parameter or the instruction will get a MDSC_UNITS_CONFLICT_ERROR error."
TEST(Seed001Modes, MixedUnitsAreUnitsConflict94) {
  Rig r = rig({"X", "Y"});
  r.exec("MDAC(Y, X, l, all, command);");
  const char* bad[] = {
      "MAJ(Y,j,forward,1,unitspermasterunit,1,unitspersec2,1,unitspermasterunit2,trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0,immediateforwardonly);",
      "MAJ(Y,j,forward,1,unitspersec,1,unitspersec2,1,unitspermasterunit2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none);",
      "MAJ(Y,j,forward,1,unitspermasterunit,1,unitspermasterunit2,1,unitspermasterunit2,scurve,1,1,unitspersec3,disabled,programmed,0,immediateforwardonly);",
      "MAJ(Y,j,forward,1,unitspersec,1,unitspersec2,1,unitspersec2,scurve,50,50,%oftimemasterdriven,disabled,programmed,0,none);",
      "MAM(Y,m,incremental,1,1,masterunits,0.1,seconds,0.1,masterunits,trapezoidal,0,0,masterunits,disabled,programmed,0,immediateforwardonly,0,0);",
      "MAM(Y,m,incremental,1,1,seconds,0.1,seconds,0.1,masterunits,trapezoidal,0,0,seconds,disabled,programmed,0,none,0,0);",
  };
  for (const char* b : bad) {
    SCOPED_TRACE(b);
    EXPECT_EQ(r.exec(b), Err::MdscUnitsConflict);
  }
  // trapezoidal: the jerk units are not used, so they cannot conflict
  EXPECT_EQ(r.exec("MAJ(Y,j,forward,1,unitspermasterunit,1,unitspermasterunit2,1,unitspermasterunit2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,immediateforwardonly);"),
            Err::None);
}

// "the error MDSC IDLE_MASTER_AND_SLAVE_MOVING is generated if MDSC mode is
// started while the Slave ... is moving when the master is idle." "If both the
// master and slave axes are idle ... [it] can make a change on the slave."
TEST(Seed001Modes, IdleMasterWithAMovingSlaveIs97) {
  Rig r = rig({"X", "Y"});
  r.exec("MDAC(Y, X, l, jog, command);");
  ASSERT_EQ(r.exec(maj("Y", "t", 0, 5)), Err::None);
  r.step(50);
  EXPECT_EQ(r.exec(md_maj("Y", "m", 1.0)), Err::MdscIdleMasterSlaveMoving);
  EXPECT_EQ(r.tag("m").err, 97);
  EXPECT_TRUE(r.tag("t").ip());  // nothing changed
  ASSERT_EQ(r.exec("MAS(Y, s, jog, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  r.step_until([&] { return r.tag("s").pc(); });
  EXPECT_EQ(r.exec(md_maj("Y", "m2", 1.0)), Err::None);  // both idle
}

// ================================================================ seed 003 MAG

namespace {
std::string mag(const std::string& c, const std::string& dir, double ratio, const std::string& master = "M") {
  return "MAG(S, " + master + ", " + c + ", " + dir + ", " + std::to_string(ratio) +
         ", 1, 1, command, real, disabled, 0, unitspersec2);";
}
}  // namespace

// "When executed for the first time with Reverse selected, the control defaults
// the direction to Opposite." / Unchanged: "... defaults the direction to Same"
TEST(Seed003Mag, ReverseAndUnchangedFirstExecutionDefaults) {
  for (const auto& [dir, sign] : {std::pair{"reverse", -1.0}, std::pair{"unchanged", 1.0}}) {
    SCOPED_TRACE(dir);
    Rig r = rig({"M", "S"});
    ASSERT_EQ(r.exec(mag("g", dir, 0.5)), Err::None);
    r.exec(mam("M", "mm", 1, 4, 100));
    r.step_until([&] { return r.tag("mm").pc(); });
    EXPECT_DOUBLE_EQ(pos(r, "S"), sign * 2.0);
  }
}

// "Reverse ... the current direction of the electronic gearing is changed from
// same to opposite or from opposite to same"; "Unchanged ... the gear ratio may
// be changed while preserving the current gearing direction"
TEST(Seed003Mag, ReverseFlipsAndUnchangedKeepsTheCurrentDirection) {
  Rig r = rig({"M", "S"});
  ASSERT_EQ(r.exec(mag("g1", "opposite", 1.0)), Err::None);
  ASSERT_EQ(r.exec(mag("g2", "unchanged", 2.0)), Err::None);  // keeps opposite, new ratio
  EXPECT_FALSE(r.tag("g1").ip());  // superseded by another MAG
  r.exec(mam("M", "m1", 1, 1, 100));
  r.step_until([&] { return r.tag("m1").pc(); });
  EXPECT_DOUBLE_EQ(pos(r, "S"), -2.0);
  ASSERT_EQ(r.exec(mag("g3", "reverse", 2.0)), Err::None);  // opposite -> same
  r.exec(mam("M", "m2", 1, 1, 100));
  r.step_until([&] { return r.tag("m2").pc(); });
  EXPECT_DOUBLE_EQ(pos(r, "S"), 0.0);
}

// "The master axis for electronic gearing can be changed at any time, even
// while gearing is currently enabled."
TEST(Seed003Mag, ChangingTheMasterWhileGearing) {
  Rig r = rig({"M", "N", "S"});
  ASSERT_EQ(r.exec(mag("g1", "same", 1.0, "M")), Err::None);
  jog(r, "M", "jm", 10);
  r.step(50);
  EXPECT_NEAR(vel(r, "S"), 10.0, 1e-9);
  ASSERT_EQ(r.exec(mag("g2", "same", 1.0, "N")), Err::None);
  EXPECT_FALSE(r.tag("g1").ip());
  EXPECT_TRUE(r.tag("g2").ip());
  r.step(50);
  EXPECT_EQ(vel(r, "S"), 0.0);  // N at rest: M no longer drives S
  jog(r, "N", "jn", 4);
  r.step(50);
  EXPECT_NEAR(vel(r, "S"), 4.0, 1e-9);
}

// "Electronic gearing remains active through any subsequent execution of jog,
// or move processes for the slave axis ... superimposed"
TEST(Seed003Mag, GearingSuperimposesWithAJog) {
  Rig r = rig({"M", "S"});
  ASSERT_EQ(r.exec(mag("g", "same", 0.5)), Err::None);
  jog(r, "M", "jm", 10);
  jog(r, "S", "js", 2);
  r.step(50);
  EXPECT_NEAR(vel(r, "S"), 0.5 * 10 + 2, 1e-9);
  EXPECT_TRUE(r.tag("g").ip());
  EXPECT_TRUE(r.axis("S").motion(motion_status::GearingStatus));
  EXPECT_TRUE(r.axis("S").motion(motion_status::JogStatus));
}

// Clutch: "the slave axis accelerates ... to the speed that it would be moving
// if it were currently geared ... Once the slave axis has reached the gearing
// speed, electronic gearing is automatically activated" (GearingLockStatus)
TEST(Seed003Mag, ClutchLocksOnlyAtGearingSpeed) {
  Rig r = rig({"M", "S"});
  jog(r, "M", "jm", 10);
  r.step(10);
  ASSERT_EQ(r.exec("MAG(S, M, g, same, 1, 1, 1, command, real, enabled, 100, unitspersec2);"), Err::None);
  r.step(50);  // 100 u/s^2: 0.05 s -> 5 u/s
  EXPECT_TRUE(r.axis("S").motion(motion_status::GearingStatus));
  EXPECT_FALSE(r.axis("S").motion(motion_status::GearingLockStatus));
  EXPECT_NEAR(vel(r, "S"), 5.0, 0.11);
  r.step(60);
  EXPECT_TRUE(r.axis("S").motion(motion_status::GearingLockStatus));
  EXPECT_NEAR(vel(r, "S"), 10.0, 1e-9);
}

// =============================================================== seed 004 MATC

namespace {
struct TcRig {
  Rig r = rig({"X"});
  cam::CamProfile a{4}, b{4}, u{4};
  TcRig() {
    calc(a, 10.0);
    calc(b, 5.0);
    r.p->attach_cam_profile(0, &a);
    r.p->attach_cam_profile(1, &b);
    r.p->attach_cam_profile(2, &u);
    r.sym.cam_profiles["a"] = 0;
    r.sym.cam_profiles["b"] = 1;
    r.sym.cam_profiles["u"] = 2;
  }
  Err tc(const std::string& c, const std::string& prof, const std::string& sched, const std::string& mode,
         const std::string& dir = "same", double ds = 1, double ts = 1) {
    return r.exec(matc("X", c, prof, sched, mode, "timedrivenmode", "none", dir, ds, ts));
  }
};
}  // namespace

// Direction: Same adds, Opposite subtracts; Reverse first time = Opposite,
// then flips; Unchanged first time = Same, then keeps.
TEST(Seed004Matc, DirectionRules) {
  struct Step { const char* dir; double sign; };
  const std::vector<std::vector<Step>> seqs = {
      {{"same", 1}, {"opposite", -1}},
      {{"reverse", -1}, {"reverse", 1}, {"reverse", -1}},
      {{"unchanged", 1}, {"opposite", -1}, {"unchanged", -1}, {"reverse", 1}, {"unchanged", 1}},
  };
  for (const auto& seq : seqs) {
    TcRig t;
    double expect = 0;
    int n = 0;
    for (const Step& s : seq) {
      SCOPED_TRACE(std::string(s.dir) + " #" + std::to_string(n));
      const std::string c = "c" + std::to_string(n++);
      ASSERT_EQ(t.tc(c, "a", "immediate", "once", s.dir), Err::None);
      t.r.step_until([&] { return t.r.tag(c).pc(); });
      expect += s.sign * 10.0;
      EXPECT_NEAR(pos(t.r, "X"), expect, 1e-9);
    }
  }
}

// Cam Profile Array Checks: Status 0/1 not calculated -> error; > 1 the
// instruction increments it; decremented when the cam completes or terminates.
TEST(Seed004Matc, CamProfileStatusCountsUsers) {
  TcRig t;
  EXPECT_EQ(t.u.status(), 0);
  EXPECT_EQ(t.tc("e", "u", "immediate", "once"), Err::CamProfileNotCalculated);
  EXPECT_EQ(t.a.status(), 2);
  ASSERT_EQ(t.tc("c1", "a", "immediate", "continuous"), Err::None);
  EXPECT_EQ(t.a.status(), 3);
  t.r.add_axis("Y", cfg());
  ASSERT_EQ(t.r.exec("MSO(Y, on);"), Err::None);
  ASSERT_EQ(t.r.exec("MATC(Y, c2, same, a[0], 1, 1, once, immediate, 0, none, timedrivenmode);"), Err::None);
  EXPECT_EQ(t.a.status(), 4);
  t.r.step_until([&] { return t.r.tag("c2").pc(); });  // completes
  EXPECT_EQ(t.a.status(), 3);
  ASSERT_EQ(t.r.exec("MAS(X, s, timecam, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);  // terminates
  EXPECT_EQ(t.a.status(), 2);
}

// Status bits: Immediate -> TimeCamStatus TRUE, TimeCamPendingStatus FALSE;
// Pending -> TimeCamStatus unchanged, TimeCamPendingStatus TRUE until the
// pending cam becomes the active cam (then immediately cleared).
TEST(Seed004Matc, StatusBitTables) {
  TcRig t;
  ASSERT_EQ(t.tc("p0", "b", "pending", "once"), Err::None);
  EXPECT_FALSE(t.r.axis("X").motion(motion_status::TimeCamStatus));  // unchanged (no cam)
  EXPECT_TRUE(t.r.axis("X").motion(motion_status::TimeCamPendingStatus));
  ASSERT_EQ(t.tc("i", "a", "immediate", "once"), Err::None);
  EXPECT_TRUE(t.r.axis("X").motion(motion_status::TimeCamStatus));
  EXPECT_TRUE(t.r.axis("X").motion(motion_status::TimeCamPendingStatus));  // the preloaded one still pends
  EXPECT_FALSE(t.r.axis("X").motion(motion_status::TimeCamLockStatus));    // time driven, None: not used
  t.r.step_until([&] { return !t.r.tag("i").ip(); });
  EXPECT_FALSE(t.r.axis("X").motion(motion_status::TimeCamPendingStatus));
  EXPECT_TRUE(t.r.axis("X").motion(motion_status::TimeCamStatus));
}

// Pending: "If the current cam is configured to execute once, the new profile
// is initiated at the completion of the pass ... and the PC bit of the
// currently active MATC instruction is set. If ... continuously, ... the IP bit
// of the currently active MATC instruction is cleared." Synchronisation is kept.
TEST(Seed004Matc, PendingBlendPositionContinuityAndPcIpOfTheOldInstruction) {
  for (const char* first : {"once", "continuous"}) {
    SCOPED_TRACE(first);
    TcRig t;
    ASSERT_EQ(t.tc("c1", "a", "immediate", first), Err::None);
    t.r.step(250);
    ASSERT_EQ(t.tc("c2", "b", "pending", "once"), Err::None);
    EXPECT_TRUE(t.r.tag("c1").ip());
    int cycle_of_takeover = -1;
    for (int k = 251; k <= 2100; ++k) {
      const double before = pos(t.r, "X");
      t.r.step();
      const double now = pos(t.r, "X");
      // time = k ms; the takeover happens at 1 s exactly: the position is the model
      const double time = k * 0.001;
      const double model = time <= 1.0 ? 10.0 * time : std::min(10.0 + 5.0 * (time - 1.0), 15.0);
      ASSERT_NEAR(now, model, 1e-9) << "k=" << k;
      ASSERT_LE(std::fabs(now - before), 10.0 * 0.001 + 1e-9);
      if (cycle_of_takeover < 0 && !t.r.tag("c1").ip()) cycle_of_takeover = k;
    }
    EXPECT_EQ(cycle_of_takeover, 1000);
    EXPECT_EQ(t.r.tag("c1").pc(), std::string(first) == "once");
    EXPECT_TRUE(t.r.tag("c2").pc());
  }
}

// "A second pending CAM overlays the first pending CAM in memory."
TEST(Seed004Matc, SecondPendingOverlaysTheFirst) {
  TcRig t;
  ASSERT_EQ(t.tc("c1", "a", "immediate", "once"), Err::None);
  ASSERT_EQ(t.tc("p1", "a", "pending", "once"), Err::None);
  ASSERT_EQ(t.tc("p2", "b", "pending", "once", "opposite"), Err::None);
  EXPECT_FALSE(t.r.tag("p1").ip());
  EXPECT_TRUE(t.r.tag("p2").ip());
  t.r.step_until([&] { return t.r.tag("p2").pc(); });
  EXPECT_FALSE(t.r.tag("p1").pc());
  EXPECT_NEAR(pos(t.r, "X"), 10.0 - 5.0, 1e-9);
}

// Scaling: "Increasing the Time Scaling value ... decreases the velocities,
// while increasing the Distance Scaling value increases the velocities ... if
// the Distance Scaling value of a profile is 2, the Time Scaling value should
// also be 2 to maintain approximately equal velocities"
TEST(Seed004Matc, EqualTimeAndDistanceScalingKeepsTheVelocity) {
  TcRig t;
  ASSERT_EQ(t.tc("c", "a", "immediate", "once", "same", 2, 2), Err::None);
  t.r.step(500);
  EXPECT_NEAR(vel(t.r, "X"), 10.0, 1e-9);
  t.r.step_until([&] { return t.r.tag("c").pc(); });
  EXPECT_NEAR(pos(t.r, "X"), 20.0, 1e-9);
  EXPECT_NEAR(static_cast<double>(t.r.cycle), 1 + 2000, 1);
}

// "Moves and Jogs, in particular, must be able to merge from active camming"
// and "Electronic camming remains active through any subsequent execution of
// jog, or move processes" (superimposed when not merging)
TEST(Seed004Matc, MergeFromACamAndSuperpositionWithAJog) {
  TcRig t;
  ASSERT_EQ(t.tc("c", "a", "immediate", "continuous"), Err::None);
  t.r.step(100);
  jog(t.r, "X", "j", 2);
  t.r.step(10);
  EXPECT_NEAR(vel(t.r, "X"), 12.0, 1e-9);
  EXPECT_TRUE(t.r.tag("c").ip());
  ASSERT_EQ(t.r.exec(maj("X", "jm", 0, 3, 1000, 1000, "trapezoidal", "enabled")), Err::None);
  EXPECT_FALSE(t.r.tag("c").ip());
  EXPECT_FALSE(t.r.axis("X").motion(motion_status::TimeCamStatus));
  EXPECT_EQ(t.a.status(), 2);
  t.r.step();
  EXPECT_NEAR(vel(t.r, "X"), 12.0 - 1000 * 0.001, 1e-9);  // from the present velocity
}

// EXERR for ERR 13 counts the faceplate operands from 0: 4 DistanceScaling,
// 5 TimeScaling ("an extended error code of 5 would refer to the Time Scaling")
TEST(Seed004Matc, ExerrNamesTheScalingOperand) {
  TcRig t;
  EXPECT_EQ(t.r.exec("MATC(X, e, same, a[0], 1, -1, once, immediate, 0, none, timedrivenmode);"),
            Err::ParameterOutOfRange);
  EXPECT_EQ(t.r.tag("e").exerr, 5);
  Request q = t.r.req("MATC(X, e, same, a[0], 1, 1, once, immediate, 0, none, timedrivenmode);");
  q.op[4].value = std::numeric_limits<double>::infinity();  // a REAL tag holding inf
  EXPECT_EQ(t.r.p->execute(q), Err::ParameterOutOfRange);
  EXPECT_EQ(t.r.tag("e").exerr, 4);
}
