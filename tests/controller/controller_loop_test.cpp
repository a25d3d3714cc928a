// Controller + SimWorld: the planner drives emulated CiA 402 drives through
// the CANopen master, cycle by cycle in virtual time.
#include <gtest/gtest.h>

#include <cmath>

#include "rt/controller/controller.hpp"
#include "rt/controller/sim_world.hpp"
#include "tests/support/allocation_counter.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt {
namespace {

using motion::Instr;

constexpr std::int64_t kPeriod = test::SimController::kPeriod;

struct Rig : test::SimController {
  motion::ControlId submit(Instr instr, const std::string& control, std::vector<motion::Operand> ops) {
    cmd::Instruction c;
    c.request.instr = instr;
    c.request.control = *ctl->control_id(control);
    c.request.count = static_cast<std::uint8_t>(ops.size());
    for (std::size_t i = 0; i < ops.size(); ++i) c.request.op[i] = ops[i];
    EXPECT_NE(ctl->submit(c), 0u);
    return c.request.control;
  }
};

motion::Operand ref(std::uint16_t id) { return motion::Operand{0.0, id}; }
motion::Operand val(double v) { return motion::Operand{v, 0xFFFF}; }

/// MAM(X, ctl, Absolute, pos, speed, units/s, accel, units/s2, decel, units/s2, trapezoidal, ...)
std::vector<motion::Operand> mam(std::uint16_t axis, std::uint16_t ctl, double pos, double speed) {
  return {ref(axis), ref(ctl), val(0), val(pos), val(speed), val(0), val(1000), val(0), val(1000), val(0), val(0),
          val(100), val(100), val(2), val(0), val(0), val(0), val(0), val(0), val(0)};
}

TEST(ControllerLoop, BootEnableMoveAndFollow) {
  Rig r;
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].phase == cia402::Phase::kOperational; }, 5000))
      << "drive never became operational; failure: " << r.status().axes[1].failure.to_string();
  const auto mso = r.submit(Instr::MSO, "mso1", {ref(1), ref(*r.ctl->control_id("mso1"))});
  ASSERT_TRUE(r.run_until([&](const Status& s) { return s.controls[mso].dn() || s.controls[mso].er(); }, 3000));
  Status s = r.status();
  ASSERT_TRUE(s.controls[mso].dn()) << "MSO ERR " << s.controls[mso].err;
  EXPECT_EQ(s.axes[1].drive_state, cia402::State::kOperationEnabled);

  const auto m = *r.ctl->control_id("mam1");
  r.submit(Instr::MAM, "mam1", mam(1, m, 100.0, 50.0));
  double worst = 0;
  ASSERT_TRUE(r.run_until(
      [&](const Status& st) {
        worst = std::max(worst, std::abs(st.axes[1].tag.position_error));
        return st.controls[m].pc() || st.controls[m].er();
      },
      10000));
  s = r.status();
  ASSERT_TRUE(s.controls[m].pc()) << "MAM ERR " << s.controls[m].err << " EXERR " << int(s.controls[m].exerr);
  EXPECT_DOUBLE_EQ(s.axes[1].tag.command_position, 100.0);
  EXPECT_EQ(s.axes[1].target_counts, 100000);
  // The emulated drive follows within its lag: at 50 mm/s a few cycles of lag
  // are well under the 5 mm tolerance.
  EXPECT_LT(worst, 1.0);
  r.run_until([](const Status&) { return false; }, 200);
  s = r.status();
  EXPECT_NEAR(s.axes[1].tag.actual_position, 100.0, 0.01);
  EXPECT_EQ(s.axes[1].actual_counts, r.world.drive(0).position());
  EXPECT_EQ(s.axes[1].tpdo_missed, 0u);
}

/// A representative run with every RT-thread cycle counted from power-on:
/// boot and SDO configuration, enabling, gearing to a jogging master, a move
/// superposed on the gear, a time cam, a drive fault with reset and
/// re-enable, and a stop. Only the non-RT side (submitting, draining) runs
/// outside the count.
TEST(ControllerLoop, RepresentativeRunAllocatesNothingOnTheCycle) {
  Rig r;
  r.ctl->set_trace(true);
  r.ctl->set_telemetry(true);
  TraceRecord tr;
  Sample sm;
  Event ev;
  std::uint64_t cycles = 0;
  auto counted = [&](int n) {
    for (int i = 0; i < n; ++i, ++cycles) {
      {
        // The simulated drives run in the same cycle under --sim (their
        // acceptance filters are refreshed there too): counted as well.
        test::CountAllocationsInScope count;
        r.world.begin_cycle(r.now);
        r.ctl->cycle(r.now);
        r.world.end_cycle(r.now);
      }
      r.now += kPeriod;
      while (r.ctl->pop_trace(tr)) {
      }
      while (r.ctl->pop_sample(sm)) {
      }
      while (r.ctl->pop_event(ev)) {
      }
    }
  };
  auto ctl = [&](const char* n) { return *r.ctl->control_id(n); };
  auto until = [&](const std::function<bool(const Status&)>& done, int max) {
    for (int i = 0; i < max; ++i) {
      counted(1);
      if (done(r.status())) return true;
    }
    return false;
  };
  test::reset_allocation_count();
  // Boot: boot-up, SDO configuration, NMT start.
  ASSERT_TRUE(until([](const Status& s) { return s.axes[1].phase == cia402::Phase::kOperational; }, 5000));
  // Enable both axes.
  r.submit(Instr::MSO, "mso0", {ref(0), ref(ctl("mso0"))});
  r.submit(Instr::MSO, "mso1", {ref(1), ref(ctl("mso1"))});
  ASSERT_TRUE(until([&](const Status& s) { return s.controls[ctl("mso1")].dn(); }, 3000));
  // Master jogs; X gears to it (real ratio 0.5, clutch) and a move is superposed.
  r.submit(Instr::MAJ, "maj0", {ref(0), ref(ctl("maj0")), val(0), val(40), val(0), val(400), val(0), val(400), val(0),
                                val(0), val(100), val(100), val(2), val(0), val(0), val(0), val(0)});
  r.submit(Instr::MAG, "mag1", {ref(1), ref(0), ref(ctl("mag1")), val(0), val(0.5), val(1), val(1), val(1), val(0),
                                val(0), val(500), val(0)});
  counted(500);
  r.submit(Instr::MAM, "mam1", mam(1, ctl("mam1"), 5.0, 20.0));
  counted(500);
  Status s = r.status();
  EXPECT_TRUE(s.controls[ctl("mag1")].ip()) << "MAG ERR " << s.controls[ctl("mag1")].err;
  EXPECT_TRUE(s.axes[1].tag.motion(motion::motion_status::GearingStatus));
  // Stop gearing and the move; run the time cam.
  r.submit(Instr::MAS, "mas1", {ref(1), ref(ctl("mas1")), val(0), val(0), val(100), val(1), val(0), val(100), val(2)});
  ASSERT_TRUE(until([&](const Status& st) { return st.controls[ctl("mas1")].pc(); }, 3000));
  const motion::Operand cam{0.0, *r.ctl->cam_id("cam1")};
  r.submit(Instr::MATC, "matc1", {ref(1), ref(ctl("matc1")), val(0), cam, val(1), val(1), val(1), val(0), val(0),
                                  val(0), val(0)});
  counted(1500);
  s = r.status();
  EXPECT_TRUE(s.controls[ctl("matc1")].ip()) << "MATC ERR " << s.controls[ctl("matc1")].err;
  EXPECT_EQ(s.cam_status[0], 3);
  // A drive fault, then fault reset and re-enable.
  r.world.drive(0).inject_fault(0x2310);
  ASSERT_TRUE(until([](const Status& st) { return st.axes[1].drive_state == cia402::State::kFault; }, 200));
  counted(20);
  r.submit(Instr::MAFR, "mafr1", {ref(1), ref(ctl("mafr1"))});
  counted(50);
  r.submit(Instr::MSO, "mso1b", {ref(1), ref(ctl("mso1b"))});
  ASSERT_TRUE(until([&](const Status& st) { return st.controls[ctl("mso1b")].dn(); }, 3000))
      << "re-enable failed, ERR " << r.status().controls[ctl("mso1b")].err;
  // Stop everything.
  r.submit(Instr::MAS, "mas0", {ref(0), ref(ctl("mas0")), val(0), val(0), val(100), val(1), val(0), val(100), val(2)});
  ASSERT_TRUE(until([&](const Status& st) { return st.controls[ctl("mas0")].pc(); }, 3000));
  EXPECT_EQ(test::counted_allocations(), 0u)
      << test::counted_bytes() << " bytes allocated on the cycle over " << cycles << " cycles";
  EXPECT_GT(cycles, 2000u);  // the whole scenario ran (about 2600 cycles)
  EXPECT_EQ(r.status().trace_dropped, 0u);
}

TEST(ControllerLoop, InjectedFaultFaultsTheAxis) {
  Rig r;
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].phase == cia402::Phase::kOperational; }, 5000));
  const auto mso = r.submit(Instr::MSO, "mso1", {ref(1), ref(*r.ctl->control_id("mso1"))});
  ASSERT_TRUE(r.run_until([&](const Status& s) { return s.controls[mso].dn(); }, 3000));
  r.world.drive(0).inject_fault(0x2310);
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].drive_state == cia402::State::kFault; }, 100));
  r.run_until([](const Status&) { return false; }, 5);
  const Status s = r.status();
  EXPECT_EQ(s.axes[1].last_emcy, 0x2310);
  EXPECT_NE(s.axes[1].tag.axis_fault, 0u) << "the planner saw no drive fault";
  bool saw_emcy = false;
  Event e;
  while (r.ctl->pop_event(e))
    if (e.kind == Event::Kind::kNode && e.node.kind == canopen::NodeEvent::Kind::kEmcy) saw_emcy = true;
  EXPECT_TRUE(saw_emcy);
}


TEST(ControllerLoop, ControlledStopDisarmsHeartbeatWatchAndHalts) {
  Rig r;
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.axes[1].phase == cia402::Phase::kOperational; }, 5000));
  r.ctl->set_trace(true);
  ASSERT_NE(r.ctl->submit(cmd::PreOperational{}), 0u);
  ASSERT_TRUE(r.run_until([](const Status& s) { return s.halted; }, 500));
  EXPECT_EQ(r.world.drive(0).nmt_state(), canopen::NmtState::kPreOperational);
  EXPECT_EQ(r.world.drive(0).read_int(0x1016, 1), 0) << "the drive still watches the master's heartbeat";
  // The master is silent from now on; a drive that still watched it would
  // fault with EMCY 0x8130 after 300 ms.
  TraceRecord tr;
  while (r.ctl->pop_trace(tr)) {
  }
  r.run_until([](const Status&) { return false; }, 1000);
  std::size_t sent = 0;
  while (r.ctl->pop_trace(tr)) sent += tr.tx ? 1u : 0u;
  EXPECT_EQ(sent, 0u) << "frames sent after the halt";
  EXPECT_NE(r.world.drive(0).state(), cia402::State::kFault);
  EXPECT_NE(r.world.drive(0).state(), cia402::State::kFaultReactionActive);
  EXPECT_EQ(r.status().axes[1].last_emcy, 0);
}

}  // namespace
}  // namespace canmotion::rt
