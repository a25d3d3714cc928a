#include "motion/cam/cam_motion.hpp"

#include <cmath>
#include <limits>

namespace canmotion::motion::cam {

CamError check_scaling(const CamScaling& scaling, bool& bad_slave, bool& bad_master) noexcept {
  bad_slave = !std::isfinite(scaling.slave);
  bad_master = !std::isfinite(scaling.master) || !(scaling.master > 0.0);
  return bad_slave || bad_master ? CamError::ParameterOutOfRange : CamError::None;
}

CamSample evaluate_scaled(const CamProfile& profile, double x, const CamScaling& scaling, CamCursor& cursor,
                          EndBehaviour end) noexcept {
  const double inv = 1.0 / scaling.master;
  const CamSample s = profile.evaluate(x * inv, cursor, end);
  return CamSample{scaling.slave * s.position, scaling.slave * inv * s.velocity,
                   scaling.slave * inv * inv * s.acceleration};
}

CamError CamMotion::start(const CamProfile& profile, const CamMotionConfig& config, int* bad_operand) noexcept {
  auto bad = [&](int which) {
    if (bad_operand != nullptr) *bad_operand = which;
    return CamError::ParameterOutOfRange;
  };
  if (bad_operand != nullptr) *bad_operand = 0;
  if (!profile.calculated()) return CamError::CamProfileNotCalculated;
  bool bad_slave = false;
  bool bad_master = false;
  if (check_scaling(config.scaling, bad_slave, bad_master) != CamError::None) return bad(bad_slave ? 1 : 2);
  if (config.direction != 1 && config.direction != -1) return bad(3);
  if (config.mode != ExecutionMode::Once && config.mode != ExecutionMode::Continuous &&
      config.mode != ExecutionMode::Persistent) {
    return bad(5);
  }
  const double m0 = profile.master_start();
  const double m1 = profile.master_end();
  double lock = m0;
  if (config.use_lock_position) {
    if (!std::isfinite(config.lock_position) || config.lock_position < m0 || config.lock_position > m1) return bad(4);
    lock = config.lock_position;
  }
  profile_ = &profile;
  config_ = config;
  cursor_ = CamCursor{};
  m0_ = m0;
  m1_ = m1;
  span_ = m1 - m0;
  slave_span_ = profile.slave_span();
  lock_ = lock;
  dir_ = static_cast<double>(config.direction);
  y_lock_ = profile.evaluate(lock, cursor_).position;
  last_ = CamMotionOutput{};
  last_.profile_master = lock;
  last_.segment = cursor_.segment;
  return CamError::None;
}

double CamMotion::pass_end(std::int64_t pass) const noexcept {
  if (profile_ == nullptr) return 0.0;
  const double km = config_.scaling.master;
  if (config_.mode != ExecutionMode::Continuous) return (m1_ - lock_) * km;
  return (m0_ + static_cast<double>(pass + 1) * span_ - lock_) * km;
}

CamMotionOutput CamMotion::step(double x) noexcept {
  CamMotionOutput out{};
  if (profile_ == nullptr) return out;
  if (!std::isfinite(x)) {
    // A non-finite master/time (a fault upstream): hold the last output.
    out = last_;
    out.velocity = 0.0;
    out.acceleration = 0.0;
    return out;
  }
  const double ks = dir_ * config_.scaling.slave;
  const double inv = 1.0 / config_.scaling.master;
  double v = lock_ + x * inv;
  double offset = 0.0;
  if (config_.mode == ExecutionMode::Continuous) {
    const double turns = std::floor((v - m0_) / span_);
    // Keep the pass count representable; a cam would need ~1e18 passes to get here.
    constexpr double kMaxPasses = 9.0e18;
    const double p = turns > kMaxPasses ? kMaxPasses : (turns < -kMaxPasses ? -kMaxPasses : turns);
    out.pass = static_cast<std::int64_t>(p);
    v -= p * span_;
    // Rounding can leave v a hair outside [m0, m1]; the polynomial is smooth
    // there, so clamping the coordinate is exact to rounding.
    if (v < m0_) v = m0_;
    if (v > m1_) v = m1_;
    offset = p * slave_span_;
  } else if (v < m0_ || v > m1_) {
    out.range = v < m0_ ? CamRange::BeforeStart : CamRange::PastEnd;
    out.complete = config_.mode == ExecutionMode::Once;
    v = v < m0_ ? m0_ : m1_;
    const CamSample s = profile_->evaluate(v, cursor_);
    out.position = ks * (s.position - y_lock_);
    out.profile_master = v;
    out.segment = cursor_.segment;
    last_ = out;
    return out;  // outside the range: holds the end position, velocity 0
  }
  const CamSample s = profile_->evaluate(v, cursor_);
  out.position = ks * (s.position - y_lock_ + offset);
  out.velocity = ks * inv * s.velocity;
  out.acceleration = ks * inv * inv * s.acceleration;
  out.profile_master = v;
  out.segment = cursor_.segment;
  last_ = out;
  return out;
}

}  // namespace canmotion::motion::cam
