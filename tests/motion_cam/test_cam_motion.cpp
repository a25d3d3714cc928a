// Scaling laws and execution modes (Once / Continuous / Persistent) of a
// running cam, as MATC and MAPC use them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "motion/cam/cam_motion.hpp"
#include "cam_test_util.hpp"

namespace {

using namespace canmotion::motion::cam;
constexpr std::int32_t L = kSegmentLinear;
constexpr std::int32_t C = kSegmentCubic;

void calc(const std::vector<CamPoint>& cam, CamProfile& p, double s0 = 0.0, double s1 = 0.0) {
  const auto r = mccp(MccpRequest{cam, 0, static_cast<std::int64_t>(cam.size()), s0, s1}, p);
  ASSERT_TRUE(r.ok()) << describe(r);
}

// Time scaling by k divides velocity by k; distance scaling by k multiplies it
// by k (seed 004 "Scaling Time Cams"). Checked on evaluate_scaled and on a
// running CamMotion, at random points of random profiles.
TEST(CamScalingProperty, TimeDividesAndDistanceMultipliesVelocity) {
  const auto seed = cam_test::seed() + 10;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 50);
  std::uniform_real_distribution<double> kdist(0.1, 10.0);
  std::uniform_real_distribution<double> frac(0.0, 1.0);
  std::uniform_real_distribution<double> slope(-10.0, 10.0);
  CamProfile p(50);
  for (int c = 0; c < cam_test::count(300); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::Mixed);
    calc(cam, p, slope(rng), slope(rng));
    const double k = kdist(rng);
    const double u = p.master_start() + frac(rng) * p.master_span();  // unscaled profile coordinate
    CamCursor c0, c1, c2, c3;
    const CamSample base = evaluate_scaled(p, u, CamScaling{1.0, 1.0}, c0);
    const CamSample timed = evaluate_scaled(p, k * u, CamScaling{1.0, k}, c1);
    // k * u / k can differ from u by an ulp; compare the time-scaled cam with
    // the unscaled one at the very coordinate it used.
    const CamSample base_t = evaluate_scaled(p, (k * u) * (1.0 / k), CamScaling{1.0, 1.0}, c3);
    const CamSample dist = evaluate_scaled(p, u, CamScaling{k, 1.0}, c2);
    const double tol = 1e-12 * (1 + std::abs(base.velocity) * k + std::abs(base.velocity) / k);
    EXPECT_NEAR(base_t.position, base.position, 1e-9 * (1 + std::abs(base.position))) << "ulp-level only";
    EXPECT_EQ(timed.position, base_t.position);
    EXPECT_NEAR(timed.velocity, base_t.velocity / k, tol);
    EXPECT_NEAR(timed.acceleration, base_t.acceleration / (k * k), 1e-12 * (1 + std::abs(base_t.acceleration)));
    EXPECT_NEAR(dist.position, k * base.position, 1e-12 * (1 + k * std::abs(base.position)));
    EXPECT_NEAR(dist.velocity, k * base.velocity, tol);
    EXPECT_NEAR(dist.acceleration, k * base.acceleration, 1e-9 * (1 + k * std::abs(base.acceleration)));

    // The same through a running cam: x is measured from the start.
    CamMotion unscaled, t_scaled, d_scaled;
    ASSERT_EQ(unscaled.start(p, {ExecutionMode::Once, {1.0, 1.0}}), CamError::None);
    ASSERT_EQ(t_scaled.start(p, {ExecutionMode::Once, {1.0, k}}), CamError::None);
    ASSERT_EQ(d_scaled.start(p, {ExecutionMode::Once, {k, 1.0}}), CamError::None);
    const double x = u - p.master_start();
    const auto a = unscaled.step(x);
    const auto b = t_scaled.step(k * x);
    const auto a_t = unscaled.step((k * x) * (1.0 / k));
    const auto d = d_scaled.step(x);
    EXPECT_NEAR(b.velocity, a_t.velocity / k, tol);
    EXPECT_NEAR(d.velocity, k * a.velocity, tol);
    EXPECT_NEAR(t_scaled.pass_length(), k * p.master_span(), 1e-12 * (1 + k * p.master_span()));
  }
}

// Continuous mode: position has no jump across passes, and each pass adds the
// profile's slave span (scaled, with direction).
TEST(CamContinuousProperty, NoPositionJumpAcrossPasses) {
  const auto seed = cam_test::seed() + 11;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> npts(2, 30);
  std::uniform_real_distribution<double> kdist(0.2, 5.0);
  std::uniform_real_distribution<double> frac(0.0, 1.0);
  std::bernoulli_distribution coin(0.5);
  CamProfile p(30);
  for (int c = 0; c < cam_test::count(100); ++c) {
    SCOPED_TRACE(cam_test::repro(c));
    const auto cam = cam_test::random_cam(rng, npts(rng), cam_test::Mix::Mixed);
    calc(cam, p, 1.0, 1.0);
    CamMotionConfig cfg;
    cfg.mode = ExecutionMode::Continuous;
    cfg.scaling = {kdist(rng), kdist(rng)};
    cfg.direction = coin(rng) ? 1 : -1;
    cfg.use_lock_position = coin(rng);
    cfg.lock_position = p.master_start() + frac(rng) * p.master_span();
    CamMotion cm;
    ASSERT_EQ(cm.start(p, cfg), CamError::None);
    EXPECT_EQ(cm.step(0.0).position, 0.0);
    // Largest |velocity| of the scaled cam (exact: per segment the velocity
    // is a quadratic; check both ends and the vertex) bounds the change of
    // position over a step.
    double vmax = 0;
    const auto el = p.elements();
    for (std::size_t s = 0; s + 1 < el.size(); ++s) {
      const double h = el[s + 1].master - el[s].master;
      auto vel = [&](double u) { return std::abs(el[s].a1 + u * (2 * el[s].a2 + 3 * u * el[s].a3)); };
      vmax = std::max({vmax, vel(0), vel(h)});
      if (el[s].a3 != 0) {
        const double uv = -el[s].a2 / (3 * el[s].a3);
        if (uv > 0 && uv < h) vmax = std::max(vmax, vel(uv));
      }
    }
    vmax *= std::abs(cfg.scaling.slave) / cfg.scaling.master;
    const double tol = 1e-9 * (1 + 50 * std::abs(cfg.scaling.slave)) * 10;
    for (std::int64_t pass = 0; pass < 5; ++pass) {
      const double xe = cm.pass_end(pass);
      const double eps = 1e-9 * cm.pass_length();
      const auto before = cm.step(xe - eps);
      const auto at = cm.step(xe);
      const auto after = cm.step(xe + eps);
      EXPECT_EQ(before.pass, pass);
      EXPECT_EQ(after.pass, pass + 1);
      EXPECT_NEAR(before.position, at.position, vmax * eps + tol) << "pass " << pass;
      EXPECT_NEAR(after.position, at.position, vmax * eps + tol) << "pass " << pass;
      // Position at the end of pass p = (what pass 0 adds until its end) + p * pass distance.
      EXPECT_NEAR(at.position, cm.step(cm.pass_end(0)).position + static_cast<double>(pass) * cm.pass_distance(),
                  tol * static_cast<double>(pass + 1));
    }
    // A fine walk over several passes: no step changes position by more than
    // vmax * dx (plus rounding).
    const double dx = cm.pass_length() / 997.0;
    double prev = cm.step(0.0).position;
    for (int i = 1; i < 997 * 3 + 5; ++i) {
      const double now = cm.step(dx * i).position;
      ASSERT_LE(std::abs(now - prev), vmax * dx + tol) << "step " << i;
      prev = now;
    }
    EXPECT_EQ(cm.step(cm.pass_end(2) + 0.5 * dx).pass, 3);
    // Running backwards unwinds too: negative passes.
    EXPECT_LT(cm.step(-3.5 * cm.pass_length()).pass, -2);
  }
}

// A rotary example by hand: profile 0..360 master, slave 0..100 linear; one
// pass adds 100; time scaling 2 makes a pass last 720.
TEST(CamContinuous, RotaryAccumulatesSlaveSpan) {
  CamProfile p(2);
  calc({{0, 0, L}, {360, 100, L}}, p);
  CamMotion cm;
  ASSERT_EQ(cm.start(p, {ExecutionMode::Continuous, {1.0, 2.0}}), CamError::None);
  EXPECT_DOUBLE_EQ(cm.pass_length(), 720.0);
  EXPECT_DOUBLE_EQ(cm.pass_distance(), 100.0);
  auto o = cm.step(720.0 * 3 + 360.0);
  EXPECT_EQ(o.pass, 3);
  EXPECT_NEAR(o.position, 350.0, 1e-9);
  EXPECT_NEAR(o.velocity, 100.0 / 720.0, 1e-15);
  EXPECT_NEAR(o.profile_master, 180.0, 1e-9);
  EXPECT_FALSE(o.complete);
  EXPECT_DOUBLE_EQ(cm.pass_end(3), 2880.0);
  // Opposite direction.
  ASSERT_EQ(cm.start(p, {ExecutionMode::Continuous, {1.0, 2.0}, -1}), CamError::None);
  EXPECT_NEAR(cm.step(720.0 * 3 + 360.0).position, -350.0, 1e-9);
}

TEST(CamOnce, CompletesAndHoldsTheEndPosition) {
  CamProfile p(3);
  calc({{0, 0, C}, {1, 1, C}, {2, 0, L}}, p);  // smoothstep up and down
  CamMotion cm;
  ASSERT_EQ(cm.start(p, {ExecutionMode::Once, {2.0, 0.5}}), CamError::None);
  EXPECT_DOUBLE_EQ(cm.pass_end(), 1.0);
  auto o = cm.step(0.25);  // profile coordinate 0.5
  EXPECT_NEAR(o.position, 2.0 * 0.5, 1e-14);
  EXPECT_NEAR(o.velocity, 2.0 * 1.5 / 0.5, 1e-13);
  EXPECT_FALSE(o.complete);
  EXPECT_EQ(o.range, CamRange::Inside);
  o = cm.step(1.0);
  EXPECT_FALSE(o.complete) << "the end point itself is still inside";
  o = cm.step(1.0001);
  EXPECT_TRUE(o.complete);
  EXPECT_EQ(o.range, CamRange::PastEnd);
  EXPECT_NEAR(o.position, 0.0, 1e-14);
  EXPECT_EQ(o.velocity, 0.0);
  EXPECT_EQ(o.acceleration, 0.0);
  o = cm.step(-0.1);  // a master running backwards leaves the range at the start
  EXPECT_TRUE(o.complete);
  EXPECT_EQ(o.range, CamRange::BeforeStart);
}

TEST(CamOnce, NonFiniteCoordinateHoldsTheLastOutput) {
  CamProfile p(2);
  calc({{0, 0, L}, {1, 3, L}}, p);
  CamMotion cm;
  ASSERT_EQ(cm.start(p, {ExecutionMode::Continuous, {1, 1}}), CamError::None);
  const auto a = cm.step(2.5);
  for (double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    const auto o = cm.step(bad);
    EXPECT_EQ(o.position, a.position);
    EXPECT_EQ(o.pass, a.pass);
    EXPECT_EQ(o.velocity, 0.0);
  }
  EXPECT_DOUBLE_EQ(cm.step(2.75).position, 8.25);
}

TEST(CamDirection, SameOppositeReverseUnchangedWithFirstUseDefaults) {
  // First execution (no previous direction): Reverse -> Opposite, Unchanged -> Same.
  EXPECT_EQ(resolve_direction(0, 0), 1);
  EXPECT_EQ(resolve_direction(1, 0), -1);
  EXPECT_EQ(resolve_direction(2, 0), -1);
  EXPECT_EQ(resolve_direction(3, 0), 1);
  // Relative to the current direction.
  EXPECT_EQ(resolve_direction(2, 1), -1);
  EXPECT_EQ(resolve_direction(2, -1), 1);
  EXPECT_EQ(resolve_direction(3, -1), -1);
  EXPECT_EQ(resolve_direction(3, 1), 1);
  EXPECT_EQ(resolve_direction(0, -1), 1);
  EXPECT_EQ(resolve_direction(1, 1), -1);
  EXPECT_EQ(resolve_direction(4, 1), 0);
  EXPECT_EQ(resolve_direction(-1, 0), 0);
}

TEST(CamPersistent, UnlocksOutsideAndRelocksInside) {
  CamProfile p(3);
  calc({{0, 0, L}, {1, 1, L}, {2, 1, L}}, p);
  CamMotion cm;
  ASSERT_EQ(cm.start(p, {ExecutionMode::Persistent, {1.0, 1.0}}), CamError::None);
  auto o = cm.step(3.0);
  EXPECT_FALSE(o.complete);
  EXPECT_EQ(o.range, CamRange::PastEnd);
  EXPECT_EQ(o.position, 1.0);
  o = cm.step(0.5);
  EXPECT_EQ(o.range, CamRange::Inside);
  EXPECT_DOUBLE_EQ(o.position, 0.5);
  EXPECT_DOUBLE_EQ(o.velocity, 1.0);
}

TEST(CamLock, LockPositionStartsInsideTheProfileWithoutAJump) {
  CamProfile p(3);
  calc({{0, 0, L}, {10, 20, L}, {20, 20, L}}, p);
  CamMotion cm;
  CamMotionConfig cfg{ExecutionMode::Once, {1.0, 1.0}};
  cfg.use_lock_position = true;
  cfg.lock_position = 5.0;
  ASSERT_EQ(cm.start(p, cfg), CamError::None);
  EXPECT_EQ(cm.step(0.0).position, 0.0);
  EXPECT_DOUBLE_EQ(cm.step(1.0).position, 2.0);
  EXPECT_DOUBLE_EQ(cm.pass_end(), 15.0);
  EXPECT_DOUBLE_EQ(cm.step(20.0).position, 10.0);  // past the end: S_end - S(lock)
}

TEST(CamMotionErrors, EveryStartError) {
  CamProfile p(3);
  CamMotion cm;
  int bad = -1;
  EXPECT_EQ(cm.start(p, {}, &bad), CamError::CamProfileNotCalculated);
  EXPECT_FALSE(cm.active());
  calc({{0, 0, L}, {1, 1, L}}, p);
  const double nan = std::nan("");
  struct Case {
    CamMotionConfig cfg;
    int operand;
  };
  CamMotionConfig lock_out{ExecutionMode::Once, {1, 1}};
  lock_out.use_lock_position = true;
  lock_out.lock_position = 1.5;
  CamMotionConfig lock_nan = lock_out;
  lock_nan.lock_position = nan;
  const std::vector<Case> cases{
      {{ExecutionMode::Once, {nan, 1}}, 1},
      {{ExecutionMode::Once, {1, 0}}, 2},
      {{ExecutionMode::Once, {1, -2}}, 2},
      {{ExecutionMode::Once, {1, HUGE_VAL}}, 2},
      {{ExecutionMode::Once, {1, 1}, 0}, 3},
      {{ExecutionMode::Once, {1, 1}, 2}, 3},
      {lock_out, 4},
      {lock_nan, 4},
      {{static_cast<ExecutionMode>(7), {1, 1}}, 5},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(cm.start(p, c.cfg, &bad), CamError::ParameterOutOfRange) << c.operand;
    EXPECT_EQ(bad, c.operand);
    EXPECT_FALSE(cm.active());
  }
  bool bs = false, bm = false;
  EXPECT_EQ(check_scaling({0.0, 1.0}, bs, bm), CamError::None) << "distance scaling 0 is allowed";
  EXPECT_EQ(check_scaling({1.0, 0.0}, bs, bm), CamError::ParameterOutOfRange);
  EXPECT_TRUE(bm);
  EXPECT_FALSE(bs);
  EXPECT_EQ(cm.start(p, {}, &bad), CamError::None);
  EXPECT_EQ(bad, 0);
  cm.stop();
  EXPECT_FALSE(cm.active());
  EXPECT_EQ(cm.step(0.5).position, 0.0);
}

// Pending hand-over as MATC does it with these helpers: when the current
// pass ends, the next cam starts with x' = x - pass_end and position offset =
// the old cam's position at its pass end. No position jump.
TEST(CamPending, HandOverAtPassEndIsContinuous) {
  CamProfile accel(3), run(2);
  calc({{0, 0, C}, {1, 0.5, C}, {2, 2, L}}, accel, 0.0, 2.0);  // accelerate to slope 2
  calc({{0, 0, L}, {1, 2, L}}, run);                          // constant slope 2
  CamMotion first, second;
  ASSERT_EQ(first.start(accel, {ExecutionMode::Once, {1, 1}}), CamError::None);
  ASSERT_EQ(second.start(run, {ExecutionMode::Continuous, {1, 1}}), CamError::None);
  const double t_switch = first.pass_end();
  const double base = first.step(t_switch).position;
  double prev = 0;
  for (int i = 1; i <= 4000; ++i) {
    const double t = i * 1e-3;
    const double pos = t <= t_switch ? first.step(t).position : base + second.step(t - t_switch).position;
    ASSERT_LE(std::abs(pos - prev), 2.0 * 1e-3 + 1e-12) << "t=" << t;
    prev = pos;
  }
  EXPECT_NEAR(prev, 2.0 + 2.0 * 2.0, 1e-9);
}

}  // namespace
