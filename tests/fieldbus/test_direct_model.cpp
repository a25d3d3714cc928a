// MDS on the drive side (issue 5, seed 002), master + emulated drive on the
// SimBus with a virtual clock: the ramp objects written at boot shape the CSV
// velocity (0x6083/0x6084, 0x2010:1/2, 0x2011), the CST load model and SLAT
// 0/1/2 (0x2020..0x2022) switch between torque and speed control exactly per
// the seed's velocity-error rules and time delay, and a refused mode switch
// (0x6061 never shows the 0x6060 request) fails the proxy after
// DriveConfig::mode_switch_timeout_ns, naming node and modes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "fieldbus/emulator/sim_rig.hpp"

using namespace canmotion;
using cia402::SdoWrite;
using emulator::SimRig;
using emulator::SimRigConfig;
namespace obj = cia402::obj;

namespace {

constexpr std::uint8_t kNode = 2;
constexpr double kDt = 0.001;

/// A strict drive that has the MDS objects 0x2010..0x2022 (and 0x1016):
/// these tests model the ramps and SLAT they configure.
emulator::EmulatorConfig with_mds_objects() {
  emulator::EmulatorConfig e;
  e.behaviour.optional_objects_absent = false;
  return e;
}

SimRigConfig one_drive(std::vector<SdoWrite> writes, emulator::EmulatorConfig e = with_mds_objects()) {
  SimRigConfig c;
  c.nodes = {kNode};
  c.drive.pdo_profile = cia402::PdoProfile::kCspCsvCst;
  c.drive.extra_writes = std::move(writes);
  c.emulator = e;
  return c;
}

void boot_and_enable(SimRig& rig) {
  rig.power_on();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().all_operational() || rig.network().any_failed(); }, 3000));
  ASSERT_FALSE(rig.network().any_failed()) << rig.network().at(0).failure().to_string();
  rig.network().enable_all();
  ASSERT_TRUE(rig.run_until([&] { return rig.network().all_enabled() || rig.network().any_failed(); }, 2000));
  ASSERT_FALSE(rig.network().any_failed()) << rig.network().at(0).failure().to_string();
}

}  // namespace

TEST(DirectModel, RampObjectsWrittenAtBootShapeTheCsvVelocity) {
  const std::vector<SdoWrite> w = {{obj::kProfileAcceleration, 0, 4, 100'000},
                                   {obj::kProfileDeceleration, 0, 4, 250'000},
                                   {obj::kRampVelocityLimit, obj::kRampVelocityPositiveSub, 4, 60'000},
                                   {obj::kRampVelocityLimit, obj::kRampVelocityNegativeSub, 4, 40'000}};
  SimRig rig(one_drive(w));
  boot_and_enable(rig);
  auto& emu = rig.emulator(kNode);
  EXPECT_EQ(emu.read_int(0x6083), 100'000);
  EXPECT_EQ(emu.read_int(0x6084), 250'000);
  EXPECT_EQ(emu.read_int(0x2010, 1), 60'000);
  EXPECT_EQ(emu.read_int(0x2010, 2), 40'000);
  auto& d = rig.drive(kNode);
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCsv));
  ASSERT_TRUE(rig.run_until([&] { return d.feedback().mode_display == 9; }, 20));
  // Step to 50 000 counts/s: +100 counts/s per 1 ms SYNC (0x6083), never more.
  d.set_target_velocity(50'000);
  int cycles_to_reach = -1;
  for (int i = 0; i < 700; ++i) {
    const double v0 = emu.velocity();
    rig.step();
    const double dv = emu.velocity() - v0;
    ASSERT_LE(dv, 100'000 * kDt + 1e-6) << "cycle " << i;
    ASSERT_GE(dv, -1e-6) << "cycle " << i;
    if (cycles_to_reach < 0 && emu.velocity() == 50'000.0) cycles_to_reach = i;
  }
  // 500 ramp cycles plus the RPDO-to-SYNC delay and the model's lag (2 SYNCs).
  EXPECT_GE(cycles_to_reach, 499);
  EXPECT_LE(cycles_to_reach, 504);
  EXPECT_EQ(d.feedback().velocity, 50'000);  // 0x606C in TPDO2
  // Above the positive ramp velocity: limited to 60 000 (0x2010:1).
  d.set_target_velocity(1'000'000);
  for (int i = 0; i < 200; ++i) rig.step();
  EXPECT_EQ(emu.velocity(), 60'000.0);
  // Stop: down at 0x6084 (-250 counts/s per SYNC): 240 SYNCs from 60 000.
  d.set_target_velocity(0);
  for (int i = 0; i < 4; ++i) rig.step();
  for (int i = 0; i < 230; ++i) {
    const double v0 = emu.velocity();
    rig.step();
    ASSERT_NEAR(emu.velocity() - v0, -250.0, 1e-6) << "cycle " << i;
  }
  ASSERT_TRUE(rig.run_until([&] { return emu.velocity() == 0.0; }, 20));
  // Negative: accelerating away from zero uses 0x6083; limited by 0x2010:2.
  d.set_target_velocity(-1'000'000);
  for (int i = 0; i < 3; ++i) rig.step();
  const double v0 = emu.velocity();
  rig.step();
  EXPECT_NEAR(emu.velocity() - v0, -100.0, 1e-6);
  for (int i = 0; i < 600; ++i) rig.step();
  EXPECT_EQ(emu.velocity(), -40'000.0);
  EXPECT_EQ(d.feedback().velocity, -40'000);
  EXPECT_FALSE(d.failed()) << d.failure().to_string();
}

TEST(DirectModel, JerkControlGivesAnSCurveWithoutOvershoot) {
  const std::vector<SdoWrite> w = {{obj::kProfileAcceleration, 0, 4, 100'000},
                                   {obj::kProfileDeceleration, 0, 4, 100'000},
                                   {obj::kRampVelocityLimit, 1, 4, 50'000},
                                   {obj::kRampVelocityLimit, 2, 4, 50'000},
                                   {obj::kRampJerkControl, 0, 1, 50}};
  SimRig rig(one_drive(w));
  boot_and_enable(rig);
  auto& emu = rig.emulator(kNode);
  EXPECT_EQ(emu.read_int(0x2011), 50);
  auto& d = rig.drive(kNode);
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCsv));
  for (int i = 0; i < 5; ++i) rig.step();
  d.set_target_velocity(50'000);
  // Full-scale ramp 0.5 s; 50 %: two jerk segments of 125 ms, J = 800 000 counts/s^3.
  const double jerk = 100'000 / 0.125;
  double a_prev = 0;
  double v_prev = emu.velocity();
  int reached = -1;
  for (int i = 0; i < 1200; ++i) {
    rig.step();
    const double v = emu.velocity();
    const double a = (v - v_prev) / kDt;
    ASSERT_LE(a, 100'000 + 1e-6) << "cycle " << i;
    ASSERT_GE(a, -1e-6) << "cycle " << i;         // monotonic
    ASSERT_LE(v, 50'000.0) << "cycle " << i;      // no overshoot
    if (reached < 0) {
      ASSERT_LE(std::abs(a - a_prev), jerk * kDt + 1e-3) << "cycle " << i;
    }
    if (reached < 0 && v == 50'000.0) reached = i;
    a_prev = a;
    v_prev = v;
  }
  // Slower than the trapezoid (500 ms) by about one jerk segment.
  EXPECT_GT(reached, 560);
  EXPECT_LT(reached, 700);
}

TEST(DirectModel, CstPlainTorqueFollowsTheLoadModel) {
  emulator::EmulatorConfig e;
  e.behaviour.optional_objects_absent = false;  // a drive with the MDS objects 0x2010..0x2022 (and 0x1016)
  e.lag_cycles = 0;
  e.rated_torque_acceleration = 1'000'000;
  e.viscous_friction = 0.01;
  e.load_torque = 20;
  SimRig rig(one_drive({{obj::kSlatConfiguration, 0, 1, 0}}, e));
  boot_and_enable(rig);
  auto& emu = rig.emulator(kNode);
  auto& d = rig.drive(kNode);
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCst));
  d.set_target_torque(200);
  for (int i = 0; i < 400; ++i) {
    const double v0 = emu.velocity();
    rig.step();
    if (emu.mode_display() != 10) continue;
    // dv = (T - load - b v) / 1000 * A * dt
    ASSERT_NEAR(emu.velocity() - v0, (200 - 20 - 0.01 * v0) / 1000.0 * 1e6 * kDt, 1e-6) << "cycle " << i;
    ASSERT_FALSE(emu.slat_speed_control());
  }
  EXPECT_EQ(d.feedback().torque, 200);  // 0x6077 in TPDO2 = the command in plain torque control
  // Steady state where T = load + b v: 18 000 counts/s.
  EXPECT_NEAR(emu.velocity(), 18'000, 400);
}

namespace {

/// Run CST with SLAT `mode`, checking every SYNC against the seed's rules,
/// recomputed here from the observed velocities: mode 1 enters speed control
/// when Velocity Error > set point has held for the time delay and leaves it
/// when Speed Error < 0; mode 2 enters when Velocity Error < -set point has
/// held for the delay and leaves when Speed Error > 0. Returns the number of
/// torque->speed and speed->torque switches seen.
struct SlatRun {
  int to_speed = 0;
  int to_torque = 0;
};

SlatRun run_slat(SimRig& rig, int mode, double set_point, int delay_ms, int cycles) {
  auto& emu = rig.emulator(kNode);
  auto& d = rig.drive(kNode);
  SlatRun r;
  int held = 0;
  for (int i = 0; i < cycles; ++i) {
    const double v = emu.velocity();
    const bool speed = emu.slat_speed_control();
    const double vcmd = d.target_velocity();  // lag 0: the RPDO of this cycle acts at this SYNC
    const double err = vcmd - v;              // Velocity Error = command - actual
    bool expect;
    if (speed) {
      expect = mode == 1 ? !(err < 0) : !(err > 0);
      held = 0;
    } else {
      const bool cond = mode == 1 ? err > set_point : err < -set_point;
      held = cond ? held + 1 : 0;
      expect = cond && held >= delay_ms;  // 1 ms SYNC
    }
    rig.step();
    EXPECT_EQ(emu.slat_speed_control(), expect) << "SLAT " << mode << " cycle " << i << " v " << v << " cmd " << vcmd;
    if (!speed && emu.slat_speed_control()) ++r.to_speed;
    if (speed && !emu.slat_speed_control()) ++r.to_torque;
    if (!emu.slat_speed_control()) {
      EXPECT_DOUBLE_EQ(emu.torque(), d.target_torque()) << "torque control applies 0x6071, cycle " << i;
    }
    if (::testing::Test::HasFailure()) break;
  }
  return r;
}

}  // namespace

TEST(DirectModel, Slat1MinSpeedTorqueSwitchesPerTheSeed) {
  emulator::EmulatorConfig e;
  e.behaviour.optional_objects_absent = false;  // a drive with the MDS objects 0x2010..0x2022 (and 0x1016)
  e.lag_cycles = 0;
  e.rated_torque_acceleration = 1'000'000;
  e.viscous_friction = 0.01;
  SimRig rig(one_drive({{obj::kSlatConfiguration, 0, 1, 1}, {obj::kSlatSetPoint, 0, 4, 2'000}, {obj::kSlatTimeDelay, 0, 2, 5}}, e));
  boot_and_enable(rig);
  auto& emu = rig.emulator(kNode);
  auto& d = rig.drive(kNode);
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCst));
  ASSERT_TRUE(rig.run_until([&] { return d.feedback().mode_display == 10; }, 20));
  d.set_target_torque(0);
  d.set_target_velocity(10'000);
  // At rest the error (10 000) exceeds the set point: speed control after 5 ms,
  // then the speed loop brings the motor to the command.
  SlatRun a = run_slat(rig, 1, 2'000, 5, 400);
  EXPECT_EQ(a.to_speed, 1);
  EXPECT_TRUE(emu.slat_speed_control());
  EXPECT_NEAR(emu.velocity(), 10'000, 1);
  // Command lowered live below the actual: Speed Error < 0 -> torque control at
  // once; with no torque the friction slows the motor until the error exceeds
  // the set point again (v < 2 000) for 5 ms -> speed control, back to 4 000.
  d.set_target_velocity(4'000);
  SlatRun b = run_slat(rig, 1, 2'000, 5, 800);
  EXPECT_EQ(b.to_torque, 1);
  EXPECT_EQ(b.to_speed, 1);
  EXPECT_TRUE(emu.slat_speed_control());
  EXPECT_NEAR(emu.velocity(), 4'000, 1);
  EXPECT_LT(d.feedback().velocity, 4'001);
}

TEST(DirectModel, Slat2MaxSpeedTorqueSwitchesPerTheSeed) {
  emulator::EmulatorConfig e;
  e.behaviour.optional_objects_absent = false;  // a drive with the MDS objects 0x2010..0x2022 (and 0x1016)
  e.lag_cycles = 0;
  e.rated_torque_acceleration = 1'000'000;
  e.viscous_friction = 0.01;
  SimRig rig(one_drive({{obj::kSlatConfiguration, 0, 1, 2}, {obj::kSlatSetPoint, 0, 4, 1'000}, {obj::kSlatTimeDelay, 0, 2, 3}}, e));
  boot_and_enable(rig);
  auto& emu = rig.emulator(kNode);
  auto& d = rig.drive(kNode);
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCst));
  ASSERT_TRUE(rig.run_until([&] { return d.feedback().mode_display == 10; }, 20));
  d.set_target_velocity(5'000);
  d.set_target_torque(300);  // alone it would run to 30 000 counts/s
  SlatRun a = run_slat(rig, 2, 1'000, 3, 500);
  EXPECT_EQ(a.to_speed, 1);
  EXPECT_TRUE(emu.slat_speed_control());
  EXPECT_NEAR(emu.velocity(), 5'000, 1);  // held at the maximum speed
  // A higher command: Speed Error > 0 -> torque control at once, the torque
  // accelerates past command + set point -> speed control at 20 000.
  d.set_target_velocity(20'000);
  SlatRun b = run_slat(rig, 2, 1'000, 3, 800);
  EXPECT_EQ(b.to_torque, 1);
  EXPECT_EQ(b.to_speed, 1);
  EXPECT_NEAR(emu.velocity(), 20'000, 1);
  // Speed control holds against the friction (200 per mille at 20 000), not the 300 commanded.
  EXPECT_NEAR(d.feedback().torque, 200, 1);
}

TEST(DirectModel, SlatObjectsRejectInvalidValues) {
  emulator::EmulatorConfig e;
  e.behaviour.optional_objects_absent = false;  // a drive with the MDS objects 0x2010..0x2022 (and 0x1016)
  emulator::Emulator emu(e);
  const std::uint8_t three[] = {3};
  const std::uint8_t too_much[] = {101};
  EXPECT_EQ(emu.sdo_write(obj::kSlatConfiguration, 0, three), canopen::SdoAbort::kInvalidValue);
  EXPECT_EQ(emu.sdo_write(obj::kRampJerkControl, 0, too_much), canopen::SdoAbort::kValueTooHigh);
  const std::uint8_t two[] = {2};
  EXPECT_EQ(emu.sdo_write(obj::kSlatConfiguration, 0, two), canopen::SdoAbort::kNone);
  const std::uint8_t wide[] = {1, 0};
  EXPECT_EQ(emu.sdo_write(obj::kSlatConfiguration, 0, wide), canopen::SdoAbort::kLengthTooHigh);
}

TEST(DirectModel, RefusedModeSwitchFailsAfterTheTimeout) {
  SimRigConfig c = one_drive({});
  c.drive.mode_switch_timeout_ns = 50'000'000;
  SimRig rig(c);
  boot_and_enable(rig);
  auto& d = rig.drive(kNode);
  rig.emulator(kNode).set_refuse_mode_switch(true);
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCsv));
  const std::int64_t t0 = rig.now_ns();
  ASSERT_TRUE(rig.run_until([&] { return d.failed(); }, 200));
  const cia402::Failure& f = d.failure();
  EXPECT_EQ(f.kind, cia402::FailureKind::kModeSwitchTimeout);
  EXPECT_GT(rig.now_ns() - t0, 50'000'000);
  EXPECT_LE(rig.now_ns() - t0, 53'000'000);
  EXPECT_EQ(f.node, kNode);
  EXPECT_EQ(f.mode_requested, 9);
  EXPECT_EQ(f.mode_shown, 8);
  EXPECT_EQ(f.timeout_ns, 50'000'000);
  const std::string s = f.to_string();
  EXPECT_NE(s.find("node 2"), std::string::npos) << s;
  EXPECT_NE(s.find("mode switch to 9 (cyclic synchronous velocity (CSV))"), std::string::npos) << s;
  EXPECT_NE(s.find("still shows 8 (cyclic synchronous position (CSP))"), std::string::npos) << s;
  EXPECT_NE(s.find("50.0 ms"), std::string::npos) << s;
  // A fault reset clears it; an accepted switch does not fail.
  rig.emulator(kNode).set_refuse_mode_switch(false);
  d.fault_reset();
  EXPECT_FALSE(d.failed());
  d.enable();
  ASSERT_TRUE(rig.run_until([&] { return d.enabled(); }, 500));
  ASSERT_TRUE(d.set_mode(cia402::Mode::kCst));
  for (int i = 0; i < 100; ++i) rig.step();
  EXPECT_FALSE(d.failed()) << d.failure().to_string();
  EXPECT_EQ(d.feedback().mode_display, 10);
}

TEST(DirectModel, AcceptedModeSwitchWithinTheTimeoutDoesNotFail) {
  SimRigConfig c = one_drive({});
  c.drive.mode_switch_timeout_ns = 5'000'000;  // the emulator shows 0x6061 within 2 cycles
  SimRig rig(c);
  boot_and_enable(rig);
  auto& d = rig.drive(kNode);
  for (auto m : {cia402::Mode::kCsv, cia402::Mode::kCst, cia402::Mode::kCsp, cia402::Mode::kCsv}) {
    ASSERT_TRUE(d.set_mode(m));
    for (int i = 0; i < 20; ++i) rig.step();
    EXPECT_EQ(d.feedback().mode_display, static_cast<std::int8_t>(m));
  }
  EXPECT_FALSE(d.failed()) << d.failure().to_string();
}
