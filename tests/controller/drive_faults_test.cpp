// The fault matrix on the SimBus (issue 12): the Controller with an emulated
// CiA 402 drive in virtual time, each fault with its reaction (what the axis
// and the drive proxy show, and when) and its recovery without restarting
// the controller. The same scenarios run over vcan with separate processes
// (tests/faults/); the reaction times measured here are in BENCHMARKS.md.
#include <gtest/gtest.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fieldbus/canopen/sdo_abort.hpp"
#include "rt/controller/controller.hpp"
#include "rt/controller/host.hpp"
#include "rt/controller/sim_world.hpp"
#include "tests/support/allocation_counter.hpp"

namespace canmotion::rt {
namespace {

constexpr std::int64_t kPeriod = 1'000'000;  // 1 ms
constexpr std::uint8_t kNode = 2;
constexpr std::uint32_t kDriveHeartbeatId = 0x700 + kNode;
double ms(std::int64_t ns) { return static_cast<double>(ns) / 1e6; }

/// One CIP axis "X" (node 2, 1000 counts per mm) with an emulated drive on
/// one SimBus, driven through ST calls like a script.
struct FaultRig {
  SimWorld world;
  std::unique_ptr<Controller> ctl;
  std::unique_ptr<ControllerHost> host;
  std::int64_t now = 0;
  std::int64_t last_hb_rx_ns = -1;  ///< receive time of the drive's last heartbeat (trace)
  std::uint64_t hb_rx = 0;
  /// Controlword of the RPDO1 sent in each cycle (cycle time -> controlword), from the trace.
  std::vector<std::pair<std::int64_t, std::uint16_t>> cw;
  std::function<void()> each_cycle;  ///< test hook after every cycle

  explicit FaultRig(const std::function<void(AxisSpec&, emulator::EmulatorConfig&)>& tweak = {}, bool power_on = true) {
    ControllerSpec spec;
    spec.period_ns = kPeriod;
    BusSpec bus;
    bus.name = "sim0";
    bus.transport = &world.add_bus("sim0");
    spec.buses.push_back(bus);
    AxisSpec x;
    x.name = "X";
    x.config.type = motion::AxisType::CipDrive;
    x.config.conversion_constant = 1000;
    x.config.max_speed = 200;
    x.config.max_accel = 2000;
    x.config.max_decel = 2000;
    x.bus = 0;
    x.drive.node = kNode;
    emulator::EmulatorConfig ec;
    ec.node = kNode;
    ec.behaviour = emulator::EmulatorBehaviour::strict();
    if (tweak) tweak(x, ec);
    spec.axes.push_back(x);
    world.add_drive(0, ec);
    ctl = std::make_unique<Controller>(spec);
    host = std::make_unique<ControllerHost>(*ctl);
    ctl->set_trace(true);
    test::reset_allocation_count();
    if (power_on) {
      world.power_on(0);
    } else {
      world.disconnect(0);  // the drive is off (or not there)
    }
  }
  /// Every cycle allocates nothing (the RT path), faults and recoveries
  /// included: checked when the rig goes.
  ~FaultRig() {
    if (check_allocations) {
      EXPECT_EQ(test::counted_allocations(), 0u) << test::counted_bytes() << " bytes allocated in the cycle";
    }
  }
  bool check_allocations = true;
  FaultRig(const FaultRig&) = delete;
  FaultRig& operator=(const FaultRig&) = delete;
  void step() {
    {
      test::CountAllocationsInScope count;
      world.begin_cycle(now);
      ctl->cycle(now);
      world.end_cycle(now);
    }
    now += kPeriod;
    TraceRecord tr;
    while (ctl->pop_trace(tr)) {
      const can::Frame& f = tr.frame.frame;
      if (!tr.tx && f.id == kDriveHeartbeatId) {
        last_hb_rx_ns = tr.frame.t_ns;
        ++hb_rx;
      }
      if (tr.tx && f.id == 0x200u + kNode && f.len >= 2)
        cw.emplace_back(tr.frame.t_ns, static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8)));
    }
    if (each_cycle) each_cycle();
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i) step();
  }
  Status status() const {
    Status s;
    ctl->read_status(s);
    return s;
  }
  const AxisSnapshot& axis() {
    host->refresh();
    return host->refresh().axes[0];
  }
  bool run_until(const std::function<bool()>& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      step();
      if (done()) return true;
    }
    return false;
  }
  double read(const std::string& tag) {
    std::string e;
    auto v = host->read(tag, &e);
    EXPECT_TRUE(v) << tag << ": " << e;
    return v.value_or(-1);
  }
  /// Execute an ST call and run until the planner took it.
  void exec(const std::string& call) {
    std::string ctl_name;
    const auto err = host->execute(call, &ctl_name);
    ASSERT_FALSE(err) << call << ": " << *err;
    ASSERT_TRUE(run_until([&] { return host->settled(); }, 10)) << call;
  }
  /// Run until `tag` (a control tag bit) is 1; fails the test after max cycles.
  bool wait(const std::string& tag, int max_cycles) {
    return run_until([&] { return read(tag) != 0.0; }, max_cycles);
  }
  bool operational() {
    return run_until([&] { return axis().phase == cia402::Phase::kOperational; }, 5000);
  }
  /// Boot, MSO, and jog forward at 10 mm/s.
  void enable_and_jog() {
    ASSERT_TRUE(operational()) << axis().failure.to_string();
    exec("MSO(X, mso1)");
    ASSERT_TRUE(wait("mso1.DN", 2000)) << "MSO ERR " << read("mso1.ERR");
    exec("MAJ(X, maj1, Forward, 10, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, Trapezoidal, 100, 100, "
         "%ofTime, Disabled, Programmed, 0, None)");
    cycles(300);
    ASSERT_EQ(read("X.JogStatus"), 1.0);
  }
  /// After a fault: reset with `reset` (MAFR or MASR), MSO, and a move that
  /// arrives. The axis is usable again without restarting anything.
  void recover(const std::string& reset) {
    exec(reset + "(X, rst)");
    ASSERT_TRUE(run_until([&] { return read("rst.DN") != 0.0 || read("rst.ER") != 0.0; }, 5000));
    ASSERT_EQ(read("rst.DN"), 1.0) << reset << " ERR " << read("rst.ERR") << " EXERR " << read("rst.EXERR")
                                   << "; failure: " << axis().failure.to_string();
    enable_and_move();
  }
  void enable_and_move() {
    exec("MSO(X, mso2)");
    ASSERT_TRUE(run_until([&] { return read("mso2.DN") != 0.0 || read("mso2.ER") != 0.0; }, 3000));
    ASSERT_EQ(read("mso2.DN"), 1.0) << "MSO after the reset: ERR " << read("mso2.ERR") << " EXERR "
                                    << read("mso2.EXERR");
    const double target = read("X.ActualPosition") + 5.0;
    char mam[256];
    std::snprintf(mam, sizeof mam,
                  "MAM(X, mam2, Absolute, %.6f, 20, UnitsPerSec, 200, UnitsPerSec2, 200, UnitsPerSec2, Trapezoidal, "
                  "100, 100, %%ofTime, Disabled, Programmed, 0, None, 0, 0)",
                  target);
    exec(mam);
    ASSERT_TRUE(run_until([&] { return read("mam2.PC") != 0.0 || read("mam2.ER") != 0.0; }, 5000));
    ASSERT_EQ(read("mam2.PC"), 1.0) << "MAM ERR " << read("mam2.ERR");
    cycles(50);
    EXPECT_NEAR(read("X.ActualPosition"), target, 0.01);
    EXPECT_EQ(read("X.AxisFault"), 0.0);
  }
};

bool fault_bit(double axis_fault, unsigned bit) { return (static_cast<std::uint32_t>(axis_fault) >> bit) & 1u; }
bool module_fault(double axis_fault) { return fault_bit(axis_fault, motion::axis_fault::ModuleFault); }
bool physical_fault(double axis_fault) { return fault_bit(axis_fault, motion::axis_fault::PhysicalAxisFault); }
bool config_fault(double axis_fault) { return fault_bit(axis_fault, motion::axis_fault::ConfigFault); }

// ---------------------------------------------------------------------------
// Drive vanishes (stops heartbeats and TPDOs) while jogging.
// Reaction: the master's heartbeat consumer (3 x the drive's 0x1017 period
// unless drive.heartbeat_timeout) expires; the axis gets AxisFault.ModuleFault
// (node_lost exception, default action Shutdown: the jog is aborted, the
// drive disabled) in the cycle that detects it: at most the consumer time
// plus one cycle after the last heartbeat was received, never before.
// Recovery: the drive comes back (boot-up: reconfigured), MASR, MSO, move.
TEST(DriveFaults, VanishedDriveFaultsTheAxisWithinConsumerTimePlusOneCycle) {
  FaultRig r;
  r.enable_and_jog();
  const std::int64_t consumer_ns = 3 * 100 * 1'000'000;  // DriveConfig default: 0x1017 = 100 ms
  r.world.disconnect(0);
  const std::int64_t vanished = r.now;
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 1000)) << "the lost drive was not noticed";
  const std::int64_t faulted_at = r.status().time_ns;  // the cycle that showed the fault
  const std::int64_t after_hb = faulted_at - r.last_hb_rx_ns;
  std::printf("vanished drive: last heartbeat received %.1f ms before the drive vanished; axis faulted %.1f ms after "
              "that heartbeat (consumer time %.1f ms, cycle %.1f ms)\n",
              ms(vanished - r.last_hb_rx_ns), ms(after_hb), ms(consumer_ns), ms(kPeriod));
  EXPECT_GT(after_hb, consumer_ns) << "faulted before the consumer time expired";
  EXPECT_LE(after_hb, consumer_ns + kPeriod) << "faulted later than the consumer time plus one cycle";
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  EXPECT_EQ(r.read("X.ServoActionStatus"), 0.0);
  EXPECT_EQ(r.axis().failure.kind, cia402::FailureKind::kHeartbeatLost);
  // The drive comes back (killed and restarted: boot-up) and is reconfigured.
  r.cycles(100);
  r.world.power_cycle(0, r.now);
  r.recover("MASR");
}

// ---------------------------------------------------------------------------
// EMCY fault while jogging, then the Logix recovery MAFR; WAIT r.DN; MSO; move.
// Reaction: the EMCY and the Fault statusword arrive together; the axis
// faults (PhysicalAxisFault, drive_fault action Stop Drive) in that cycle.
// MAFR: the fault reset (bit 7 rising) goes out in the RPDO of the cycle
// that executes MAFR (the proxy sends 0x0000 in Fault, so the edge is there);
// DN in the first cycle whose feedback shows the drive out of Fault, not before.
TEST(DriveFaults, EmcyFaultThenMafrResetsOnTheNextRpdoAndDnWhenTheDriveLeftFault) {
  FaultRig r;
  r.enable_and_jog();
  const std::int64_t injected = r.now;
  r.world.drive(0).inject_fault(0xFF00);  // as a write of 0x2000 does
  ASSERT_TRUE(r.run_until([&] { return physical_fault(r.read("X.AxisFault")); }, 100));
  const std::int64_t faulted_at = r.status().time_ns;
  std::printf("EMCY fault: injected before the SYNC of %.0f ms, axis faulted in the cycle of %.0f ms\n", ms(injected),
              ms(faulted_at));
  EXPECT_LE(faulted_at - injected, 2 * kPeriod);  // the drive faults at its SYNC; its EMCY/TPDO come next cycle
  EXPECT_EQ(r.read("X.LastEmcy"), 0xFF00);
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  EXPECT_TRUE(r.axis().drive_state == cia402::State::kFault || r.axis().drive_state == cia402::State::kFaultReactionActive);
  r.cycles(20);
  EXPECT_EQ(r.axis().drive_state, cia402::State::kFault);
  ASSERT_FALSE(r.cw.empty());
  EXPECT_EQ(r.cw.back().second & 0x80, 0) << "bit 7 must be clear in Fault before the reset";
  // MAFR runs in the next cycle.
  std::string ctl_name;
  ASSERT_FALSE(r.host->execute("MAFR(X, rst)", &ctl_name));
  const std::int64_t mafr_cycle = r.now;
  r.step();
  ASSERT_TRUE(r.host->settled());
  ASSERT_EQ(r.cw.back().first, mafr_cycle);
  EXPECT_EQ(r.cw.back().second, 0x0080) << "the fault reset is not in the RPDO of the MAFR's cycle";
  EXPECT_EQ(r.read("rst.DN"), 0.0) << "MAFR DN while the drive is still in Fault";
  int cycles = 0;
  while (r.read("rst.DN") == 0.0 && r.read("rst.ER") == 0.0 && cycles < 1000) {
    EXPECT_EQ(r.axis().drive_state, cia402::State::kFault) << "the drive left Fault but MAFR is not DN";
    r.step();
    ++cycles;
  }
  ASSERT_EQ(r.read("rst.DN"), 1.0) << "MAFR ERR " << r.read("rst.ERR");
  EXPECT_NE(r.axis().drive_state, cia402::State::kFault);
  std::printf("MAFR: reset controlword in the MAFR's cycle, DN %d cycle(s) later\n", cycles);
  EXPECT_LE(cycles, 2);
  EXPECT_EQ(r.read("X.AxisFault"), 0.0);
  r.enable_and_move();
}

// A drive that does not leave Fault after the reset (here: its RPDOs are
// lost, so it never sees bit 7): MAFR ends with ERR 12 (EXERR 16) after the
// transition timeout, the failure names transition 15, and the axis is
// faulted again. Once the drive hears the master again, MAFR works.
TEST(DriveFaults, FaultResetTimeoutEndsMafrWithErrorAndAClearMessage) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig&) { x.drive.transition_timeout_ns = 200'000'000; });
  r.enable_and_jog();
  r.world.drive(0).inject_fault(0x2310);
  ASSERT_TRUE(r.run_until([&] { return physical_fault(r.read("X.AxisFault")); }, 100));
  r.cycles(10);
  r.world.bus(0).add_fault({0x200u + kNode, can::SimFault::Action::kDrop, 0, 0});  // every RPDO1 lost
  const std::int64_t t0 = r.now;
  r.exec("MAFR(X, rst)");
  ASSERT_TRUE(r.run_until([&] { return r.read("rst.DN") != 0.0 || r.read("rst.ER") != 0.0; }, 2000));
  const std::int64_t t_er = r.status().time_ns;
  EXPECT_EQ(r.read("rst.ER"), 1.0);
  EXPECT_EQ(r.read("rst.ERR"), 12.0);
  EXPECT_EQ(r.read("rst.EXERR"), 16.0);
  EXPECT_GT(t_er - t0, 200'000'000);
  EXPECT_LE(t_er - t0, 200'000'000 + 3 * kPeriod);
  const std::string why = r.axis().failure.to_string();
  EXPECT_NE(why.find("transition 15 (Fault -> Switch on disabled)"), std::string::npos) << why;
  EXPECT_NE(why.find("timed out after"), std::string::npos) << why;
  EXPECT_NE(why.find("last EMCY 0x2310"), std::string::npos) << why;
  r.cycles(2);
  EXPECT_TRUE(physical_fault(r.read("X.AxisFault"))) << "the unreset drive fault is latched again";
  r.world.bus(0).clear_faults();
  r.recover("MAFR");
}

// ---------------------------------------------------------------------------
// The drive reboots while operational (reset or power cycle, heartbeats go on):
// the unexpected boot-up faults the axis at once (drive fault: Stop Drive)
// and the boot and configuration run again without being asked, so that
// MAFR (DN once it is configured and out of Fault) + MSO + a move work.
TEST(DriveFaults, DriveRebootWhileOperationalIsReconfiguredAndMafrMsoWork) {
  FaultRig r;
  r.enable_and_jog();
  const std::int64_t rebooted = r.now;
  r.world.power_cycle(0, r.now);
  ASSERT_TRUE(r.run_until([&] { return physical_fault(r.read("X.AxisFault")); }, 100));
  const std::int64_t faulted_at = r.status().time_ns;
  std::printf("drive reboot: boot-up sent at %.0f ms, axis faulted in the cycle of %.0f ms\n", ms(rebooted), ms(faulted_at));
  EXPECT_LE(faulted_at - rebooted, kPeriod);
  EXPECT_EQ(r.axis().failure.kind, cia402::FailureKind::kUnexpectedBootUp) << r.axis().failure.to_string();
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  EXPECT_NE(r.axis().phase, cia402::Phase::kOperational);
  EXPECT_NE(r.axis().phase, cia402::Phase::kFailed);
  // Configured again by itself.
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kOperational; }, 2000));
  EXPECT_EQ(r.ctl->network(0).at(0).reboots(), 1u);
  EXPECT_EQ(r.world.drive(0).nmt_state(), canopen::NmtState::kOperational);
  EXPECT_EQ(r.world.drive(0).read_int(0x60C2, 1), 1) << "0x60C2 not written again";
  r.recover("MAFR");
}

// MAFR right after the reboot, while the drive is still being configured:
// DN waits for the configuration, then MSO works.
TEST(DriveFaults, MafrDuringTheReconfigurationWaitsForIt) {
  FaultRig r;
  r.enable_and_jog();
  r.world.power_cycle(0, r.now);
  ASSERT_TRUE(r.run_until([&] { return physical_fault(r.read("X.AxisFault")); }, 100));
  ASSERT_EQ(r.axis().phase, cia402::Phase::kConfiguring);
  r.exec("MAFR(X, rst)");
  EXPECT_EQ(r.read("rst.DN"), 0.0);
  ASSERT_TRUE(r.run_until([&] { return r.read("rst.DN") != 0.0 || r.read("rst.ER") != 0.0; }, 2000));
  ASSERT_EQ(r.read("rst.DN"), 1.0) << "ERR " << r.read("rst.ERR");
  EXPECT_EQ(r.axis().phase, cia402::Phase::kOperational);
  r.enable_and_move();
}

// ---------------------------------------------------------------------------
// NMT state while running: a drive that drops to pre-operational or stopped
// (CiA 301 0x1029 on a communication error, or another tool) stops its
// PDOs. Its next heartbeat shows it: the axis faults at once (node lost:
// ModuleFault, default action Shutdown). MASR runs the boot again (NMT
// start included), then MSO and a move.
class NmtStateWhileRunning : public ::testing::TestWithParam<std::uint8_t> {};

TEST_P(NmtStateWhileRunning, FaultsTheAxisAtTheHeartbeatAndMasrRestartsTheNode) {
  FaultRig r;
  auto& tool = r.world.bus(0).add_endpoint("tool");
  r.enable_and_jog();
  const std::uint64_t hb_before = r.hb_rx;
  can::Frame nmt;
  nmt.id = 0x000;
  nmt.len = 2;
  nmt.data[0] = GetParam();  // 0x80 enter pre-operational, 0x02 stop
  nmt.data[1] = kNode;
  ASSERT_EQ(tool.send(nmt), can::SendResult::kOk);
  const std::int64_t sent = r.now;
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 1000));
  std::printf("NMT 0x%02X sent at %.0f ms: the drive's next heartbeat received at %.0f ms, axis faulted in the cycle "
              "of %.0f ms (0x1017 = 100 ms)\n",
              GetParam(), ms(sent), ms(r.last_hb_rx_ns), ms(r.status().time_ns));
  EXPECT_EQ(r.hb_rx, hb_before + 1) << "the axis faulted at the first heartbeat after the NMT change";
  EXPECT_GE(r.status().time_ns, r.last_hb_rx_ns);
  EXPECT_LE(r.status().time_ns - r.last_hb_rx_ns, kPeriod) << "not in the cycle that received the heartbeat";
  EXPECT_EQ(r.axis().failure.kind, cia402::FailureKind::kNmtState) << r.axis().failure.to_string();
  const std::string why = r.axis().failure.to_string();
  EXPECT_NE(why.find(GetParam() == 0x80 ? "pre-operational" : "stopped"), std::string::npos) << why;
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  r.recover("MASR");
  EXPECT_EQ(r.world.drive(0).nmt_state(), canopen::NmtState::kOperational);
}

INSTANTIATE_TEST_SUITE_P(DriveFaults, NmtStateWhileRunning, ::testing::Values(std::uint8_t{0x80}, std::uint8_t{0x02}));

// A drive that left NMT operational keeps its CiA 402 state: here Operation
// enabled (no fault: another tool's NMT enter pre-operational). After MASR
// its first TPDOs still show Operation enabled while canmotiond, the axis
// being servo off, sends Disable voltage. A drive does not always show a
// commanded transition in the next TPDO: tests/peers/cia402_peer.py samples
// its TPDO at the SYNC before it acts on that SYNC's controlword, a drive
// may act in its own slower cycle, or leave Operation enabled only after a
// ramp (0x605B/0x605C). Here the RPDOs reach the drive 2.5 cycles late: it
// shows each controlword's effect 3 TPDOs later. An MSO issued right after
// MASR's DN must not end DN on a report from before the Disable voltage:
// the drive then takes it (transition 9) and sits in Switch on disabled
// while MSO said DN; the axis switched itself off at the next TPDO and the
// MAM ended with ERR 5, servo off (found by vcan.peer.nmt_preop, where the
// Python peer lagged several cycles in the VM). The enable waits until the
// drive has shown that it left Operation enabled, then goes 2, 3, 4.
TEST(DriveFaults, MsoAfterMasrWaitsUntilTheStillEnabledDriveWasDisabled) {
  FaultRig r;
  r.check_allocations = false;  // the SimBus's delayed-frame queue allocates (test infrastructure, not the cycle)
  auto& tool = r.world.bus(0).add_endpoint("tool");
  r.enable_and_jog();
  can::Frame nmt;
  nmt.id = 0x000;
  nmt.len = 2;
  nmt.data[0] = 0x80;  // enter pre-operational
  nmt.data[1] = kNode;
  ASSERT_EQ(tool.send(nmt), can::SendResult::kOk);
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 1000));
  ASSERT_EQ(r.world.drive(0).state(), cia402::State::kOperationEnabled);
  can::SimFault late;
  late.cob_id = 0x200u + kNode;
  late.action = can::SimFault::Action::kDelay;
  late.count = 0;  // every RPDO1 from now on
  late.delay_ns = 2 * kPeriod + kPeriod / 2;
  r.world.bus(0).add_fault(late);
  const std::size_t cw_before = r.cw.size();
  r.exec("MASR(X, rst)");
  ASSERT_TRUE(r.run_until([&] { return r.read("rst.DN") != 0.0 || r.read("rst.ER") != 0.0; }, 5000));
  ASSERT_EQ(r.read("rst.DN"), 1.0) << "MASR ERR " << r.read("rst.ERR") << "; " << r.axis().failure.to_string();
  r.exec("MSO(X, mso2)");
  ASSERT_TRUE(r.run_until([&] { return r.read("mso2.DN") != 0.0 || r.read("mso2.ER") != 0.0; }, 3000));
  ASSERT_EQ(r.read("mso2.DN"), 1.0) << "MSO ERR " << r.read("mso2.ERR") << " EXERR " << r.read("mso2.EXERR");
  // The drive took the Disable voltage and was enabled again (9, then 2, 3, 4).
  bool disabled = false;
  for (std::size_t i = cw_before; i < r.cw.size(); ++i) disabled = disabled || r.cw[i].second == 0x0000;
  EXPECT_TRUE(disabled) << "no Disable voltage sent after MASR";
  r.cycles(20);
  EXPECT_EQ(r.world.drive(0).state(), cia402::State::kOperationEnabled);
  EXPECT_EQ(r.read("X.DriveEnableStatus"), 1.0) << "the axis switched itself off after MSO's DN";
  const double target = r.read("X.ActualPosition") + 5.0;
  char mam[256];
  std::snprintf(mam, sizeof mam,
                "MAM(X, mam2, Absolute, %.6f, 20, UnitsPerSec, 200, UnitsPerSec2, 200, UnitsPerSec2, Trapezoidal, "
                "100, 100, %%ofTime, Disabled, Programmed, 0, None, 0, 0)",
                target);
  r.exec(mam);
  ASSERT_TRUE(r.run_until([&] { return r.read("mam2.PC") != 0.0 || r.read("mam2.ER") != 0.0; }, 5000));
  ASSERT_EQ(r.read("mam2.PC"), 1.0) << "MAM ERR " << r.read("mam2.ERR");
  r.cycles(50);
  EXPECT_NEAR(r.read("X.ActualPosition"), target, 0.01);
}

// ---------------------------------------------------------------------------
// The master's heartbeat no longer reaches a strict drive that watches it
// (0x1016): the drive faults (EMCY 0x8130) and, per its 0x1029:1 error
// behaviour, leaves NMT operational: 0 (the default) Pre-operational, 2
// Stopped. It sends no more TPDOs, so its Fault never shows in one.
// Reaction: at its next heartbeat the axis faults (node lost: ModuleFault);
// a Pre-operational node still answers SDO: the master reads 0x6041, and the
// drive's Fault shows as a drive fault too (PhysicalAxisFault, drive state
// Fault); the message names the node, the NMT state, the statusword and the
// EMCY. A Stopped node answers no SDO (CiA 301): nothing is read, and the
// message says so. Recovery once the heartbeat reaches the drive again: MASR
// configures the node again without resetting it (NMT enter pre-operational
// when Stopped, the SDO configuration, NMT start) and resets the Fault it
// took; MSO and a move work. On main these drives ran without 0x1029
// (error_behaviour = false): with it the Fault was not seen, and MASR ended
// with ERR 12 (EXERR 16) with the re-started drive still in Fault.
class MasterHeartbeatLost : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(MasterHeartbeatLost, DriveLeavesOperationalItsFaultIsReportedAndMasrRecovers) {
  const std::uint32_t behaviour = GetParam();  // 0x1029:1
  const bool stopped = behaviour == 2;
  FaultRig r([&](AxisSpec& x, emulator::EmulatorConfig& e) {
    e.behaviour.optional_objects_absent = false;  // the drive has 0x1016: it watches the master
    if (behaviour != 0) x.drive.extra_writes.push_back({0x1029, 1, 1, behaviour});
  });
  // What goes over the bus (the tap runs inside the cycle: no allocation).
  std::int64_t emcy_at = -1;
  int sdo_requests = 0, nmt_preop = 0, nmt_start = 0, nmt_reset = 0;
  r.world.bus(0).set_tap([&](const can::TimedFrame& f, std::string_view) {
    const can::Frame& c = f.frame;
    if (c.id == 0x080u + kNode && c.len >= 2 && c.data[0] == 0x30 && c.data[1] == 0x81 && emcy_at < 0) emcy_at = f.t_ns;
    if (c.id == 0x600u + kNode) ++sdo_requests;
    if (c.id == 0 && c.len == 2 && c.data[1] == kNode) {
      nmt_preop += c.data[0] == 0x80 ? 1 : 0;
      nmt_start += c.data[0] == 0x01 ? 1 : 0;
      nmt_reset += c.data[0] == 0x81 || c.data[0] == 0x82 ? 1 : 0;
    }
  });
  std::vector<std::string> reported;  // kDriveFailed messages, as canmotiond logs them
  std::int64_t read_at = -1;         // the cycle that reported the statusword read over SDO
  r.each_cycle = [&] {
    Event e;
    while (r.ctl->pop_event(e)) {
      if (e.kind != Event::Kind::kDriveFailed) continue;
      reported.push_back(e.failure.to_string());
      if (read_at < 0 && reported.back().find("read over SDO") != std::string::npos) read_at = r.status().time_ns;
    }
  };
  r.enable_and_jog();
  ASSERT_EQ(r.world.drive(0).read_int(0x1029, 1), static_cast<std::int64_t>(behaviour));
  const std::uint64_t boot_ups = r.world.drive(0).counters().boot_ups;
  reported.clear();
  sdo_requests = 0;
  r.world.bus(0).add_fault({0x77Fu, can::SimFault::Action::kDrop, 0, 0});  // the master's heartbeat (node 127)
  const std::int64_t dropped_at = r.now;
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 1000));
  const std::int64_t faulted_at = r.status().time_ns;
  ASSERT_GT(emcy_at, 0) << "no EMCY 0x8130 from the drive";
  EXPECT_EQ(r.axis().failure.kind, cia402::FailureKind::kNmtState) << r.axis().failure.to_string();
  EXPECT_EQ(r.axis().failure.nmt_state, stopped ? canopen::NmtState::kStopped : canopen::NmtState::kPreOperational);
  EXPECT_EQ(r.world.drive(0).nmt_state(), stopped ? canopen::NmtState::kStopped : canopen::NmtState::kPreOperational);
  // (Stopped, the drive processes no SYNC: its fault reaction does not end)
  EXPECT_TRUE(r.world.drive(0).state() == cia402::State::kFault ||
              (stopped && r.world.drive(0).state() == cia402::State::kFaultReactionActive));
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  EXPECT_EQ(r.read("X.LastEmcy"), 0x8130);
  // The statusword read (Pre-operational) takes an SDO round trip.
  r.cycles(20);
  const cia402::Failure f = r.axis().failure;
  const std::string why = f.to_string();
  std::printf("0x1029:1 = %u: master heartbeat dropped at %.0f ms, EMCY 0x8130 at %.0f ms, axis faulted in the cycle of "
              "%.0f ms, statusword read reported in the cycle of %.0f ms: %s\n",
              behaviour, ms(dropped_at), ms(emcy_at), ms(faulted_at), ms(read_at), why.c_str());
  for (const char* part : {"node 2: left NMT operational: its heartbeat shows ", stopped ? "stopped" : "pre-operational",
                           "CiA 301 0x1029", "last EMCY 0x8130 (life guard error or heartbeat error)"})
    EXPECT_NE(why.find(part), std::string::npos) << "missing '" << part << "' in: " << why;
  if (stopped) {
    EXPECT_NE(why.find("a stopped node answers no SDO: its CiA 402 state is not known (its last TPDO showed Operation "
                       "enabled, statusword 0x"),
              std::string::npos)
        << why;
    EXPECT_EQ(sdo_requests, 0) << "SDO requests to a stopped node";
  } else {
    EXPECT_NE(why.find("; the drive is in Fault (statusword 0x0228, read over SDO)"), std::string::npos) << why;
    EXPECT_EQ(sdo_requests, 1) << "one read of 0x6041 (the EMCY came: no read of 0x603F)";
    EXPECT_EQ(r.axis().drive_state, cia402::State::kFault);
    EXPECT_TRUE(physical_fault(r.read("X.AxisFault"))) << "the drive's own Fault is not seen";
  }
  // canmotiond logs the failure when it is recorded, and again with the detail that came later.
  ASSERT_FALSE(reported.empty());
  EXPECT_EQ(reported.back(), why);
  // Recovery: the master's heartbeat reaches the drive again.
  r.world.bus(0).clear_faults();
  r.cycles(150);  // at least one heartbeat (100 ms): the drive's cause is gone
  nmt_preop = nmt_start = nmt_reset = 0;
  sdo_requests = 0;
  const std::uint32_t edges = r.ctl->network(0).at(0).fault_reset_edges();
  const std::int64_t masr_at = r.now;
  r.exec("MASR(X, rst)");
  ASSERT_TRUE(r.run_until([&] { return r.read("rst.DN") != 0.0 || r.read("rst.ER") != 0.0; }, 5000));
  ASSERT_EQ(r.read("rst.DN"), 1.0) << "MASR ERR " << r.read("rst.ERR") << " EXERR " << r.read("rst.EXERR")
                                   << "; failure: " << r.axis().failure.to_string();
  std::printf("MASR at %.0f ms: DN %.0f ms later (%d SDO requests of the configuration, %u fault-reset edge(s))\n",
              ms(masr_at), ms(r.status().time_ns - masr_at), sdo_requests,
              r.ctl->network(0).at(0).fault_reset_edges() - edges);
  EXPECT_EQ(nmt_reset, 0) << "the node was reset";
  EXPECT_EQ(r.world.drive(0).counters().boot_ups, boot_ups) << "the node was reset";
  EXPECT_EQ(nmt_preop, stopped ? 1 : 0) << "NMT enter pre-operational (only from Stopped, before its configuration)";
  EXPECT_EQ(nmt_start, 1);
  EXPECT_GT(sdo_requests, 20) << "the node was not configured again";
  EXPECT_GE(r.ctl->network(0).at(0).fault_reset_edges(), edges + 1) << "the drive's Fault was not reset";
  EXPECT_EQ(r.world.drive(0).nmt_state(), canopen::NmtState::kOperational);
  EXPECT_NE(r.world.drive(0).state(), cia402::State::kFault);
  r.enable_and_move();
  r.world.bus(0).set_tap(nullptr);
  r.each_cycle = nullptr;
}

// MASR at once, while the read of 0x6041 is still out (a drive that takes
// 5 ms to answer SDO): the restart cancels it, and its cancelled result is
// not taken for one of the boot's transfers (it failed the boot as "configuration
// ... aborted with 0x08000000" before the boot skipped results it did not ask for).
TEST(DriveFaults, MasrWhileTheStatuswordReadIsOutRunsTheBoot) {
  FaultRig r([](AxisSpec&, emulator::EmulatorConfig& e) {
    e.behaviour.optional_objects_absent = false;  // the drive has 0x1016: it watches the master
    e.behaviour.sdo_reply_delay_ns = 5'000'000;
  });
  r.enable_and_jog();
  r.world.bus(0).add_fault({0x77Fu, can::SimFault::Action::kDrop, 0, 0});  // the master's heartbeat
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 1000));
  r.world.bus(0).clear_faults();
  r.exec("MASR(X, rst)");  // the next cycle: the read went out in the last one
  EXPECT_EQ(r.axis().phase, cia402::Phase::kConfiguring) << r.axis().failure.to_string();
  ASSERT_TRUE(r.run_until([&] { return r.read("rst.DN") != 0.0 || r.read("rst.ER") != 0.0; }, 5000));
  ASSERT_EQ(r.read("rst.DN"), 1.0) << "MASR ERR " << r.read("rst.ERR") << "; failure: " << r.axis().failure.to_string();
  r.enable_and_move();
}

INSTANTIATE_TEST_SUITE_P(DriveFaults, MasterHeartbeatLost, ::testing::Values(0u, 2u),
                         [](const ::testing::TestParamInfo<std::uint32_t>& i) {
                           return i.param == 0 ? std::string("PreOperational0x1029is0") : std::string("Stopped0x1029is2");
                         });

// ---------------------------------------------------------------------------
// Boot failures. An axis whose drive refused its configuration, or never
// answered, is not configured: MSO, MAH (and MDS) end with ERR 11 at once, a
// MSO issued while it was booting with ERR 12 (EXERR 16) as soon as the boot
// fails; AxisFault shows ConfigFault (refused) or ModuleFault (no answer).
// MAFR runs the boot again; so does a boot-up of the node (drive repaired,
// replaced or switched on).

// SDO abort at boot, with the configuration key that causes it.
TEST(DriveFaults, RefusedConfigurationWriteEndsMsoAtOnceAndNamesTheKey) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig&) {
    x.drive.extra_writes.push_back({0x2FFF, 0, 4, 1});  // no such object in the drive
    x.drive.hints.extra.push_back("axes[0].drive.sdo_writes[0] (line 12)");
  });
  r.exec("MSO(X, mso0)");  // while booting: waits for the drive
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kFailed; }, 3000));
  const std::int64_t failed_at = r.status().time_ns;
  ASSERT_TRUE(r.run_until([&] { return r.read("mso0.ER") != 0.0; }, 2)) << "the pending MSO did not end at once";
  EXPECT_EQ(r.read("mso0.ERR"), 12.0);
  EXPECT_EQ(r.read("mso0.EXERR"), 16.0);
  EXPECT_LE(r.status().time_ns - failed_at, kPeriod);
  const cia402::Failure f = r.axis().failure;
  EXPECT_EQ(f.kind, cia402::FailureKind::kSdoAbort);
  const std::string why = f.to_string();
  std::printf("%s\n", why.c_str());
  for (const char* part : {"node 2", "0x2FFF:0", "the drive refused it", "0x06020000", "object does not exist",
                           "axes[0].drive.sdo_writes[0] (line 12)"})
    EXPECT_NE(why.find(part), std::string::npos) << "missing '" << part << "' in: " << why;
  EXPECT_LT(f.waited_ns, 10 * kPeriod) << why;  // the response's time on the cycle's clock
  EXPECT_TRUE(config_fault(r.read("X.AxisFault")));
  EXPECT_EQ(r.read("X.ServoActionStatus"), 0.0);
  r.exec("MSO(X, mso1)");
  EXPECT_EQ(r.read("mso1.ER"), 1.0);
  EXPECT_EQ(r.read("mso1.ERR"), 11.0) << "MSO on an axis whose drive refused its configuration";
  r.exec("MAH(X, mah1)");
  EXPECT_EQ(r.read("mah1.ERR"), 11.0);
  // MAFR runs the boot again; the same refusal ends it with ER.
  r.exec("MAFR(X, rst)");
  ASSERT_TRUE(r.run_until([&] { return r.read("rst.DN") != 0.0 || r.read("rst.ER") != 0.0; }, 3000));
  EXPECT_EQ(r.read("rst.ER"), 1.0);
  EXPECT_EQ(r.read("rst.ERR"), 12.0);
  EXPECT_EQ(r.axis().failure.kind, cia402::FailureKind::kSdoAbort);
}

// A drive without the optional 0x1016 and with two PDOs per direction (like
// the independent peer drive): 0x1016 is written only when the drive is to
// watch the master, and the unused PDOs it does not have are fine.
TEST(DriveFaults, DriveWithoutHeartbeatConsumerAndWithFewerPdosBoots) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig& e) {
    x.drive.consumer_heartbeat_ms = 0;  // master_heartbeat_timeout_ms: 0
    e.absent_objects = {0x1016, 0x1402, 0x1403, 0x1602, 0x1603, 0x1802, 0x1803, 0x1A02, 0x1A03};
  });
  ASSERT_TRUE(r.operational()) << r.axis().failure.to_string();
  EXPECT_EQ(r.ctl->network(0).at(0).tolerated_aborts(), 5u)
      << "RPDO3/4 and TPDO3/4 answered 0x06020000, 0x60C2:2 0x06010002 (read-only: 0x60C2:1 written in ms)";
  r.enable_and_move();
}

// The same drive asked to watch the master: the refused 0x1016 write names
// the key that leaves it out.
TEST(DriveFaults, RefusedHeartbeatConsumerNamesTheKeyThatLeavesItOut) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig& e) {
    x.drive.consumer_heartbeat_ms = 300;
    x.drive.consumer_heartbeat_optional = false;  // asked for (canmotiond: master_heartbeat_timeout_ms in the file)
    x.drive.hints.consumer_heartbeat = "axes[0].drive.master_heartbeat_timeout_ms";
    e.absent_objects = {0x1016};
  });
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kFailed; }, 3000));
  const std::string why = r.axis().failure.to_string();
  std::printf("%s\n", why.c_str());
  for (const char* part : {"node 2", "0x1016:1", "0x06020000", "set axes[0].drive.master_heartbeat_timeout_ms: 0"})
    EXPECT_NE(why.find(part), std::string::npos) << "missing '" << part << "' in: " << why;
}

// SDO timeout at boot: the drive sends boot-up and heartbeats but its SDO
// answers are lost. The failure says the write got no answer after the SDO
// timeout; ModuleFault; MSO ERR 11. MAFR runs the boot again once the
// answers come through, and the axis works.
TEST(DriveFaults, SdoTimeoutAtBootThenMafrRetriesTheBoot) {
  FaultRig r;
  r.world.bus(0).add_fault({0x580u + kNode, can::SimFault::Action::kDrop, 0, 0});  // every SDO response lost
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kFailed; }, 3000));
  const cia402::Failure f = r.axis().failure;
  const std::string why = f.to_string();
  std::printf("%s\n", why.c_str());
  EXPECT_EQ(f.sdo_abort, 0x05040000u);
  // (the first transfer of the boot is the read of 0x1000, issue 15)
  EXPECT_NE(why.find("configuration read of 0x1000:0 (Device type)"), std::string::npos) << why;
  EXPECT_NE(why.find("the drive did not answer"), std::string::npos) << why;
  // DriveConfig::sdo_timeout_ns twice (one retry): each timeout seen at the
  // first cycle past it, and one cycle between the first try's abort and the
  // second initiate.
  EXPECT_GE(f.waited_ns, 2 * 200'000'000 + kPeriod);
  EXPECT_LE(f.waited_ns, 2 * 200'000'000 + 4 * kPeriod);
  r.cycles(1);
  EXPECT_TRUE(module_fault(r.read("X.AxisFault")));
  r.exec("MSO(X, mso1)");
  EXPECT_EQ(r.read("mso1.ERR"), 11.0);
  r.world.bus(0).clear_faults();
  r.recover("MAFR");
}

// No boot-up at all (the drive is off): after boot_timeout the master resets
// the node, after another the boot fails (ModuleFault, ERR 11). The drive is
// switched on later: its boot-up runs the boot by itself.
TEST(DriveFaults, AbsentDriveFailsTheBootAndItsLaterBootUpConfiguresIt) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig&) { x.drive.boot_timeout_ns = 200'000'000; }, false);
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kFailed; }, 3000));
  EXPECT_EQ(r.axis().failure.kind, cia402::FailureKind::kBootTimeout);
  EXPECT_GE(r.status().time_ns, 400'000'000);
  r.cycles(1);
  EXPECT_TRUE(module_fault(r.read("X.AxisFault")));
  r.exec("MSO(X, mso1)");
  EXPECT_EQ(r.read("mso1.ERR"), 11.0);
  r.world.power_cycle(0, r.now);
  ASSERT_TRUE(r.operational()) << r.axis().failure.to_string();
  EXPECT_EQ(r.read("X.AxisFault"), 0.0);
  r.enable_and_move();
}

// ---------------------------------------------------------------------------
// Bus-off: nothing can be sent or received. The controller sees the state
// change in the next cycle's bus events; the axis faults (bus_off exception:
// ModuleFault, default action Shutdown) in that cycle. Meanwhile the drive's
// watch of the master (0x1016) and the master's of the drive expire. When the
// bus is back (error active), the controller re-boots the bus's nodes (NMT
// reset node, then the boot and configuration: issue 15; on main the drive
// stayed in the Fault of its 0x8130 reaction), and MASR resets the axis; MSO
// and a move work.
TEST(DriveFaults, BusOffFaultsTheAxisAndMasrRecoversOnceTheBusIsBack) {
  // The strict drive with 0x1029 = 0: it also goes Pre-operational when it
  // loses the master's heartbeat (the NMT reset node re-boots it anyway).
  // Instant boot: the MSO right after MASR's node restart fails (ERR 20)
  // while the drive is still in Not ready to switch on (issue 15, master side).
  FaultRig r([](AxisSpec&, emulator::EmulatorConfig& e) {
    e.behaviour.boot_ns = 0;
    e.behaviour.optional_objects_absent = false;  // the drive has 0x1016: it watches the master
  });
  r.enable_and_jog();
  const std::int64_t off_at = r.now;
  r.world.bus(0).set_state(can::BusState::kBusOff);
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 100));
  std::printf("bus-off: set before the cycle of %.0f ms, axis faulted in the cycle of %.0f ms\n", ms(off_at),
              ms(r.status().time_ns));
  EXPECT_EQ(r.status().time_ns, off_at) << "not in the first cycle after the bus-off";
  EXPECT_EQ(r.status().buses[0].state, can::BusState::kBusOff);
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  const std::uint64_t sent_before = r.status().buses[0].syncs_sent;
  const std::uint64_t refused_before = r.status().buses[0].syncs_refused;
  r.cycles(500);  // both heartbeat watches expire meanwhile
  EXPECT_TRUE(r.axis().failure.kind == cia402::FailureKind::kHeartbeatLost) << r.axis().failure.to_string();
  // Every cycle on the off bus tried its SYNC and was refused: each one is
  // counted (canmotiond's summary prints them per bus), none as sent.
  EXPECT_EQ(r.status().buses[0].syncs_sent, sent_before);
  EXPECT_EQ(r.status().buses[0].syncs_refused, refused_before + 500);
  // The drive's own watch of the master faulted it (no SYNC reaches it to
  // finish the fault reaction while the bus is off).
  EXPECT_TRUE(r.world.drive(0).state() == cia402::State::kFault ||
              r.world.drive(0).state() == cia402::State::kFaultReactionActive);
  const std::uint64_t boot_ups = r.world.drive(0).counters().boot_ups;
  bool reset_sent = false;
  bool recovered_event = false;
  r.each_cycle = [&] {
    Event e;
    while (r.ctl->pop_event(e)) recovered_event = recovered_event || e.kind == Event::Kind::kBusRecovered;
  };
  r.world.bus(0).set_tap([&](const can::TimedFrame& f, std::string_view) {
    reset_sent = reset_sent || (f.frame.id == 0 && f.frame.len == 2 && f.frame.data[0] == 0x81 && f.frame.data[1] == kNode);
  });
  r.world.bus(0).set_state(can::BusState::kErrorActive);
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kOperational; }, 3000))
      << r.axis().failure.to_string();
  EXPECT_TRUE(reset_sent) << "no NMT reset node after the bus-off";
  EXPECT_TRUE(recovered_event);
  EXPECT_EQ(r.world.drive(0).counters().boot_ups, boot_ups + 1) << "the drive was not re-booted";
  EXPECT_NE(r.axis().drive_state, cia402::State::kFault) << "the re-booted drive left its Fault";
  r.each_cycle = nullptr;
  r.world.bus(0).set_tap(nullptr);
  r.recover("MASR");
}

// The controller's interface goes down and up (`ip link set can0 down`, the
// SimBus endpoint's set_link: every send fails with ENETDOWN, nothing is
// received). The first refused send (the cycle's RPDO) reports it; in the
// next cycle the axis faults as at bus-off (bus_off exception: ModuleFault,
// Shutdown) and kLinkDown names the errno. Every cycle meanwhile tries its
// SYNC (refused, counted). The first frame that gets out after the interface
// is up again (kLinkUp) makes the controller re-boot the bus's nodes (NMT
// reset node, the configuration); MASR, MSO and a move work, canmotiond never
// restarted (vcan.peer.link_down does the same on a real vcan0).
TEST(DriveFaults, InterfaceDownFaultsTheAxisAndItsDrivesRebootWhenItIsUp) {
  FaultRig r([](AxisSpec&, emulator::EmulatorConfig& e) {
    e.behaviour.boot_ns = 0;
    e.behaviour.optional_objects_absent = false;  // the drive has 0x1016: it watches the master
  });
  auto& link = static_cast<can::SimBus::Endpoint&>(*r.ctl->spec().buses[0].transport);
  r.enable_and_jog();
  std::vector<Event> events;
  r.each_cycle = [&] {
    Event e;
    while (r.ctl->pop_event(e))
      if (e.kind == Event::Kind::kLinkDown || e.kind == Event::Kind::kLinkUp || e.kind == Event::Kind::kBusRecovered)
        events.push_back(e);
  };
  const std::int64_t down_at = r.now;
  link.set_link(false);
  ASSERT_TRUE(r.run_until([&] { return module_fault(r.read("X.AxisFault")); }, 100));
  std::printf("interface down before the cycle of %.0f ms, axis faulted in the cycle of %.0f ms\n", ms(down_at),
              ms(r.status().time_ns));
  EXPECT_EQ(r.status().time_ns, down_at + kPeriod) << "not in the cycle after the first refused send";
  EXPECT_TRUE(link.link_down());
  EXPECT_EQ(r.read("X.JogStatus"), 0.0);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, Event::Kind::kLinkDown);
  EXPECT_EQ(events[0].value, static_cast<std::uint64_t>(ENETDOWN));
  const std::uint64_t sent_before = r.status().buses[0].syncs_sent;
  const std::uint64_t refused_before = r.status().buses[0].syncs_refused;
  const std::uint64_t boot_ups = r.world.drive(0).counters().boot_ups;
  r.cycles(300);  // 3 s: both heartbeat watches expire meanwhile
  EXPECT_EQ(r.status().buses[0].syncs_sent, sent_before);
  EXPECT_EQ(r.status().buses[0].syncs_refused, refused_before + 300);
  EXPECT_EQ(events.size(), 1u) << "the interface down is reported once";
  EXPECT_TRUE(module_fault(r.read("X.AxisFault")));
  bool reset_sent = false;
  r.world.bus(0).set_tap([&](const can::TimedFrame& f, std::string_view) {
    reset_sent = reset_sent || (f.frame.id == 0 && f.frame.len == 2 && f.frame.data[0] == 0x81 && f.frame.data[1] == kNode);
  });
  link.set_link(true);
  r.step();  // its frames go out again: kLinkUp
  EXPECT_FALSE(link.link_down());
  ASSERT_TRUE(r.run_until([&] { return r.axis().phase == cia402::Phase::kOperational; }, 3000))
      << r.axis().failure.to_string();
  EXPECT_TRUE(reset_sent) << "no NMT reset node after the interface came back";
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].kind, Event::Kind::kLinkUp);
  EXPECT_EQ(r.world.drive(0).counters().boot_ups, boot_ups + 1) << "the drive was not re-booted";
  EXPECT_TRUE(module_fault(r.read("X.AxisFault"))) << "the fault stays until MASR";
  r.each_cycle = nullptr;
  r.world.bus(0).set_tap(nullptr);
  r.recover("MASR");
  EXPECT_EQ(r.read("X.AxisFault"), 0.0);
}

// Error passive: frames still flow. The state change is reported (an event
// and the bus status) and nothing else happens: the jog goes on.
TEST(DriveFaults, ErrorPassiveIsReportedAndMotionGoesOn) {
  FaultRig r;
  r.enable_and_jog();
  Event e;
  while (r.ctl->pop_event(e)) {
  }
  r.world.bus(0).set_state(can::BusState::kErrorPassive);
  r.cycles(200);
  EXPECT_EQ(r.status().buses[0].state, can::BusState::kErrorPassive);
  bool reported = false;
  while (r.ctl->pop_event(e))
    reported = reported || (e.kind == Event::Kind::kBusState && e.bus_state == can::BusState::kErrorPassive);
  EXPECT_TRUE(reported);
  EXPECT_EQ(r.read("X.AxisFault"), 0.0);
  EXPECT_EQ(r.read("X.JogStatus"), 1.0);
  EXPECT_EQ(r.axis().tpdo_missed, 0u);
  r.world.bus(0).set_state(can::BusState::kErrorActive);
  r.cycles(10);
  EXPECT_EQ(r.status().buses[0].state, can::BusState::kErrorActive);
  EXPECT_EQ(r.read("X.JogStatus"), 1.0);
}

// TPDOs lost for N cycles (the drive and its heartbeat are fine): each
// missing TPDO is counted in the next cycle (X.TpdoMissed); the feedback
// holds its last value, so the position error grows by the motion of those
// cycles and shrinks again; no fault unless it exceeds the axis's
// position_error_tolerance.
TEST(DriveFaults, TpdosLostForNCyclesAreCountedAndMotionGoesOn) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig&) { x.config.position_error_tolerance = 5; });
  r.enable_and_jog();
  for (const std::uint64_t n : {1u, 5u, 50u}) {
    const std::uint64_t before = r.axis().tpdo_missed;
    r.world.bus(0).add_fault({0x180u + kNode, can::SimFault::Action::kDrop, 0, n});
    double worst = 0;
    for (std::uint64_t i = 0; i < n + 20; ++i) {
      r.step();
      worst = std::max(worst, std::abs(r.read("X.PositionError")));
    }
    r.world.bus(0).clear_faults();
    EXPECT_EQ(r.axis().tpdo_missed - before, n);
    std::printf("TPDOs lost for %llu cycles: %llu counted, largest position error %.3f mm at 10 mm/s\n",
                static_cast<unsigned long long>(n), static_cast<unsigned long long>(r.axis().tpdo_missed - before), worst);
    EXPECT_EQ(r.read("X.AxisFault"), 0.0);
    EXPECT_EQ(r.read("X.JogStatus"), 1.0);
    EXPECT_LT(worst, 10.0 * (static_cast<double>(n) + 5) * 1e-3 + 0.01);
  }
}

// A late SYNC (delayed on the bus by 2.5 cycles): the drive applies it late
// and its TPDO comes after the master's next SYNC, counted as missed; nothing
// is lost and nothing faults.
TEST(DriveFaults, LateSyncIsCountedAsAMissedTpdoAndMotionGoesOn) {
  FaultRig r;
  // The SimBus keeps delayed frames in a std::deque (the simulated wire,
  // not the controller): a delay allocates there.
  r.check_allocations = false;
  r.enable_and_jog();
  const std::uint64_t syncs = r.world.drive(0).counters().syncs;
  can::SimFault late{0x080, can::SimFault::Action::kDelay, 0, 1};
  late.delay_ns = 2'500'000;
  r.world.bus(0).add_fault(late);
  r.cycles(50);
  EXPECT_GE(r.axis().tpdo_missed, 1u);
  EXPECT_LE(r.axis().tpdo_missed, 3u);
  std::printf("late SYNC (2.5 ms): %llu TPDO(s) counted missed\n", static_cast<unsigned long long>(r.axis().tpdo_missed));
  EXPECT_EQ(r.world.drive(0).counters().syncs - syncs, 50u) << "a SYNC was lost";
  EXPECT_EQ(r.read("X.AxisFault"), 0.0);
  EXPECT_EQ(r.read("X.JogStatus"), 1.0);
}


// The drive was powered before the master: its boot-up was missed, and a
// drive without a configured heartbeat sends nothing more. After boot_timeout
// the master resets the node and configures it from its new boot-up; an MSO
// issued while all this goes on completes (DN) once the drive is operational,
// or ends with ER, but never stays pending (issue 15; seen over vcan: the
// controlword stayed 0 for 60 s, no ER).
TEST(DriveFaults, MsoIssuedBeforeAMissedBootUpCompletes) {
  FaultRig r(
      [](AxisSpec& x, emulator::EmulatorConfig& e) {
        x.drive.boot_timeout_ns = 200'000'000;
        e.behaviour = emulator::EmulatorBehaviour::strict();
        e.behaviour.ip_index_read_only = false;
        e.behaviour.optional_objects_absent = false;
      },
      false);
  can::SimFault drop;
  drop.cob_id = 0x700u + kNode;
  drop.count = 1;
  r.world.bus(0).add_fault(drop);
  r.world.power_cycle(0, r.now);  // its boot-up is lost
  r.exec("MSO(X, mso1)");
  ASSERT_TRUE(r.run_until([&] { return r.read("mso1.DN") != 0.0 || r.read("mso1.ER") != 0.0; }, 5000))
      << "MSO still pending: phase " << static_cast<int>(r.axis().phase) << ", " << r.axis().failure.to_string();
  std::printf("missed boot-up: MSO DN=%g ER=%g at %.0f ms; boot-up frames dropped %llu, drive heartbeats seen %llu\n",
              r.read("mso1.DN"), r.read("mso1.ER"), ms(r.status().time_ns),
              static_cast<unsigned long long>(r.world.bus(0).counters().dropped), static_cast<unsigned long long>(r.hb_rx));
  EXPECT_EQ(r.world.bus(0).counters().dropped, 1u);
  EXPECT_GE(r.status().time_ns, 200'000'000) << "configured before the boot timeout: the boot-up was not missed";
  EXPECT_EQ(r.read("mso1.DN"), 1.0) << "ERR " << r.read("mso1.ERR");
  EXPECT_EQ(r.read("X.DriveEnableStatus"), 1.0);
}

// An axis that latches an exception as a fault reports it once, as an event
// with the value that latched it (canmotiond logs describe_axis_fault(): the
// value against its configuration key, the action and what clears it): a
// drive that stops following (its TPDOs lost while jogging at 10 mm/s) trips
// position_error_tolerance 1 mm. After MAFR it is reported again when it
// latches again, never in between.
TEST(DriveFaults, PositionErrorFaultIsReportedOnceWithItsValueAndKeys) {
  FaultRig r([](AxisSpec& x, emulator::EmulatorConfig&) {
    x.config.position_error_tolerance = 1.0;
    std::snprintf(x.config.units_name, sizeof x.config.units_name, "mm");
  });
  std::vector<Event> faults;
  r.each_cycle = [&] {
    Event e;
    while (r.ctl->pop_event(e))
      if (e.kind == Event::Kind::kAxisFault) faults.push_back(e);
  };
  const std::string tail =
      " mm beyond its tolerance 1 mm (axes[0].position_error_tolerance): Stop Drive "
      "(axes[0].exception_actions.position_error): motion stopped, servo off (drive disabled); MAFR clears it, then MSO";
  for (int round = 0; round < 2; ++round) {
    r.enable_and_jog();
    ASSERT_TRUE(faults.empty()) << "reported before it latched: " << describe_axis_fault(faults[0], r.ctl->axis_spec(0), 0);
    r.world.bus(0).add_fault({0x180u + kNode, can::SimFault::Action::kDrop, 0, 0});  // TPDO1: the feedback stops
    ASSERT_TRUE(r.run_until([&] { return physical_fault(r.read("X.AxisFault")); }, 500));
    r.world.bus(0).clear_faults();
    r.cycles(100);  // still latched: no second report
    ASSERT_EQ(faults.size(), 1u);
    const Event& e = faults[0];
    EXPECT_EQ(e.axis, 0);
    EXPECT_EQ(e.value, static_cast<std::uint64_t>(motion::ExceptionKind::PositionError));
    // 10 mm/s = 0.01 mm per cycle: it latches in the first cycle past 1 mm
    EXPECT_GT(e.detail, 1.0);
    EXPECT_LE(e.detail, 1.0 + 0.02 + 1e-9);
    const std::string text = describe_axis_fault(e, r.ctl->axis_spec(0), 0);
    std::printf("round %d: %s\n", round + 1, text.c_str());
    EXPECT_EQ(text.rfind("position error 1.0", 0), 0u) << text;
    EXPECT_NE(text.rfind("position error 1 mm", 0), 0u) << "a value past the tolerance reads as the tolerance: " << text;
    EXPECT_NE(text.find(tail), std::string::npos) << text;
    EXPECT_EQ(r.read("X.JogStatus"), 0.0);
    faults.clear();
    r.exec("MAFR(X, mafr)");
    ASSERT_TRUE(r.wait("mafr.DN", 1000)) << "MAFR ERR " << r.read("mafr.ERR");
    r.cycles(50);
    EXPECT_TRUE(faults.empty()) << "the reset reported a fault";
  }
}

// The other texts, from a configuration (no cycle needed): each names the
// keys to look at and what clears the fault.
TEST(DriveFaults, AxisFaultTexts) {
  AxisSpec a;
  a.config.soft_limits_enabled = true;
  a.config.soft_limit_pos = 500;
  a.config.soft_limit_neg = -20;
  std::snprintf(a.config.units_name, sizeof a.config.units_name, "deg");
  a.config.exception_actions[static_cast<std::size_t>(motion::ExceptionKind::SoftOvertravelNeg)] =
      motion::ExceptionAction::FaultStatusOnly;
  Event e;
  e.kind = Event::Kind::kAxisFault;
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::SoftOvertravelNeg);
  e.detail = -20.25;
  EXPECT_EQ(describe_axis_fault(e, a, 3),
            "command position -20.25 deg beyond the negative soft limit -20 deg (axes[3].soft_limits.negative): Fault "
            "Status Only (axes[3].exception_actions.soft_overtravel_negative): the fault is shown, motion goes on; MAFR "
            "clears it");
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::SoftOvertravelPos);
  e.detail = 500.125;
  EXPECT_EQ(describe_axis_fault(e, a, 0),
            "command position 500.125 deg beyond the positive soft limit 500 deg (axes[0].soft_limits.positive): Stop "
            "Planner (axes[0].exception_actions.soft_overtravel_positive): motion stopped, the servo stays on; MAFR "
            "clears it");
  e.detail = 500.0000000000001;  // just past: shown with the digits that make it so
  EXPECT_EQ(describe_axis_fault(e, a, 0).rfind("command position 500.0000000000001 deg beyond the positive soft limit 500 "
                                               "deg (axes[0].soft_limits.positive)",
                                               0),
            0u)
      << describe_axis_fault(e, a, 0);
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::NodeLost);
  EXPECT_EQ(describe_axis_fault(e, a, 1),
            "node lost (heartbeat lost, or the node left NMT operational): Shutdown "
            "(axes[1].exception_actions.node_lost): motion stopped, servo off, the axis in Shutdown; MASR clears it, "
            "then MSO");
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::DriveFault);
  EXPECT_EQ(describe_axis_fault(e, a, 1),
            "drive fault (its cause is logged for the drive): Stop Drive (axes[1].exception_actions.drive_fault): motion "
            "stopped, servo off (drive disabled); MAFR clears it, then MSO");
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::BusOff);
  EXPECT_EQ(describe_axis_fault(e, a, 2).rfind("its bus is off (bus-off, or its interface down): Shutdown (axes[2].exception_actions.bus_off)", 0), 0u);
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::HardOvertravelPos);
  EXPECT_EQ(describe_axis_fault(e, a, 4),
            "PositiveOvertravelFault: the positive limit switch is active (0x60FD bit 1): Stop Drive "
            "(axes[4].exception_actions.hard_overtravel_positive): motion stopped, servo off (drive disabled); MAFR "
            "clears it, then MSO");
  e.value = static_cast<std::uint64_t>(motion::ExceptionKind::HardOvertravelNeg);
  EXPECT_EQ(describe_axis_fault(e, a, 4).rfind("NegativeOvertravelFault: the negative limit switch is active (0x60FD bit 0): "
                                               "Stop Drive (axes[4].exception_actions.hard_overtravel_negative)",
                                               0),
            0u);
}

}  // namespace
}  // namespace canmotion::rt
