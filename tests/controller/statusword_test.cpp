// Issue 29 part 4 end to end: the Controller with an emulated drive on the
// SimBus, virtual time; TPDO1's statusword bits flipped on the bus
// (can::SimFault kCorrupt: an XOR of byte 0 or 1). In CSP, MSO ends only
// once bit 12 (drive follows the command) shows; a drive that never sets it
// makes MSO end with ERR 12 at the transition timeout, naming bit 12. Bits
// 7, 11 and 13 are axis tags and give one event on each rising edge.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "rt/controller/host.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

constexpr std::uint32_t kTpdo1 = 0x180 + test::SimController::kNode;

struct Rig : test::SimHost {
  using test::SimHost::SimHost;
  std::vector<Event> events = std::vector<Event>(4096);  ///< every event, in order (room reserved: no allocation in a cycle)
  std::size_t nevents = 0;
  void after_cycle() override {
    Event e;
    while (ctl->pop_event(e))
      if (nevents < events.size()) events[nevents++] = e;
  }
  void exec(const std::string& call) { SimHost::exec(call, /*settle=*/false); }
  void operational() {
    ASSERT_TRUE(run_until([](const Status& s) { return s.axes[1].phase == cia402::Phase::kOperational; }, 5000));
  }
  /// Flip statusword bits on every TPDO1 from now on (byte 0: bits 0..7, byte 1: bits 8..15).
  void flip(std::uint8_t byte, std::uint8_t mask) {
    can::SimFault f;
    f.cob_id = kTpdo1;
    f.action = can::SimFault::Action::kCorrupt;
    f.count = 0;  // every frame
    f.byte = byte;
    f.xor_mask = mask;
    world.bus(0).add_fault(f);
  }
  std::size_t count(Event::Kind k, std::uint64_t value) const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < nevents; ++i) n += events[i].kind == k && events[i].value == value ? 1 : 0;
    return n;
  }
};

TEST(ControllerStatusword, MsoEndsOnlyOnceBit12Shows) {
  Rig r;
  r.operational();
  r.flip(1, 0x10);  // bit 12 cleared in Operation enabled (the emulator sets it there)
  r.exec("MSO(X, mso1)");
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].drive_state == cia402::State::kOperationEnabled; },
                          200));
  r.cycles(100);  // 100 ms in Operation enabled without bit 12
  EXPECT_EQ(r.read("mso1.DN"), 0.0);
  EXPECT_EQ(r.read("mso1.ER"), 0.0);
  EXPECT_EQ(r.read("X.DriveFollowsCommand"), 0.0);
  EXPECT_EQ(r.read("X.ServoActionStatus"), 0.0);
  r.world.bus(0).clear_faults();  // the drive follows now
  int cycles = 0;
  while (r.read("mso1.DN") == 0.0 && cycles < 10) {
    r.step();
    ++cycles;
  }
  EXPECT_EQ(r.read("mso1.DN"), 1.0);
  EXPECT_LE(cycles, 2);  // in the cycle that reads the first TPDO with bit 12
  EXPECT_EQ(r.read("X.DriveFollowsCommand"), 1.0);
  EXPECT_EQ(r.read("mso1.ER"), 0.0);
}

TEST(ControllerStatusword, NeverBit12EndsMsoWithErr12AtTheTransitionTimeout) {
  Rig r([](AxisSpec& x, emulator::EmulatorConfig&) { x.drive.transition_timeout_ns = 300'000'000; });
  r.operational();
  r.flip(1, 0x10);
  r.exec("MSO(X, mso1)");
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].drive_state == cia402::State::kOperationEnabled; },
                          200));
  const double t0 = r.now_s();  // Operation enabled shown, bit 12 not
  ASSERT_TRUE(r.run_until([&](const Status&) { return r.read("mso1.ER") != 0.0; }, 2000));
  EXPECT_EQ(r.read("mso1.ERR"), 12.0);
  EXPECT_EQ(r.read("mso1.DN"), 0.0);
  EXPECT_NEAR(r.now_s() - t0, 0.3, 0.005);  // the transition timeout, not the MSO's own limit
  bool named = false;
  for (std::size_t i = 0; i < r.nevents; ++i)
    if (const Event& e = r.events[i]; e.kind == Event::Kind::kDriveFailed && e.failure.follow_missing) {
      const std::string text = e.failure.to_string();
      named = text.find("bit 12") != std::string::npos;
      EXPECT_TRUE(named) << text;
    }
  EXPECT_TRUE(named) << "no kDriveFailed event with follow_missing";
}

TEST(ControllerStatusword, Bits7_11_13AreTagsWithOneEventPerRisingEdge) {
  Rig r;
  r.operational();
  r.exec("MSO(X, mso1)");
  ASSERT_TRUE(r.run_until([&](const Status&) { return r.read("mso1.DN") != 0.0; }, 2000));
  EXPECT_EQ(r.read("X.DriveWarning"), 0.0);
  EXPECT_EQ(r.read("X.InternalLimitActive"), 0.0);
  EXPECT_EQ(r.read("X.DriveFollowingError"), 0.0);
  struct Bit {
    std::uint8_t byte, mask;
    const char* tag;
    std::uint64_t number;
  };
  for (const Bit& b : {Bit{0, 0x80, "X.DriveWarning", 7}, Bit{1, 0x08, "X.InternalLimitActive", 11},
                       Bit{1, 0x20, "X.DriveFollowingError", 13}}) {
    for (int edge = 1; edge <= 2; ++edge) {
      r.flip(b.byte, b.mask);
      test::reset_allocation_count();
      {
        test::CountAllocationsInScope count;
        r.cycles(50);
      }
      EXPECT_EQ(test::counted_allocations(), 0u) << b.tag;
      EXPECT_EQ(r.read(b.tag), 1.0) << b.tag;
      EXPECT_EQ(r.count(Event::Kind::kDriveStatusBit, b.number), static_cast<std::size_t>(edge)) << b.tag;
      r.world.bus(0).clear_faults();
      r.cycles(5);
      EXPECT_EQ(r.read(b.tag), 0.0) << b.tag;
    }
    const Event* last = nullptr;
    for (std::size_t i = 0; i < r.nevents; ++i)
      if (r.events[i].kind == Event::Kind::kDriveStatusBit && r.events[i].value == b.number) last = &r.events[i];
    ASSERT_NE(last, nullptr);
    EXPECT_EQ(last->axis, 1);
    EXPECT_EQ(last->mode_display, 8);
    const std::string text = describe_drive_status_bit(*last, r.ctl->axis_spec(1), 1);
    EXPECT_NE(text.find("bit " + std::to_string(b.number)), std::string::npos) << text;
    EXPECT_NE(text.find("node 2"), std::string::npos) << text;
  }
  EXPECT_EQ(r.read("mso1.ER"), 0.0);
  EXPECT_EQ(r.read("X.ServoActionStatus"), 1.0);  // reported, the axis runs on
}

}  // namespace
}  // namespace canmotion::rt
