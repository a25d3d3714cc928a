// Seeded property tests for MATC, time driven and master driven (seed 004
// "Scaling Time Cams", "Pending Cam Execution"; reference §5). Seed and count:
// CANMOTION_SEED / CANMOTION_PROP_COUNT (printed on failure).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "motion/cam/cam_profile.hpp"
#include "prop_util.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::maj;
using canmotion::motion::test::prop_count;
using canmotion::motion::test::prop_seed;
using canmotion::motion::test::Rig;
using canmotion::motion::test::num;
using canmotion::motion::test::Rng;

namespace {

AxisConfig cfg() { return canmotion::motion::test::axis_cfg(1e6, 1e9); }

/// A random calculated profile: 2..6 points, increasing master values, linear
/// or cubic segments.
void random_profile(Rng& g, cam::CamProfile& p) {
  const int n = 2 + g.pick(5);
  std::vector<cam::CamPoint> pts;
  double m = g.uni(-1, 1);
  for (int i = 0; i < n; ++i) {
    pts.push_back(cam::CamPoint{m, g.uni(-5, 5), g.coin() ? 1 : 0});
    m += g.uni(0.1, 1.0);
  }
  ASSERT_TRUE(cam::mccp(cam::MccpRequest{pts, 0, static_cast<std::int64_t>(n), g.uni(-3, 3), g.uni(-3, 3)}, p).ok());
}

/// max |dP/dx| of a profile (dense sampling, 2 % margin).
double max_slope(const cam::CamProfile& p) {
  double mx = 0;
  const double a = p.master_start(), b = p.master_end();
  for (int i = 0; i <= 4000; ++i) mx = std::max(mx, std::fabs(p.evaluate(a + (b - a) * i / 4000.0).velocity));
  return mx * 1.02 + 1e-9;
}

/// dP/dx at unscaled driving coordinate `x` (continuous: unwound).
double slope_at(const cam::CamProfile& p, double x) {
  const double m0 = p.master_start(), span = p.master_span();
  double v = m0 + x;
  v -= std::floor((v - m0) / span) * span;
  return p.evaluate(v).velocity;
}

struct PropRig {
  Rig r;
  cam::CamProfile a{16}, b{16};
  PropRig() {
    r.add_axis("X", cfg());
    r.add_axis("Y", cfg());
    r.add_axis("Y2", cfg());
    r.add_axis("Y3", cfg());
    for (const char* ax : {"X", "Y", "Y2", "Y3"}) EXPECT_EQ(r.exec(std::string("MSO(") + ax + ", on" + ax + ");"), Err::None);
    r.p->attach_cam_profile(0, &a);
    r.p->attach_cam_profile(1, &b);
    r.sym.cam_profiles["a"] = 0;
    r.sym.cam_profiles["b"] = 1;
    EXPECT_EQ(r.exec("MDAC(Y, X, l1, timecam, command);"), Err::None);
    EXPECT_EQ(r.exec("MDAC(Y2, X, l2, timecam, command);"), Err::None);
    EXPECT_EQ(r.exec("MDAC(Y3, X, l3, timecam, command);"), Err::None);
    r.step();
  }
};


std::string matc(const std::string& ax, const std::string& c, const std::string& prof, double ds, double ts,
                 const std::string& mode, const std::string& sched, bool md, const std::string& lock,
                 const std::string& dir = "same") {
  return "MATC(" + ax + ", " + c + ", " + dir + ", " + prof + "[0], " + num(ds) + ", " + num(ts) + ", " + mode + ", " + sched + ", 0, " + (md ? lock : std::string("none")) + ", " +
         (md ? "masterdrivenmode" : "timedrivenmode") + ");";
}

}  // namespace

// A pending cam takes over at the end of the active pass without a position
// jump: no cycle moves the slave further than the fastest of the two scaled
// profiles allows (time driven: x 1 s/s; master driven: x the master speed).
TEST(MatcProperty, PendingBlendHasNoPositionJump) {
  const std::uint64_t seed = prop_seed();
  const std::uint64_t count = prop_count(60);
  Rng g(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    SCOPED_TRACE("CANMOTION_SEED=" + std::to_string(seed) + " case " + std::to_string(n));
    PropRig p;
    random_profile(g, p.a);
    random_profile(g, p.b);
    const bool md = g.coin();
    const double dsa = g.uni(0.2, 3) * (g.coin() ? 1 : -1), tsa = g.uni(0.2, 2);
    const double dsb = g.uni(0.2, 3), tsb = g.uni(0.2, 2);
    const bool cont = g.coin();
    const double V = g.uni(1, 20);  // master speed (master driven)
    if (md) {
      ASSERT_EQ(p.r.exec(maj("X", "jx", 0, V, 1e9, 1e9)), Err::None);
    }
    p.r.step(2);
    ASSERT_EQ(p.r.exec(matc("Y", "ca", "a", dsa, tsa, cont ? "continuous" : "once", "immediate", md,
                            "immediateforwardonly")),
              Err::None);
    const double rate = md ? V : 1.0;
    const double pass_a = p.a.master_span() * tsa / rate;  // seconds per pass of A
    const int pend_at = 1 + g.pick(std::max(1, static_cast<int>(pass_a * 1000 * 0.9)));
    p.r.step(pend_at);
    ASSERT_EQ(p.r.exec(matc("Y", "cb", "b", dsb, tsb, "once", "pending", md, "immediateforwardonly")), Err::None);
    const double vmax = std::max(std::fabs(dsa) / tsa * max_slope(p.a), dsb / tsb * max_slope(p.b)) * rate;
    const double bound = vmax * 0.001 * 1.0001 + 1e-9;
    double prev = p.r.axis("Y").command_position;
    bool took_over = false;
    const int limit = static_cast<int>((pass_a + p.b.master_span() * tsb / rate) * 1000) + 50;
    for (int k = 0; k < limit && !p.r.tag("cb").pc(); ++k) {
      p.r.step();
      const double y = p.r.axis("Y").command_position;
      ASSERT_LE(std::fabs(y - prev), bound) << "cycle " << k << (md ? " master driven" : " time driven");
      prev = y;
      took_over = took_over || p.r.tag("cb").ac() || !p.r.tag("ca").ip();
    }
    EXPECT_TRUE(took_over);
    EXPECT_TRUE(p.r.tag("cb").pc());
    EXPECT_FALSE(p.r.tag("ca").ip());
    EXPECT_EQ(p.r.tag("ca").pc(), !cont);
  }
}

// Time scaling by k divides the velocity by k; distance scaling by k
// multiplies it by k -- in time-driven and master-driven mode.
TEST(MatcProperty, TimeScalingDividesAndDistanceScalingMultipliesVelocity) {
  const std::uint64_t seed = prop_seed();
  const std::uint64_t count = prop_count(40);
  Rng g(seed + 1);
  for (std::uint64_t n = 0; n < count; ++n) {
    SCOPED_TRACE("CANMOTION_SEED=" + std::to_string(seed) + " case " + std::to_string(n));
    PropRig p;
    random_profile(g, p.a);
    const bool md = g.coin();
    const int k = 2 + g.pick(3);        // integer time scale: sample cycle n*k against cycle n
    const double kd = g.uni(-4, 4);     // distance scale
    const double V = g.uni(1, 20);
    if (md) {
      ASSERT_EQ(p.r.exec(maj("X", "jx", 0, V, 1e9, 1e9)), Err::None);
      p.r.step(3);  // at constant speed before the cams start: master travel = n V T exactly
    }
    p.r.submit(matc("Y", "c1", "a", 1, 1, "continuous", "immediate", md, "immediateforwardonly"));
    p.r.submit(matc("Y2", "c2", "a", 1, k, "continuous", "immediate", md, "immediateforwardonly"));
    p.r.submit(matc("Y3", "c3", "a", kd, 1, "continuous", "immediate", md, "immediateforwardonly"));
    const int cycles = 400;
    std::vector<double> v1, v2, v3;
    for (int c = 0; c < cycles * k; ++c) {
      p.r.step();
      if (c == 0) {
        ASSERT_TRUE(p.r.tag("c1").ip() && p.r.tag("c2").ip() && p.r.tag("c3").ip());
      }
      v1.push_back(p.r.axis("Y").command_velocity);
      v2.push_back(p.r.axis("Y2").command_velocity);
      v3.push_back(p.r.axis("Y3").command_velocity);
    }
    const double scale = (md ? V : 1.0) * max_slope(p.a);
    for (int c = 1; c < cycles; ++c) {
      // cycle index i = c-th step: driving coordinate (c + 1) T (x V)
      const std::size_t i = static_cast<std::size_t>(c) - 1;
      const std::size_t ik = static_cast<std::size_t>(c * k) - 1;
      ASSERT_NEAR(v2[ik] * k, v1[i], 1e-7 * scale + 1e-9) << "time scaling, cycle " << c;
      ASSERT_NEAR(v3[i], kd * v1[i], 1e-7 * scale * std::max(1.0, std::fabs(kd)) + 1e-9) << "distance scaling";
    }
  }
}

// Master-driven MATC: slave velocity = scaled cam slope x master velocity
// (in the lock direction), for random master velocity programs.
TEST(MatcProperty, MasterDrivenCamVelocityIsSlopeTimesMasterVelocity) {
  const std::uint64_t seed = prop_seed();
  const std::uint64_t count = prop_count(40);
  Rng g(seed + 2);
  const char* locks[] = {"none", "immediateforwardonly", "immediatereverseonly"};
  for (std::uint64_t n = 0; n < count; ++n) {
    SCOPED_TRACE("CANMOTION_SEED=" + std::to_string(seed) + " case " + std::to_string(n));
    PropRig p;
    random_profile(g, p.a);
    const int li = g.pick(3);
    const double ds = g.uni(-3, 3), ts = g.uni(0.2, 3);
    const bool opposite = g.coin();
    const double dir = opposite ? -1.0 : 1.0;
    ASSERT_EQ(p.r.exec(matc("Y", "c", "a", ds, ts, "continuous", "immediate", true, locks[li],
                            opposite ? "opposite" : "same")),
              Err::None);
    double u = 0, x_prev = p.r.axis("X").command_position, v_prev = 0;
    int checked_const = 0;
    for (int seg = 0; seg < 8; ++seg) {
      const double v = g.uni(-20, 20);
      ASSERT_EQ(p.r.exec(maj("X", "jx" + std::to_string(seg), v < 0 ? 1 : 0, std::fabs(v), 1e9, 1e9)), Err::None);
      const int len = 20 + g.pick(150);
      for (int c = 0; c < len; ++c) {
        p.r.step();
        const double x = p.r.axis("X").command_position;
        const double dx = x - x_prev;
        x_prev = x;
        const double du = li == 0 ? dx : li == 1 ? std::max(dx, 0.0) : std::max(-dx, 0.0);
        u += du;
        const double slope = dir * ds / ts * slope_at(p.a, u / ts);
        const double vs = p.r.axis("Y").command_velocity;
        const double tol = 1e-6 * (1 + std::fabs(slope) * 20);
        ASSERT_NEAR(vs, slope * du / 0.001, tol) << "segment " << seg << " cycle " << c;
        const double vm = p.r.axis("X").command_velocity;
        if (c > 1 && vm == v_prev) {  // master at constant velocity: slope x master velocity
          const double vm_lock = li == 0 ? vm : li == 1 ? std::max(vm, 0.0) : std::max(-vm, 0.0);
          ASSERT_NEAR(vs, slope * vm_lock, tol) << "segment " << seg << " cycle " << c;
          ++checked_const;
        }
        v_prev = vm;
      }
    }
    EXPECT_GT(checked_const, 100);
  }
}
