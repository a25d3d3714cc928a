// Master-driven MATC (issue 5; seeds 000 and 004, reference §2.15 and §5):
// the cam coordinate is master travel through the slave's Time Cam MDAC link;
// lock directions and TimeCamLockStatus; pending cams in master-driven mode;
// TrackingMaster for MATC, MAM and MAJ; the AC bits.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "motion/cam/cam_profile.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::maj;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cfg() { return canmotion::motion::test::axis_cfg(1000, 1e6); }

/// X and Z masters, Y the slave (all virtual), cam profiles registered.
struct MdRig {
  Rig r;
  cam::CamProfile fast{8}, slow{8};
  MdRig() {
    r.add_axis("X", cfg());
    r.add_axis("Y", cfg());
    r.add_axis("Z", cfg());
    for (const char* a : {"X", "Y", "Z"}) EXPECT_EQ(r.exec(std::string("MSO(") + a + ", on" + a + ");"), Err::None);
    calc(fast, 10.0);
    calc(slow, 5.0);
    r.p->attach_cam_profile(0, &fast);
    r.p->attach_cam_profile(1, &slow);
    r.sym.cam_profiles["fast"] = 0;
    r.sym.cam_profiles["slow"] = 1;
    r.step();
  }
  static void calc(cam::CamProfile& p, double rise) {  // linear: 0..1 -> 0..rise
    const std::array<cam::CamPoint, 2> pts{{{0.0, 0.0, 0}, {1.0, rise, 0}}};
    ASSERT_TRUE(cam::mccp(cam::MccpRequest{pts, 0, 2, 0.0, 0.0}, p).ok());
  }
  double pos(const char* a) { return r.axis(a).command_position; }
  double vel(const char* a) { return r.axis(a).command_velocity; }
  bool ms(const char* a, unsigned bit) { return r.axis(a).motion(bit); }
  /// Jog the master at `v` (signed) units/s with (almost) instant accel.
  void jog(const char* a, const std::string& c, double v) {
    ASSERT_EQ(r.exec(maj(a, c, v < 0 ? 1 : 0, std::fabs(v), 1e6, 1e6)), Err::None);
  }
  void stop(const char* a, const std::string& c) {
    ASSERT_EQ(r.exec(std::string("MAS(") + a + ", " + c + ", jog, yes, 1e6, unitspersec2, no, 0, unitspersec3);"),
              Err::None);
  }
};

std::string md_matc(const std::string& ctl, const std::string& prof, double ds, double ts, const std::string& mode,
                    const std::string& sched, double lockpos, const std::string& lockdir,
                    const std::string& dir = "same", const std::string& im = "masterdrivenmode") {
  return "MATC(Y, " + ctl + ", " + dir + ", " + prof + "[0], " + std::to_string(ds) + ", " + std::to_string(ts) + ", " +
         mode + ", " + sched + ", " + std::to_string(lockpos) + ", " + lockdir + ", " + im + ");";
}

}  // namespace

TEST(MatcMd, NeedsAnActiveTimeCamOrAllLink) {
  MdRig m;
  EXPECT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "once", "immediate", 0, "immediateforwardonly")),
            Err::MdscNotActivated);
  EXPECT_EQ(m.r.tag("t").err, 93);
  ASSERT_EQ(m.r.exec("MDAC(Y, X, lm, move, command);"), Err::None);  // a Move link does not drive a time cam
  EXPECT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "once", "immediate", 0, "immediateforwardonly")),
            Err::MdscNotActivated);
  EXPECT_EQ(m.fast.status(), 2);  // nothing acquired by the failed MATC
  ASSERT_EQ(m.r.exec("MDAC(Y, X, lt, timecam, command);"), Err::None);
  EXPECT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "once", "immediate", 0, "immediateforwardonly")), Err::None);
  MdRig a;  // MotionType All covers the time cam
  ASSERT_EQ(a.r.exec("MDAC(Y, X, la, all, command);"), Err::None);
  EXPECT_EQ(a.r.exec(md_matc("t", "fast", 1, 1, "once", "immediate", 0, "immediateforwardonly")), Err::None);
  EXPECT_TRUE(a.r.tag("la").ac());
}

TEST(MatcMd, CamCoordinateIsMasterTravelAndOnceCompletes) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "once", "immediate", 0, "immediateforwardonly")), Err::None);
  EXPECT_TRUE(m.r.tag("t").dn() && m.r.tag("t").ip() && m.r.tag("t").ac());
  EXPECT_TRUE(m.r.tag("l").ac());  // AC: a MATC went IP in master-driven mode [seed 000]
  EXPECT_EQ(m.fast.status(), 3);
  m.r.step(100);  // master at rest: the cam waits
  EXPECT_EQ(m.pos("Y"), 0.0);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamStatus));
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));  // immediate lock: set at once [seed 004]
  m.jog("X", "jx", 10);
  for (int i = 0; i < 80; ++i) {
    m.r.step();
    ASSERT_NEAR(m.pos("Y"), 10.0 * m.pos("X"), 1e-9) << "cycle " << i;
  }
  EXPECT_NEAR(m.vel("Y"), 10.0 * m.vel("X"), 1e-6);  // slope x master velocity
  EXPECT_TRUE(m.r.tag("t").get(flag::TrackingMaster));
  m.r.step_until([&] { return m.r.tag("t").pc(); });
  EXPECT_NEAR(m.pos("X"), 1.0, 0.011);  // completes after one profile span of master travel
  EXPECT_NEAR(m.pos("Y"), 10.0, 1e-9);
  EXPECT_FALSE(m.r.tag("t").ip());
  EXPECT_FALSE(m.r.tag("t").get(flag::TrackingMaster));
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamStatus));
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));
  EXPECT_FALSE(m.r.tag("l").ac());  // master-driven motion ended
  EXPECT_TRUE(m.r.tag("l").ip());   // the link stays
  EXPECT_EQ(m.fast.status(), 2);
}

TEST(MatcMd, PausingTheMasterPausesTheCamAndKeepsTheLockStatus) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly"));
  m.jog("X", "jx", 10);
  m.r.step(30);
  m.stop("X", "sx");
  m.r.step(5);
  const double y = m.pos("Y");
  m.r.step(200);
  EXPECT_EQ(m.pos("Y"), y);
  EXPECT_EQ(m.vel("Y"), 0.0);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));  // paused at speed 0: stays set [seed 004]
  EXPECT_TRUE(m.r.tag("t").ip());
  m.jog("X", "jx2", 10);
  m.r.step(20);
  EXPECT_GT(m.pos("Y"), y);
  EXPECT_NEAR(m.pos("Y"), 10.0 * m.pos("X"), 1e-9);
}

TEST(MatcMd, ForwardOnlyHoldsWhileTheMasterReversesThenResumes) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly"));
  m.jog("X", "jx", 10);
  m.r.step(30);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));
  m.jog("X", "jx2", -10);  // master reverses
  m.r.step(2);
  const double y = m.pos("Y");
  m.r.step(50);
  EXPECT_EQ(m.pos("Y"), y);  // the slave stops, it does not back up
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));  // cleared: not following [seed 004]
  EXPECT_FALSE(m.r.tag("t").get(flag::TrackingMaster));
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamStatus));
  const double x_turn = m.pos("X");
  m.jog("X", "jx3", 10);  // forward again: resumes with the forward travel
  m.r.step(20);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));  // set again when it resumes
  EXPECT_TRUE(m.r.tag("t").get(flag::TrackingMaster));
  EXPECT_GT(m.pos("Y"), y);
  EXPECT_NEAR(m.pos("Y") - y, 10.0 * (m.pos("X") - x_turn), 0.15);  // ~ forward travel since the turn
}

TEST(MatcMd, ImmediateReverseOnlyFollowsNegativeMasterTravel) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "immediatereverseonly"));
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));
  m.jog("X", "jx", 10);  // forward: not the lock direction
  m.r.step(30);
  EXPECT_EQ(m.pos("Y"), 0.0);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));
  m.jog("X", "jx2", -10);
  m.r.step(2);
  const double x0 = m.pos("X"), y0 = m.pos("Y");
  m.r.step(40);
  EXPECT_NEAR(m.pos("Y") - y0, 10.0 * (x0 - m.pos("X")), 1e-9);  // cam advances with reverse travel
  EXPECT_GT(m.vel("Y"), 0);  // direction Same: the cam adds its (rising) values
  EXPECT_NEAR(m.vel("Y"), -10.0 * m.vel("X"), 1e-6);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));
}

TEST(MatcMd, PositionForwardLockStartsWhenTheMasterCrossesLockPosition) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 2.0, "positionforwardonly")), Err::None);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamStatus));
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));
  m.jog("X", "jx", 10);
  m.r.step(150);  // master ~1.5
  EXPECT_EQ(m.pos("Y"), 0.0);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));
  EXPECT_FALSE(m.r.tag("t").get(flag::TrackingMaster));
  m.r.step(100);  // master ~2.5
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));
  EXPECT_NEAR(m.pos("Y"), 10.0 * (m.pos("X") - 2.0), 1e-9);  // only the travel past LockPosition counts
}

TEST(MatcMd, PositionReverseLockAndLockAtTheStartPositionNeverStarts) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", -1.0, "positionreverseonly")), Err::None);
  m.jog("X", "jx", 10);  // forward first: never crosses -1
  m.r.step(50);
  m.jog("X", "jx2", -10);
  m.r.step(100);  // ~0.5 -> ~-0.5
  EXPECT_EQ(m.pos("Y"), 0.0);
  m.r.step(100);  // ~-1.5
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));
  EXPECT_NEAR(m.pos("Y"), 10.0 * (-1.0 - m.pos("X")), 1e-9);
  // a master standing exactly on LockPosition never crosses it [reference §5]
  MdRig n;
  n.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(n.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0.0, "positionforwardonly")), Err::None);
  n.jog("X", "jx", 10);
  n.r.step(100);
  EXPECT_EQ(n.pos("Y"), 0.0);
  EXPECT_FALSE(n.ms("Y", motion_status::TimeCamLockStatus));
}

TEST(MatcMd, LockNoneFollowsBothDirectionsAndLeavesTheLockBitUnused) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "none")), Err::None);
  m.jog("X", "jx", 10);
  m.r.step(50);
  EXPECT_NEAR(m.pos("Y"), 10.0 * m.pos("X"), 1e-9);
  m.jog("X", "jx2", -10);
  m.r.step(120);  // below the start: continuous unwinds backwards
  EXPECT_LT(m.pos("X"), 0);
  EXPECT_NEAR(m.pos("Y"), 10.0 * m.pos("X"), 1e-9);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));  // "not used when NONE" [seed 004]
  EXPECT_TRUE(m.r.tag("t").get(flag::TrackingMaster));
}

TEST(MatcMd, ScalingIsInMasterUnits) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(m.r.exec(md_matc("t", "fast", 2, 4, "once", "immediate", 0, "immediateforwardonly")), Err::None);
  m.jog("X", "jx", 10);
  m.r.step(200);  // 2 of the 4 master units
  EXPECT_NEAR(m.pos("Y"), 2.0 * 10.0 * m.pos("X") / 4.0, 1e-9);
  EXPECT_NEAR(m.vel("Y"), 2.0 * 10.0 / 4.0 * m.vel("X"), 1e-6);
  m.r.step_until([&] { return m.r.tag("t").pc(); });
  EXPECT_NEAR(m.pos("X"), 4.0, 0.011);
  EXPECT_NEAR(m.pos("Y"), 20.0, 1e-9);
}

TEST(MatcMd, ActualMasterReferenceOnACipMaster) {
  Rig r;
  AxisConfig mc = cfg();
  mc.type = AxisType::CipDrive;
  mc.position_error_tolerance = 1e9;
  r.add_axis("M", mc);
  r.add_axis("Y", cfg());
  cam::CamProfile prof(8);
  MdRig::calc(prof, 10.0);
  r.p->attach_cam_profile(0, &prof);
  r.sym.cam_profiles["fast"] = 0;
  r.fb[0].drive = DriveState::Enabled;
  r.exec("MSO(M, a);");
  r.exec("MSO(Y, b);");
  r.step(2);
  ASSERT_EQ(r.exec("MDAC(Y, M, l, timecam, actual);"), Err::None);
  ASSERT_EQ(r.exec("MATC(Y, t, same, fast[0], 1, 1, continuous, immediate, 0, immediateforwardonly, masterdrivenmode);"),
            Err::None);
  for (int i = 1; i <= 50; ++i) {  // the drive moves (its command does not): the slave follows the feedback
    r.fb[0].position = 0.01 * i;
    r.step();
  }
  EXPECT_NEAR(r.axis("Y").command_position, 10.0 * 0.5, 1e-9);
  EXPECT_EQ(r.axis("M").command_position, 0.0);
}

TEST(MatcMd, StopsClearTheLockStatusAndMasAllBreaksTheLink) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly"));
  m.jog("X", "jx", 10);
  m.r.step(20);
  ASSERT_EQ(m.r.exec("MAS(Y, s, timecam, yes, 1e4, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));  // cleared by MAS [seed 004]
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamStatus));
  EXPECT_FALSE(m.r.tag("t").ip());
  EXPECT_FALSE(m.r.tag("t").ac());
  EXPECT_FALSE(m.r.tag("l").ac());
  EXPECT_TRUE(m.r.tag("l").ip());  // MAS timecam does not break the link
  m.r.step_until([&] { return m.r.tag("s").pc(); });
  EXPECT_EQ(m.vel("Y"), 0.0);
  // again, then MGS: lock status cleared, link broken
  ASSERT_EQ(m.r.exec(md_matc("t2", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly")), Err::None);
  m.r.step(5);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamLockStatus));
  ASSERT_EQ(m.r.exec("MGS(g, gs, faststop);"), Err::None);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamLockStatus));
  EXPECT_FALSE(m.r.tag("l").ip());
  // MASD on the slave
  MdRig n;
  n.r.exec("MDAC(Y, X, l, all, command);");
  n.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly"));
  n.r.step(2);
  EXPECT_TRUE(n.ms("Y", motion_status::TimeCamLockStatus));
  ASSERT_EQ(n.r.exec("MASD(Y, sd);"), Err::None);
  EXPECT_FALSE(n.ms("Y", motion_status::TimeCamLockStatus));
  EXPECT_FALSE(n.r.tag("l").ip());
  EXPECT_EQ(n.fast.status(), 2);
}

TEST(MatcMd, PendingRules) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  // pending without an active cam in master-driven mode still needs the link
  MdRig n;
  EXPECT_EQ(n.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "immediateforwardonly")), Err::MdscNotActivated);
  ASSERT_EQ(m.r.exec(md_matc("a", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly")), Err::None);
  // a pending cam with a position lock: LOCK_DIRECTION_CONFLICT (95) [seed 004]
  EXPECT_EQ(m.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 1.0, "positionforwardonly")),
            Err::MdscLockDirConflict);
  EXPECT_EQ(m.r.tag("p").err, 95);
  EXPECT_EQ(m.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 1.0, "positionreverseonly")),
            Err::MdscLockDirConflict);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamPendingStatus));
  // a pending cam in the other mode than the active cam errs [seed 004]
  EXPECT_EQ(m.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "none", "same", "timedrivenmode")),
            Err::MdscInvalidModeOrMasterChange);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamPendingStatus));
  // and the other way round: a time-driven active cam with a master-driven pending one
  MdRig t;
  t.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(t.r.exec(md_matc("a", "fast", 1, 1, "continuous", "immediate", 0, "none", "same", "timedrivenmode")),
            Err::None);
  EXPECT_EQ(t.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "immediateforwardonly")),
            Err::MdscInvalidModeOrMasterChange);
  // immediate on an active master-driven cam: Illegal Dynamic Change (23)
  EXPECT_EQ(m.r.exec(md_matc("i", "slow", 1, 1, "once", "immediate", 0, "immediateforwardonly")),
            Err::IllegalDynamicChange);
  // an immediate-lock pending cam is accepted: IP, not AC, TimeCamPendingStatus
  ASSERT_EQ(m.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "immediatereverseonly")), Err::None);
  EXPECT_TRUE(m.r.tag("p").ip());
  EXPECT_FALSE(m.r.tag("p").ac());
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamPendingStatus));
}

TEST(MatcMd, PendingBlendsAtThePassEndInMasterTravelAndKeepsTheActiveLock) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  ASSERT_EQ(m.r.exec(md_matc("a", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly")), Err::None);
  m.jog("X", "jx", 10);
  m.r.step(30);
  // its own lock (reverse only) is ignored: it runs with the active cam's forward lock [seed 000]
  ASSERT_EQ(m.r.exec(md_matc("b", "slow", 1, 1, "once", "pending", 0, "immediatereverseonly")), Err::None);
  double prev = m.pos("Y"), worst = 0;
  int cycles = 0;
  while (!m.r.tag("b").pc() && cycles < 5000) {
    m.r.step();
    ++cycles;
    worst = std::max(worst, std::fabs(m.pos("Y") - prev));
    prev = m.pos("Y");
    if (m.r.tag("a").ip()) {
      ASSERT_NEAR(m.pos("Y"), 10.0 * m.pos("X"), 1e-9);
    } else if (!m.r.tag("b").pc()) {  // after the takeover at master travel 1: the slow cam from y = 10
      ASSERT_NEAR(m.pos("Y"), 10.0 + 5.0 * (m.pos("X") - 1.0), 1e-9);
      EXPECT_TRUE(m.r.tag("b").ac());
      EXPECT_TRUE(m.r.tag("l").ac());  // the link stays active across the blend
    }
  }
  EXPECT_TRUE(m.r.tag("b").pc());
  EXPECT_LE(worst, 10.0 * 10.0 * 0.001 + 1e-9);  // never faster than the fast cam at 10 u/s master: no jump
  EXPECT_FALSE(m.r.tag("a").ip());  // a continuous cam superseded: IP cleared, no PC [seed 004]
  EXPECT_FALSE(m.r.tag("a").pc());
  EXPECT_FALSE(m.r.tag("a").ac());
  EXPECT_NEAR(m.pos("X"), 2.0, 0.011);
  EXPECT_NEAR(m.pos("Y"), 15.0, 1e-9);
  EXPECT_EQ(m.fast.status(), 2);
  EXPECT_EQ(m.slow.status(), 2);
}

TEST(MatcMd, TimeDrivenMatcWithALockDirectionIsErr95) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, timecam, command);");
  for (const char* ld : {"immediateforwardonly", "immediatereverseonly", "positionforwardonly", "positionreverseonly"}) {
    SCOPED_TRACE(ld);
    for (const char* sched : {"immediate", "pending"}) {
      EXPECT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "once", sched, 0, ld, "same", "timedrivenmode")),
                Err::MdscLockDirConflict);
      EXPECT_EQ(m.r.tag("t").err, 95);
    }
  }
  EXPECT_EQ(m.fast.status(), 2);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamStatus));
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamPendingStatus));
}

TEST(TrackingMaster, MasterDrivenJogSetsItOnceTheRampToTheRatioIsDone) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, jog, command);");
  // 1 unit per master unit, ramp 0.5 master units (accel 2 u/mu^2)
  ASSERT_EQ(m.r.exec("MAJ(Y, j, forward, 1, unitspermasterunit, 2, unitspermasterunit2, 2, unitspermasterunit2, "
                     "trapezoidal, 0, 0, unitspermasterunit3, disabled, programmed, 0, immediateforwardonly);"),
            Err::None);
  EXPECT_FALSE(m.r.tag("j").get(flag::TrackingMaster));
  m.jog("X", "jx", 10);
  m.r.step(20);  // 0.2 master units: still ramping
  EXPECT_FALSE(m.r.tag("j").get(flag::TrackingMaster));
  m.r.step(50);  // 0.7: tracking
  EXPECT_TRUE(m.r.tag("j").get(flag::TrackingMaster));
  EXPECT_NEAR(m.vel("Y"), m.vel("X"), 1e-6);
  m.jog("X", "jx2", -10);  // master reverses: not following
  m.r.step(3);
  EXPECT_FALSE(m.r.tag("j").get(flag::TrackingMaster));
  m.jog("X", "jx3", 10);
  m.r.step(3);
  EXPECT_TRUE(m.r.tag("j").get(flag::TrackingMaster));
  // a time-driven jog never sets it
  ASSERT_EQ(m.r.exec(maj("Y", "tj", 0, 5)), Err::None);
  m.r.step(100);
  EXPECT_FALSE(m.r.tag("tj").get(flag::TrackingMaster));
  EXPECT_FALSE(m.r.tag("j").get(flag::TrackingMaster));  // superseded
}

TEST(TrackingMaster, MasterDrivenMoveTracksInCruiseOnly) {
  MdRig m;
  m.r.exec("MDAC(Y, X, l, move, command);");
  // 4 units at 1 u/mu, accel/decel 2 u/mu^2: ramp 0.5 mu each side
  ASSERT_EQ(m.r.exec("MAM(Y,m,incremental,4,1,unitspermasterunit,2,unitspermasterunit2,2,unitspermasterunit2,"
                     "trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0,immediateforwardonly,0,0);"),
            Err::None);
  m.jog("X", "jx", 10);
  bool seen_before = false, seen_cruise = false, seen_after = false, tracked_in_ramp = false;
  while (!m.r.tag("m").pc()) {
    m.r.step();
    const double x = m.pos("X");
    const bool t = m.r.tag("m").get(flag::TrackingMaster);
    if (x < 0.45) { seen_before = true; tracked_in_ramp = tracked_in_ramp || t; }
    if (x > 0.55 && x < 3.95) { seen_cruise = true; ASSERT_TRUE(t) << x; }
    if (x > 4.05 && x < 4.45 && m.r.tag("m").ip()) { seen_after = true; tracked_in_ramp = tracked_in_ramp || t; }
  }
  EXPECT_TRUE(seen_before && seen_cruise && seen_after);
  EXPECT_FALSE(tracked_in_ramp);
  EXPECT_FALSE(m.r.tag("m").get(flag::TrackingMaster));  // cleared at PC
}

// LockPosition is a master position as the user sees it (after MRP / homing).
TEST(MatcMd, LockPositionIsInTheMastersUserFrame) {
  for (const bool cam : {true, false}) {
    SCOPED_TRACE(cam ? "MATC" : "MAM");
    MdRig m;
    ASSERT_EQ(m.r.exec("MRP(X, mrp, absolute, command, 100);"), Err::None);  // X user position 100 (drive 0)
    m.r.exec("MDAC(Y, X, l, all, command);");
    if (cam) {
      ASSERT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 102.0, "positionforwardonly")),
                Err::None);
    } else {
      ASSERT_EQ(m.r.exec("MAM(Y,t,incremental,100,1,unitspermasterunit,1e6,unitspermasterunit2,1e6,"
                         "unitspermasterunit2,trapezoidal,0,0,unitspermasterunit3,disabled,programmed,102,"
                         "positionforwardonly,0,0);"),
                Err::None);
    }
    m.jog("X", "jx", 10);
    m.r.step(150);  // user 101.5
    EXPECT_EQ(m.pos("Y"), 0.0);
    m.r.step(100);  // user 102.5
    EXPECT_GT(m.pos("Y"), 0.0);
    EXPECT_NEAR(m.pos("Y"), (cam ? 10.0 : 1.0) * (m.pos("X") - 102.0), 1e-6);
  }
}

// The master is stepped before its cam slave even when its axis id is higher:
// the slave sees the master's command of the same cycle (no one-cycle lag).
TEST(MatcMd, MasterWithAHigherAxisIdIsSteppedFirst) {
  MdRig m;
  ASSERT_EQ(m.r.exec("MDAC(Y, Z, l, timecam, command);"), Err::None);  // Z (id 2) drives Y (id 1)
  ASSERT_EQ(m.r.exec(md_matc("t", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly")), Err::None);
  m.jog("Z", "jz", 10);
  for (int i = 0; i < 50; ++i) {
    m.r.step();
    ASSERT_NEAR(m.pos("Y"), 10.0 * m.pos("Z"), 1e-9) << "cycle " << i;
  }
  EXPECT_GT(m.pos("Y"), 0.0);
}

// Issue 16 item 6. "Both a pending CAM and the active CAM must be in the same
// mode ... An instruction that pends a CAM to an active CAM in a different
// mode (than the active CAM) will cause an error" and "All pending CAMs must
// use the Immediate Forward or the Immediate Reverse Lock Direction" [seed 004].
// (a) A pending cam preloaded without an active cam (seed 004: it "executes
// but no camming motion occurs until another MATC instruction with a
// non-pending Execution Schedule is initiated") in the other mode than that
// immediate cam errs when the immediate cam starts (ERR 105, IP cleared,
// TimeCamPendingStatus cleared) instead of running in the wrong mode; in the
// same mode it takes over as before. (b) A master-driven pending cam with Lock
// Direction None is LOCK_DIRECTION_CONFLICT (95).
TEST(MatcMd, PreloadedPendingCamOfTheOtherModeErrsAndPendingNoneLockIsRefused) {
  MdRig m;
  ASSERT_EQ(m.r.exec("MDAC(Y, X, l, timecam, command);"), Err::None);
  // (b)
  EXPECT_EQ(m.r.exec(md_matc("n", "slow", 1, 1, "once", "pending", 0, "none")), Err::MdscLockDirConflict);
  EXPECT_EQ(m.r.tag("n").err, 95);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamPendingStatus));
  // (a) a master-driven pending cam preloaded, then a time-driven immediate cam
  ASSERT_EQ(m.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "immediateforwardonly")), Err::None);
  EXPECT_TRUE(m.ms("Y", motion_status::TimeCamPendingStatus));
  ASSERT_EQ(m.r.exec(md_matc("a", "fast", 1, 0.1, "once", "immediate", 0, "none", "same", "timedrivenmode")),
            Err::None);
  EXPECT_TRUE(m.r.tag("p").er());
  EXPECT_EQ(m.r.tag("p").err, 105);
  EXPECT_FALSE(m.r.tag("p").ip());
  m.r.step();
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamPendingStatus));
  m.r.step_until([&] { return m.r.tag("a").pc(); });
  m.r.step(10);
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamStatus));  // no cam took over
  EXPECT_NEAR(m.pos("Y"), 10.0, 1e-9);                    // the time-driven pass only
  // the same mode: the preloaded cam takes over at the end of the pass
  MdRig s;
  ASSERT_EQ(s.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "none", "same", "timedrivenmode")),
            Err::None);
  ASSERT_EQ(s.r.exec(md_matc("a", "fast", 1, 0.1, "once", "immediate", 0, "none", "same", "timedrivenmode")),
            Err::None);
  EXPECT_FALSE(s.r.tag("p").er());
  s.r.step_until([&] { return s.r.tag("a").pc(); });
  s.r.step();
  EXPECT_TRUE(s.ms("Y", motion_status::TimeCamStatus));  // the pending cam runs
  EXPECT_TRUE(s.r.tag("p").ip());
}

// Issue 16 item 9: the controller mode. "A mode change (Rem Run to Rem Prog
// or Rem Prog to Rem Run) or an axis fault also breaks the MDAC link"
// [seed 000]; "CAM motion must also stop when the ControlLogix processor
// changes OS modes" [seed 004]; gearing is stopped like camming ("This
// behavior should be identical to the MAS functionality that specifically
// stops a gearing process" [seed 004]). Into Program mode every axis stops by
// its Programmed Stop Mode (FastStop here: a ramp at the maximum decel); in
// Program mode instructions that would start motion answer ERR 24 Illegal
// Controller Mode while stops and servo off run; back in Run they run again.
TEST(MatcMd, ProgramModeBreaksLinksAndStopsCamsGearsAndMoves) {
  MdRig m;
  ASSERT_EQ(m.r.exec("MDAC(Y, X, l, timecam, command);"), Err::None);
  m.jog("X", "jx", 10);
  ASSERT_EQ(m.r.exec(md_matc("c", "fast", 1, 1, "continuous", "immediate", 0, "immediateforwardonly")), Err::None);
  ASSERT_EQ(m.r.exec(md_matc("p", "slow", 1, 1, "once", "pending", 0, "immediateforwardonly")), Err::None);
  ASSERT_EQ(m.r.exec("MAG(Z, X, g, same, 1, 1, 1, command, real, disabled, 0, unitspersec2);"), Err::None);
  m.r.step(100);
  ASSERT_GT(m.vel("Y"), 0.0);
  ASSERT_GT(m.vel("Z"), 0.0);
  m.r.p->set_controller_mode(ControllerMode::Program);
  EXPECT_EQ(m.r.p->controller_mode(), ControllerMode::Program);
  EXPECT_FALSE(m.r.tag("l").ip());  // the link is broken
  EXPECT_FALSE(m.r.tag("c").ip());  // the cam, the pending cam, the gear and the jog are ended
  EXPECT_FALSE(m.r.tag("p").ip());
  EXPECT_FALSE(m.r.tag("g").ip());
  EXPECT_FALSE(m.r.tag("jx").ip());
  for (const char* a : {"X", "Y", "Z"}) EXPECT_TRUE(m.ms(a, motion_status::StoppingStatus)) << a;  // FastStop ramps
  m.r.step();
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamStatus));
  EXPECT_FALSE(m.ms("Y", motion_status::TimeCamPendingStatus));
  EXPECT_FALSE(m.ms("Z", motion_status::GearingStatus));
  m.r.step(1000);
  for (const char* a : {"X", "Y", "Z"}) {
    EXPECT_EQ(m.vel(a), 0.0) << a;
    EXPECT_TRUE(m.r.axis(a).status(axis_status::ServoActionStatus)) << a;  // FastStop keeps the servo on
  }
  // Program mode: nothing starts motion; stops and servo off run
  EXPECT_EQ(m.r.exec(maj("X", "j2", 0, 10)), Err::IllegalControllerMode);
  EXPECT_EQ(m.r.tag("j2").err, 24);
  EXPECT_EQ(m.r.exec("MDAC(Y, X, l2, timecam, command);"), Err::IllegalControllerMode);
  EXPECT_EQ(m.r.exec("MAS(X, s, all, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_EQ(m.r.exec("MSF(Z, off);"), Err::None);
  m.r.step();
  EXPECT_EQ(m.vel("X"), 0.0);
  // back to Run: motion runs again
  m.r.p->set_controller_mode(ControllerMode::Run);
  EXPECT_EQ(m.r.exec(maj("X", "j3", 0, 10)), Err::None);
  m.r.step(10);
  EXPECT_GT(m.vel("X"), 0.0);
}
