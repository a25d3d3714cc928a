// Golden bytes of every frame kind the master and the emulator send, the
// CiA 402 state table transition by transition, PDO packing, bus budget and
// the SimBus.
#include <gtest/gtest.h>

#include <algorithm>

#include <cstdlib>
#include <random>

#include "fieldbus/can/sim_bus.hpp"
#include "fieldbus/canopen/bus_budget.hpp"
#include "fieldbus/canopen/master.hpp"
#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/canopen/receive_filters.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"

using namespace canmotion;
using cia402::Command;
using cia402::State;
using fbtest::frame;
using fbtest::hex;
using fbtest::VecSink;

namespace {
std::uint64_t test_seed() {
  if (const char* s = std::getenv("CANMOTION_SEED")) return std::strtoull(s, nullptr, 0);
  return std::random_device{}();
}
int test_count(int dflt) {
  if (const char* s = std::getenv("CANMOTION_PROP_COUNT")) return std::atoi(s);
  return dflt;
}
}  // namespace

// ---- master frames -------------------------------------------------------------
TEST(FieldbusGolden, MasterNmtSyncHeartbeat) {
  canopen::MasterConfig mc;
  mc.node_id = 127;
  mc.heartbeat_period_ms = 100;
  canopen::Master m(mc);
  ASSERT_TRUE(m.add_node(2));
  VecSink out;
  m.send_nmt(canopen::NmtCommand::kStart, 2, out);
  m.send_nmt(canopen::NmtCommand::kStop, 2, out);
  m.send_nmt(canopen::NmtCommand::kEnterPreOperational, 0, out);
  m.send_nmt(canopen::NmtCommand::kResetNode, 2, out);
  m.send_nmt(canopen::NmtCommand::kResetCommunication, 2, out);
  m.send_sync(out);
  m.step(0, out);              // heartbeat at start
  m.step(99'000'000, out);     // not yet
  m.step(100'000'000, out);    // period reached
  std::vector<std::string> got;
  for (auto& f : out.frames) got.push_back(hex(f));
  const std::vector<std::string> expected = {"000#0102", "000#0202", "000#8000", "000#8102",
                                             "000#8202", "080#",     "77F#05",   "77F#05"};
  EXPECT_EQ(got, expected);
}

TEST(FieldbusGolden, SyncCounterWraps) {
  canopen::MasterConfig mc;
  mc.sync_counter_overflow = 3;
  mc.heartbeat_period_ms = 0;
  canopen::Master m(mc);
  VecSink out;
  for (int i = 0; i < 4; ++i) m.send_sync(out);
  std::vector<std::string> got;
  for (auto& f : out.frames) got.push_back(hex(f));
  EXPECT_EQ(got, (std::vector<std::string>{"080#01", "080#02", "080#03", "080#01"}));
}

TEST(FieldbusGolden, MasterRpdosAndBootConfiguration) {
  cia402::NetworkConfig nc;
  cia402::DriveNetwork net(nc);
  cia402::DriveConfig dc;
  dc.node = 2;
  dc.pdo_profile = cia402::PdoProfile::kCspCsvCst;
  auto& d = net.add_drive(dc);
  // Boot-up seen: the proxy starts configuring.
  net.on_frame(can::TimedFrame{frame("702#00"), 0});
  VecSink out;
  net.cycle(1'000'000, out);  // boot-up seen: the boot starts with the read of 0x1000 (device type)
  std::vector<std::string> got;
  for (auto& f : out.frames) got.push_back(hex(f));
  // SYNC first (no RPDOs yet), then what may wait: the SDO request, the heartbeat.
  EXPECT_EQ(got, (std::vector<std::string>{"080#", "602#4000100000000000", "77F#05"}));
  EXPECT_EQ(d.phase(), cia402::Phase::kConfiguring);
  // RPDO packing: controlword + target position; target velocity + torque + mode.
  const auto& pdos = d.pdos();
  ASSERT_EQ(pdos.rpdo_count, 2);
  EXPECT_EQ(pdos.rpdo[0].size_bytes, 6);
  EXPECT_EQ(pdos.rpdo[1].size_bytes, 7);
  EXPECT_EQ(pdos.tpdo[1].entries[2].raw(), 0x60610008u);
  const auto filters = net.receive_filters();
  ASSERT_EQ(filters.size(), 7u);
  EXPECT_EQ(filters[0].id, 0x082u);
  EXPECT_EQ(filters[1].id, 0x182u);
  EXPECT_EQ(filters[4].id, 0x482u);
  EXPECT_EQ(filters[5].id, 0x582u);
  EXPECT_EQ(filters[6].id, 0x702u);
  EXPECT_EQ(filters[6].mask, 0x7FFu);
}

TEST(FieldbusGolden, MasterReceiveFiltersAreOneListForNetworkAndDaemon) {
  // canopen::master_receive_filters() serves DriveNetwork::receive_filters()
  // and the daemon's SocketCAN set-up (config/runtime.cpp).
  EXPECT_EQ(canopen::master_receive_ids(5),
            (std::array<std::uint32_t, 7>{0x085, 0x185, 0x285, 0x385, 0x485, 0x585, 0x705}));
  cia402::DriveNetwork net;
  const std::array<std::uint8_t, 2> nodes{2, 5};
  for (std::uint8_t n : nodes) {
    cia402::DriveConfig dc;
    dc.node = n;
    net.add_drive(dc);
  }
  const auto expected = canopen::master_receive_filters(nodes);
  const auto got = net.receive_filters();
  ASSERT_EQ(got.size(), 14u);
  ASSERT_EQ(expected.size(), got.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].id, expected[i].id) << i;
    EXPECT_EQ(got[i].mask, 0x7FFu);
    EXPECT_FALSE(got[i].extended);
  }
  EXPECT_EQ(got[7].id, 0x085u);
  EXPECT_EQ(got[13].id, 0x705u);
}

TEST(FieldbusGolden, ProxyRpdoAndTpdoBytes) {
  cia402::DriveNetwork net;
  cia402::DriveConfig dc;
  dc.node = 3;
  dc.producer_heartbeat_ms = 0;
  dc.consumer_heartbeat_ms = 0;
  auto& d = net.add_drive(dc);
  net.on_frame(can::TimedFrame{frame("703#00"), 0});
  VecSink out;
  // Answer every SDO write, and the boot's reads (0x1000 CiA 402 servo
  // drive, 0x6502 every mode, 0x6061 CSP), until NMT start goes out.
  for (int i = 1; i < 200 && d.phase() != cia402::Phase::kStarting; ++i) {
    out.clear();
    net.cycle(i * 1'000'000, out);
    for (auto& f : out.frames)
      if (f.id == 0x603) {
        const bool upload = f.data[0] == 0x40;
        can::Frame r = frame(upload ? "583#4300000000000000" : "583#6000000000000000");
        r.data[1] = f.data[1], r.data[2] = f.data[2], r.data[3] = f.data[3];
        const std::uint16_t index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
        const std::uint32_t v = index == 0x1000 ? 0x00020192u : index == 0x6502 ? 0x000003FFu : 8u;
        if (upload)
          for (int k = 0; k < 4; ++k) r.data[4 + k] = static_cast<std::uint8_t>(v >> (8 * k));
        net.on_frame(can::TimedFrame{r, i * 1'000'000});
      }
  }
  ASSERT_EQ(d.phase(), cia402::Phase::kStarting) << cia402::phase_name(d.phase());
  {  // NMT start, then SYNC
    std::vector<std::string> sent;
    for (auto& f : out.frames) sent.push_back(hex(f));
    const auto start = std::find(sent.begin(), sent.end(), "000#0103");
    ASSERT_NE(start, sent.end());
    EXPECT_NE(std::find(start, sent.end(), "080#"), sent.end());
  }
  // TPDO1: statusword 0x0231 (Ready to switch on), position -2.
  net.on_frame(can::TimedFrame{frame("183#3102FEFFFFFF"), 300'000'000});
  out.clear();
  net.cycle(301'000'000, out);
  EXPECT_EQ(d.phase(), cia402::Phase::kOperational);
  EXPECT_EQ(d.feedback().position, -2);
  EXPECT_EQ(d.state(), State::kReadyToSwitchOn);
  auto rpdo = [&] {
    for (auto& f : out.frames)
      if (f.id == 0x203) return hex(f);
    return std::string("none");
  };
  // Disabled: controlword 0 (disable voltage), target follows actual.
  EXPECT_EQ(rpdo(), "203#0000FEFFFFFF");
  d.enable();
  out.clear();
  net.cycle(302'000'000, out);
  EXPECT_EQ(rpdo(), "203#0700FEFFFFFF");  // switch on (3)
  ASSERT_GE(out.frames.size(), 2u);
  EXPECT_EQ(hex(out.frames[0]), "203#0700FEFFFFFF");  // RPDOs before the SYNC
  EXPECT_EQ(hex(out.frames[1]), "080#");
}

// ---- emulator frames -------------------------------------------------------
TEST(FieldbusGolden, EmulatorBootHeartbeatSdoTpdoEmcy) {
  emulator::EmulatorConfig ec;
  ec.node = 2;
  ec.initial_position = 0x01020304;
  // Permissive: these golden bytes are the lenient drive's (PDO1 = statusword
  // + position at type 1, instant boot, same-call SDO replies); the strict
  // drive's frames: test_emulator_strict.cpp.
  ec.behaviour = emulator::EmulatorBehaviour::permissive();
  emulator::Emulator emu(ec);
  VecSink out;
  emu.power_on(0, out);
  ASSERT_EQ(out.frames.size(), 1u);
  EXPECT_EQ(hex(out.frames[0]), "702#00");
  out.clear();
  // Heartbeat producer 0x1017 = 10 ms.
  emu.on_frame(can::TimedFrame{frame("602#2B1710000A000000"), 0}, out);
  EXPECT_EQ(hex(out.frames.at(0)), "582#6017100000000000");
  emu.step(10'000'000, out);
  EXPECT_EQ(hex(out.frames.at(1)), "702#7F");
  out.clear();
  // Operational, then a SYNC: TPDO1 = statusword 0x0250 (switch on disabled + remote + qs bit), position.
  emu.on_frame(can::TimedFrame{frame("000#0102"), 0}, out);
  emu.on_frame(can::TimedFrame{frame("080#"), 0}, out);
  ASSERT_EQ(out.frames.size(), 1u);
  EXPECT_EQ(hex(out.frames[0]), "182#600204030201");
  out.clear();
  emu.step(20'000'000, out);
  EXPECT_EQ(hex(out.frames.at(0)), "702#05");
  out.clear();
  // Fault injection through 0x2000: EMCY 0x8611, error register generic+profile.
  emu.on_frame(can::TimedFrame{frame("602#2B00200011860000"), 0}, out);
  emu.on_frame(can::TimedFrame{frame("080#"), 0}, out);
  std::vector<std::string> got;
  for (auto& f : out.frames) got.push_back(hex(f));
  EXPECT_EQ(got, (std::vector<std::string>{"582#6000200000000000", "082#1186210000000000", "182#1F0204030201"}));
  EXPECT_EQ(emu.state(), State::kFaultReactionActive);
  out.clear();
  emu.on_frame(can::TimedFrame{frame("080#"), 0}, out);
  EXPECT_EQ(hex(out.frames.at(0)), "182#280204030201");  // Fault (14)
  // Fault reset over RPDO1 (edge of bit 7), applied at the next SYNC: EMCY 0000.
  out.clear();
  emu.on_frame(can::TimedFrame{frame("202#800004030201"), 0}, out);
  EXPECT_TRUE(out.frames.empty());  // RPDOs wait for SYNC
  emu.on_frame(can::TimedFrame{frame("080#"), 0}, out);
  got.clear();
  for (auto& f : out.frames) got.push_back(hex(f));
  EXPECT_EQ(got, (std::vector<std::string>{"082#0000000000000000", "182#600204030201"}));
}

TEST(FieldbusGolden, EmulatorRpdoLengthErrorGivesEmcy8210) {
  emulator::EmulatorConfig ec;
  ec.node = 2;
  emulator::Emulator emu(ec);
  VecSink out;
  emu.power_on(0, out);
  emu.on_frame(can::TimedFrame{frame("000#0100"), 0}, out);  // start all
  out.clear();
  emu.on_frame(can::TimedFrame{frame("202#0F"), 0}, out);  // RPDO1 = controlword (2 bytes)
  ASSERT_EQ(out.frames.size(), 1u);
  // Error register generic + communication (it was 00 before issue 15).
  EXPECT_EQ(hex(out.frames[0]), "082#1082110000000000");
}

// ---- CiA 402 state table, transition by transition ---------------------------
TEST(FieldbusStateTable, EveryCommandedTransition) {
  struct Row {
    State from;
    std::uint16_t cw;
    State to;
    std::uint8_t transition;
  };
  const Row rows[] = {
      {State::kSwitchOnDisabled, 0x0006, State::kReadyToSwitchOn, 2},
      {State::kReadyToSwitchOn, 0x0007, State::kSwitchedOn, 3},
      {State::kReadyToSwitchOn, 0x000F, State::kSwitchedOn, 3},
      {State::kSwitchedOn, 0x000F, State::kOperationEnabled, 4},
      {State::kOperationEnabled, 0x0007, State::kSwitchedOn, 5},
      {State::kSwitchedOn, 0x0006, State::kReadyToSwitchOn, 6},
      {State::kReadyToSwitchOn, 0x0000, State::kSwitchOnDisabled, 7},
      {State::kReadyToSwitchOn, 0x0002, State::kSwitchOnDisabled, 7},
      {State::kOperationEnabled, 0x0006, State::kReadyToSwitchOn, 8},
      {State::kOperationEnabled, 0x0000, State::kSwitchOnDisabled, 9},
      {State::kSwitchedOn, 0x0000, State::kSwitchOnDisabled, 10},
      {State::kSwitchedOn, 0x0002, State::kSwitchOnDisabled, 10},
      {State::kOperationEnabled, 0x0002, State::kQuickStopActive, 11},
      {State::kQuickStopActive, 0x0000, State::kSwitchOnDisabled, 12},
  };
  for (const Row& r : rows) {
    const auto res = cia402::apply_controlword(r.from, 0, r.cw);
    EXPECT_EQ(res.next, r.to) << cia402::state_name(r.from) << " + 0x" << std::hex << r.cw;
    EXPECT_EQ(res.transition, r.transition) << cia402::state_name(r.from) << " + 0x" << std::hex << r.cw;
    // The table agrees with the transition list.
    EXPECT_EQ(cia402::kTransitions[r.transition].from, r.from);
    EXPECT_EQ(cia402::kTransitions[r.transition].to, r.to);
  }
  // 15: only on the rising edge of bit 7.
  EXPECT_EQ(cia402::apply_controlword(State::kFault, 0x0000, 0x0080), (cia402::StepResult{State::kSwitchOnDisabled, 15}));
  EXPECT_EQ(cia402::apply_controlword(State::kFault, 0x0080, 0x0080).transition, cia402::kNoTransition);
  EXPECT_EQ(cia402::apply_controlword(State::kFault, 0x0000, 0x000F).transition, cia402::kNoTransition);
  // 16: only with 0x605A = 5..8.
  EXPECT_EQ(cia402::apply_controlword(State::kQuickStopActive, 0x0002, 0x000F, 6),
            (cia402::StepResult{State::kOperationEnabled, 16}));
  EXPECT_EQ(cia402::apply_controlword(State::kQuickStopActive, 0x0002, 0x000F, 2).transition, cia402::kNoTransition);
}

TEST(FieldbusStateTable, CommandsWithoutTransitionLeaveTheStateAlone) {
  const State all[] = {State::kSwitchOnDisabled, State::kReadyToSwitchOn, State::kSwitchedOn,
                       State::kOperationEnabled, State::kQuickStopActive};
  const std::uint16_t cws[] = {0x0000, 0x0002, 0x0006, 0x0007, 0x000F};
  int transitions = 0;
  for (State s : all)
    for (std::uint16_t cw : cws) {
      const auto r = cia402::apply_controlword(s, cw, cw);
      if (r.transition != cia402::kNoTransition) {
        ++transitions;
        EXPECT_NE(r.next, s);
      } else {
        EXPECT_EQ(r.next, s);
      }
    }
  EXPECT_EQ(transitions, 14);  // the rows of EveryCommandedTransition
  // Drive-side automatic states never move on a command.
  EXPECT_EQ(cia402::apply_controlword(State::kNotReadyToSwitchOn, 0, 0x0006).transition, cia402::kNoTransition);
  EXPECT_EQ(cia402::apply_controlword(State::kFaultReactionActive, 0, 0x0080).transition, cia402::kNoTransition);
}

TEST(FieldbusStateTable, MasterPlanReachesEveryTargetThroughNumberedTransitions) {
  const State starts[] = {State::kSwitchOnDisabled, State::kReadyToSwitchOn, State::kSwitchedOn,
                          State::kOperationEnabled, State::kQuickStopActive, State::kFault};
  const State targets[] = {State::kOperationEnabled, State::kSwitchOnDisabled, State::kSwitchedOn,
                           State::kReadyToSwitchOn};
  for (State s0 : starts)
    for (State target : targets) {
      State s = s0;
      std::uint16_t prev = 0;
      for (int i = 0; i < 6 && s != target; ++i) {
        const auto p = cia402::next_step(s, target);
        ASSERT_TRUE(p.has_value()) << cia402::state_name(s) << " -> " << cia402::state_name(target);
        const std::uint16_t cw = cia402::controlword(p->command);
        const auto r = cia402::apply_controlword(s, p->command == Command::kFaultReset ? 0 : prev, cw);
        EXPECT_EQ(r.transition, p->transition);
        EXPECT_EQ(r.next, p->expect);
        s = r.next;
        prev = cw;
      }
      EXPECT_EQ(s, target) << "from " << cia402::state_name(s0);
    }
  EXPECT_FALSE(cia402::next_step(State::kFaultReactionActive, State::kOperationEnabled).has_value());
}

// Quick stop from every state where CiA 402 defines the command (7, 10, 11);
// on main only from Operation enabled.
TEST(FieldbusStateTable, QuickStopPlannedFromReadySwitchedOnAndOperationEnabled) {
  struct Case {
    State from;
    std::uint8_t transition;
    State to;
  };
  for (const Case c : {Case{State::kReadyToSwitchOn, 7, State::kSwitchOnDisabled}, Case{State::kSwitchedOn, 10, State::kSwitchOnDisabled},
                       Case{State::kOperationEnabled, 11, State::kQuickStopActive}}) {
    const auto p = cia402::next_step(c.from, State::kQuickStopActive);
    ASSERT_TRUE(p.has_value()) << cia402::state_name(c.from);
    EXPECT_EQ(p->command, Command::kQuickStop);
    EXPECT_EQ(p->transition, c.transition);
    EXPECT_EQ(p->expect, c.to);
    const auto r = cia402::apply_controlword(c.from, 0x000F, cia402::controlword(p->command));
    EXPECT_EQ(r.transition, c.transition);
    EXPECT_EQ(r.next, c.to);
  }
  EXPECT_FALSE(cia402::next_step(State::kSwitchOnDisabled, State::kQuickStopActive).has_value());
}

// A drive under local control (statusword bit 9 clear) says so in the
// transition timeout instead of a bare timeout.
TEST(FieldbusStateTable, TransitionTimeoutNamesLocalControl) {
  cia402::Failure f;
  f.kind = cia402::FailureKind::kTransitionTimeout;
  f.node = 2;
  f.transition = 2;
  f.wanted = State::kOperationEnabled;
  f.reached = State::kSwitchOnDisabled;
  f.statusword = 0x0050;  // switch on disabled, voltage enabled, remote 0
  f.waited_ns = 500'000'000;
  EXPECT_EQ(f.to_string(),
            "node 2: transition 2 (Switch on disabled -> Ready to switch on) towards Operation enabled timed out after "
            "500.0 ms: drive is in Switch on disabled, statusword 0x0050; the drive is under local control (statusword "
            "bit 9 remote = 0: it does not process the controlword): switch it to bus/remote control on the drive");
}

TEST(FieldbusStateTable, ProxyFailureExplainsItself) {
  cia402::Failure f;
  f.kind = cia402::FailureKind::kTransitionTimeout;
  f.node = 2;
  f.transition = 4;
  f.wanted = State::kOperationEnabled;
  f.reached = State::kSwitchedOn;
  f.statusword = 0x0233;
  f.has_emcy = true;
  f.emcy_code = 0x8611;
  f.waited_ns = 500'000'000;
  EXPECT_EQ(f.to_string(),
            "node 2: transition 4 (Switched on -> Operation enabled) towards Operation enabled timed out after 500.0 ms: "
            "drive is in Switched on, statusword 0x0233, last EMCY 0x8611 (following error)");
}

// ---- PDO packing ----------------------------------------------------------------
TEST(FieldbusPdo, OffsetsComputedAtConfiguration) {
  canopen::PdoMap m;
  m.add(0x6040, 0, 16);
  m.add(0x607A, 0, 32);
  m.add(0x6060, 0, 8);
  ASSERT_TRUE(m.finalize());
  EXPECT_EQ(m.entries[1].bit_offset, 16);
  EXPECT_EQ(m.entries[2].bit_offset, 48);
  EXPECT_EQ(m.size_bytes, 7);
  m.add(0x60FF, 0, 32);
  EXPECT_FALSE(m.finalize());  // 88 bits
}

TEST(FieldbusPdo, PackUnpackRoundTripProperty) {
  const std::uint64_t seed = test_seed();
  const int count = test_count(20000);
  std::mt19937_64 rng(seed);
  for (int i = 0; i < count; ++i) {
    std::array<std::uint8_t, 8> buf{};
    for (auto& b : buf) b = static_cast<std::uint8_t>(rng());
    const auto before = buf;
    const unsigned bits = 1 + static_cast<unsigned>(rng() % 32);
    const unsigned off = static_cast<unsigned>(rng() % (65 - bits));
    const std::uint64_t v = rng() & ((std::uint64_t{1} << bits) - 1);
    canopen::pack_bits(buf, off, bits, v);
    ASSERT_EQ(canopen::unpack_bits(buf, off, bits), v) << "seed " << seed << " i " << i;
    for (unsigned b = 0; b < 64; ++b) {  // other bits untouched
      if (b >= off && b < off + bits) continue;
      ASSERT_EQ((buf[b / 8] >> (b % 8)) & 1, (before[b / 8] >> (b % 8)) & 1) << "seed " << seed << " i " << i;
    }
  }
  EXPECT_EQ(canopen::sign_extend(0xFFFE, 16), -2);
}

// ---- bus budget ------------------------------------------------------------------
TEST(FieldbusBusBudget, WorstCaseFrameLengths) {
  EXPECT_EQ(canopen::frame_bits_worst_case(0), 55u);
  EXPECT_EQ(canopen::frame_bits_worst_case(1), 65u);
  EXPECT_EQ(canopen::frame_bits_worst_case(6), 115u);
  EXPECT_EQ(canopen::frame_bits_worst_case(8), 135u);
  EXPECT_EQ(canopen::frame_bits_worst_case(8, true), 160u);
  EXPECT_EQ(canopen::frame_bits_no_stuffing(8), 111u);
}

TEST(FieldbusBusBudget, DefaultCspMapping) {
  canopen::NodeTraffic axis;
  axis.rpdo_bytes[0] = 6;
  axis.rpdo_count = 1;
  axis.tpdo_bytes[0] = 6;
  axis.tpdo_count = 1;
  const canopen::NodeTraffic three[] = {axis, axis, axis};
  canopen::BusBudgetInput in;
  in.cycle_ns = 1'000'000;
  in.nodes = three;
  const auto b = canopen::bus_budget(in);
  EXPECT_EQ(b.frames_per_cycle, 7u);
  EXPECT_EQ(b.cyclic_bits, 55u + 3 * 230u);
  EXPECT_DOUBLE_EQ(b.load_percent, 74.5);
  EXPECT_EQ(canopen::max_axes(axis, 1'000'000, 1'000'000), 4u);
  EXPECT_EQ(canopen::max_axes(axis, 2'000'000, 1'000'000), 8u);
  EXPECT_EQ(canopen::max_axes(axis, 4'000'000, 1'000'000), 17u);
  // The same from the profile the proxy configures.
  const auto t = cia402::node_traffic(cia402::PdoProfile::kCsp);
  EXPECT_EQ(t.rpdo_count, 1);
  EXPECT_EQ(t.rpdo_bytes[0], 6);
  EXPECT_EQ(t.tpdo_bytes[0], 6);
  const auto full = cia402::node_traffic(cia402::PdoProfile::kCspCsvCst, 100);
  EXPECT_EQ(full.rpdo_count + full.tpdo_count, 4);
  EXPECT_EQ(canopen::max_axes(full, 2'000'000, 1'000'000), 4u);
  // Heartbeats are averaged over their period: 65 bits every 100 ms at 1 ms = 0.65 bits.
  const canopen::NodeTraffic one[] = {full};
  canopen::BusBudgetInput hb;
  hb.nodes = one;
  EXPECT_DOUBLE_EQ(canopen::bus_budget(hb).heartbeat_bits, 0.65);
}

// ---- SimBus -----------------------------------------------------------------------
TEST(FieldbusSimBus, BroadcastDropDelayCorrupt) {
  can::SimBus bus;
  auto& a = bus.add_endpoint("a");
  auto& b = bus.add_endpoint("b");
  auto& c = bus.add_endpoint("c");
  std::array<can::TimedFrame, 8> buf;
  bus.set_time(5);
  ASSERT_EQ(a.send(frame("181#01")), can::SendResult::kOk);
  EXPECT_EQ(a.receive(buf), 0u);  // not to the sender
  ASSERT_EQ(b.receive(buf), 1u);
  EXPECT_EQ(buf[0].t_ns, 5);
  EXPECT_EQ(c.receive(buf), 1u);
  bus.add_fault(can::SimFault{0x181, can::SimFault::Action::kDrop, 1, 1});  // drop the 2nd match only
  can::SimFault delay{0x182, can::SimFault::Action::kDelay, 0, 1};
  delay.delay_ns = 100;
  bus.add_fault(delay);
  can::SimFault corrupt{0x183, can::SimFault::Action::kCorrupt, 0, 1};
  corrupt.byte = 0;
  corrupt.xor_mask = 0x0F;
  bus.add_fault(corrupt);
  a.send(frame("181#02"));  // passes (skip 1)
  a.send(frame("181#03"));  // dropped
  a.send(frame("181#04"));  // passes
  a.send(frame("182#05"));  // delayed
  a.send(frame("183#F0"));  // corrupted
  ASSERT_EQ(b.receive(buf), 3u);
  EXPECT_EQ(hex(buf[0].frame), "181#02");
  EXPECT_EQ(hex(buf[1].frame), "181#04");
  EXPECT_EQ(hex(buf[2].frame), "183#FF");
  bus.set_time(104);
  EXPECT_EQ(b.receive(buf), 0u);
  bus.set_time(105);
  ASSERT_EQ(b.receive(buf), 1u);
  EXPECT_EQ(hex(buf[0].frame), "182#05");
  EXPECT_EQ(buf[0].t_ns, 105);
  EXPECT_EQ(bus.counters().dropped, 1u);
  EXPECT_EQ(bus.counters().delayed, 1u);
  EXPECT_EQ(bus.counters().corrupted, 1u);
}

TEST(FieldbusSimBus, OverflowAndBusOffAreEvents) {
  can::SimBus bus;
  auto& a = bus.add_endpoint("a");
  auto& b = bus.add_endpoint("b", 2);
  for (int i = 0; i < 3; ++i) a.send(frame("080#"));
  EXPECT_EQ(b.counters().rx_dropped, 1u);
  std::array<can::BusEvent, 4> ev;
  ASSERT_EQ(b.poll_events(ev), 1u);
  EXPECT_EQ(ev[0].kind, can::BusEvent::Kind::kRxOverflow);
  bus.set_state(can::BusState::kBusOff);
  EXPECT_EQ(a.send(frame("080#")), can::SendResult::kBusOff);
  ASSERT_EQ(a.poll_events(ev), 1u);
  EXPECT_EQ(ev[0].state, can::BusState::kBusOff);
}
