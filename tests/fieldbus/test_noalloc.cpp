// The master's cyclic path allocates nothing: DriveNetwork::on_frame and
// cycle (boot, SDO configuration, state machine, RPDOs, SYNC) run with a
// counting global operator new. The emulated drives and the SimBus are
// counted too (they are built to be allocation-free after set-up).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "fieldbus/emulator/sim_rig.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocs{0};
}  // namespace

// The replacement operator new allocates with malloc, so free is the match.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocs.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

using namespace canmotion;

TEST(FieldbusNoAlloc, BootConfigureEnableAndRunWithoutAllocating) {
  emulator::SimRigConfig cfg;
  cfg.drive.pdo_profile = cia402::PdoProfile::kCspCsvCst;
  emulator::SimRig rig(cfg);
  rig.power_on();
  // The counter works: one allocation is seen.
  g_counting = true;
  { auto* v = new std::vector<int>(3); delete v; }
  g_counting = false;
  ASSERT_GE(g_allocs.load(), 1u);
  g_allocs = 0;
  g_counting = true;
  bool ok = rig.run_until([&] { return rig.network().all_operational(); }, 2000);
  rig.network().enable_all();
  ok = ok && rig.run_until([&] { return rig.network().all_enabled(); }, 2000);
  for (int k = 0; k < 2000; ++k) {
    for (std::size_t i = 0; i < rig.network().size(); ++i) rig.network().at(i).set_target_position(k * 10);
    if (k == 1000) rig.network().at(1).set_mode(cia402::Mode::kCsv);
    rig.step();
  }
  g_counting = false;
  ASSERT_TRUE(ok);
  EXPECT_EQ(g_allocs.load(), 0u);
  EXPECT_EQ(rig.network().at(1).feedback().mode_display, 9);
}

TEST(FieldbusNoAlloc, MdsRampSlatAndModeSwitchTimeoutWithoutAllocating) {
  namespace obj = cia402::obj;
  emulator::SimRigConfig cfg;
  cfg.nodes = {2, 3};
  cfg.drive.pdo_profile = cia402::PdoProfile::kCspCsvCst;
  cfg.drive.mode_switch_timeout_ns = 20'000'000;
  cfg.drive.extra_writes = {{obj::kProfileAcceleration, 0, 4, 200'000}, {obj::kProfileDeceleration, 0, 4, 300'000},
                            {obj::kRampJerkControl, 0, 1, 40},       {obj::kSlatConfiguration, 0, 1, 1},
                            {obj::kSlatSetPoint, 0, 4, 1'000},       {obj::kSlatTimeDelay, 0, 2, 2}};
  cfg.emulator.viscous_friction = 0.01;
  cfg.emulator.rated_torque_acceleration = 1'000'000;
  cfg.emulator.behaviour.optional_objects_absent = false;  // a drive with the MDS objects 0x2010..0x2022
  emulator::SimRig rig(cfg);
  rig.power_on();
  g_allocs = 0;
  g_counting = true;
  bool ok = rig.run_until([&] { return rig.network().all_operational(); }, 3000);
  rig.network().enable_all();
  ok = ok && rig.run_until([&] { return rig.network().all_enabled(); }, 2000);
  auto& v = rig.network().at(0);
  auto& t = rig.network().at(1);
  v.set_mode(cia402::Mode::kCsv);
  t.set_mode(cia402::Mode::kCst);
  for (int k = 0; k < 1500; ++k) {
    v.set_target_velocity(k < 700 ? 40'000 : -20'000);  // S-curve ramps both ways
    t.set_target_velocity(k < 700 ? 10'000 : 3'000);     // SLAT 1 in and out of speed control
    t.set_target_torque(0);
    if (k == 1200) {
      rig.emulator(2).set_refuse_mode_switch(true);
      v.set_mode(cia402::Mode::kCst);  // refused: the mode-switch timeout fails the proxy
    }
    rig.step();
  }
  g_counting = false;
  ASSERT_TRUE(ok);
  EXPECT_EQ(g_allocs.load(), 0u);
  EXPECT_EQ(v.failure().kind, cia402::FailureKind::kModeSwitchTimeout);
  EXPECT_EQ(t.feedback().mode_display, 10);
}
