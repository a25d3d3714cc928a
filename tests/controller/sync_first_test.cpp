// controller.sync_first (issue 28 item 4): the SYNC goes out first, at the
// cycle's wake-up, and the RPDOs computed in the cycle follow it; the drive
// applies them at the next SYNC. The Controller with an emulated CiA 402
// drive on the SimBus, virtual time, in both orders: where the SYNC is in
// every burst, the one cycle the drive applies a command later, the
// position error compared like with like, enable / disable / fault reset,
// the missed-TPDO count, and no allocation in any cycle.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rt/controller/host.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

constexpr std::uint32_t kSync = 0x080;
constexpr std::uint32_t kRpdo1 = 0x200u + test::SimController::kNode;
constexpr std::uint32_t kTpdo1 = 0x180u + test::SimController::kNode;
constexpr std::size_t kX = 1;  // axis X (axis 0 is the virtual Master)

const char* order_name(bool sync_first) { return sync_first ? "SYNC first" : "RPDOs, then SYNC"; }

/// SimController (axis X on node 2) in one order, driven by ST calls. Every
/// cycle is counted for allocations (checked when the rig goes), and the
/// master's frames of every cycle are checked against the order: exactly one
/// SYNC, the first frame with sync_first, else after the last RPDO.
struct OrderRig : test::SimController {
  bool sync_first;
  std::unique_ptr<ControllerHost> host = std::make_unique<ControllerHost>(*ctl);
  std::uint64_t bursts = 0;         ///< cycles whose frames were checked
  std::uint64_t misplaced = 0;      ///< of them, with the SYNC not where the order puts it
  std::string first_misplaced;      ///< the first one, described
  std::vector<std::uint32_t> burst; ///< the last cycle's transmitted identifiers, in order
  std::uint64_t read_after_sync = 0; ///< frames the controller read after its SYNC in the same cycle

  explicit OrderRig(bool first, const std::function<void(AxisSpec&, emulator::EmulatorConfig&)>& tweak = {})
      : SimController(tweak, first), sync_first(first) {
    ctl->set_trace(true);
    test::reset_allocation_count();
  }
  ~OrderRig() override {
    EXPECT_EQ(test::counted_allocations(), 0u) << test::counted_bytes() << " bytes allocated in the cycle";
    EXPECT_EQ(read_after_sync, 0u) << "frames read after the cycle's SYNC (" << order_name(sync_first) << ")";
  }
  OrderRig(const OrderRig&) = delete;
  OrderRig& operator=(const OrderRig&) = delete;

  void step() {
    {
      test::CountAllocationsInScope count;
      world.begin_cycle(now);
      ctl->cycle(now);
      world.end_cycle(now);
    }
    const std::int64_t t = now;
    now += kPeriod;
    burst.clear();
    TraceRecord tr;
    bool synced = false;
    while (ctl->pop_trace(tr)) {
      if (tr.tx && tr.frame.t_ns == t) burst.push_back(tr.frame.frame.id);
      if (tr.tx && tr.frame.frame.id == kSync) synced = true;
      // Every frame of a cycle is read before its SYNC goes out (sync_first:
      // a drive's answer to this SYNC, however fast, is read next cycle).
      if (!tr.tx && synced) ++read_after_sync;
    }
    check_burst();
  }
  void check_burst() {
    if (burst.empty()) return;
    ++bursts;
    std::size_t syncs = 0, sync_at = 0, last_rpdo = 0;
    bool rpdo = false;
    for (std::size_t i = 0; i < burst.size(); ++i) {
      if (burst[i] == kSync) {
        ++syncs;
        sync_at = i;
      }
      if (burst[i] == kRpdo1) {
        rpdo = true;
        last_rpdo = i;
      }
    }
    const bool ok = syncs == 1 && (sync_first ? sync_at == 0 : (!rpdo || sync_at > last_rpdo));
    if (!ok && misplaced++ == 0) {
      first_misplaced = "cycle " + std::to_string(now / kPeriod - 1) + ":";
      for (const std::uint32_t id : burst) first_misplaced += " " + std::to_string(id);
    }
  }
  bool run_until(const std::function<bool()>& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      step();
      if (done()) return true;
    }
    return false;
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i) step();
  }
  double read(const std::string& tag) {
    std::string e;
    const auto v = host->read(tag, &e);
    EXPECT_TRUE(v) << tag << ": " << e;
    return v.value_or(-1.0);
  }
  /// Queue an ST call and run until the planner took it.
  void exec(const std::string& call) {
    std::string name;
    const auto err = host->execute(call, &name);
    ASSERT_FALSE(err) << call << ": " << *err;
    ASSERT_TRUE(run_until([&] { return host->settled(); }, 10)) << call;
  }
  /// Run until `tag`.DN or .ER (or `tag`.PC with pc); the number of cycles it took, or -1.
  int wait(const std::string& tag, int max_cycles, bool pc = false) {
    const std::string done = tag + (pc ? ".PC" : ".DN");
    for (int i = 1; i <= max_cycles; ++i) {
      step();
      if (read(done) != 0.0 || read(tag + ".ER") != 0.0) return i;
    }
    return -1;
  }
  const AxisSnapshot& axis() { return host->refresh().axes[kX]; }
  void operational() {
    ASSERT_TRUE(run_until([&] { return axis().phase == cia402::Phase::kOperational; }, 5000))
        << axis().failure.to_string();
  }
  /// MSO `tag` to DN; the cycles it took.
  int servo_on(const std::string& tag) {
    exec("MSO(X, " + tag + ")");
    const int n = wait(tag, 3000);
    EXPECT_EQ(read(tag + ".DN"), 1.0) << tag << " ERR " << read(tag + ".ERR") << "; " << axis().failure.to_string();
    return n;
  }
  static std::string mam(const std::string& tag, double position, double speed) {
    char b[256];
    std::snprintf(b, sizeof b,
                  "MAM(X, %s, Absolute, %.6f, %.6f, UnitsPerSec, 1000, UnitsPerSec2, 1000, UnitsPerSec2, "
                  "Trapezoidal, 100, 100, %%ofTime, Disabled, Programmed, 0, None, 0, 0)",
                  tag.c_str(), position, speed);
    return b;
  }
};

class SyncOrder : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(Orders, SyncOrder, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& i) { return i.param ? "SyncFirst" : "RpdosThenSync"; });

// Boot, enable, a move, disable: every cycle sends exactly one SYNC, with
// sync_first as the first frame of the cycle's burst (before the RPDO, the
// SDO requests of the boot and the heartbeat), else after the RPDO.
TEST_P(SyncOrder, EveryBurstHasOneSyncWhereTheOrderPutsIt) {
  OrderRig r(GetParam());
  r.operational();
  r.servo_on("mso1");
  r.exec(OrderRig::mam("mam1", 10.0, 50.0));
  ASSERT_GT(r.wait("mam1", 2000, true), 0);
  r.exec("MSF(X, msf1)");
  ASSERT_GT(r.wait("msf1", 2000), 0);
  r.cycles(20);
  EXPECT_GT(r.bursts, 300u);
  EXPECT_EQ(r.misplaced, 0u) << order_name(GetParam()) << ": first misplaced burst (identifiers) " << r.first_misplaced;
  Status s = r.status();
  EXPECT_EQ(s.buses[0].syncs_sent, s.cycle + 1) << "one SYNC per cycle";
  EXPECT_EQ(s.axes[kX].tpdo_missed, 0u);
}

/// One move at 50 mm/s on a drive that follows its target exactly
/// (lag_cycles 0), recorded cycle by cycle from the cycle that took the MAM.
struct MoveRecord {
  std::vector<std::int32_t> target;   ///< the RPDO target computed in the cycle (counts)
  std::vector<std::int64_t> applied;  ///< 0x607A the drive applied at that cycle's SYNC
  std::vector<std::int32_t> position; ///< the drive's position after that SYNC
  double max_position_error = 0;      ///< |X.PositionError|, mm
  double axis_fault = -1;
};
MoveRecord record_move(bool sync_first, double tolerance, bool planner_lag = true) {
  OrderRig r(sync_first, [&](AxisSpec& x, emulator::EmulatorConfig& ec) {
    x.config.position_error_tolerance = tolerance;
    ec.lag_cycles = 0;
  });
  if (!planner_lag) (void)r.ctl->planner().set_command_lag(0);  // a planner that ignores the order
  MoveRecord m;
  r.operational();
  r.servo_on("mso1");
  r.exec(OrderRig::mam("mam1", 100.0, 50.0));  // taken in the last cycle exec() ran
  auto sample = [&] {
    m.target.push_back(static_cast<int>(r.axis().target_counts));
    m.applied.push_back(r.world.drive(0).read_int(0x607A));
    m.position.push_back(r.world.drive(0).position());
    m.max_position_error = std::max(m.max_position_error, std::abs(r.read("X.PositionError")));
  };
  sample();
  for (int i = 0; i < 4000 && r.read("mam1.PC") == 0.0 && r.read("mam1.ER") == 0.0 && r.read("X.AxisFault") == 0.0; ++i) {
    r.step();
    sample();
  }
  for (int i = 0; i < 5; ++i) {
    r.step();
    sample();
  }
  m.axis_fault = r.read("X.AxisFault");
  if (m.axis_fault == 0.0) {
    EXPECT_EQ(r.read("mam1.PC"), 1.0) << order_name(sync_first) << ": MAM ERR " << r.read("mam1.ERR");
    EXPECT_EQ(r.world.drive(0).position(), 100000);
  }
  return m;
}

// The drive applies a cycle's target at that cycle's SYNC (RPDOs, then
// SYNC), or one SYNC later (SYNC first): 0x607A after cycle k is the target
// of cycle k, or of cycle k-1. The planner's targets are the same in both
// orders; the drive's applied targets and positions are the default order's,
// one cycle later.
TEST(SyncFirst, TheDriveAppliesEachCommandOneCycleLater) {
  const MoveRecord a = record_move(false, 0.0);
  const MoveRecord b = record_move(true, 0.0);
  ASSERT_GT(a.target.size(), 2000u);  // 100 mm at 50 mm/s
  std::size_t moving = 0;
  for (std::size_t k = 0; k < a.target.size(); ++k) {
    ASSERT_EQ(a.applied[k], a.target[k]) << "RPDOs, then SYNC: cycle " << k;
    if (k > 0) {
      ASSERT_EQ(b.applied[k], b.target[k - 1]) << "SYNC first: cycle " << k;
      moving += b.target[k] != b.target[k - 1] ? 1 : 0;
    }
  }
  EXPECT_GT(moving, 1900u) << "the check needs targets that change from cycle to cycle";
  // The planner ends the move (PC) in the same cycle in both orders; the
  // drive gets there one cycle later with the SYNC first.
  ASSERT_EQ(b.target.size(), a.target.size());
  for (std::size_t k = 0; k + 1 < a.target.size(); ++k) {
    ASSERT_EQ(b.target[k], a.target[k]) << "cycle " << k;
    ASSERT_EQ(b.applied[k + 1], a.applied[k]) << "cycle " << k;
    ASSERT_EQ(b.position[k + 1], a.position[k]) << "cycle " << k;
  }
}

// position_error_tolerance 0.02 mm with a move at 50 mm/s (0.05 mm per
// cycle) on a drive that follows exactly: compared with the command the
// drive applied, the error is rounding only and the move completes in both
// orders; the PositionError tag reads the same in both. A planner that
// compared the SYNC-first feedback with the last cycle's command would see
// one cycle of travel and fault: shown with the lag taken away.
TEST(SyncFirst, PositionErrorComparesTheCommandTheDriveApplied) {
  const MoveRecord a = record_move(false, 0.02);
  const MoveRecord b = record_move(true, 0.02);
  std::printf("max |PositionError| at 50 mm/s, tolerance 0.02 mm: RPDOs then SYNC %.6f mm, SYNC first %.6f mm\n",
              a.max_position_error, b.max_position_error);
  EXPECT_EQ(a.axis_fault, 0.0);
  EXPECT_EQ(b.axis_fault, 0.0);
  EXPECT_NEAR(b.max_position_error, a.max_position_error, 1e-9);
  EXPECT_NEAR(a.max_position_error, 0.05, 0.001) << "the tag is the command minus the actual a cycle behind it";
  const MoveRecord naive = record_move(true, 0.02, false);
  EXPECT_NE(naive.axis_fault, 0.0) << "without the lag the SYNC-first feedback is one cycle of travel behind";
}

// Enable, disable, enable again, a drive fault with MAFR and a move after
// it; the cycles each MSO took (first, after MSF, after MAFR).
void enable_disable_fault_reset_and_move(OrderRig& r, std::array<int, 3>& mso) {
  r.operational();
  mso[0] = r.servo_on("mso1");
  EXPECT_EQ(r.axis().drive_state, cia402::State::kOperationEnabled);
  r.exec("MSF(X, msf1)");
  ASSERT_GT(r.wait("msf1", 2000), 0);
  ASSERT_TRUE(r.run_until([&] { return r.world.drive(0).state() == cia402::State::kSwitchOnDisabled; }, 100))
      << "the drive did not leave Operation enabled";
  r.cycles(10);
  EXPECT_EQ(r.read("X.DriveEnableStatus"), 0.0);
  mso[1] = r.servo_on("mso2");
  r.world.drive(0).inject_fault(0x2310);
  ASSERT_TRUE(r.run_until([&] { return r.read("X.AxisFault") != 0.0; }, 100)) << "the drive fault never reached the axis";
  r.exec("MAFR(X, mafr1)");
  ASSERT_GT(r.wait("mafr1", 3000), 0);
  ASSERT_EQ(r.read("mafr1.DN"), 1.0) << "MAFR ERR " << r.read("mafr1.ERR") << "; " << r.axis().failure.to_string();
  mso[2] = r.servo_on("mso3");
  r.exec(OrderRig::mam("mam1", 5.0, 20.0));
  ASSERT_GT(r.wait("mam1", 3000, true), 0);
  ASSERT_EQ(r.read("mam1.PC"), 1.0);
  r.cycles(20);
  EXPECT_EQ(r.world.drive(0).position(), 5000);
  EXPECT_EQ(r.read("X.AxisFault"), 0.0);
  EXPECT_EQ(r.misplaced, 0u) << r.first_misplaced;
}

std::array<int, 3> enable_disable_fault_reset_and_move(bool sync_first) {
  std::array<int, 3> mso{-1, -1, -1};
  OrderRig r(sync_first);
  enable_disable_fault_reset_and_move(r, mso);
  std::printf("%s: MSO took %d, %d and %d cycles (first, after MSF, after MAFR)\n", order_name(sync_first), mso[0],
              mso[1], mso[2]);
  return mso;
}

TEST_P(SyncOrder, EnableDisableFaultResetAndMove) {
  for (const int n : enable_disable_fault_reset_and_move(GetParam())) {
    EXPECT_GT(n, 0);
    EXPECT_LE(n, 100);  // (the first MSO also waits for the drive to become ready: about 40 cycles)
  }
}

// With the SYNC first each controlword reaches the drive one SYNC later and
// its statusword shows it one cycle later: an enable (transitions 2, 3, 4)
// takes a few cycles more, never fewer.
TEST(SyncFirst, AnEnableTakesAFewCyclesMore) {
  const std::array<int, 3> a = enable_disable_fault_reset_and_move(false);
  const std::array<int, 3> b = enable_disable_fault_reset_and_move(true);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_GT(b[i], a[i]) << "MSO " << i + 1;
    EXPECT_LE(b[i], a[i] + 4) << "MSO " << i + 1;
  }
}

// TPDO1 lost for n cycles is counted n times, in both orders (with the SYNC
// first the TPDO answering SYNC k is expected in cycle k+1, after SYNC k+1),
// and none is counted while nothing is lost.
TEST_P(SyncOrder, LostTpdosAreCountedOncePerCycle) {
  OrderRig r(GetParam());
  r.operational();
  r.servo_on("mso1");
  r.cycles(500);
  EXPECT_EQ(r.axis().tpdo_missed, 0u);
  for (const std::uint64_t n : {1u, 7u}) {
    const std::uint64_t before = r.axis().tpdo_missed;
    r.world.bus(0).add_fault({kTpdo1, can::SimFault::Action::kDrop, 0, n});
    r.cycles(static_cast<int>(n) + 10);
    r.world.bus(0).clear_faults();
    EXPECT_EQ(r.axis().tpdo_missed - before, n) << order_name(GetParam());
  }
}

}  // namespace
}  // namespace canmotion::rt
