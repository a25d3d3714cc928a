// Instructions that wait on a drive always end (issue 26): an MSO, MSF,
// MAFR, MASR or MAH ends with DN/PC or with ER within its limit, whatever
// happens to the node meanwhile. The runtime is built from a configuration
// (config::simulated_runtime, every bus simulated) so that the limit is the one
// canmotiond uses: drive.timeouts.wait_ms, by default 3 x boot_ms +
// mode_switch_ms + 4 x transition_ms (config::drive_wait_limit_s).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "config/runtime.hpp"
#include "tests/config/runtime_rig.hpp"
#include "tests/support/random_seed.hpp"

namespace canmotion::config {
namespace {

/// The rig with what these tests look at: the drive-wait events, a tool on
/// the bus (NMT commands another master or tool may send), virtual time that
/// can jump (a late wake-up: the cycle runs periods after its deadline).
struct WaitRig : test::RuntimeRig {
  using test::RuntimeRig::RuntimeRig;
  std::vector<rt::Event> waits;  ///< Event::Kind::kDriveWait, in order
  std::vector<std::string> texts;  ///< their describe_drive_wait() texts
  std::uint64_t cycle_count = 0;
  void after_cycle() override {
    ++cycle_count;
    rt::Event e;
    while (ctl().pop_event(e)) {
      if (e.kind != rt::Event::Kind::kDriveWait) continue;
      waits.push_back(e);
      const auto id = static_cast<motion::AxisId>(e.axis);
      std::string control;
      for (const auto& [name, cid] : ctl().controls())
        if (cid == e.wait.control) control = name;
      texts.push_back(rt::describe_drive_wait(e, ctl().axis_spec(id), id, control, ctl().period_s()));
    }
  }
  std::int64_t period_ns() { return ctl().spec().period_ns; }
  bool run_until(const std::function<bool()>& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      cycle();
      if (done()) return true;
    }
    return false;
  }
};

// ---------------------------------------------------------------------------
// The hang of vcan.realdrives.burst_raise (../shared/evidence/mso-hang-2026-11-28),
// on the SimBus: drives that were up before canmotiond (their boot-up
// missed, no heartbeat configured yet), a 4 ms period, boot_ms 5000. The
// master resets them after boot_ms and configures them; the MSOs issued at
// t = 0 waited with the planner's fixed 5 s drive timeout, which expired
// at 5.0 s, just before the drives were up (5.1 s here, 5.26 s in the VM):
// ERR 12 EXERR 16 that neither the script (it waited for DN) nor the log
// showed, and every RPDO after it carried controlword 0. With the limit from
// the drive's timeouts (3 x 5000 + 500 + 4 x 2000 ms) the MSOs complete.
const char* kBurstYaml = R"(controller: {period_ms: 4}
buses:
  - {name: can0, interface: sim, master_heartbeat_ms: 100}
drives:
  heartbeat_ms: 200
  master_heartbeat_timeout_ms: 0
  timeouts: {sdo_ms: 1000, boot_ms: 5000, transition_ms: 2000}
axes:
  - {name: A2, type: AXIS_CIP_DRIVE, bus: can0, node: 2, units: mm, conversion_constant: 1000, max_speed: 100, max_accel: 1000, max_decel: 1000}
  - {name: A3, type: AXIS_CIP_DRIVE, bus: can0, node: 3, units: mm, conversion_constant: 1000, max_speed: 100, max_accel: 1000, max_decel: 1000}
)";

TEST(DriveWait, MsoIssuedBeforeTheResetOfADriveWhoseBootUpWasMissedCompletes) {
  WaitRig r(load_string(kBurstYaml, "burst.yaml"));
  for (std::uint32_t node : {2u, 3u}) {  // the boot-ups go unheard (the drives were up before canmotiond)
    can::SimFault drop;
    drop.cob_id = 0x700u + node;
    drop.count = 1;
    r.rt.sim->bus(0).add_fault(drop);
  }
  r.rt.sim->power_on(0);
  ASSERT_TRUE(r.execute("MSO(A2, mso2)"));
  ASSERT_TRUE(r.execute("MSO(A3, mso3)"));
  const bool ended = r.run_until(
      [&] { return (r.read("mso2.DN") != 0 || r.read("mso2.ER") != 0) && (r.read("mso3.DN") != 0 || r.read("mso3.ER") != 0); },
      10'000);
  const double t = static_cast<double>(r.cycle_count) * r.ctl().period_s();
  std::printf("missed boot-ups, 4 ms period, boot_ms 5000: MSOs ended at %.3f s: mso2 DN=%g ER=%g ERR=%g EXERR=%g\n", t,
              r.read("mso2.DN"), r.read("mso2.ER"), r.read("mso2.ERR"), r.read("mso2.EXERR"));
  for (const auto& s : r.texts) std::printf("  %s\n", s.c_str());
  ASSERT_TRUE(ended);
  EXPECT_GT(t, 5.0) << "the drives were configured before boot_ms: the boot-ups were not missed";
  EXPECT_EQ(r.read("mso2.DN"), 1.0) << "ERR " << r.read("mso2.ERR") << " EXERR " << r.read("mso2.EXERR");
  EXPECT_EQ(r.read("mso3.DN"), 1.0) << "ERR " << r.read("mso3.ERR") << " EXERR " << r.read("mso3.EXERR");
  EXPECT_EQ(r.read("A2.DriveEnableStatus"), 1.0);
  EXPECT_EQ(r.rt.sim->bus(0).counters().dropped, 2u);
}

// The default limit and wait_ms.
TEST(DriveWait, LimitComesFromTheDriveTimeouts) {
  DriveTimeouts t;
  EXPECT_DOUBLE_EQ(drive_wait_limit_s(t), 3 * 5.0 + 0.5 + 4 * 1.0);
  t.boot_ms = 5000;
  t.transition_ms = 2000;
  EXPECT_DOUBLE_EQ(drive_wait_limit_s(t), 23.5);
  t.wait_ms = 750;
  EXPECT_DOUBLE_EQ(drive_wait_limit_s(t), 0.75);
  const Config c = load_string(R"(controller: {period_ms: 1}
buses: [{name: can0, interface: sim}]
drives: {timeouts: {wait_ms: 1500}}
axes:
  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2, units: mm, conversion_constant: 1000}
  - {name: Y, type: AXIS_CIP_DRIVE, bus: can0, node: 3, units: mm, conversion_constant: 1000, drive: {timeouts: {boot_ms: 100, wait_ms: 0}}}
)",
                               "wait.yaml");
  WaitRig r(c);
  EXPECT_DOUBLE_EQ(r.ctl().axis_spec(0).config.drive_wait_limit, 1.5);
  EXPECT_DOUBLE_EQ(r.ctl().axis_spec(1).config.drive_wait_limit, (3 * 100 + 500 + 4 * 1000) / 1e3);
  try {
    (void)load_string(R"(controller: {period_ms: 1}
buses: [{name: can0, interface: sim}]
axes:
  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2, units: mm, conversion_constant: 1000, drive: {timeouts: {wait_ms: -5}}}
)",
                      "bad.yaml");
    ADD_FAILURE() << "a negative wait_ms was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("wait_ms"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.yaml:4"), std::string::npos) << e.what();
  }
}

// An MSO whose drive never gets there ends at its limit, and the log says
// why: the drive refuses to enable (it stays in Switched on) but answers,
// with the transition timeout longer than the limit.
TEST(DriveWait, MsoAtTheLimitIsLoggedWithTheDrivesState) {
  WaitRig r(load_string(R"(controller: {period_ms: 1}
buses: [{name: can0, interface: sim}]
axes:
  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2, units: mm, conversion_constant: 1000,
     drive: {timeouts: {transition_ms: 60000, wait_ms: 300}}}
)",
                        "limit.yaml"));
  r.rt.sim->power_on(0);
  ASSERT_TRUE(r.run_until([&] { return r.host.refresh().axes[0].phase == cia402::Phase::kOperational; }, 3000));
  r.rt.sim->drive(0).set_remote(false);  // local control: the drive ignores the controlword
  ASSERT_TRUE(r.execute("MSO(X, mso1)"));
  const std::uint64_t start = r.cycle_count;
  ASSERT_TRUE(r.run_until([&] { return r.read("mso1.DN") != 0 || r.read("mso1.ER") != 0; }, 1000));
  EXPECT_EQ(r.read("mso1.ER"), 1.0);
  EXPECT_EQ(r.read("mso1.ERR"), 12.0);
  EXPECT_EQ(r.read("mso1.EXERR"), 16.0);
  EXPECT_NEAR(static_cast<double>(r.cycle_count - start), 300.0, 2.0);
  ASSERT_EQ(r.waits.size(), 1u);
  EXPECT_EQ(r.waits[0].wait.cause, motion::DriveWaitCause::Limit);
  const std::string& text = r.texts[0];
  std::printf("%s\n", text.c_str());
  EXPECT_NE(text.find("MSO mso1 ended with ERR 12 EXERR 16 after 0.30"), std::string::npos) << text;
  EXPECT_NE(text.find("wait limit 0.3 s (axes[0].drive.timeouts.wait_ms"), std::string::npos) << text;
  EXPECT_NE(text.find("drive node 2: operational, Switch on disabled"), std::string::npos) << text;
}

// ---------------------------------------------------------------------------
// The rule as a property: random node events thrown at a pending MSO, MSF,
// MAFR, MASR or MAH; each ends within its limit (MSO/MSF/MAFR/MASR: DN or
// ER within drive_wait_limit; MAH: PC, ER or IP cleared within homing_ms
// plus that limit). Events: the drive power-cycled (a reboot), its boot-up
// lost, NMT reset node / reset communication / enter pre-operational / stop
// / start from another tool on the bus, heartbeats lost for a while, the
// drive dead for a while, TPDOs delayed, late cycles (the cycle runs periods
// after its deadline), a drive fault (held for a while: the reset refused).
// CANMOTION_SEED / CANMOTION_COUNT replay or extend it.
const char* kPropertyYaml = R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim, master_heartbeat_ms: 20}
drives:
  heartbeat_ms: 20
  timeouts: {sdo_ms: 40, boot_ms: 150, transition_ms: 60, mode_switch_ms: 40, homing_ms: 500}
axes:
  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2, units: mm, conversion_constant: 1000, max_speed: 200,
     max_accel: 2000, max_decel: 2000,
     homing: {mode: Active, sequence: Switch, method: 35, speed_search: 20, speed_zero: 2, accel: 200}}
)";

enum class Waiter : std::uint8_t { kMso, kMsf, kMafr, kMasr, kMah };
const char* waiter_name(Waiter w) {
  switch (w) {
    case Waiter::kMso: return "MSO";
    case Waiter::kMsf: return "MSF";
    case Waiter::kMafr: return "MAFR";
    case Waiter::kMasr: return "MASR";
    case Waiter::kMah: return "MAH";
  }
  return "?";
}

struct Trial {
  std::mt19937_64 rng;
  WaitRig r;
  can::SimBus::Endpoint& tool;
  std::string log;  ///< what happened, for the failure message
  int dead_for = 0;  ///< cycles left until a dead drive is powered again (0: alive)
  int fault_held = 0;  ///< cycles left until a held fault cause goes

  explicit Trial(std::uint64_t seed) : rng(seed), r(load_string(kPropertyYaml, "property.yaml")),
                                       tool(r.rt.sim->bus(0).add_endpoint("tool")) {}
  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
  void note(const std::string& s) { log += "  t=" + std::to_string(r.cycle_count) + " " + s + "\n"; }
  void nmt(std::uint8_t cs) {
    can::Frame f;
    f.id = 0;
    f.len = 2;
    f.data[0] = cs;
    f.data[1] = 2;
    (void)tool.send(f);
  }
  void drop(std::uint32_t id, std::uint64_t count) {
    can::SimFault d;
    d.cob_id = id;
    d.count = count;
    r.rt.sim->bus(0).add_fault(d);
  }
  /// One random node event.
  void event() {
    switch (uniform(0, 11)) {
      case 0: note("power cycle"); r.rt.sim->power_cycle(0, r.now); break;
      case 1: note("power cycle, boot-up lost"); drop(0x702, 1); r.rt.sim->power_cycle(0, r.now); break;
      case 2: note("NMT reset node"); nmt(0x81); break;
      case 3: note("NMT reset communication"); nmt(0x82); break;
      case 4: note("NMT enter pre-operational"); nmt(0x80); break;
      case 5: note("NMT stop"); nmt(0x02); break;
      case 6: note("NMT start"); nmt(0x01); break;
      case 7: {
        const int n = uniform(2, 12);
        note("heartbeats lost: " + std::to_string(n));
        drop(0x702, static_cast<std::uint64_t>(n));
        break;
      }
      case 8:
        if (dead_for == 0) {
          dead_for = uniform(10, 400);
          note("drive dead for " + std::to_string(dead_for) + " cycles");
          r.rt.sim->disconnect(0);
        }
        break;
      case 9: {
        can::SimFault d;
        d.cob_id = 0x182;
        d.action = can::SimFault::Action::kDelay;
        d.count = static_cast<std::uint64_t>(uniform(1, 40));
        d.delay_ns = uniform(1, 6) * r.period_ns() / 2;
        note("TPDO1 delayed: " + std::to_string(d.count) + " x " + std::to_string(d.delay_ns) + " ns");
        r.rt.sim->bus(0).add_fault(d);
        break;
      }
      case 10: {
        const int k = uniform(1, 30);
        note("late cycle: " + std::to_string(k) + " periods");
        r.now += k * r.period_ns();
        break;
      }
      case 11:
        fault_held = uniform(0, 300);
        note("drive fault, cause held " + std::to_string(fault_held) + " cycles");
        r.rt.sim->drive(0).inject_fault(0x2310);
        r.rt.sim->drive(0).hold_fault_cause(fault_held > 0);
        break;
    }
  }
  void cycle() {
    r.cycle();
    if (dead_for > 0 && --dead_for == 0) {
      note("drive powered again");
      r.rt.sim->power_cycle(0, r.now);
    }
    if (fault_held > 0 && --fault_held == 0) r.rt.sim->drive(0).hold_fault_cause(false);
  }
  bool cycles_until(const std::function<bool()>& done, int max) {
    for (int i = 0; i < max; ++i) {
      cycle();
      if (done()) return true;
    }
    return false;
  }
  bool ended(const std::string& tag, Waiter w) {
    if (w == Waiter::kMah) return r.read(tag + ".PC") != 0 || r.read(tag + ".ER") != 0 || r.read(tag + ".IP") == 0;
    return r.read(tag + ".DN") != 0 || r.read(tag + ".ER") != 0;
  }
  /// Call and wait; true when it ended DN (setup steps without events).
  bool setup(const std::string& call, const std::string& tag) {
    note(call);
    if (!r.execute(call)) return false;
    return cycles_until([&] { return r.read(tag + ".DN") != 0 || r.read(tag + ".ER") != 0; }, 3000) &&
           r.read(tag + ".DN") != 0;
  }
};

TEST(DriveWait, EveryWaitingInstructionEndsWithinItsLimitWhateverTheNodeDoes) {
  const std::uint64_t seed = canmotion::test::test_seed(20261128);
  const std::uint64_t count = canmotion::test::test_count(1000);
  std::mt19937_64 seeds(seed);
  int outcomes[5][3] = {};  // per waiter: DN/PC, ER, IP cleared (MAH)
  double worst = 0;          // the longest wait as a fraction of its limit
  std::uint64_t events = 0, logged = 0;
  for (std::uint64_t trial = 0; trial < count; ++trial) {
    const std::uint64_t trial_seed = seeds();
    Trial t(trial_seed);
    const auto w = static_cast<Waiter>(t.uniform(0, 4));
    // How the drive comes up: powered with the master, its boot-up lost,
    // powered later; the instruction may come before it is up.
    switch (t.uniform(0, 2)) {
      case 0: t.r.rt.sim->power_on(0); break;
      case 1: t.drop(0x702, 1); t.r.rt.sim->power_on(0); t.note("boot-up lost"); break;
      case 2: t.r.rt.sim->disconnect(0); t.dead_for = t.uniform(1, 300); t.note("drive powered later"); break;
    }
    const bool early = w == Waiter::kMso && t.uniform(0, 1) == 0;
    if (!early) {
      const bool up = t.cycles_until([&] { return t.r.host.refresh().axes[0].phase == cia402::Phase::kOperational; }, 3000);
      ASSERT_TRUE(up) << "trial " << trial << ": the drive never came up" << canmotion::test::seed_note(seed) << "\n" << t.log;
    }
    if (w == Waiter::kMsf || w == Waiter::kMah || w == Waiter::kMafr || w == Waiter::kMasr) {
      ASSERT_TRUE(t.setup("MSO(X, mso0)", "mso0")) << "trial " << trial << canmotion::test::seed_note(seed) << "\n" << t.log;
    }
    if (w == Waiter::kMafr || w == Waiter::kMasr) {  // something to reset: a drive fault, its cause held a while
      t.fault_held = t.uniform(0, 200);
      t.r.rt.sim->drive(0).hold_fault_cause(t.fault_held > 0);
      t.r.rt.sim->drive(0).inject_fault(0x2310);
      t.note("drive fault, cause held " + std::to_string(t.fault_held));
      ASSERT_TRUE(t.cycles_until([&] { return t.r.read("X.AxisFault") != 0; }, 500)) << canmotion::test::seed_note(seed);
    }
    const std::string call = w == Waiter::kMso    ? "MSO(X, w)"
                             : w == Waiter::kMsf  ? "MSF(X, w)"
                             : w == Waiter::kMafr ? "MAFR(X, w)"
                             : w == Waiter::kMasr ? "MASR(X, w)"
                                                  : "MAH(X, w)";
    if (t.uniform(0, 2) == 0) t.event();  // something happens just before the call
    t.note(call);
    ASSERT_TRUE(t.r.execute(call));
    t.cycle();  // the planner takes it
    const std::uint64_t start = t.r.cycle_count - 1;
    const double limit_s = t.r.ctl().axis_spec(0).config.drive_wait_limit + (w == Waiter::kMah ? 0.5 : 0.0);
    const auto bound = static_cast<std::uint64_t>(std::ceil(limit_s / t.r.ctl().period_s())) + 2;
    const double p_event = 1.0 / t.uniform(3, 100);
    std::bernoulli_distribution maybe(p_event);
    bool done = t.ended("w", w);
    while (!done && t.r.cycle_count - start <= bound) {
      if (maybe(t.rng)) {
        t.event();
        ++events;
      }
      t.cycle();
      done = t.ended("w", w);
    }
    const std::uint64_t waited = t.r.cycle_count - start;
    ASSERT_TRUE(done) << "trial " << trial << " (trial seed " << trial_seed << "): " << waiter_name(w)
                      << " still pending after " << waited << " cycles, limit " << limit_s << " s"
                      << canmotion::test::seed_note(seed) << "\n"
                      << t.log << "phase " << static_cast<int>(t.r.host.refresh().axes[0].phase) << ", failure: "
                      << t.r.host.refresh().axes[0].failure.to_string();
    worst = std::max(worst, static_cast<double>(waited) / static_cast<double>(bound));
    const bool er = t.r.read("w.ER") != 0;
    const int outcome = er ? 1 : (w == Waiter::kMah && t.r.read("w.PC") == 0) ? 2 : 0;
    ++outcomes[static_cast<int>(w)][outcome];
    // A wait that ended with ERR 12 EXERR 16 is logged once, with its instruction.
    if (er && w != Waiter::kMah && t.r.read("w.ERR") == 12 && t.r.read("w.EXERR") == 16) {
      ASSERT_FALSE(t.r.waits.empty()) << "trial " << trial << ": " << waiter_name(w) << " ended with ERR 12 unlogged"
                                      << canmotion::test::seed_note(seed) << "\n" << t.log;
      EXPECT_EQ(t.r.texts.back().rfind(waiter_name(w), 0), 0u) << t.r.texts.back() << canmotion::test::seed_note(seed);
      ++logged;
    }
  }
  std::printf("seed %llu, %llu trials, %llu node events; longest wait %.2f of its bound\n",
              static_cast<unsigned long long>(seed), static_cast<unsigned long long>(count),
              static_cast<unsigned long long>(events), worst);
  for (int w = 0; w < 5; ++w)
    std::printf("  %-4s DN/PC %d, ER %d, IP cleared %d\n", waiter_name(static_cast<Waiter>(w)), outcomes[w][0],
                outcomes[w][1], outcomes[w][2]);
  std::printf("  %llu ERR 12 ends logged\n", static_cast<unsigned long long>(logged));
}

}  // namespace
}  // namespace canmotion::config
