// MAG (electronic gearing), issue 5: directions 0-3 with first-use defaults,
// real ratio range, exact fractional ratio in integer counts, master
// reference, clutch, superposition with MAM/MAJ, supersede and stop.
#include <gtest/gtest.h>

#include <cmath>

#include "prop_util.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::maj;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cfg(double cc = 1.0) {
  AxisConfig c;
  c.max_speed = 1000;
  c.max_accel = 1000;
  c.max_decel = 1000;
  c.conversion_constant = cc;
  return c;
}

std::string mag(const std::string& ctl, const std::string& dir, double ratio, const std::string& clutch = "disabled",
                double acc = 0, const std::string& fmt = "real", long sc = 1, long mc = 1,
                const std::string& ref = "command") {
  return "MAG(S, M, " + ctl + ", " + dir + ", " + std::to_string(ratio) + ", " + std::to_string(sc) + ", " +
         std::to_string(mc) + ", " + ref + ", " + fmt + ", " + clutch + ", " + std::to_string(acc) + ", unitspersec2);";
}

Rig geared_rig(AxisConfig m = cfg(), AxisConfig s = cfg()) {
  Rig r;
  r.add_axis("M", m);
  r.add_axis("S", s);
  EXPECT_EQ(r.exec("MSO(M, a);"), Err::None);
  EXPECT_EQ(r.exec("MSO(S, b);"), Err::None);
  r.step();
  return r;
}

}  // namespace

TEST(Mag, LocksAtOnceWithoutClutchAndFollowsTheMaster) {
  Rig r = geared_rig();
  EXPECT_EQ(r.exec(mag("g", "same", 0.5)), Err::None);
  const auto& t = r.tag("g");
  EXPECT_TRUE(t.en() && t.dn() && t.ip() && !t.er() && !t.pc());
  r.step();
  EXPECT_TRUE(r.axis("S").motion(motion_status::GearingStatus));
  EXPECT_TRUE(r.axis("S").motion(motion_status::GearingLockStatus));
  r.exec(mam("M", "mm", 1, 100, 50));
  r.step(3000);
  EXPECT_EQ(r.axis("M").command_position, 100.0);
  EXPECT_DOUBLE_EQ(r.axis("S").command_position, 50.0);
  EXPECT_TRUE(r.tag("g").ip());  // gearing stays in process
}

TEST(Mag, DirectionsAndFirstUseDefaults) {
  {  // reverse on first use = opposite
    Rig r = geared_rig();
    r.exec(mag("g", "reverse", 1.0));
    r.exec(mam("M", "mm", 1, 10, 50));
    r.step(1000);
    EXPECT_DOUBLE_EQ(r.axis("S").command_position, -10.0);
    // reverse again flips to same (new MAG supersedes the old one)
    EXPECT_EQ(r.exec(mag("g2", "reverse", 1.0)), Err::None);
    EXPECT_FALSE(r.tag("g").ip());
    r.exec(mam("M", "mm2", 1, 10, 50));
    r.step(1000);
    EXPECT_DOUBLE_EQ(r.axis("S").command_position, 0.0);  // -10 + 10
    // unchanged keeps "same"; opposite reverses explicitly
    r.exec(mag("g3", "unchanged", 2.0));
    r.exec(mam("M", "mm3", 1, 1, 50));
    r.step(1000);
    EXPECT_DOUBLE_EQ(r.axis("S").command_position, 2.0);
  }
  {  // unchanged on first use = same
    Rig r = geared_rig();
    r.exec(mag("g", "3", 1.0));
    r.exec(mam("M", "mm", 1, 10, 50));
    r.step(1000);
    EXPECT_DOUBLE_EQ(r.axis("S").command_position, 10.0);
  }
  {  // opposite, and a negative ratio is sign-sensitive: opposite * -1 = same
    Rig r = geared_rig();
    r.exec(mag("g", "opposite", -0.25));
    r.exec(mam("M", "mm", 1, 8, 50));
    r.step(1000);
    EXPECT_DOUBLE_EQ(r.axis("S").command_position, 2.0);
  }
}

TEST(Mag, RealRatioRangeIsErr13WithOperandIndex) {
  Rig r = geared_rig();
  for (double bad : {0.0, 0.000001, 10.0, -10.0, 9.999995}) {
    SCOPED_TRACE(bad);
    EXPECT_EQ(r.exec(mag("e", "same", bad)), Err::ParameterOutOfRange);
    EXPECT_EQ(r.tag("e").exerr, 4);
    EXPECT_FALSE(r.axis("S").motion(motion_status::GearingStatus));
  }
  for (double ok : {0.00001, 9.99999, -9.99999, -0.00001}) EXPECT_EQ(r.exec(mag("o", "same", ok)), Err::None) << ok;
  EXPECT_EQ(r.exec(mag("e2", "same", 1, "disabled", 0, "fraction_slave_master_counts", 0, 3)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("e2").exerr, 5);
  EXPECT_EQ(r.exec(mag("e3", "same", 1, "disabled", 0, "fraction_slave_master_counts", 1, 0)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("e3").exerr, 6);
  EXPECT_EQ(r.exec(mag("e4", "same", 1, "enabled", 0)), Err::ParameterOutOfRange);  // clutch needs AccelRate > 0
  EXPECT_EQ(r.tag("e4").exerr, 10);
}

TEST(Mag, MasterConflicts) {
  Rig r = geared_rig();
  EXPECT_EQ(r.exec("MAG(S, S, g, same, 1, 1, 1, command, real, disabled, 0, unitspersec2);"), Err::MasterAxisConflict);
  EXPECT_EQ(r.tag("g").err, 10);
  Rig off;
  off.add_axis("M", cfg());
  off.add_axis("S", cfg());
  EXPECT_EQ(off.exec(mag("g", "same", 1)), Err::ServoOffState);
}

// 1:3 in counts over 10^7 cycles: the slave position is always exactly
// floor(master counts moved / 3) counts: no accumulated error.
TEST(Mag, FractionalRatioIsExactOverTenMillionCycles) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 20;
  const auto cycles = static_cast<int>(canmotion::motion::test::env_u64("CANMOTION_GEAR_CYCLES", 10000000));
  canmotion::motion::test::Rng rng(seed);
  Rig r = geared_rig(cfg(4096), cfg(1000));
  ASSERT_EQ(r.exec(mag("g", "same", 1, "disabled", 0, "fraction_slave_master_counts", 1, 3)), Err::None);
  const double v = rng.uni(0.3, 3.0);  // master jog, rev/s
  r.exec(maj("M", "j", 0, v, 10, 10));
  const double m0 = r.axis("M").command_position;
  const long long m0c = std::llround(m0 * 4096);
  long long worst = 0;
  for (int i = 0; i < cycles; ++i) {
    r.step();
    if (i % 997 == 0 || i == cycles - 1) {
      const long long mc = std::llround(r.axis("M").command_position * 4096) - m0c;
      long long expect = mc / 3;
      if (mc % 3 != 0 && mc < 0) --expect;
      const double sp = r.axis("S").command_position * 1000;  // slave counts
      const long long diff = std::llround(sp) - expect;
      worst = std::max(worst, std::llabs(diff));
      // the runtime sends llround(position * conversion constant) counts
      ASSERT_EQ(diff, 0) << "seed=" << seed << " cycle " << i;
      ASSERT_NEAR(sp, static_cast<double>(expect), 1e-6);
    }
  }
  EXPECT_EQ(worst, 0);
}

TEST(Mag, ClutchRampsAtTheAccelRateThenLocks) {
  Rig r = geared_rig();
  r.exec(maj("M", "j", 0, 100, 1e6, 1e6));
  r.step(10);
  ASSERT_DOUBLE_EQ(r.axis("M").command_velocity, 100.0);
  EXPECT_EQ(r.exec(mag("g", "same", 2.0, "enabled", 500)), Err::None);  // to 200 u/s at 500 u/s^2: 0.4 s
  double prev = 0;
  int n = 0;
  while (!r.axis("S").motion(motion_status::GearingLockStatus) && n < 10000) {
    r.step();
    ++n;
    const double v = r.axis("S").command_velocity;
    EXPECT_LE(std::fabs(v - prev), 500 * 0.001 * (1 + 1e-9));
    EXPECT_TRUE(r.axis("S").motion(motion_status::GearingStatus));
    prev = v;
  }
  EXPECT_NEAR(n, 400, 2);
  r.step(100);
  EXPECT_DOUBLE_EQ(r.axis("S").command_velocity, 200.0);
  // once locked, the slave follows the master position exactly (ratio 2)
  const double s0 = r.axis("S").command_position, m0 = r.axis("M").command_position;
  r.step(1000);
  EXPECT_NEAR(r.axis("S").command_position - s0, 2 * (r.axis("M").command_position - m0), 1e-9);
}

TEST(Mag, NoAxisLimitsApplyToGearing) {
  AxisConfig s = cfg();
  s.max_speed = 1;
  Rig r = geared_rig(cfg(), s);
  r.exec(mag("g", "same", 5.0));
  r.exec(maj("M", "j", 0, 100));
  r.step(1000);
  EXPECT_DOUBLE_EQ(r.axis("S").command_velocity, 500.0);
  EXPECT_TRUE(r.axis("S").motion(motion_status::MaximumSpeedExceeded));
}

TEST(Mag, SuperposesWithAnIncrementalMoveForPhaseAdvance) {
  Rig r = geared_rig();
  r.exec(mag("g", "same", 1.0));
  r.exec(maj("M", "j", 0, 10));
  r.step(500);
  const double before = r.axis("S").command_position - r.axis("M").command_position;
  r.exec(mam("S", "adv", 1, 2.5, 5));
  r.step_until([&] { return r.tag("adv").pc(); });
  r.step(10);
  EXPECT_NEAR(r.axis("S").command_position - r.axis("M").command_position, before + 2.5, 1e-9);
  EXPECT_TRUE(r.tag("g").ip());
}

TEST(Mag, MasStopsGearingAndClearsIp) {
  Rig r = geared_rig();
  r.exec(mag("g", "same", 1.0));
  r.exec(maj("M", "j", 0, 10));
  r.step(500);
  EXPECT_EQ(r.exec("MAS(S, s, gear, yes, 100, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(r.tag("g").ip());
  EXPECT_TRUE(r.tag("s").ip());
  r.step_until([&] { return r.tag("s").pc(); });
  EXPECT_EQ(r.axis("S").command_velocity, 0.0);
  EXPECT_FALSE(r.axis("S").motion(motion_status::GearingStatus));
  EXPECT_DOUBLE_EQ(r.axis("M").command_velocity, 10.0);
}

TEST(Mag, MergedMoveCancelsGearing) {
  Rig r = geared_rig();
  r.exec(mag("g", "same", 1.0));
  r.exec(maj("M", "j", 0, 10));
  r.step(500);
  r.exec(mam("S", "m", 0, 100, 10, 1000, 1000, "trapezoidal", 100, 100, "%oftime", "enabled"));
  EXPECT_FALSE(r.tag("g").ip());
  r.step();
  EXPECT_NEAR(r.axis("S").command_velocity, 10.0, 1e-9);  // continuous hand-over
  r.step_until([&] { return r.tag("m").pc(); });
  EXPECT_EQ(r.axis("S").command_position, 100.0);
}

// "Actual – slave axis motion is generated from the current position of the
// master axis as measured by its encoder"; "Command – ... from the desired or
// commanded position of the master axis" [seed 003]. The master is servo-on
// (with the servo off its command would follow the actual position and the
// two references could not be told apart, issue 16 item 10): its actual
// position moves by 3 (a following error) while its command stays at 0. With
// `actual` the slave follows to 3, with `command` it stays at 0.
TEST(Mag, ActualMasterReferenceOnACipMaster) {
  for (const char* ref : {"actual", "command"}) {
    SCOPED_TRACE(ref);
    Rig r;
    AxisConfig m = cfg();
    m.type = AxisType::CipDrive;
    r.add_axis("M", m);
    r.add_axis("S", cfg());
    r.fb[0].drive = DriveState::Enabled;
    ASSERT_EQ(r.exec("MSO(M, a);"), Err::None);
    ASSERT_EQ(r.exec("MSO(S, b);"), Err::None);
    r.step();
    ASSERT_TRUE(r.tag("a").dn());  // the master's servo is on: its command is the planner's
    ASSERT_EQ(r.exec(mag("g", "same", 1.0, "disabled", 0, "real", 1, 1, ref)), Err::None);
    r.fb[0].position = 3.0;  // the drive is pushed away: actual 3, command 0
    r.step();
    ASSERT_EQ(r.axis("M").command_position, 0.0);
    ASSERT_EQ(r.axis("M").actual_position, 3.0);
    EXPECT_DOUBLE_EQ(r.axis("S").command_position, std::string(ref) == "actual" ? 3.0 : 0.0);
  }
}

// Property: while the clutch ramps the slave to gearing speed, its command
// velocity never changes by more than AccelRate x period per cycle, whatever
// the ratio, its sign, the master speed and whether the master is still
// accelerating; and the slave locks, within the time the ramp needs.
TEST(MagProperty, ClutchRampsRespectTheAccelRate) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 21;
  const auto count = canmotion::motion::test::prop_count(200);
  canmotion::motion::test::Rng rng(seed);
  for (std::uint64_t k = 0; k < count; ++k) {
    Rig r = geared_rig();
    const double v = (rng.coin() ? 1 : -1) * rng.uni(5, 200);              // master jog speed
    const double ma = rng.coin(0.3) ? rng.uni(50, 500) : 1e6;              // master still accelerating?
    const double ratio = std::round((rng.coin() ? 1 : -1) * rng.uni(0.1, 5) * 1e5) / 1e5;
    const double acc = std::round(rng.uni(50, 5000));                      // clutch accel, units/s^2
    r.exec(maj("M", "j", v > 0 ? 0 : 1, std::fabs(v), ma, ma));
    r.step(1 + static_cast<int>(rng.uni(0, 20)));
    ASSERT_EQ(r.exec(mag("g", "same", ratio, "enabled", acc)), Err::None) << "seed=" << seed << " case " << k;
    const double dv_max = acc * 0.001 * (1 + 1e-9) + 1e-9;
    double prev = r.axis("S").command_velocity;
    // ramp time to the final gear speed, plus the master's own ramp, plus margin
    const int bound = static_cast<int>((std::fabs(ratio * v) / acc + std::fabs(v) / ma) * 1000) + 50;
    int n = 0;
    while (!r.axis("S").motion(motion_status::GearingLockStatus) && n < bound) {
      r.step();
      ++n;
      const double vel = r.axis("S").command_velocity;
      if (!r.axis("S").motion(motion_status::GearingLockStatus)) {
        ASSERT_LE(std::fabs(vel - prev), dv_max)
            << "seed=" << seed << " case " << k << " cycle " << n << " ratio " << ratio << " master " << v
            << " accel " << acc;
      }
      prev = vel;
    }
    ASSERT_TRUE(r.axis("S").motion(motion_status::GearingLockStatus))
        << "seed=" << seed << " case " << k << ": not locked after " << n << " cycles (ratio " << ratio
        << ", master " << v << ", accel " << acc << ")";
    r.step(static_cast<int>(std::fabs(v) / ma * 1000) + 5);
    EXPECT_NEAR(r.axis("S").command_velocity, ratio * v, 1e-6 * std::fabs(ratio * v) + 1e-9)
        << "seed=" << seed << " case " << k;
  }
}

// Issue 16 item 7. "if a Servo master axis and slave axis are reversed, the
// axes become cross-coupled and unexpected motion may result. For example, if
// you are gearing Axis 0 to Axis 1 ... and then want to change to gearing Axis
// 1 to Axis 0, you must first disable gearing on Axis 0" [seed 003]: a warning,
// not an error. The reversed MAG is allowed; both gears run, cross-coupled:
// with 0.5 both ways an incremental move of 10 on M settles at M = 10 + S/2,
// S = M/2, i.e. M = 40/3 (the "unexpected motion").
TEST(Mag, ReversedPairIsAllowedAndCrossCoupled) {
  Rig r = geared_rig();
  ASSERT_EQ(r.exec(mag("g1", "same", 0.5)), Err::None);  // S follows M
  ASSERT_EQ(r.exec("MAG(M, S, g2, same, 0.5, 1, 1, command, real, disabled, 0, unitspersec2);"), Err::None);
  EXPECT_TRUE(r.tag("g1").ip() && r.tag("g2").ip());
  r.step();
  EXPECT_TRUE(r.axis("M").motion(motion_status::GearingStatus));
  EXPECT_TRUE(r.axis("S").motion(motion_status::GearingStatus));
  ASSERT_EQ(r.exec(mam("M", "mm", 1, 10, 50)), Err::None);
  r.step(3000);
  EXPECT_NEAR(r.axis("M").command_position, 40.0 / 3.0, 1e-6);
  EXPECT_NEAR(r.axis("S").command_position, 20.0 / 3.0, 1e-6);
}

// Issue 16 item 7. "Slave Counts UINT32 ... Master Counts UINT32" [seed 003]:
// 1 .. 4294967295 (not the DINT maximum 2147483647); 0 and 2^32 are ERR 13
// with the operand index (5 SlaveCounts, 6 MasterCounts).
TEST(Mag, FractionCountsAreUint32) {
  Rig r = geared_rig();
  const std::string frac = "fraction_slave_master_counts";
  EXPECT_EQ(r.exec(mag("a", "same", 1, "disabled", 0, frac, 4294967295L, 3)), Err::None);
  EXPECT_EQ(r.exec(mag("b", "same", 1, "disabled", 0, frac, 3, 4294967295L)), Err::None);
  EXPECT_EQ(r.exec(mag("c", "same", 1, "disabled", 0, frac, 4294967296L, 3)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("c").exerr, 5);
  EXPECT_EQ(r.exec(mag("d", "same", 1, "disabled", 0, frac, 3, 4294967296L)), Err::ParameterOutOfRange);
  EXPECT_EQ(r.tag("d").exerr, 6);
  // exact: 4294967295 slave counts per 4294967295 master counts is 1:1
  ASSERT_EQ(r.exec(mag("e", "same", 1, "disabled", 0, frac, 4294967295L, 4294967295L)), Err::None);
  r.exec(mam("M", "mm", 1, 7, 50));
  r.step(1000);
  EXPECT_EQ(r.axis("S").command_position, r.axis("M").command_position);
}
