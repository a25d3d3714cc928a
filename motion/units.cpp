// The decoder of a move's rate operands (motion/units.hpp). Pure; realtime-safe.
#include "motion/units.hpp"

namespace canmotion::motion::units {
namespace {

constexpr Checked fail(Err e, int operand = 0) noexcept { return Checked{e, operand}; }

/// Accel or Decel: > 0, and for an axis also its value in units (%ofMaximum
/// of a zero maximum).
constexpr bool positive(double v, double in_units, bool axis) noexcept { return v > 0 && (!axis || in_units > 0); }

}  // namespace

Checked convert_rates(const RateOperands& y, const RateRule& r, Limits& lim, bool& md) noexcept {
  if (Err e = rates_mode(y, r, md); e != Err::None) return fail(e);
  if (r.speed) {
    if (!(y.speed >= 0)) return fail(Err::ParameterOutOfRange, y.at.speed);
    lim.v = rate(y.speed, y.speed_units, r.max_speed);
  }
  if (r.axis && r.decel && y.decel_units == AccelUnits::PercentOfMaximum && !(r.max_decel > 0))
    return fail(Err::ZeroMaxDecel);
  if (r.accel) {
    const double a = rate(y.accel, y.accel_units, r.max_accel);
    if (!positive(y.accel, a, r.axis)) return fail(Err::ParameterOutOfRange, y.at.accel);
    lim.a = a;
  }
  if (r.decel) {
    const double d = rate(y.decel, y.decel_units, r.max_decel);
    if (!positive(y.decel, d, r.axis)) return fail(Err::ParameterOutOfRange, y.at.decel);
    lim.d = d;
  }
  if (!r.jerks) return Checked{};
  const JerkUnits ju = y.jerk_units;
  if (!is_jerk_rate(ju)) return fail(Err::ParameterOutOfRange, y.at.jerk_units);
  // the ramp of %ofTime: the move's own, or the one the rule gives (MCCD)
  const JerkRamp ramp = r.ramp ? *r.ramp : JerkRamp{lim.a, lim.d, lim.v > 0 ? lim.v : r.idle_speed};
  if (r.accel_jerk) {
    const Converted c = jerk(y.accel_jerk, ju, ramp.accel, ramp.speed, r.max_accel_jerk, y.at.accel_jerk);
    if (!c.ok()) return fail(c.err, c.operand);
    lim.ja = c.value;
  }
  if (r.decel_jerk) {
    const Converted c = jerk(y.decel_jerk, ju, ramp.decel, ramp.speed, r.max_decel_jerk, y.at.decel_jerk);
    if (!c.ok()) return fail(c.err, c.operand);
    lim.jd = c.value;
  }
  if (r.axis && ju == JerkUnits::PercentOfMaximum) {
    if (!(r.max_decel_jerk > 0)) return fail(Err::ZeroMaxDecelJerk);
    if (!(r.max_accel_jerk > 0)) return fail(Err::ParameterOutOfRange, y.at.accel_jerk);
  }
  return Checked{};
}

}  // namespace canmotion::motion::units
