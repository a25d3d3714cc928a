// Controller::set_deferred_publish (canmotiond --sim): a reader on the cycle
// thread sees exactly the Status that immediate publishing gives, whichever
// cycles it reads and skips. Two identical rigs run the same commands; one
// defers. Reads happen at seeded random cycles (CANMOTION_SEED overrides the
// seed, printed on failure).
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>

#include "rt/controller/host.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

struct Rig : test::SimController {
  explicit Rig(bool deferred) {
    ctl->set_deferred_publish(deferred);
    ctl->set_telemetry(true);
  }
  ControllerHost host{*ctl};
};

void expect_same(const Status& a, const Status& b, const std::string& where) {
  SCOPED_TRACE(where);
  EXPECT_EQ(a.cycle, b.cycle);
  EXPECT_EQ(a.time_ns, b.time_ns);
  EXPECT_EQ(a.done_seq, b.done_seq);
  EXPECT_EQ(a.axis_count, b.axis_count);
  EXPECT_EQ(a.bus_count, b.bus_count);
  for (std::size_t i = 0; i < a.axis_count; ++i) {
    const AxisSnapshot &x = a.axes[i], &y = b.axes[i];
    EXPECT_EQ(x.tag.state, y.tag.state);
    EXPECT_EQ(x.tag.cip_state, y.tag.cip_state);
    EXPECT_EQ(x.tag.motion_status, y.tag.motion_status);
    EXPECT_EQ(x.tag.axis_status, y.tag.axis_status);
    EXPECT_EQ(x.tag.axis_fault, y.tag.axis_fault);
    EXPECT_EQ(x.tag.command_position, y.tag.command_position);
    EXPECT_EQ(x.tag.command_velocity, y.tag.command_velocity);
    EXPECT_EQ(x.tag.actual_position, y.tag.actual_position);
    EXPECT_EQ(x.tag.actual_velocity, y.tag.actual_velocity);
    EXPECT_EQ(x.tag.position_error, y.tag.position_error);
    EXPECT_EQ(x.phase, y.phase);
    EXPECT_EQ(x.drive_state, y.drive_state);
    EXPECT_EQ(x.statusword, y.statusword);
    EXPECT_EQ(x.controlword, y.controlword);
    EXPECT_EQ(x.target_counts, y.target_counts);
    EXPECT_EQ(x.actual_counts, y.actual_counts);
    EXPECT_EQ(x.mode_display, y.mode_display);
    EXPECT_EQ(x.tpdo_missed, y.tpdo_missed);
    EXPECT_EQ(x.failure.kind, y.failure.kind);
    EXPECT_EQ(x.max_abs_position_error, y.max_abs_position_error);
  }
  for (std::size_t i = 0; i < a.bus_count; ++i) {
    EXPECT_EQ(a.buses[i].state, b.buses[i].state);
    EXPECT_EQ(a.buses[i].counters.tx_frames, b.buses[i].counters.tx_frames);
    EXPECT_EQ(a.buses[i].counters.rx_frames, b.buses[i].counters.rx_frames);
    EXPECT_EQ(a.buses[i].send_rejected, b.buses[i].send_rejected);
  }
  for (std::size_t c = 0; c < motion::kMaxControlTags; ++c) {
    EXPECT_EQ(a.controls[c].flags, b.controls[c].flags) << "control " << c;
    EXPECT_EQ(a.controls[c].err, b.controls[c].err) << "control " << c;
    EXPECT_EQ(a.controls[c].state, b.controls[c].state) << "control " << c;
    EXPECT_EQ(a.controls[c].generation, b.controls[c].generation) << "control " << c;
  }
  EXPECT_EQ(a.cam_status, b.cam_status);
  EXPECT_EQ(a.telemetry_dropped, b.telemetry_dropped);
  EXPECT_EQ(a.commands_deferred, b.commands_deferred);
  EXPECT_EQ(a.halted, b.halted);
}

TEST(ControllerDeferredPublish, ReadersSeeTheSameStatusAsImmediatePublishing) {
  std::uint64_t seed = 20261121;
  if (const char* e = std::getenv("CANMOTION_SEED")) seed = std::strtoull(e, nullptr, 10);
  SCOPED_TRACE("seed " + std::to_string(seed) + " (CANMOTION_SEED)");
  std::mt19937_64 rng(seed);
  Rig now(false), later(true);
  Status s0, s1;
  EXPECT_FALSE(now.ctl->read_status(s0));  // nothing published before the first cycle
  EXPECT_FALSE(later.ctl->read_status(s1));
  const char* calls[] = {
      "MSO(Master, mso0)",
      "MSO(X, mso1)",
      "MAJ(Master, maj0, Forward, 50, UnitsPerSec, 500, UnitsPerSec2, 500, UnitsPerSec2, Trapezoidal, 100, 100, "
      "%ofTime, Disabled, Programmed, 0, None)",
      "MAG(X, Master, mag0, Same, 1.5, 0, 0, Command, Real, Enabled, 500, UnitsPerSec2)",
      "MATC(X, matc0, Same, cam1, 1, 1, Once, Immediate, 0, None, TimeDrivenMode)",
      "MAS(X, mas0, All, No, 100, %ofMaximum, No, 100, %ofTime)",
      "MAS(Master, mas1, All, No, 100, %ofMaximum, No, 100, %ofTime)",
      "MSF(X, msf0)",
  };
  std::size_t next = 0;
  int reads = 0;
  for (int cycle = 0; cycle < 3000; ++cycle) {
    if (next < std::size(calls) && cycle == 50 + static_cast<int>(next) * 300) {
      std::string c0, c1;
      // The host only binds and queues: the same request reaches both rigs.
      const auto e0 = now.host.execute(calls[next], &c0);
      const auto e1 = later.host.execute(calls[next], &c1);
      ASSERT_EQ(e0, std::nullopt) << calls[next] << ": " << *e0;
      ASSERT_EQ(e1, std::nullopt) << calls[next];
      ++next;
    }
    now.step();
    later.step();
    if (rng() % 7 == 0) {  // read some cycles, skip others (several in a row)
      ASSERT_TRUE(now.ctl->read_status(s0));
      ASSERT_TRUE(later.ctl->read_status(s1));
      expect_same(s0, s1, "cycle " + std::to_string(cycle));
      ++reads;
      if (rng() % 2 == 0) {  // a second read without a cycle in between
        ASSERT_TRUE(later.ctl->read_status(s1));
        expect_same(s0, s1, "second read, cycle " + std::to_string(cycle));
      }
      if (::testing::Test::HasFailure()) return;
    }
  }
  EXPECT_EQ(next, std::size(calls));
  EXPECT_GT(reads, 100);
  // Telemetry is taken every cycle either way.
  Sample a, b;
  int samples = 0;
  while (now.ctl->pop_sample(a)) {
    ASSERT_TRUE(later.ctl->pop_sample(b));
    EXPECT_EQ(a.cycle, b.cycle);
    EXPECT_EQ(a.cmd_pos, b.cmd_pos);
    EXPECT_EQ(a.act_pos, b.act_pos);
    EXPECT_EQ(a.motion_status, b.motion_status);
    ++samples;
  }
  EXPECT_FALSE(later.ctl->pop_sample(b));
  EXPECT_GT(samples, 1000);
}

}  // namespace
}  // namespace canmotion::rt
