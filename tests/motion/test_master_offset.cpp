// MAM master offset moves (MoveType 5 absolute, 6 incremental master offset,
// reference 2.9; MDAC Motion Type 4 in seed 000): they shift the master
// coordinate the active position cam sees (Slot::MasterOffset), time driven
// or master driven; MasterOffsetMoveStatus / MasterOffsetMoveLockStatus; MAS
// masteroffsetmove; ERR 33 without a position cam; and a seeded property
// test: a finished master offset move of d shifts the cam by exactly d.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <random>
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

/// The position-cam rig, plus starting a continuous or once MAPC named pc.
struct OffRig : canmotion::motion::test::PcRig {
  using PcRig::PcRig;
  void cam(const std::string& prof = "lin", const std::string& mode = "continuous", const std::string& ref = "command") {
    ASSERT_EQ(r.exec("MAPC(S, M, pc, same, " + prof + "[0], 1, 1, " + mode + ", immediate, 0, 0, " + ref +
                     ", bidirectional);"),
              Err::None);
  }
};

/// A master-driven MAM (units per master unit) with an immediate forward lock.
std::string md_mam(const std::string& ctl, int type, double pos, double speed, double acc) {
  return "MAM(S," + ctl + "," + std::to_string(type) + "," + std::to_string(pos) + "," + std::to_string(speed) +
         ",unitspermasterunit," + std::to_string(acc) + ",unitspermasterunit2," + std::to_string(acc) +
         ",unitspermasterunit2,trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0,immediateforwardonly,0,0);";
}

}  // namespace

TEST(MasterOffset, WithoutAPositionCamIsErr33) {
  OffRig c;
  for (int type : {5, 6}) {
    EXPECT_EQ(c.r.exec(mam("S", "o", type, 1, 1)), Err::PositionCamNotEnabled);
    EXPECT_EQ(c.r.tag("o").err, 33);
  }
  // gearing is not a position cam
  ASSERT_EQ(c.r.exec("MAG(S, M, g, same, 1, 1, 1, command, real, disabled, 0, unitspersec2);"), Err::None);
  EXPECT_EQ(c.r.exec(mam("S", "o", 6, 1, 1)), Err::PositionCamNotEnabled);
  // keywords work as well as numbers
  c.cam();
  EXPECT_EQ(c.r.exec("MAM(S,o,incrementalmasteroffset,1,1,unitspersec,10,unitspersec2,10,unitspersec2,trapezoidal,0,0,"
                     "unitspersec3,disabled,programmed,0,none,0,0);"),
            Err::None);
}

TEST(MasterOffset, IncrementalShiftsTheCamByExactlyD) {
  OffRig c;
  c.move_master(2);
  c.cam();
  ASSERT_EQ(c.r.exec(mam("S", "o", 6, 1.5, 1, 10, 10)), Err::None);
  const ControlTag& o = c.r.tag("o");
  EXPECT_TRUE(o.dn() && o.ip());
  c.r.step(500);  // cruising at 1 master unit/s, the master stands still
  EXPECT_TRUE(c.bit(MasterOffsetMoveStatus));
  EXPECT_FALSE(c.bit(MoveStatus));
  EXPECT_FALSE(c.bit(MasterOffsetMoveLockStatus));  // time driven
  EXPECT_TRUE(c.bit(PositionCamStatus));
  EXPECT_NEAR(c.r.axis("S").command_velocity, 2.0, 1e-9);  // slope 2 x 1 master unit/s
  c.r.step_until([&] { return o.pc(); });
  EXPECT_FALSE(o.ip());
  EXPECT_FALSE(c.bit(MasterOffsetMoveStatus));
  EXPECT_EQ(c.s(), 2 * 1.5);  // exactly
  // the shift stays while the master moves on
  c.move_master(4.5);
  EXPECT_NEAR(c.s(), 2 * (2.5 + 1.5), 1e-12);
}

TEST(MasterOffset, AbsoluteTargetsTheTotalOffset) {
  OffRig c;
  c.cam();
  ASSERT_EQ(c.r.exec(mam("S", "o", 6, 3, 5, 100, 100)), Err::None);
  c.r.step_until([&] { return c.r.tag("o").pc(); });
  ASSERT_EQ(c.r.exec(mam("S", "a", 5, 1, 5, 100, 100)), Err::None);
  c.r.step_until([&] { return c.r.tag("a").pc(); });
  EXPECT_NEAR(c.s(), 2 * 1.0, 1e-12);
  ASSERT_EQ(c.r.exec(mam("S", "a2", 5, -2, 5, 100, 100)), Err::None);
  c.r.step_until([&] { return c.r.tag("a2").pc(); });
  EXPECT_NEAR(c.s(), 2 * -2.0, 1e-12);
}

TEST(MasterOffset, IncrementalOntoARunningIncrementalAddsTheDistance) {
  OffRig c;
  c.cam();
  ASSERT_EQ(c.r.exec(mam("S", "o1", 6, 2, 1, 10, 10)), Err::None);
  c.r.step(300);
  ASSERT_EQ(c.r.exec(mam("S", "o2", 6, 1, 1, 10, 10)), Err::None);
  EXPECT_FALSE(c.r.tag("o1").ip());  // replaced
  c.r.step_until([&] { return c.r.tag("o2").pc(); });
  EXPECT_NEAR(c.s(), 2 * 3.0, 1e-12);
}

TEST(MasterOffset, SecondsUnitsAndAtRestRule) {
  OffRig c;
  c.cam();
  const std::string sec = "MAM(S,o,6,2,1,seconds,0.2,seconds,0.2,seconds,trapezoidal,0,0,unitspersec3,disabled,programmed,0,"
                          "none,0,0);";
  ASSERT_EQ(c.r.exec(sec), Err::None);
  c.r.step(100);
  EXPECT_EQ(c.r.exec("MAM(S,o2,6,2,1,seconds,0.2,seconds,0.2,seconds,trapezoidal,0,0,unitspersec3,disabled,programmed,"
                     "0,none,0,0);"),
            Err::AxisNotAtRest);  // the offset is moving
  c.r.step_until([&] { return c.r.tag("o").pc(); });
  EXPECT_NEAR(static_cast<double>(c.r.cycle), 1 + 1000 + 1, 3);  // one second
  EXPECT_NEAR(c.s(), 4.0, 1e-12);
}

TEST(MasterOffset, MasMasterOffsetMoveStopsOnlyTheOffset) {
  OffRig c;
  c.cam();
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 1, 1e6, 1e6)), Err::None);
  ASSERT_EQ(c.r.exec(mam("S", "o", 6, 10, 2, 100, 100)), Err::None);
  c.r.step(500);
  ASSERT_EQ(c.r.exec("MAS(S, s, masteroffsetmove, yes, 20, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(c.r.tag("o").ip());
  EXPECT_FALSE(c.r.tag("o").pc());
  EXPECT_TRUE(c.r.tag("pc").ip());  // the cam runs on
  c.r.step_until([&] { return c.r.tag("s").pc(); });
  EXPECT_FALSE(c.bit(MasterOffsetMoveStatus));
  EXPECT_TRUE(c.bit(PositionCamStatus));
  const double off = c.s() / 2 - c.m();
  EXPECT_GT(off, 0.9);  // ~0.99 + 2^2 / (2 * 20)
  EXPECT_LT(off, 1.2);
  c.r.step(700);
  EXPECT_NEAR(c.s() / 2 - c.m(), off, 1e-9);  // frozen offset
}

TEST(MasterOffset, EndsWithThePositionCam) {
  OffRig c;
  c.cam();
  ASSERT_EQ(c.r.exec(mam("S", "o", 6, 10, 2, 100, 100)), Err::None);
  c.r.step(100);
  ASSERT_EQ(c.r.exec("MAS(S, s, positioncam, no, 0, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(c.r.tag("o").ip());
  EXPECT_FALSE(c.bit(MasterOffsetMoveStatus));
  EXPECT_EQ(c.lin.status(), 2);
  // Once cam completion ends it too
  c.r.step_until([&] { return c.r.tag("s").pc(); });
  c.cam("lin", "once");
  ASSERT_EQ(c.r.exec(mam("S", "o2", 6, 20, 5, 100, 100)), Err::None);
  c.r.step_until([&] { return c.r.tag("pc").pc(); });
  EXPECT_FALSE(c.r.tag("o2").ip());
  EXPECT_FALSE(c.r.tag("o2").pc());
  EXPECT_FALSE(c.bit(MasterOffsetMoveStatus));
}

TEST(MasterOffset, MasterDrivenFollowsTheMasterWithLockStatus) {
  OffRig c;
  c.cam();
  EXPECT_EQ(c.r.exec(md_mam("o", 6, 2, 0.5, 1)), Err::MdscNotActivated);  // no MDAC yet
  EXPECT_EQ(c.r.tag("o").err, 93);
  ASSERT_EQ(c.r.exec("MDAC(S, M, l, masteroffsetmove, command);"), Err::None);
  ASSERT_EQ(c.r.exec(md_mam("o", 6, 2, 0.5, 1)), Err::None);
  EXPECT_TRUE(c.r.tag("o").ac());
  EXPECT_TRUE(c.r.tag("l").ac());
  c.r.step(10);
  EXPECT_TRUE(c.bit(MasterOffsetMoveStatus));
  // immediate lock: the lock condition is met at once and a master standing
  // still keeps it (one lock rule for all master-driven motion, motion/master_follow.hpp;
  // seed 004 TimeCamLockStatus); the slave does not move yet
  EXPECT_TRUE(c.bit(MasterOffsetMoveLockStatus));
  EXPECT_EQ(c.s(), 0.0);
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 4, 1e6, 1e6)), Err::None);
  c.r.step(100);
  EXPECT_TRUE(c.bit(MasterOffsetMoveLockStatus));
  c.r.step_until([&] { return c.r.tag("o").pc(); }, 100000);
  EXPECT_FALSE(c.r.tag("l").ac());
  EXPECT_FALSE(c.bit(MasterOffsetMoveStatus));
  EXPECT_FALSE(c.bit(MasterOffsetMoveLockStatus));
  c.r.step(3);
  EXPECT_NEAR(c.s(), 2 * (c.m() + 2.0), 1e-9);
  // the offset took 0.5 x master travel per master unit: about 2 / 0.5 + 0.5 = 4.5 units of master travel
  EXPECT_GT(c.m(), 4.0);
  EXPECT_LT(c.m(), 5.5);
}

TEST(MasterOffset, MdacAllCoversMasterOffsetMoves) {
  OffRig c;
  c.cam();
  ASSERT_EQ(c.r.exec("MDAC(S, M, l, all, command);"), Err::None);
  ASSERT_EQ(c.r.exec(md_mam("o", 5, -1, 0.5, 1)), Err::None);
  ASSERT_EQ(c.r.exec(maj("M", "j", 0, 4, 1e6, 1e6)), Err::None);
  c.r.step_until([&] { return c.r.tag("o").pc(); }, 100000);
  c.r.step();
  EXPECT_NEAR(c.s(), 2 * (c.m() - 1.0), 1e-9);
}

// ----------------------------------------------------------------- property
// Over random master trajectories (CIP master, actual feedback), random
// profiles, scaling and offsets d (several moves, time driven): when the moves
// are finished the slave equals the cam at (master travel + sum of d), exactly.
TEST(MasterOffsetProperty, FinishedOffsetShiftsTheCamByExactlyD) {
  const char* env_seed = std::getenv("MAPC_SEED");
  const char* env_count = std::getenv("MAPC_COUNT");
  const unsigned seed = env_seed ? static_cast<unsigned>(std::strtoul(env_seed, nullptr, 10)) : 77u;
  const int count = env_count ? std::atoi(env_count) : 30;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  auto r3 = [](double v) { return std::round(v * 1000) / 1000; };  // exact through the ST text
  for (int n = 0; n < count; ++n) {
    SCOPED_TRACE("MAPC_SEED=" + std::to_string(seed) + " case " + std::to_string(n));
    OffRig c(AxisType::CipDrive);
    const bool cubic = U(rng) < 0.5;
    const cam::CamProfile& prof = cubic ? c.cub : c.lin;
    const double ss = r3(0.2 + 2 * U(rng)), ms = r3(0.5 + 2 * U(rng));
    double mpos = r3(10 * U(rng));
    c.r.fb[1].position = mpos;
    c.r.step();
    ASSERT_EQ(c.r.exec("MAPC(S, M, pc, same, " + std::string(cubic ? "cub" : "lin") + "[0], " + std::to_string(ss) +
                       ", " + std::to_string(ms) + ", continuous, immediate, 0, 0, actual, bidirectional);"),
              Err::None);
    const double m0 = mpos;
    double total = 0;
    const int moves = 1 + static_cast<int>(U(rng) * 3);
    for (int k = 0; k < moves; ++k) {
      const double d = r3(-5 + 10 * U(rng));
      const bool absolute = U(rng) < 0.3;
      const std::string ctl = "o" + std::to_string(k);
      ASSERT_EQ(c.r.exec(mam("S", ctl, absolute ? 5 : 6, d, r3(0.5 + 5 * U(rng)), r3(5 + 50 * U(rng)),
                             r3(5 + 50 * U(rng)), U(rng) < 0.5 ? "trapezoidal" : "scurve")),
                Err::None);
      total = absolute ? d : total + d;
      for (int i = 0; i < 200000 && !c.r.tag(ctl).pc(); ++i) {
        mpos += (U(rng) - 0.5) * 0.01;
        c.r.fb[1].position = mpos;
        c.r.step();
      }
      ASSERT_TRUE(c.r.tag(ctl).pc());
    }
    double worst = 0;
    for (int i = 0; i < 200; ++i) {
      mpos += (U(rng) - 0.5) * 0.02;
      c.r.fb[1].position = mpos;
      c.r.step();
      const double v = (mpos - m0 + total) / ms;
      const double p = std::floor(v / prof.master_span());
      const double y = prof.evaluate(v - p * prof.master_span()).position + p * prof.slave_span();
      worst = std::max(worst, std::fabs(c.s() - ss * y));
    }
    EXPECT_LE(worst, 1e-9);
  }
}
