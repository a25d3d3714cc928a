// MDS drive-side behaviour of the emulated drive (seed 002): the CSV ramp
// (RampAcceleration/Deceleration 0x6083/0x6084, RampVelocity - Positive /
// Negative 0x2010:1/2, RampJerk - Control 0x2011) and the CST load model with
// SLAT (0x2020..0x2022). Called from advance_motor() on SYNC only; realtime-
// safe (no allocation, no exceptions). See README.md "Motor and load model".
#include <algorithm>
#include <cmath>

#include "fieldbus/emulator/emulator.hpp"

namespace canmotion::emulator {

void Emulator::reset_direct_model() noexcept {
  ramp_acc_ = 0;
  slat_speed_ = false;
  slat_held_ns_ = 0;
}

double Emulator::csv_ramp(double target, double dt) noexcept {
  // A drive without 0x2010 (EmulatorBehaviour::optional_objects_absent) has
  // no ramp velocity limit but its own maximum velocity.
  const double vpos = hot_.ramp_vpos != nullptr ? static_cast<double>(val(hot_.ramp_vpos)) * vel_scale_ : cfg_.max_velocity;
  const double vneg = hot_.ramp_vneg != nullptr ? static_cast<double>(val(hot_.ramp_vneg)) * vel_scale_ : cfg_.max_velocity;
  target = std::clamp(target, -vneg, vpos);
  const double v = vel_;
  const double e = target - v;
  if (e == 0.0) {
    ramp_acc_ = 0;
    return v;
  }
  // Deceleration while the speed magnitude falls (moving towards zero).
  const bool decelerating = (v > 0 && e < 0) || (v < 0 && e > 0);
  double rate = static_cast<double>(val(decelerating ? hot_.profile_decel : hot_.profile_accel)) * acc_scale_;
  if (rate <= 0) rate = cfg_.max_acceleration;  // 0: no ramp limit
  // S-curve: each of the two jerk segments of a full-scale ramp (0 to the
  // larger ramp velocity) lasts jerk_pct/2 % of that ramp's time.
  const auto jerk_pct = static_cast<double>(val(hot_.ramp_jerk));
  const double vfull = std::max({vpos, vneg, std::abs(target), std::abs(v)});
  const double t_jerk = jerk_pct / 100.0 * (vfull / rate) / 2.0;
  if (!(t_jerk > 0)) {  // trapezoidal
    ramp_acc_ = 0;
    return v + std::clamp(e, -rate * dt, rate * dt);
  }
  const double jerk = rate / t_jerk;
  // The largest acceleration from which the ramp still ends on the target
  // when the acceleration falls by jerk*dt per SYNC (a^2/2J + a dt/2 <= |e|),
  // within the ramp rate.
  const double h = jerk * dt / 2.0;
  const double a_want = std::copysign(std::min(rate, -h + std::sqrt(h * h + 2.0 * jerk * std::abs(e))), e);
  ramp_acc_ += std::clamp(a_want - ramp_acc_, -jerk * dt, jerk * dt);
  double dv = ramp_acc_ * dt;
  if ((e > 0 && dv >= e) || (e < 0 && dv <= e)) {  // arrives: no overshoot
    dv = e;
    ramp_acc_ = 0;
  }
  return v + dv;
}

double Emulator::cst_step(double torque_cmd, double velocity_cmd, double dt, double& torque) noexcept {
  const double a_rated = cfg_.rated_torque_acceleration > 0 ? cfg_.rated_torque_acceleration : cfg_.max_acceleration;
  const double load = cfg_.load_torque + cfg_.viscous_friction * vel_;  // per mille
  const auto c = static_cast<cia402::SlatConfiguration>(val(hot_.slat_config));
  const auto set_point = static_cast<double>(val(hot_.slat_set_point)) * vel_scale_;
  const std::int64_t delay_ns = static_cast<std::int64_t>(val(hot_.slat_delay)) * 1'000'000;
  // Velocity Error = velocity command (0x60FF) - actual velocity.
  slat_speed_ = cia402::slat_speed_control(c, slat_speed_, velocity_cmd - vel_, set_point, sync_period_.ns, delay_ns,
                                           slat_held_ns_);
  if (slat_speed_) {
    // Speed control: the torque that removes speed_loop_gain of the error
    // this SYNC against the load, within the torque limit 0x6072.
    const auto tmax = static_cast<double>(val(hot_.max_torque));
    const double gain = std::clamp(cfg_.speed_loop_gain, 1e-6, 1.0);
    torque = std::clamp(gain * (velocity_cmd - vel_) / dt * 1000.0 / a_rated + load, -tmax, tmax);
  } else {
    torque = torque_cmd;
  }
  return vel_ + (torque - load) / 1000.0 * a_rated * dt;
}

}  // namespace canmotion::emulator
