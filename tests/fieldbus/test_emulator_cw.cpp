// The emulated drive's CiA 402 state machine under random controlwords (as
// RPDOs, applied at SYNC), random quick stop option codes (0x605A) and
// injected faults, against a reference built on the pure table
// cia402::apply_controlword. The emulator skips a repeated controlword in a
// state where it was seen to change nothing (Emulator::apply_controlword):
// the random sequences repeat controlwords often, so a wrong skip shows here.
// Seeded (CANMOTION_SEED / CANMOTION_COUNT, tests/support/random_seed.hpp).
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"
#include "tests/support/random_seed.hpp"

using namespace canmotion;
using cia402::State;

namespace {

/// What the emulator does with the drive state at one SYNC (handle_sync and
/// advance_motor), for a drive standing still in CSP with no heartbeat
/// consumer and no following error.
struct Reference {
  State s = State::kSwitchOnDisabled;
  std::uint16_t last_cw = 0;
  std::int16_t qs = 2;
  void sync(std::uint16_t cw, bool fault) {
    std::uint16_t prev = last_cw;
    for (int i = 0; i < 2; ++i) {  // at most two transitions per controlword
      const cia402::StepResult r = cia402::apply_controlword(s, prev, cw, qs);
      if (r.transition == cia402::kNoTransition) break;
      s = r.next;
      prev = cw;
    }
    last_cw = cw;
    if (s == State::kFaultReactionActive) s = State::kFault;  // 14: reaction done
    if (fault && s != State::kFault) s = State::kFaultReactionActive;  // 13
    if (s == State::kQuickStopActive && !cia402::quick_stop_stays(qs)) s = State::kSwitchOnDisabled;  // 12, at rest
  }
};

can::TimedFrame rpdo1(std::uint8_t node, std::uint16_t cw) {
  can::Frame f(0x200u + node, {static_cast<std::uint8_t>(cw), static_cast<std::uint8_t>(cw >> 8), 0, 0, 0, 0});
  return can::TimedFrame{f, 0};
}

}  // namespace

TEST(EmulatorControlword, StateMachineFollowsThePureTableUnderRandomControlwords) {
  const std::uint64_t seed = canmotion::test::test_seed(6040);
  const std::uint64_t count = canmotion::test::test_count(50000);
  std::mt19937_64 rng(seed);
  emulator::EmulatorConfig cfg;
  cfg.node = 3;
  // Permissive: compares each controlword against the pure table's 3+4 in
  // one step, with instant boot and fault reset (the strict one-transition,
  // boot and fault-cause behaviours: test_emulator_strict.cpp).
  cfg.behaviour = emulator::EmulatorBehaviour::permissive();
  emulator::Emulator emu(cfg);
  fbtest::VecSink out;
  emu.power_on(0, out);
  emu.on_frame(can::TimedFrame{fbtest::frame("000#0103"), 0}, out);  // NMT start node 3
  ASSERT_EQ(emu.nmt_state(), canopen::NmtState::kOperational);
  constexpr std::array<std::uint16_t, 12> kCws{0x0000, 0x0002, 0x0006, 0x0007, 0x000F, 0x0080,
                                               0x0086, 0x008F, 0x001F, 0x000B, 0x0003, 0x0106};
  Reference ref;
  std::uint16_t cw = 0;
  int transitions = 0, repeats = 0;
  for (std::uint64_t k = 0; k < count; ++k) {
    if (rng() % 5 < 2) {
      cw = kCws[rng() % kCws.size()];
    } else {
      ++repeats;
    }
    if (rng() % 64 == 0) {  // quick stop option code: 2 (to Switch on disabled) or 6 (stays)
      ref.qs = rng() % 2 == 0 ? 2 : 6;
      const std::array<std::uint8_t, 2> v{static_cast<std::uint8_t>(ref.qs), 0};
      ASSERT_EQ(emu.sdo_write(cia402::obj::kQuickStopOptionCode, 0, v), canopen::SdoAbort::kNone);
    }
    const bool fault = rng() % 40 == 0;
    if (fault) emu.inject_fault(0x2310);
    emu.set_time(static_cast<std::int64_t>(k) * 1'000'000);
    emu.on_frame(rpdo1(cfg.node, cw), out);
    emu.on_frame(can::TimedFrame{fbtest::frame("080#"), 0}, out);
    const State before = ref.s;
    ref.sync(cw, fault);
    if (ref.s != before) ++transitions;
    ASSERT_EQ(emu.state(), ref.s) << canmotion::test::seed_note(seed) << " sync " << k << " cw 0x" << std::hex << cw
                                  << " qs " << std::dec << ref.qs;
    out.clear();
  }
  // The sequence must have exercised both: many transitions and many repeats.
  EXPECT_GT(transitions, static_cast<int>(count / 50));
  EXPECT_GT(repeats, static_cast<int>(count / 3));
}
