// plan_move_to (motion/profile.hpp): a move that ends at its target with a
// given speed (the Follow Contour junction). Seeded property
// (CANMOTION_SEED, CANMOTION_PROP_COUNT; seed printed on failure).
#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "coord_rig.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord::test;

namespace {

/// Distance to reach speed v from rest (a = 0 at the end) with accel a, jerk ja.
double reach_distance(double v, double a, double ja) {
  if (std::isinf(ja)) return v * v / (2 * a);
  if (v >= a * a / ja) return v * (v / a + a / ja) / 2;
  return v * std::sqrt(v / ja);
}

struct End {
  double p, v, a;
};
End integrate(const Profile& p) {
  End e{p.origin(), 0, 0};
  for (int i = 0; i < p.size(); ++i) {
    const Segment& s = p.segment(i);
    e.p = p.origin() + s.p + s.v * s.dt + s.a * s.dt * s.dt / 2 + s.j * s.dt * s.dt * s.dt / 6;
    e.v = s.v + s.a * s.dt + s.j * s.dt * s.dt / 2;
    e.a = s.a + s.j * s.dt;
  }
  return e;
}

}  // namespace

TEST(ProfileTo, EndVelocityProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 40;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000);
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    const bool scurve = r.coin();
    double X = r.logu(1e-4, 1e3);
    const Limits l = limits_for(r, X * r.logu(0.01, 100), scurve);  // moves short and long for these limits
    const double ve = l.v * r.uni(0, 1.2);
    const bool from_rest = r.coin();
    Kin k0{r.uni(-100, 100), 0, 0};
    if (!from_rest) {
      // A state the path generator re-plans from: somewhere along a move
      // planned with the same limits (so it can still stop by its target).
      Profile whole;
      ASSERT_TRUE(plan_move(whole, k0, X, l));
      int hint = 0;
      const Kin at = whole.sample(r.uni(0, 1) * whole.duration(), hint);
      X = k0.p + X - at.p;
      k0 = at;
      if (X <= 1e-9 * std::max(1.0, std::fabs(k0.p))) continue;  // at the end already (rounding)
    }
    std::ostringstream os;
    os << "seed=" << seed << " n=" << n << " X=" << X << " ve=" << ve << " k0={" << k0.p << "," << k0.v << ","
       << k0.a << "} lim={" << l.v << "," << l.a << "," << l.d << "," << l.ja << "," << l.jd << "}";
    Profile p;
    ASSERT_TRUE(plan_move_to(p, k0, X, ve, l)) << os.str();
    const End e = integrate(p);
    int h = 0;
    ASSERT_EQ(p.sample(p.duration(), h).p, k0.p + X) << os.str() << " exact end";
    ASSERT_NEAR(e.p, k0.p + X, 1e-8 * std::max(1.0, std::fabs(k0.p) + X)) << os.str();
    if (scurve) {  // trapezoidal: a steps to 0
      ASSERT_NEAR(e.a, 0.0, 1e-7 * std::max(l.a, l.d)) << os.str();
    }
    if (e.v > std::min(ve, l.v) * (1 + 1e-9) + 1e-9) {
      // Could not slow down to ve in time: the slowest reachable, not below ve,
      // not above the speed after the present acceleration is ramped out.
      const double vs = k0.v + (k0.a > 0 ? k0.a * k0.a / (2 * l.ja) : 0.0);
      ASSERT_LE(e.v, vs * (1 + 1e-9)) << os.str();
      ASSERT_FALSE(from_rest) << os.str();
    }
    ASSERT_GE(e.v, -1e-9 * l.v) << os.str();
    // Never reverses.
    for (int i = 0; i < p.size(); ++i) {
      const Segment& s = p.segment(i);
      ASSERT_GE(s.v, -1e-9 * l.v) << os.str();
    }
    if (from_rest) {
      // Within the limits, and the end speed is ve unless the move is too short to reach it.
      ASSERT_LE(p.peak_velocity(), l.v * (1 + 1e-9)) << os.str();
      for (int i = 0; i < p.size(); ++i) {
        const Segment& s = p.segment(i);
        ASSERT_LE(std::fabs(s.j), std::max(l.ja, l.jd) * (1 + 1e-9)) << os.str();
        ASSERT_LE(std::max(s.a, s.a + s.j * s.dt), l.a * (1 + 1e-9)) << os.str();
        ASSERT_GE(std::min(s.a, s.a + s.j * s.dt), -l.d * (1 + 1e-9)) << os.str();
      }
      const double want = std::min(ve, l.v);
      if (reach_distance(want, l.a, l.ja) <= X * (1 - 1e-9)) {
        ASSERT_NEAR(e.v, want, 1e-7 * l.v) << os.str();
      } else {
        ASSERT_NEAR(reach_distance(e.v, l.a, l.ja), X, 1e-6 * X) << os.str() << " fastest reachable";
      }
    }
  }
}

// With end velocity 0 it is plan_move, bit for bit.
TEST(ProfileTo, ZeroEndVelocityIsPlanMove) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 41;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000);
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    const bool scurve = r.coin();
    const double X = (r.coin() ? 1 : -1) * r.logu(1e-5, 1e4);
    const Limits l = limits_for(r, std::fabs(X) * r.logu(0.01, 100), scurve);
    const Kin k0{r.uni(-10, 10), l.v * r.uni(-1.5, 1.5), scurve ? r.uni(-l.d, l.a) : 0.0};
    const Overshoot pol = r.coin() ? Overshoot::Reverse : Overshoot::StopAtTarget;
    Profile a, b;
    const bool ra = plan_move(a, k0, X, l, pol);
    const bool rb = plan_move_to(b, k0, X, 0.0, l, pol);
    ASSERT_EQ(ra, rb);
    ASSERT_EQ(a.size(), b.size()) << "seed=" << seed << " n=" << n;
    for (int i = 0; i < a.size(); ++i)
      ASSERT_EQ(std::memcmp(&a.segment(i), &b.segment(i), sizeof(Segment)), 0) << "seed=" << seed << " n=" << n;
    const double da[2] = {a.duration(), a.origin()}, db[2] = {b.duration(), b.origin()};
    ASSERT_EQ(std::memcmp(da, db, sizeof da), 0);
  }
}
