// MDS whole loop (issue 5), deterministic on virtual time: a configuration
// file with `direct_control:` -> runtime (planner + DriveNetwork + emulated
// drives on in-process buses) -> MDS instructions through the controller
// host. Checked cycle by cycle on the emulated drives: the CSV velocity ramps
// at RampAcceleration/Deceleration within RampVelocity +/-, also after a live
// command change and after MAS; SLAT 1 and 2 in CST switch between torque and
// speed control per the seed's rules. The candump trace carries the ramp and
// SLAT SDO writes and the 0x6060 switch to 9 and 10 (RPDO2) with 0x6061 (TPDO2).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "config/runtime.hpp"
#include "fieldbus/can/candump_format.hpp"
#include "tests/config/runtime_rig.hpp"

namespace canmotion::config {
namespace {

// One CSV/CST node per bus keeps each bus under 100 % at 1 ms (RPDO1+2, TPDO1+2).
const char* kYaml = R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim}
  - {name: can1, interface: sim}
  - {name: can2, interface: sim}
drives:
  pdo: csp_csv_cst
axes:
  - name: V
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 1000
    max_speed: 100
    direct_control:
      mode: velocity
      ramp: {acceleration: 50, deceleration: 100, velocity_positive: 60, velocity_negative: 40}
  - name: T
    type: AXIS_CIP_DRIVE
    bus: can1
    node: 3
    conversion_constant: 1000
    max_speed: 100
    direct_control:
      mode: torque
      max_torque: 1000
      velocity_command: 8
      slat: {configuration: 1, set_point: 2, time_delay_ms: 5}
  - name: W
    type: AXIS_CIP_DRIVE
    bus: can2
    node: 4
    conversion_constant: 1000
    max_speed: 100
    direct_control:
      mode: torque
      max_torque: 1000
      velocity_command: 5
      slat: {configuration: SLAT Max Speed/Torque, set_point: 1, time_delay_ms: 3}
)";

struct Loop : test::RuntimeRig {
  std::vector<std::string> trace;

  explicit Loop(const char* yaml = kYaml) : RuntimeRig(load_string(yaml, "mds.yaml")) {
    rt.controller->set_trace(true);
    rt.sim->power_on(0);
  }
  emulator::Emulator& emu(std::size_t bus, std::uint8_t node) { return *rt.sim->find_drive(bus, node); }
  void after_cycle() override {
    rt::TraceRecord r;
    std::array<char, 128> line{};
    while (ctl().pop_trace(r)) {
      const std::size_t n = can::format_candump_line(line, r.frame.frame, r.frame.t_ns, rt.trace_names[r.bus]);
      trace.emplace_back(line.data(), n);
    }
  }
  void exec(const std::string& call) {
    ASSERT_TRUE(execute(call));
    cycle();  // the request is taken at the next cycle
  }
  bool until(const std::string& tag, int max) {
    for (int i = 0; i < max; ++i) {
      if (read(tag) == 1.0) return true;
      cycle();
    }
    return false;
  }
  bool traced(const std::string& text) const {
    return std::any_of(trace.begin(), trace.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
  }
  /// A frame `id#` on `iface` whose payload ends with `tail` (hex).
  bool traced_tail(const std::string& iface, const std::string& id, const std::string& tail) const {
    const std::string key = " " + iface + " " + id + "#";
    return std::any_of(trace.begin(), trace.end(), [&](const std::string& l) {
      return l.find(key) != std::string::npos && l.size() >= tail.size() && l.compare(l.size() - tail.size(), tail.size(), tail) == 0;
    });
  }
};

/// Cycle-by-cycle SLAT check on one emulated drive, recomputing the seed's
/// rule from the observed velocity and the 0x60FF value in effect (the model
/// applies targets lag_cycles SYNCs late). Counts the switches.
struct SlatChecker {
  emulator::Emulator& e;
  int mode;
  double set_point;  // counts/s
  int delay_cycles;  // time delay / 1 ms
  std::deque<double> cmd_history{};
  std::deque<double> torque_history{};
  int held = 0;
  int to_speed = 0, to_torque = 0;

  void step(Loop& l) {
    const double v = e.velocity();
    const bool speed = e.slat_speed_control();
    const bool was_cst = e.mode_display() == 10 && e.state() == cia402::State::kOperationEnabled;
    l.cycle();
    const std::size_t lag = e.config().lag_cycles;
    const auto target = static_cast<double>(e.read_int(0x60FF));
    if (e.mode_display() != 10 || e.state() != cia402::State::kOperationEnabled) return;
    const auto torque = static_cast<double>(e.read_int(0x6071));
    if (!was_cst) {  // the model restarts its delay line at the present targets
      cmd_history.assign(lag + 1, target);
      torque_history.assign(lag + 1, torque);
    }
    cmd_history.push_back(target);
    torque_history.push_back(torque);
    while (cmd_history.size() > lag + 1) cmd_history.pop_front();
    while (torque_history.size() > lag + 1) torque_history.pop_front();
    const double err = cmd_history.front() - v;  // Velocity Error = command - actual
    bool expect;
    if (speed) {
      held = 0;
      expect = mode == 1 ? !(err < 0) : !(err > 0);
    } else {
      const bool cond = mode == 1 ? err > set_point : err < -set_point;
      held = cond ? held + 1 : 0;
      expect = cond && held >= delay_cycles;
    }
    EXPECT_EQ(e.slat_speed_control(), expect) << "SLAT " << mode << " v " << v << " cmd " << cmd_history.front();
    if (!speed && e.slat_speed_control()) ++to_speed;
    if (speed && !e.slat_speed_control()) ++to_torque;
    if (!e.slat_speed_control()) {
      EXPECT_DOUBLE_EQ(e.torque(), torque_history.front());  // torque control applies 0x6071
    }
  }
};

TEST(MdsLoop, VelocityRampsAndSlat1And2EndToEnd) {
  Loop l;
  auto& ev = l.emu(0, 2);
  auto& et = l.emu(1, 3);
  auto& ew = l.emu(2, 4);
  // The configuration file has no load model (it is the emulator's): friction
  // 10 per mille per 1000 counts/s, rated torque accelerates 1e6 counts/s^2.
  et.set_load_model(1e6, 0, 0.01);
  ew.set_load_model(1e6, 0, 0.01);
  for (int i = 0; i < 50; ++i) l.cycle();

  // ---- velocity: MDS enables the drive, CSV ramps at 0x6083 -----------------
  l.exec("MDS(V, mv, 50, UnitsPerSec)");
  EXPECT_EQ(l.read("mv.IP"), 1.0);
  ASSERT_TRUE(l.until("mv.DN", 3000)) << "ERR " << l.read("mv.ERR");
  EXPECT_EQ(l.read("V.DirectVelocityControlStatus"), 1.0);
  EXPECT_EQ(l.read("V.DirectControlStatus"), 1.0);
  EXPECT_EQ(ev.mode_display(), 9);
  EXPECT_EQ(ev.read_int(0x6083), 50'000);
  int moving = -1, reached = -1;
  for (int i = 0; i < 1300; ++i) {
    const double v0 = ev.velocity();
    l.cycle();
    const double dv = ev.velocity() - v0;
    ASSERT_LE(dv, 50.0 + 1e-9) << "cycle " << i;  // 50 units/s^2 x 1000 counts/unit x 1 ms
    ASSERT_GE(dv, -1e-9) << "cycle " << i;
    if (moving < 0 && dv > 0) moving = i;
    if (reached < 0 && ev.velocity() == 50'000.0) reached = i;
  }
  EXPECT_EQ(reached - moving, 999);  // 1000 SYNCs of +50 counts/s
  EXPECT_NEAR(l.read("V.ActualVelocity"), 50.0, 1e-9);

  // ---- live command change through the tag (as canmotionctl SET / a script
  // assignment): beyond RampVelocity - Positive, then negative -------------
  ASSERT_EQ(l.host.write("V.DirectCommandVelocity", 80.0), std::nullopt);
  EXPECT_EQ(l.read("V.DirectCommandVelocity"), 80.0);
  ASSERT_EQ(l.host.write("V.DirectCommandTorque", 500.0), std::nullopt);  // velocity mode: no torque command
  EXPECT_NE(l.host.write("V.ActualVelocity", 1.0), std::nullopt);           // read-only
  for (int i = 0; i < 400; ++i) l.cycle();
  EXPECT_EQ(ev.velocity(), 60'000.0);  // 0x2010:1
  EXPECT_EQ(ev.read_int(0x6071), 0);
  ASSERT_EQ(l.host.write("V.DirectCommandVelocity", -70.0), std::nullopt);
  int decel_cycles = 0, accel_cycles = 0;
  for (int i = 0; i < 1500; ++i) {
    const double v0 = ev.velocity();
    l.cycle();
    const double dv = ev.velocity() - v0;
    if (v0 > 0) {  // slowing down towards zero: RampDeceleration
      ASSERT_GE(dv, -100.0 - 1e-9) << "cycle " << i;
      if (dv < 0) ++decel_cycles;
    } else {  // speeding up in the negative direction: RampAcceleration
      ASSERT_GE(dv, -50.0 - 1e-9) << "cycle " << i;
      if (dv < 0) ++accel_cycles;
    }
  }
  EXPECT_EQ(decel_cycles, 600);   // 60 000 / 100
  EXPECT_EQ(accel_cycles, 800);   // to -40 000 (0x2010:2) / 50
  EXPECT_EQ(ev.velocity(), -40'000.0);

  // ---- MAS All: direct command to zero, the drive ramps at its deceleration --
  l.exec("MAS(V, ms, All, No, 0, UnitsPerSec2, No, 0, UnitsPerSec3)");
  EXPECT_EQ(l.read("mv.IP"), 0.0);
  EXPECT_EQ(l.read("V.DirectVelocityControlStatus"), 0.0);
  int stop_cycles = 1;
  while (l.read("ms.PC") == 0.0 && stop_cycles < 1000) {
    const double v0 = ev.velocity();
    l.cycle();
    ++stop_cycles;
    ASSERT_LE(ev.velocity() - v0, 100.0 + 1e-9);
  }
  EXPECT_GE(stop_cycles, 399);  // 40 000 / 100 per SYNC, less the standstill threshold
  EXPECT_LE(stop_cycles, 410);
  EXPECT_LE(std::abs(ev.velocity()), 100.0);
  EXPECT_EQ(l.read("V.DirectControlStatus"), 1.0);  // only MSO/MSF/shutdown leave direct control

  // ---- torque, SLAT 1 (min speed/torque) ------------------------------------
  SlatChecker s1{et, 1, 2'000, 5};
  l.exec("MDS(T, mt, 8, UnitsPerSec)");  // SLAT: Speed is the velocity command (issue 16, seed 002)
  for (int i = 0; i < 3000 && l.read("mt.DN") == 0.0; ++i) s1.step(l);
  ASSERT_EQ(l.read("mt.DN"), 1.0) << "ERR " << l.read("mt.ERR");
  EXPECT_EQ(l.read("T.DirectTorqueControlStatus"), 1.0);
  for (int i = 0; i < 500; ++i) s1.step(l);
  EXPECT_EQ(et.mode_display(), 10);
  EXPECT_EQ(s1.to_speed, 1);  // from rest: error 8 000 > 2 000 for 5 ms
  EXPECT_NEAR(et.velocity(), 8'000, 1);
  // live, through the tag: in torque mode DirectCommandVelocity is the SLAT speed reference
  ASSERT_EQ(l.host.write("T.DirectCommandVelocity", 3.0), std::nullopt);
  for (int i = 0; i < 800; ++i) s1.step(l);
  EXPECT_EQ(s1.to_torque, 1);  // Speed Error < 0: back to torque control (0 per mille: coasting)
  EXPECT_EQ(s1.to_speed, 2);   // below 3 000 - 2 000 for 5 ms: speed control again
  EXPECT_NEAR(et.velocity(), 3'000, 1);
  EXPECT_NEAR(l.read("T.ActualVelocity"), 3.0, 0.002);

  // ---- torque, SLAT 2 (max speed/torque) ------------------------------------
  SlatChecker s2{ew, 2, 1'000, 3};
  l.exec("MDS(W, mw, 5, %ofMaximum)");  // SLAT: 5 % of max_speed 100 = the velocity command 5 units/s
  s2.step(l);
  ASSERT_EQ(l.host.write("W.DirectCommandTorque", 300.0), std::nullopt);  // 300 per mille, written live
  for (int i = 0; i < 3000 && l.read("mw.DN") == 0.0; ++i) s2.step(l);
  EXPECT_EQ(l.read("W.DirectVelocityControlStatus"), 1.0);  // SLAT: both bits [seed 002]
  EXPECT_EQ(l.read("W.DirectTorqueControlStatus"), 1.0);
  ASSERT_EQ(l.read("mw.DN"), 1.0) << "ERR " << l.read("mw.ERR");
  for (int i = 0; i < 800; ++i) s2.step(l);
  EXPECT_EQ(s2.to_speed, 1);  // above 5 000 + 1 000 for 3 ms
  EXPECT_EQ(s2.to_torque, 0);
  EXPECT_NEAR(ew.velocity(), 5'000, 1);
  EXPECT_NEAR(ew.torque(), 50, 1);  // speed control holds against the friction, not the 300 commanded
  ASSERT_EQ(l.host.write("W.DirectCommandTorque", 120.0), std::nullopt);  // live torque command through the tag
  for (int i = 0; i < 5; ++i) l.cycle();
  EXPECT_EQ(ew.read_int(0x6071), 120);

  // ---- the trace: boot SDO writes of the ramps and SLAT, mode switches -------
  EXPECT_TRUE(l.traced(" can0 602#2383600050C30000")) << "0x6083 = 50 000";
  EXPECT_TRUE(l.traced(" can0 602#23846000A0860100")) << "0x6084 = 100 000";
  EXPECT_TRUE(l.traced(" can0 602#2310200160EA0000")) << "0x2010:1 = 60 000";
  EXPECT_TRUE(l.traced(" can0 602#23102002409C0000")) << "0x2010:2 = 40 000";
  EXPECT_TRUE(l.traced(" can0 582#6083600000000000")) << "0x6083 confirmed";
  EXPECT_TRUE(l.traced(" can1 603#2F20200001")) << "0x2020 = 1";
  EXPECT_TRUE(l.traced(" can1 603#23212000D0070000")) << "0x2021 = 2 000";
  EXPECT_TRUE(l.traced(" can1 603#2B2220000500")) << "0x2022 = 5 ms";
  EXPECT_TRUE(l.traced(" can2 604#2F20200002")) << "0x2020 = 2";
  EXPECT_TRUE(l.traced(" can2 604#23212000E8030000")) << "0x2021 = 1 000";
  EXPECT_TRUE(l.traced_tail("can0", "302", "09")) << "RPDO2 0x6060 = 9 (CSV)";
  EXPECT_TRUE(l.traced_tail("can0", "282", "09")) << "TPDO2 0x6061 = 9";
  EXPECT_TRUE(l.traced_tail("can1", "303", "0A")) << "RPDO2 0x6060 = 10 (CST)";
  EXPECT_TRUE(l.traced_tail("can1", "283", "0A")) << "TPDO2 0x6061 = 10";
  EXPECT_TRUE(l.traced_tail("can2", "304", "0A"));
  EXPECT_TRUE(l.traced_tail("can2", "284", "0A"));
  for (int n : {2, 3, 4}) {
    const auto* d = l.ctl().network(static_cast<std::size_t>(n - 2)).drive(static_cast<std::uint8_t>(n));
    ASSERT_NE(d, nullptr);
    EXPECT_FALSE(d->failed()) << d->failure().to_string();
  }
}

TEST(MdsLoop, RefusedModeSwitchIsADriveFaultThatCancelsMds) {
  Loop l;
  for (int i = 0; i < 50; ++i) l.cycle();
  l.exec("MSO(V, on)");
  ASSERT_TRUE(l.until("on.DN", 3000));
  l.emu(0, 2).set_refuse_mode_switch(true);
  l.exec("MDS(V, mv, 10, UnitsPerSec)");
  EXPECT_EQ(l.read("mv.IP"), 1.0);
  // drive.timeouts.mode_switch_ms (default 500): then a drive fault, Stop Drive by default
  int cycles = 0;
  while (l.read("mv.IP") == 1.0 && cycles < 1000) {
    l.cycle();
    ++cycles;
  }
  EXPECT_GE(cycles, 500);
  EXPECT_LE(cycles, 505);
  EXPECT_EQ(l.read("V.DirectVelocityControlStatus"), 0.0);
  EXPECT_EQ(l.read("V.PhysicalAxisFault"), 1.0);
  const auto* d = l.ctl().network(0).drive(2);
  EXPECT_EQ(d->failure().kind, cia402::FailureKind::kModeSwitchTimeout);
  EXPECT_NE(d->failure().to_string().find("node 2: mode switch to 9"), std::string::npos) << d->failure().to_string();
  // MAFR resets it; the drive accepts modes again and MDS runs.
  l.emu(0, 2).set_refuse_mode_switch(false);
  l.exec("MAFR(V, fr)");
  for (int i = 0; i < 50; ++i) l.cycle();
  EXPECT_FALSE(d->failed()) << d->failure().to_string();
  l.exec("MDS(V, mv2, 10, UnitsPerSec)");
  ASSERT_TRUE(l.until("mv2.DN", 3000)) << "ERR " << l.read("mv2.ERR");
  for (int i = 0; i < 300; ++i) l.cycle();
  EXPECT_EQ(l.emu(0, 2).mode_display(), 9);
  EXPECT_EQ(l.emu(0, 2).velocity(), 10'000.0);
}

// The MDS objects at the drive's own indices (drive.mds_objects, issue 15
// item 6): the simulated drives serve them there only (cia402-emu
// --mds-objects), the master writes exactly those indices and never the
// project's 0x2010..0x2022, and the ramp limit and SLAT act from there.
const char* kRelocatedYaml = R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim}
  - {name: can1, interface: sim}
drives:
  pdo: csp_csv_cst
  mds_objects:
    ramp_velocity_positive: 0x3000:1
    ramp_velocity_negative: 0x3000:2
    ramp_jerk_control: 0x3001
    slat_configuration: 0x4010
    slat_set_point: 0x4011
    slat_time_delay: 0x4012
axes:
  - name: V
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 1000
    max_speed: 100
    direct_control:
      mode: velocity
      ramp: {acceleration: 50, deceleration: 100, velocity_positive: 60, velocity_negative: 40, jerk_control: 0}
  - name: T
    type: AXIS_CIP_DRIVE
    bus: can1
    node: 3
    conversion_constant: 1000
    max_speed: 100
    direct_control:
      mode: torque
      max_torque: 1000
      velocity_command: 8
      slat: {configuration: 1, set_point: 2, time_delay_ms: 5}
)";

TEST(MdsLoop, ObjectsAtTheDrivesOwnIndicesRampsAndSlat) {
  Loop l(kRelocatedYaml);
  auto& ev = l.emu(0, 2);
  auto& et = l.emu(1, 3);
  et.set_load_model(1e6, 0, 0.01);
  for (int i = 0; i < 50; ++i) l.cycle();

  // Velocity: beyond the relocated RampVelocity - Positive (0x3000:1) the
  // drive stops at 60 000 counts/s, ramping at 0x6083.
  l.exec("MDS(V, mv, 80, UnitsPerSec)");
  ASSERT_TRUE(l.until("mv.DN", 3000)) << "ERR " << l.read("mv.ERR");
  // Configured: the drives have them where the file says.
  EXPECT_EQ(ev.read_int(0x3000, 1), 60'000);
  EXPECT_EQ(ev.read_int(0x3000, 2), 40'000);
  EXPECT_EQ(et.read_int(0x4010), 1);
  EXPECT_EQ(et.read_int(0x4011), 2'000);
  EXPECT_EQ(et.read_int(0x4012), 5);
  for (int i = 0; i < 1500; ++i) {
    const double v0 = ev.velocity();
    l.cycle();
    ASSERT_LE(ev.velocity() - v0, 50.0 + 1e-9) << "cycle " << i;
  }
  EXPECT_EQ(ev.velocity(), 60'000.0);

  // Torque with SLAT 1 from 0x4010..0x4012: speed control after 5 ms beyond 2 000 counts/s.
  SlatChecker s1{et, 1, 2'000, 5};
  l.exec("MDS(T, mt, 8, UnitsPerSec)");
  for (int i = 0; i < 3000 && l.read("mt.DN") == 0.0; ++i) s1.step(l);
  ASSERT_EQ(l.read("mt.DN"), 1.0) << "ERR " << l.read("mt.ERR");
  for (int i = 0; i < 500; ++i) s1.step(l);
  EXPECT_EQ(s1.to_speed, 1);
  EXPECT_NEAR(et.velocity(), 8'000, 1);

  // Golden bytes: every SDO download of the master into the manufacturer
  // area (0x2000..0x5FFF), in order, per bus; none to 0x2010..0x2022.
  std::vector<std::string> vendor;
  for (const std::string& line : l.trace) {
    const auto hash = line.find('#');
    if (hash == std::string::npos || hash < 3 || line.compare(hash - 3, 2, "60") != 0) continue;  // 602#, 603#
    const std::string d = line.substr(hash + 1);
    if (d.size() < 8 || d[0] != '2') continue;  // a download request
    const unsigned long index = std::stoul(d.substr(4, 2) + d.substr(2, 2), nullptr, 16);
    if (index >= 0x2010 && index <= 0x2022) ADD_FAILURE() << "written at the project's index: " << line;
    if (index >= 0x2000 && index <= 0x5FFF) vendor.push_back(line.substr(line.rfind(' ', hash) + 1));
  }
  const std::vector<std::string> golden = {
      "602#2300300160EA0000",  // 0x3000:1 = 60 000 (RampVelocity - Positive)
      "602#23003002409C0000",  // 0x3000:2 = 40 000 (RampVelocity - Negative)
      "602#2F01300000000000",  // 0x3001 = 0 (RampJerk - Control)
      "602#2F10400000000000",  // 0x4010 = 0 (SLAT disabled on V)
      "602#2311400000000000",  // 0x4011 = 0
      "602#2B12400000000000",  // 0x4012 = 0
      "603#2F10400001000000",  // 0x4010 = 1 (SLAT Min Speed/Torque)
      "603#23114000D0070000",  // 0x4011 = 2 000 counts/s
      "603#2B12400005000000",  // 0x4012 = 5 ms
  };
  std::vector<std::string> sorted = vendor;
  std::stable_sort(sorted.begin(), sorted.end(), [](const std::string& a, const std::string& b) {
    return a.compare(0, 3, b, 0, 3) < 0;  // by node, keeping each node's order
  });
  EXPECT_EQ(sorted, golden);
  for (int n : {2, 3}) {
    const auto* d = l.ctl().network(static_cast<std::size_t>(n - 2)).drive(static_cast<std::uint8_t>(n));
    ASSERT_NE(d, nullptr);
    EXPECT_FALSE(d->failed()) << d->failure().to_string();
  }
}

// The same configuration's master against drives that keep the objects at the
// project's indices: the boot fails at the first ramp object, naming both keys.
TEST(MdsLoop, RelocatedObjectsOnADriveWithoutThemFailTheBootNamingTheKeys) {
  Config c = load_string(kRelocatedYaml, "mds.yaml");
  Runtime rt = simulated_runtime(c);
  // Node 2's simulated drive (drive 0 on can0) replaced by one that keeps the
  // objects at the project's indices.
  emulator::EmulatorConfig e = emulator_config(c.axes[0]);
  e.mds_objects = cia402::MdsObjects{};
  ASSERT_EQ(rt.sim->find_drive(0, 2), &rt.sim->drive(0));
  rt.sim->disconnect(0);
  rt.sim->add_drive(0, e);
  rt.sim->power_on(0);
  rt::ControllerHost host(*rt.controller);
  std::int64_t now = 0;
  const auto* d = rt.controller->network(0).drive(2);
  for (int i = 0; i < 3000 && !d->failed(); ++i) {
    rt.sim->begin_cycle(now);
    rt.controller->cycle(now);
    rt.sim->end_cycle(now);
    now += 1'000'000;
  }
  ASSERT_TRUE(d->failed());
  const std::string why = d->failure().to_string();
  for (const char* part : {"node 2", "write to 0x3000:1", "0x06020000",
                           "axes[0].direct_control.ramp.velocity_positive (written to 0x3000:1, placed by "
                           "drives.mds_objects.ramp_velocity_positive)"})
    EXPECT_NE(why.find(part), std::string::npos) << part << " in: " << why;
}

}  // namespace
}  // namespace canmotion::config
