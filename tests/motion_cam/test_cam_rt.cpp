// Real-time rules for the cam code: MCCP, evaluation and a running cam make
// no heap allocation once the CamProfile exists (DESIGN.md "Rules for the
// cyclic path"), and the cam error numbers agree with the motion-core enum.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "motion/cam/cam_motion.hpp"
#include "motion/types.hpp"
#include "cam_test_util.hpp"

// GCC 12 reports a false -Wmismatched-new-delete when the replaced operators
// are inlined into a new/delete pair of this file.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

// Global replacement: counts allocations while g_counting is set.
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace canmotion::motion::cam;

TEST(CamRealtime, MccpAndCammingAllocateNothing) {
  std::mt19937_64 rng(cam_test::seed());
  const auto mixed = cam_test::random_cam(rng, 1000, cam_test::Mix::Mixed);
  const auto cubic = cam_test::random_cam(rng, 1000, cam_test::Mix::AllCubic);
  auto bad = mixed;
  bad[500].master = bad[499].master;
  CamProfile profile(1000);  // the only allocation: at construction
  CamMotion cam;
  double sink = 0;

  g_allocations = 0;
  g_counting = true;
  const MccpResult r1 = mccp({mixed, 0, 1000, 1.0, -1.0}, profile);
  const MccpResult r2 = mccp({bad, 0, 1000, 1.0, -1.0}, profile);
  const MccpResult r3 = mccp({cubic, 0, 1000, 0.0, 0.0}, profile);
  const CamError acq = profile.acquire();
  const CamError started = cam.start(profile, {ExecutionMode::Continuous, {2.0, 0.5}});
  for (int i = 0; i < 100000; ++i) {
    const auto o = cam.step(i * 1e-3);
    sink += o.position + o.velocity;
    CamCursor c;
    sink += evaluate_scaled(profile, i * 7.3e-3, {1.0, 3.0}, c).acceleration;
  }
  profile.release();
  g_counting = false;

  EXPECT_TRUE(r1.ok());
  EXPECT_EQ(r2.err, CamError::IllegalCamOrder);
  EXPECT_TRUE(r3.ok());
  EXPECT_EQ(acq, CamError::None);
  EXPECT_EQ(started, CamError::None);
  EXPECT_TRUE(std::isfinite(sink));
  EXPECT_EQ(g_allocations.load(), 0) << "allocations on the cyclic path";
}

// The counter works (so the test above can fail).
TEST(CamRealtime, AllocationCounterSeesAllocations) {
  g_allocations = 0;
  g_counting = true;
  auto* p = new CamProfile(4);
  g_counting = false;
  delete p;
  EXPECT_GE(g_allocations.load(), 2);
}

// CamError numbers equal the motion-core Err numbers, so a static_cast of the
// underlying value converts one into the other.
TEST(CamErrors, NumbersMatchMotionCoreErr) {
  using canmotion::motion::Err;
  const std::pair<CamError, Err> pairs[] = {
      {CamError::None, Err::None},
      {CamError::ParameterOutOfRange, Err::ParameterOutOfRange},
      {CamError::IllegalCamLength, Err::IllegalCamLength},
      {CamError::IllegalCamProfileLength, Err::IllegalCamProfileLength},
      {CamError::IllegalCamType, Err::IllegalCamType},
      {CamError::IllegalCamOrder, Err::IllegalCamOrder},
      {CamError::CamProfileBeingCalculated, Err::CamProfileBeingCalculated},
      {CamError::CamProfileBeingUsed, Err::CamProfileBeingUsed},
      {CamError::CamProfileNotCalculated, Err::CamProfileNotCalculated},
  };
  for (const auto& [c, e] : pairs) {
    EXPECT_EQ(err_code(c), static_cast<std::int16_t>(e)) << to_string(c);
  }
}

}  // namespace
