// MCCP and CAM_PROFILE: golden profiles, spline properties, validation errors,
// Status counting and evaluation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "motion/cam/cam_profile.hpp"
#include "cam_test_util.hpp"

namespace {

using namespace canmotion::motion::cam;
constexpr std::int32_t L = kSegmentLinear;
constexpr std::int32_t C = kSegmentCubic;

MccpResult calc(const std::vector<CamPoint>& cam, CamProfile& p, double s0 = 0.0, double s1 = 0.0) {
  return mccp(MccpRequest{cam, 0, static_cast<std::int64_t>(cam.size()), s0, s1}, p);
}

// Left limit at knot k+1 of segment k (evaluated inside segment k at u = h).
CamSample left_limit(const CamProfile& p, std::size_t k) {
  const auto& e = p.elements()[k];
  const double h = p.elements()[k + 1].master - e.master;
  return CamSample{e.a0 + h * (e.a1 + h * (e.a2 + h * e.a3)), e.a1 + h * (2 * e.a2 + 3 * h * e.a3),
                   2 * e.a2 + 6 * e.a3 * h};
}
// Right limit at knot k of segment k (u = 0).
CamSample right_limit(const CamProfile& p, std::size_t k) {
  const auto& e = p.elements()[k];
  return CamSample{e.a0, e.a1, 2 * e.a2};
}

// ---- golden profiles, computed by hand (see comments) ----------------------

// Two cubic segments through (0,0) (1,1) (2,0), slopes 0 at both ends.
// Interior knot (h = 1 both sides): m0 + 4 m1 + m2 = 3 (d0 + d1) = 3 (1 - 1) = 0
// with m0 = m2 = 0, so m1 = 0. Segment 0: a2 = 3 d - 2 m0 - m1 = 3, a3 = m0 + m1 - 2 d = -2:
// y = 3u^2 - 2u^3 (smoothstep). Segment 1 (d = -1): y = 1 - 3u^2 + 2u^3.
TEST(CamGolden, SmoothstepPair) {
  CamProfile p(8);
  const std::vector<CamPoint> cam{{0, 0, C}, {1, 1, C}, {2, 0, L}};
  ASSERT_TRUE(calc(cam, p, 0.0, 0.0).ok());
  ASSERT_EQ(p.status(), profile_status::kCalculated);
  ASSERT_EQ(p.point_count(), 3u);
  const auto e = p.elements();
  EXPECT_DOUBLE_EQ(e[0].a0, 0.0);
  EXPECT_NEAR(e[0].a1, 0.0, 1e-15);
  EXPECT_NEAR(e[0].a2, 3.0, 1e-14);
  EXPECT_NEAR(e[0].a3, -2.0, 1e-14);
  EXPECT_DOUBLE_EQ(e[1].a0, 1.0);
  EXPECT_NEAR(e[1].a1, 0.0, 1e-15);
  EXPECT_NEAR(e[1].a2, -3.0, 1e-14);
  EXPECT_NEAR(e[1].a3, 2.0, 1e-14);
  EXPECT_EQ(e[0].type, C);
  EXPECT_EQ(e[1].type, C);
  // y(0.5) = 0.75 - 0.25 = 0.5, y'(0.5) = 6u - 6u^2 = 1.5, y''(0.5) = 6 - 12u = 0.
  const CamSample s = p.evaluate(0.5);
  EXPECT_NEAR(s.position, 0.5, 1e-14);
  EXPECT_NEAR(s.velocity, 1.5, 1e-14);
  EXPECT_NEAR(s.acceleration, 0.0, 1e-13);
  // y(1.25) = 1 - 3/16 + 2/64 = 0.84375; y' = -6u + 6u^2 = -1.125.
  const CamSample t = p.evaluate(1.25);
  EXPECT_NEAR(t.position, 0.84375, 1e-14);
  EXPECT_NEAR(t.velocity, -1.125, 1e-14);
  // Profile outputs.
  EXPECT_DOUBLE_EQ(p.master_start(), 0.0);
  EXPECT_DOUBLE_EQ(p.master_end(), 2.0);
  EXPECT_DOUBLE_EQ(p.master_span(), 2.0);
  EXPECT_DOUBLE_EQ(p.slave_span(), 0.0);
}

// Linear, cubic, cubic, linear: (0,0,L) (1,1,C) (2,3,C) (4,3,L) (5,5).
// Knot 1 slope = slope of linear segment 0 = 1. Knot 3 slope = slope of linear
// segment 3 = (5-3)/1 = 2. Knot 2 (h1 = 1, h2 = 2, d1 = 2, d2 = 0):
// m1/1 + 2(1 + 1/2) m2 + m3/2 = 3 (2/1 + 0/2)  ->  1 + 3 m2 + 1 = 6  ->  m2 = 4/3.
// Segment 1 (h 1, d 2): a2 = (6 - 2 - 4/3) = 8/3, a3 = (1 + 4/3 - 4) = -5/3.
// Segment 2 (h 2, d 0): a2 = (0 - 8/3 - 2)/2 = -7/3, a3 = (4/3 + 2)/4 = 5/6.
TEST(CamGolden, LinearCubicJunctions) {
  CamProfile p(5);
  const std::vector<CamPoint> cam{{0, 0, L}, {1, 1, C}, {2, 3, C}, {4, 3, L}, {5, 5, L}};
  // The slopes must be ignored: first and last segments are linear.
  ASSERT_TRUE(calc(cam, p, 123.0, -77.0).ok());
  const auto e = p.elements();
  ASSERT_EQ(e.size(), 5u);
  EXPECT_DOUBLE_EQ(e[0].a1, 1.0);
  EXPECT_EQ(e[0].a2, 0.0);
  EXPECT_EQ(e[0].a3, 0.0);
  EXPECT_NEAR(e[1].a1, 1.0, 1e-14);
  EXPECT_NEAR(e[1].a2, 8.0 / 3.0, 1e-14);
  EXPECT_NEAR(e[1].a3, -5.0 / 3.0, 1e-14);
  EXPECT_NEAR(e[2].a0, 3.0, 0.0);
  EXPECT_NEAR(e[2].a1, 4.0 / 3.0, 1e-14);
  EXPECT_NEAR(e[2].a2, -7.0 / 3.0, 1e-14);
  EXPECT_NEAR(e[2].a3, 5.0 / 6.0, 1e-14);
  EXPECT_DOUBLE_EQ(e[3].a1, 2.0);
  EXPECT_EQ(e[4].a0, 5.0);
  EXPECT_EQ(e[4].a1, 0.0);
  // Velocity is continuous at the linear/cubic junctions.
  EXPECT_NEAR(p.evaluate(1.0 - 1e-9).velocity, p.evaluate(1.0).velocity, 1e-7);
  EXPECT_NEAR(p.evaluate(4.0 - 1e-9).velocity, 2.0, 1e-7);
}

// A single cubic segment is the Hermite cubic of its two end slopes.
TEST(CamGolden, SingleCubicSegmentUsesBothSlopes) {
  CamProfile p(2);
  // (0,0)-(2,2), start slope 0, end slope 3: d = 1, h = 2.
  // a2 = (3 - 0 - 3)/2 = 0, a3 = (0 + 3 - 2)/4 = 0.25 -> y = u^3/4.
  ASSERT_TRUE(calc({{0, 0, C}, {2, 2, L}}, p, 0.0, 3.0).ok());
  const auto& e = p.elements()[0];
  EXPECT_NEAR(e.a1, 0.0, 1e-15);
  EXPECT_NEAR(e.a2, 0.0, 1e-15);
  EXPECT_NEAR(e.a3, 0.25, 1e-15);
  EXPECT_NEAR(p.evaluate(2.0).velocity, 3.0, 1e-14);
}

// ---- properties --------------------------------------------------------------

// Tolerances (stated): with master gaps >= 0.01 and |slave| <= 50, position
// continuity and interpolation to 1e-9 * (1 + max|S|), velocity continuity to
// 1e-7 * (1 + max|d|) where d are the chord slopes, curvature to 1e-5 relative.
struct Scale {
  double pos, vel, acc;
};
Scale tolerances(const std::vector<CamPoint>& cam, double s0, double s1) {
  double smax = 0, dmax = std::max(std::abs(s0), std::abs(s1)), hmin = 1e300;
  for (std::size_t i = 0; i < cam.size(); ++i) {
    smax = std::max(smax, std::abs(cam[i].slave));
    if (i + 1 < cam.size()) {
      const double h = cam[i + 1].master - cam[i].master;
      hmin = std::min(hmin, h);
      dmax = std::max(dmax, std::abs((cam[i + 1].slave - cam[i].slave) / h));
    }
  }
  return {1e-9 * (1 + smax), 1e-7 * (1 + dmax), 1e-5 * (1 + dmax / hmin)};
}

TEST(CamProperty, CubicProfileIsC1AndPassesThroughEveryPoint) {
  const auto seed = cam_test::seed();
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 80);
  std::uniform_real_distribution<double> slope(-20.0, 20.0);
  CamProfile p(80);
  for (int c = 0; c < cam_test::count(300); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::AllCubic);
    const double s0 = slope(rng), s1 = slope(rng);
    ASSERT_TRUE(calc(cam, p, s0, s1).ok());
    const Scale tol = tolerances(cam, s0, s1);
    for (std::size_t k = 0; k < cam.size(); ++k) {
      EXPECT_NEAR(p.evaluate(cam[k].master).position, cam[k].slave, tol.pos) << "knot " << k;
    }
    for (std::size_t k = 1; k + 1 < cam.size(); ++k) {
      const CamSample l = left_limit(p, k - 1), r = right_limit(p, k);
      EXPECT_NEAR(l.position, r.position, tol.pos) << "knot " << k;
      EXPECT_NEAR(l.velocity, r.velocity, tol.vel) << "knot " << k;
      EXPECT_NEAR(l.acceleration, r.acceleration, tol.acc) << "knot " << k << " (C2 inside a cubic run)";
    }
    EXPECT_NEAR(p.evaluate(cam.front().master).velocity, s0, tol.vel);
    EXPECT_NEAR(left_limit(p, cam.size() - 2).velocity, s1, tol.vel);
    EXPECT_NEAR(left_limit(p, cam.size() - 2).position, cam.back().slave, tol.pos);
  }
}

TEST(CamProperty, MixedProfileC1AtEveryKnotTouchingACubicSegment) {
  const auto seed = cam_test::seed() + 1;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 60);
  std::uniform_real_distribution<double> slope(-20.0, 20.0);
  std::uniform_real_distribution<double> frac(0.0, 1.0);
  CamProfile p(60);
  for (int c = 0; c < cam_test::count(300); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::Mixed);
    const double s0 = slope(rng), s1 = slope(rng);
    ASSERT_TRUE(calc(cam, p, s0, s1).ok());
    const Scale tol = tolerances(cam, s0, s1);
    const std::size_t n = cam.size();
    for (std::size_t k = 0; k < n; ++k) {
      EXPECT_NEAR(p.evaluate(cam[k].master).position, cam[k].slave, tol.pos) << "knot " << k;
    }
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const bool touches_cubic = cam[k - 1].segment_type == C || cam[k].segment_type == C;
      const CamSample l = left_limit(p, k - 1), r = right_limit(p, k);
      EXPECT_NEAR(l.position, r.position, tol.pos) << "knot " << k;
      if (touches_cubic) {
        EXPECT_NEAR(l.velocity, r.velocity, tol.vel) << "knot " << k;
      }
    }
    // Linear segments are straight lines between their points.
    for (std::size_t k = 0; k + 1 < n; ++k) {
      if (cam[k].segment_type != L) continue;
      const double f = frac(rng);
      const double x = cam[k].master + f * (cam[k + 1].master - cam[k].master);
      const double chord = (cam[k + 1].slave - cam[k].slave) / (cam[k + 1].master - cam[k].master);
      EXPECT_NEAR(p.evaluate(x).position, cam[k].slave + chord * (x - cam[k].master), tol.pos);
      EXPECT_NEAR(p.evaluate(x).velocity, chord, tol.vel);
      EXPECT_EQ(p.evaluate(x).acceleration, 0.0);
    }
    if (cam[0].segment_type == C) {
      EXPECT_NEAR(p.evaluate(cam[0].master).velocity, s0, tol.vel);
    }
    if (cam[n - 2].segment_type == C) {
      EXPECT_NEAR(left_limit(p, n - 2).velocity, s1, tol.vel);
    }
  }
}

TEST(CamProperty, LinearProfileExactAtPoints) {
  const auto seed = cam_test::seed() + 2;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 100);
  CamProfile p(100);
  for (int c = 0; c < cam_test::count(300); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::AllLinear);
    ASSERT_TRUE(calc(cam, p, 5.0, 5.0).ok());
    // Every knot that starts a segment is exact (a0 = S_i at u = 0).
    for (std::size_t k = 0; k + 1 < cam.size(); ++k) {
      EXPECT_EQ(p.evaluate(cam[k].master).position, cam[k].slave) << "knot " << k;
    }
    // The last knot is reached through the last segment: exact to rounding.
    EXPECT_NEAR(p.evaluate(cam.back().master).position, cam.back().slave, 1e-12 * 100);
  }
}

// Reference check of the spline system against Eigen's dense LU (the knot
// rows built independently from the README's rule).
TEST(CamProperty, SlopesMatchEigenDenseSolve) {
  const auto seed = cam_test::seed() + 3;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 40);
  std::uniform_real_distribution<double> slope(-5.0, 5.0);
  CamProfile p(40);
  for (int c = 0; c < cam_test::count(200); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::Mixed);
    const double s0 = slope(rng), s1 = slope(rng);
    ASSERT_TRUE(calc(cam, p, s0, s1).ok());
    const auto n = static_cast<Eigen::Index>(cam.size());
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
    auto h = [&](Eigen::Index s) { return cam[static_cast<std::size_t>(s + 1)].master - cam[static_cast<std::size_t>(s)].master; };
    auto d = [&](Eigen::Index s) { return (cam[static_cast<std::size_t>(s + 1)].slave - cam[static_cast<std::size_t>(s)].slave) / h(s); };
    auto cub = [&](Eigen::Index s) { return s >= 0 && s + 1 < n && cam[static_cast<std::size_t>(s)].segment_type == C; };
    for (Eigen::Index k = 0; k < n; ++k) {
      if (cub(k - 1) && cub(k)) {
        A(k, k - 1) = 1 / h(k - 1);
        A(k, k) = 2 / h(k - 1) + 2 / h(k);
        A(k, k + 1) = 1 / h(k);
        b(k) = 3 * (d(k - 1) / h(k - 1) + d(k) / h(k));
      } else if (cub(k)) {
        b(k) = k == 0 ? s0 : d(k - 1);
      } else if (cub(k - 1)) {
        b(k) = k == n - 1 ? s1 : d(k);
      }
    }
    const Eigen::VectorXd m = A.partialPivLu().solve(b);
    for (Eigen::Index k = 0; k + 1 < n; ++k) {
      if (!cub(k)) continue;
      EXPECT_NEAR(p.elements()[static_cast<std::size_t>(k)].a1, m(k), 1e-9 * (1 + std::abs(m(k)))) << "knot " << k;
      EXPECT_NEAR(left_limit(p, static_cast<std::size_t>(k)).velocity, m(k + 1), 1e-7 * (1 + std::abs(m(k + 1))));
    }
  }
}

TEST(CamProperty, CursorLookupMatchesBinarySearch) {
  const auto seed = cam_test::seed() + 4;
  std::mt19937_64 rng(seed);
  CamProfile p(500);
  const auto cam = cam_test::random_cam(rng, 500, cam_test::Mix::Mixed);
  ASSERT_TRUE(calc(cam, p, 1.0, -1.0).ok());
  std::uniform_real_distribution<double> x(cam.front().master - 10, cam.back().master + 10);
  std::uniform_real_distribution<double> small(-0.5, 3.0);
  CamCursor cur;
  double pos = cam.front().master - 5;
  for (int c = 0; c < cam_test::count(300) * 100; ++c) {
    // Mostly small forward steps, sometimes backwards, sometimes a jump.
    pos = (c % 97 == 0) ? x(rng) : pos + small(rng);
    if (pos > cam.back().master + 10) pos = cam.front().master - 5;
    const CamSample a = p.evaluate(pos, cur, EndBehaviour::Extrapolate);
    const CamSample b = p.evaluate(pos, EndBehaviour::Extrapolate);
    ASSERT_EQ(a.position, b.position) << cam_test::repro(c) << " x=" << pos;
    ASSERT_EQ(a.velocity, b.velocity) << cam_test::repro(c);
    if (pos >= cam.front().master && pos <= cam.back().master) {
      const std::size_t s = p.find_segment(pos);
      ASSERT_LE(cam[s].master, pos);
      if (s + 2 < cam.size()) {
        ASSERT_LT(pos, cam[s + 1].master);
      }
      ASSERT_EQ(cur.segment, s);
    }
  }
}

// Velocity and acceleration outputs are the derivatives of the position
// output: central differences inside a segment agree (h = 1e-5 of the
// segment, tolerance from the truncation error of the difference).
TEST(CamProperty, VelocityAndAccelerationAreDerivativesOfPosition) {
  const auto seed = cam_test::seed() + 5;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 40);
  std::uniform_real_distribution<double> slope(-10.0, 10.0);
  std::uniform_real_distribution<double> frac(0.1, 0.9);
  CamProfile p(40);
  for (int c = 0; c < cam_test::count(300); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::Mixed);
    ASSERT_TRUE(calc(cam, p, slope(rng), slope(rng)).ok());
    for (std::size_t k = 0; k + 1 < cam.size(); ++k) {
      const double hk = cam[k + 1].master - cam[k].master;
      const double x = cam[k].master + frac(rng) * hk;
      const double dx = 1e-5 * hk;
      const CamSample a = p.evaluate(x - dx), m = p.evaluate(x), b = p.evaluate(x + dx);
      const double fd_v = (b.position - a.position) / (2 * dx);
      const double fd_a = (b.velocity - a.velocity) / (2 * dx);
      const double scale_v = 1 + std::abs(m.velocity) + std::abs(m.position) / hk;
      const double scale_a = 1 + std::abs(m.acceleration) + std::abs(m.velocity) / hk;
      EXPECT_NEAR(fd_v, m.velocity, 1e-5 * scale_v) << "segment " << k;
      EXPECT_NEAR(fd_a, m.acceleration, 1e-5 * scale_a) << "segment " << k;
    }
  }
}

// A shorter recalculation into a bigger profile exposes only the new points.
TEST(CamProfileReuse, RecalculationWithFewerPointsForgetsTheOldTail) {
  CamProfile p(10);
  ASSERT_TRUE(calc({{0, 0, L}, {1, 1, L}, {2, 2, L}, {3, 9, L}}, p).ok());
  EXPECT_EQ(p.point_count(), 4u);
  ASSERT_TRUE(calc({{0, 0, C}, {1, 1, L}}, p, 0.0, 0.0).ok());
  EXPECT_EQ(p.point_count(), 2u);
  EXPECT_EQ(p.segment_count(), 1u);
  EXPECT_EQ(p.elements().size(), 2u);
  EXPECT_EQ(p.master_end(), 1.0);
  EXPECT_EQ(p.slave_end(), 1.0);
  EXPECT_EQ(p.evaluate(2.5).position, 1.0) << "clamped at the new end, not the old point (3, 9)";
  CamCursor cur{3};  // a stale cursor from the longer profile is safe
  EXPECT_NEAR(p.evaluate(0.5, cur).position, 0.5, 1e-15);
  EXPECT_EQ(cur.segment, 0u);
}

// ---- ends ------------------------------------------------------------------

TEST(CamEvaluate, ClampAndExtrapolateOutsideTheRange) {
  CamProfile p(4);
  ASSERT_TRUE(calc({{0, 0, C}, {1, 1, C}, {2, 4, L}}, p, 0.5, 3.0).ok());
  const CamSample before = p.evaluate(-1.0);
  EXPECT_EQ(before.position, 0.0);
  EXPECT_EQ(before.velocity, 0.0);
  const CamSample after = p.evaluate(5.0);
  EXPECT_EQ(after.position, 4.0);
  EXPECT_EQ(after.velocity, 0.0);
  EXPECT_EQ(after.acceleration, 0.0);
  const CamSample eb = p.evaluate(-1.0, EndBehaviour::Extrapolate);
  EXPECT_NEAR(eb.velocity, 0.5, 1e-14);
  EXPECT_NEAR(eb.position, -0.5, 1e-14);
  const CamSample ea = p.evaluate(3.0, EndBehaviour::Extrapolate);
  EXPECT_NEAR(ea.velocity, 3.0, 1e-12);
  EXPECT_NEAR(ea.position, 7.0, 1e-12);
  EXPECT_EQ(ea.acceleration, 0.0);
}

TEST(CamEvaluate, UncalculatedProfileEvaluatesToZero) {
  CamProfile p(4);
  EXPECT_EQ(p.point_count(), 0u);
  EXPECT_TRUE(p.elements().empty());
  EXPECT_EQ(p.evaluate(1.0).position, 0.0);
  CamCursor cur;
  EXPECT_EQ(p.evaluate(1.0, cur).velocity, 0.0);
}

// ---- validation: every MCCP error ------------------------------------------

class MccpErrors : public ::testing::Test {
 protected:
  std::vector<CamPoint> good{{0, 0, C}, {1, 1, C}, {2, 0, L}, {3, 2, L}};
  CamProfile profile{4};

  void expect_unchanged_after(const MccpResult& r) {
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(profile.status(), profile_status::kNotCalculated) << describe(r);
    EXPECT_EQ(profile.point_count(), 0u);
  }
};

TEST_F(MccpErrors, LengthBelowTwoIs26) {
  for (std::int64_t len : {-1, 0, 1}) {
    const auto r = mccp({good, 0, len, 0, 0}, profile);
    EXPECT_EQ(r.err, CamError::IllegalCamLength) << len;
    EXPECT_EQ(err_code(r.err), 26);
    EXPECT_EQ(r.length, len);
    expect_unchanged_after(r);
  }
  EXPECT_TRUE(mccp({good, 0, 2, 0, 0}, profile).ok()) << "2 points is the minimum";
}

TEST_F(MccpErrors, LengthPastTheCamArrayIs26) {
  auto r = mccp({good, 0, 5, 0, 0}, profile);
  EXPECT_EQ(r.err, CamError::IllegalCamLength);
  expect_unchanged_after(r);
  r = mccp({good, 3, 2, 0, 0}, profile);  // index 3 + 2 points > 4 elements
  EXPECT_EQ(r.err, CamError::IllegalCamLength);
  EXPECT_NE(describe(r).find("ERR 26 ILLEGAL_CAM_LENGTH"), std::string::npos) << describe(r);
  EXPECT_NE(describe(r).find("Length 2"), std::string::npos) << describe(r);
  EXPECT_TRUE(mccp({good, 2, 2, 0, 0}, profile).ok());
  EXPECT_EQ(profile.master_start(), 2.0);
}

TEST_F(MccpErrors, CamIndexOutsideTheArrayIs13Exerr1) {
  for (std::int64_t idx : {-1, 4, 100}) {
    const auto r = mccp({good, idx, 2, 0, 0}, profile);
    EXPECT_EQ(r.err, CamError::ParameterOutOfRange);
    EXPECT_EQ(r.exerr, mccp_operand::kCam);
    EXPECT_EQ(r.cam_index, idx);
    expect_unchanged_after(r);
  }
}

TEST_F(MccpErrors, ProfileTooShortIs27) {
  CamProfile small(3);
  const auto r = mccp({good, 0, 4, 0, 0}, small);
  EXPECT_EQ(r.err, CamError::IllegalCamProfileLength);
  EXPECT_EQ(err_code(r.err), 27);
  EXPECT_EQ(small.status(), 0);
  EXPECT_TRUE(mccp({good, 0, 3, 0, 0}, small).ok()) << "capacity == Length is enough";
}

TEST_F(MccpErrors, IllegalSegmentTypeIs28) {
  for (std::int32_t t : {-1, 2, 7}) {
    auto cam = good;
    cam[1].segment_type = t;
    const auto r = calc(cam, profile);
    EXPECT_EQ(r.err, CamError::IllegalCamType) << t;
    EXPECT_EQ(r.cam_index, 1);
    EXPECT_NE(describe(r).find("cam[1]"), std::string::npos) << describe(r);
    expect_unchanged_after(r);
  }
  // The last point starts no segment: its SegmentType is not used.
  auto cam = good;
  cam[3].segment_type = 9;
  EXPECT_TRUE(calc(cam, profile).ok());
}

TEST_F(MccpErrors, MasterNotStrictlyIncreasingIs29) {
  for (double m : {1.0 /* equal */, 0.5 /* decreasing */}) {
    auto cam = good;
    cam[2].master = m;
    const auto r = calc(cam, profile);
    EXPECT_EQ(r.err, CamError::IllegalCamOrder) << m;
    EXPECT_EQ(err_code(r.err), 29);
    EXPECT_EQ(r.cam_index, 2);
    expect_unchanged_after(r);
  }
  // The index is reported in the caller's CAM array numbering.
  std::vector<CamPoint> cam{{9, 9, L}, {0, 0, L}, {1, 0, L}, {1, 1, L}};
  const auto r = mccp({cam, 1, 3, 0, 0}, profile);
  EXPECT_EQ(r.err, CamError::IllegalCamOrder);
  EXPECT_EQ(r.cam_index, 3);
}

TEST_F(MccpErrors, NonFiniteOperandsAre13WithTheOperandIndex) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto r = mccp({good, 0, 4, nan, 0}, profile);
  EXPECT_EQ(r.err, CamError::ParameterOutOfRange);
  EXPECT_EQ(r.exerr, mccp_operand::kStartSlope);
  EXPECT_EQ(r.exerr, 3);
  r = mccp({good, 0, 4, 0, inf}, profile);
  EXPECT_EQ(r.exerr, mccp_operand::kEndSlope);
  EXPECT_EQ(r.exerr, 4);
  EXPECT_NE(describe(r).find("EXERR 4"), std::string::npos) << describe(r);
  auto cam = good;
  cam[2].slave = nan;
  r = calc(cam, profile);
  EXPECT_EQ(r.err, CamError::ParameterOutOfRange);
  EXPECT_EQ(r.exerr, mccp_operand::kCam);
  EXPECT_EQ(r.cam_index, 2);
  cam = good;
  cam[0].master = -inf;
  r = calc(cam, profile);
  EXPECT_EQ(r.err, CamError::ParameterOutOfRange);
  EXPECT_EQ(r.cam_index, 0);
  cam = good;
  cam[0].master = -std::numeric_limits<double>::max();
  cam[1].master = std::numeric_limits<double>::max();
  r = mccp({cam, 0, 2, 0, 0}, profile);
  EXPECT_EQ(r.err, CamError::ParameterOutOfRange) << "master gap overflows";
  expect_unchanged_after(r);
}

TEST_F(MccpErrors, StatusOneIs30AndInUseIs31) {
  ASSERT_TRUE(calc(good, profile).ok());
  ASSERT_EQ(profile.acquire(), CamError::None);
  EXPECT_EQ(profile.status(), 3);
  EXPECT_EQ(profile.users(), 1);
  auto r = calc(good, profile);
  EXPECT_EQ(r.err, CamError::CamProfileBeingUsed);
  EXPECT_EQ(err_code(r.err), 31);
  EXPECT_EQ(profile.status(), 3) << "a failed MCCP leaves Status alone";
  EXPECT_EQ(profile.invalidate(), CamError::CamProfileBeingUsed);
  profile.release();
  EXPECT_EQ(profile.status(), 2);
  EXPECT_TRUE(calc(good, profile).ok()) << "recalculating a calculated, unused profile is allowed";
  // Status 1: a calculation in progress elsewhere (a tag write here).
  CamProfile busy(4);
  busy.write_status(profile_status::kCalculating);
  r = calc(good, busy);
  EXPECT_EQ(r.err, CamError::CamProfileBeingCalculated);
  EXPECT_EQ(err_code(r.err), 30);
}

TEST_F(MccpErrors, FailedRecalculationKeepsThePreviousProfile) {
  ASSERT_TRUE(calc(good, profile).ok());
  auto cam = good;
  cam[3].master = -1;
  EXPECT_EQ(calc(cam, profile).err, CamError::IllegalCamOrder);
  EXPECT_EQ(profile.status(), 2);
  EXPECT_EQ(profile.point_count(), 4u);
  EXPECT_EQ(profile.master_end(), 3.0);
}

// ---- Status counter (MATC/MAPC use) ------------------------------------------

TEST(CamStatus, AcquireNeedsACalculatedProfileAndCountsUsers) {
  CamProfile p(3);
  EXPECT_EQ(p.acquire(), CamError::CamProfileNotCalculated);
  EXPECT_EQ(err_code(CamError::CamProfileNotCalculated), 32);
  EXPECT_EQ(p.status(), 0);
  ASSERT_TRUE(calc({{0, 0, L}, {1, 1, L}}, p).ok());
  for (int i = 0; i < 5; ++i) ASSERT_EQ(p.acquire(), CamError::None);
  EXPECT_EQ(p.status(), 7);
  EXPECT_EQ(p.users(), 5);
  for (int i = 0; i < 7; ++i) p.release();
  EXPECT_EQ(p.status(), 2) << "release never goes below calculated";
  EXPECT_EQ(p.invalidate(), CamError::None);
  EXPECT_EQ(p.status(), 0);
  EXPECT_EQ(p.acquire(), CamError::CamProfileNotCalculated);
  // Writing 2 to a never-calculated profile does not make it usable.
  CamProfile q(3);
  q.write_status(2);
  EXPECT_FALSE(q.calculated());
  EXPECT_EQ(q.acquire(), CamError::CamProfileNotCalculated);
}

TEST(CamStatus, CapacityIsCheckedAtConstruction) {
  EXPECT_THROW(CamProfile(0), std::invalid_argument);
  EXPECT_THROW(CamProfile(CamProfile::kMaxCapacity + 1), std::invalid_argument);
  CamProfile p(1);
  EXPECT_EQ(p.capacity(), 1u);
  EXPECT_EQ(mccp({std::vector<CamPoint>{{0, 0, L}, {1, 1, L}}, 0, 2, 0, 0}, p).err,
            CamError::IllegalCamProfileLength);
}

}  // namespace
