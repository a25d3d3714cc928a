// MAH on a CIP drive end to end (issue 15 item 1): the Controller with an
// emulated CiA 402 drive on the SimBus, virtual time. The planner's homing
// request reaches the drive as mode 6, 0x6098/0x6099/0x609A (0x607C when
// configured) and a rising edge of controlword bit 4; MAH ends PC with
// AxisHomedStatus and the configured home position; a stale "homing
// attained" does not end a second MAH; a homing timeout or a refused homing
// object ends the MAH with ER; back in CSP afterwards. No allocation in any cycle.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "rt/controller/host.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

struct HomingRig : test::SimHost {
  using test::SimHost::SimHost;
  bool saw_bit4 = false;
  bool saw_mode6 = false;
  void after_cycle() override {
    const Status s = status();
    const AxisSnapshot& x = s.axes[1];
    saw_bit4 = saw_bit4 || (x.controlword & 0x10) != 0;
    saw_mode6 = saw_mode6 || x.mode_display == 6;
  }
  bool done_or_error(const std::string& tag, int max_cycles) {
    return run_until([&](const Status&) { return read(tag + ".PC") != 0.0 || read(tag + ".ER") != 0.0; }, max_cycles);
  }
  void servo_on() {
    ASSERT_TRUE(run_until([](const Status& s) { return s.axes[1].phase == cia402::Phase::kOperational; }, 5000));
    exec("MSO(X, mso1)");
    ASSERT_TRUE(run_until([&](const Status&) { return read("mso1.DN") != 0.0; }, 2000)) << "MSO ERR " << read("mso1.ERR");
  }
};

void active_switch_homing(AxisSpec& x, std::int8_t method) {
  x.config.homing.mode = motion::HomingConfig::Mode::Active;
  x.config.homing.sequence = motion::HomingConfig::Sequence::Switch;
  x.config.homing.cia_method = method;
  x.config.homing.home_position = 5;
  x.config.homing.speed_search = 50;  // mm/s -> 50000 counts/s
  x.config.homing.speed_zero = 5;
  x.config.homing.accel = 500;
}

// The homing handshake in both orders of the cycle's burst (RPDOs then
// SYNC, or controller.sync_first): with the SYNC first the drive applies bit
// 4 one SYNC later, and only TPDOs answering a SYNC after that count.
class ControllerHomingOrder : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(Orders, ControllerHomingOrder, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& i) { return i.param ? "SyncFirst" : "RpdosThenSync"; });

TEST_P(ControllerHomingOrder, MahWithMethod35ReachesPcWithAxisHomedStatus) {
  HomingRig r(
      [](AxisSpec& x, emulator::EmulatorConfig& ec) {
        active_switch_homing(x, 35);
        x.config.homing.write_offset = true;
        x.config.homing.offset = 2;  // mm -> 0x607C = 2000 counts
        ec.initial_position = 1234;
      },
      GetParam());
  r.servo_on();
  test::reset_allocation_count();
  {
    r.exec("MAH(X, mah1)");
    test::CountAllocationsInScope count;
    ASSERT_TRUE(r.done_or_error("mah1", 3000)) << "MAH neither PC nor ER after 3 s";
  }
  EXPECT_EQ(test::counted_allocations(), 0u);
  ASSERT_EQ(r.read("mah1.PC"), 1.0) << "MAH ERR " << r.read("mah1.ERR") << " EXERR " << r.read("mah1.EXERR");
  EXPECT_EQ(r.read("X.AxisHomedStatus"), 1.0);
  EXPECT_EQ(r.read("X.HomingStatus"), 0.0);
  EXPECT_TRUE(r.saw_bit4);
  EXPECT_TRUE(r.saw_mode6);
  EXPECT_EQ(r.world.drive(0).read_int(0x6098), 35);
  EXPECT_EQ(r.world.drive(0).read_int(0x6099, 1), 50000);
  EXPECT_EQ(r.world.drive(0).read_int(0x6099, 2), 5000);
  EXPECT_EQ(r.world.drive(0).read_int(0x609A), 500000);
  EXPECT_EQ(r.world.drive(0).read_int(0x607C), 2000);
  EXPECT_NEAR(r.read("X.ActualPosition"), 5.0, 1e-9);
  // Back in CSP: a move works in the homed frame.
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].mode_display == 8; }, 1000));
  r.exec("MAM(X, mam1, Absolute, 8, 20, UnitsPerSec, 200, UnitsPerSec2, 200, UnitsPerSec2, Trapezoidal, 100, 100, "
         "%ofTime, Disabled, Programmed, 0, None, 0, 0)");
  ASSERT_TRUE(r.done_or_error("mam1", 3000));
  ASSERT_EQ(r.read("mam1.PC"), 1.0) << "MAM ERR " << r.read("mam1.ERR");
  r.cycles(50);
  EXPECT_NEAR(r.read("X.ActualPosition"), 8.0, 0.01);
}

// A searching method (home switch, 19): the drive moves to its home reference,
// then MAH is PC. A second MAH after moving away homes again: the first
// homing's "homing attained", still shown when the drive is back in mode 6,
// does not end it (on main it ended the second MAH at once, or never started).
TEST_P(ControllerHomingOrder, SearchingMethodTwiceEachHomesFromWhereTheAxisIs) {
  HomingRig r(
      [](AxisSpec& x, emulator::EmulatorConfig& ec) {
        active_switch_homing(x, 19);
        ec.initial_position = 3000;  // 3 mm from the emulator's home reference
      },
      GetParam());
  r.servo_on();
  r.exec("MAH(X, mah1)");
  const std::int64_t t0 = r.now;
  ASSERT_TRUE(r.done_or_error("mah1", 5000));
  ASSERT_EQ(r.read("mah1.PC"), 1.0) << "MAH ERR " << r.read("mah1.ERR");
  std::printf("MAH method 19 from 3 mm at 50 mm/s: PC after %.1f ms\n", static_cast<double>(r.now - t0) / 1e6);
  EXPECT_GT(r.now - t0, 50'000'000) << "a 3 mm search at 50 mm/s cannot take less than 60 ms";
  EXPECT_EQ(r.world.drive(0).position(), 0);
  EXPECT_NEAR(r.read("X.ActualPosition"), 5.0, 1e-9);
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].mode_display == 8; }, 1000));
  r.exec("MAM(X, mam1, Absolute, 9, 20, UnitsPerSec, 200, UnitsPerSec2, 200, UnitsPerSec2, Trapezoidal, 100, 100, "
         "%ofTime, Disabled, Programmed, 0, None, 0, 0)");
  ASSERT_TRUE(r.done_or_error("mam1", 3000));
  ASSERT_EQ(r.read("mam1.PC"), 1.0);
  r.cycles(20);
  ASSERT_NEAR(r.world.drive(0).position(), 4000, 5);
  r.exec("MAH(X, mah2)");
  const std::int64_t t1 = r.now;
  ASSERT_TRUE(r.done_or_error("mah2", 5000));
  ASSERT_EQ(r.read("mah2.PC"), 1.0) << "MAH ERR " << r.read("mah2.ERR");
  EXPECT_GT(r.now - t1, 50'000'000) << "the second MAH ended before the drive searched";
  EXPECT_EQ(r.world.drive(0).position(), 0);
  EXPECT_NEAR(r.read("X.ActualPosition"), 5.0, 1e-9);
  EXPECT_EQ(r.read("X.AxisHomedStatus"), 1.0);
}

// drive.timeouts.homing_ms: a homing that does not finish ends the MAH with
// ERR 12 (Servo Message Failure) EXERR 16, and bit 4 drops.
TEST(ControllerHoming, HomingTimeoutEndsMahWithEr) {
  HomingRig r([](AxisSpec& x, emulator::EmulatorConfig& ec) {
    active_switch_homing(x, 19);
    x.config.homing.speed_search = 0.001;  // 1 count/s: never there
    x.drive.homing_timeout_ns = 200'000'000;
    ec.initial_position = 100'000;
  });
  r.servo_on();
  r.exec("MAH(X, mah1)");
  const std::int64_t t0 = r.now;
  ASSERT_TRUE(r.done_or_error("mah1", 1000));
  EXPECT_EQ(r.read("mah1.ER"), 1.0);
  EXPECT_EQ(r.read("mah1.ERR"), 12.0);
  EXPECT_EQ(r.read("mah1.EXERR"), 16.0);
  EXPECT_GE(r.now - t0, 200'000'000);
  EXPECT_LE(r.now - t0, 205'000'000);
  EXPECT_EQ(r.read("X.AxisHomedStatus"), 0.0);
  r.cycles(3);
  EXPECT_EQ(r.status().axes[1].controlword & 0x10, 0);
}

// A drive without a homing object (0x6099 absent): MAH ER 12 EXERR 3, bit 4
// never raised.
TEST(ControllerHoming, DriveWithoutAHomingObjectEndsMahWithEr) {
  HomingRig r([](AxisSpec& x, emulator::EmulatorConfig& ec) {
    active_switch_homing(x, 19);
    ec.absent_objects = {0x6099};
  });
  r.servo_on();
  r.exec("MAH(X, mah1)");
  ASSERT_TRUE(r.done_or_error("mah1", 1000));
  EXPECT_EQ(r.read("mah1.ER"), 1.0);
  EXPECT_EQ(r.read("mah1.ERR"), 12.0);
  EXPECT_EQ(r.read("mah1.EXERR"), 3.0);
  EXPECT_FALSE(r.saw_bit4);
}


// drive.mode ip (issue 30 part 2): MAH on the drive switches from mode 7 to
// 6 and back to 7 (not to CSP: the RPDO carries 0x60C1:1), where bit 4
// goes out again and a MAM moves in the homed frame.
TEST(ControllerHomingIp, MahFromIpReturnsToIpAndMoves) {
  HomingRig r([](AxisSpec& x, emulator::EmulatorConfig& ec) {
    active_switch_homing(x, 35);
    x.drive.mode = cia402::Mode::kInterpolatedPosition;
    ec.supported_modes |= cia402::supported_mode_bit(cia402::Mode::kInterpolatedPosition);
    ec.initial_position = 1234;
  });
  r.servo_on();
  EXPECT_EQ(r.status().axes[1].mode_display, 7);
  r.exec("MAH(X, mah1)");
  ASSERT_TRUE(r.done_or_error("mah1", 3000));
  ASSERT_EQ(r.read("mah1.PC"), 1.0) << "MAH ERR " << r.read("mah1.ERR") << " EXERR " << r.read("mah1.EXERR");
  EXPECT_TRUE(r.saw_mode6);
  EXPECT_NEAR(r.read("X.ActualPosition"), 5.0, 1e-9);
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].mode_display == 7; }, 1000));
  ASSERT_TRUE(r.run_until([](const Status& s) { return (s.axes[1].controlword & 0x10) != 0; }, 100))
      << "bit 4 (enable ip mode) back in mode 7";
  r.exec("MAM(X, mam1, Absolute, 8, 20, UnitsPerSec, 200, UnitsPerSec2, 200, UnitsPerSec2, Trapezoidal, 100, 100, "
         "%ofTime, Disabled, Programmed, 0, None, 0, 0)");
  ASSERT_TRUE(r.done_or_error("mam1", 3000));
  ASSERT_EQ(r.read("mam1.PC"), 1.0) << "MAM ERR " << r.read("mam1.ERR");
  r.cycles(50);
  EXPECT_NEAR(r.read("X.ActualPosition"), 8.0, 0.01);
  EXPECT_EQ(r.status().axes[1].mode_display, 7);
}

}  // namespace
}  // namespace canmotion::rt
