#pragma once
/// \file motion/units.hpp
/// The one conversion of rate and jerk operands to axis units (MAM, MAJ, MAS,
/// MCD, MAG, and the coordinated MCLM, MCCM, MCS, MCCD): % of maximum, % of
/// time, and the range rule of each units value; and THE decoder of a move's
/// rate operands (convert_rates: MAM, MAJ, MCLM, MCCM, MCCD). A conversion
/// that fails returns the error with the index of the operand at fault (EXERR
/// for ERR 13). Pure; realtime-safe.

#include <cstdint>
#include <optional>

#include "motion/operands.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// Where a move's rate operands are in its instruction (ST indices, EXERR
/// for ERR 13), from the signature table.
struct RateIndex {
  std::int8_t speed = 0, speed_units = 0, accel = 0, accel_units = 0, decel = 0, decel_units = 0;
  std::int8_t accel_jerk = 0, decel_jerk = 0, jerk_units = 0;
};

/// Speed .. JerkUnits as a program writes them: the rate operands of MAM and
/// MAJ (`Dynamics`), MCLM and MCCM (`CoordMoveParams`) and MCCD, read by
/// read_rates() and converted by units::convert_rates().
struct RateOperands {
  double speed = 0.0;
  SpeedUnits speed_units = SpeedUnits::UnitsPerSec;
  double accel = 0.0;
  AccelUnits accel_units = AccelUnits::UnitsPerSec2;
  double decel = 0.0;
  AccelUnits decel_units = AccelUnits::UnitsPerSec2;
  ProfileType profile = ProfileType::Trapezoidal;  ///< MCCD has no Profile operand
  double accel_jerk = 0.0;
  double decel_jerk = 0.0;
  JerkUnits jerk_units = JerkUnits::UnitsPerSec3;
  RateIndex at{};  ///< where they are in the instruction
};

/// The rate operands of instruction `I`, by name (Profile when `I` has one).
template <Instr I>
RateOperands read_rates(const Operands& q) noexcept {
  RateOperands y;
  y.at = RateIndex{op<I>("Speed"),     op<I>("SpeedUnits"), op<I>("AccelRate"),
                   op<I>("AccelUnits"), op<I>("DecelRate"), op<I>("DecelUnits"),
                   op<I>("AccelJerk"),  op<I>("DecelJerk"), op<I>("JerkUnits")};
  y.speed = q.real(y.at.speed);
  y.speed_units = q.enumeration<SpeedUnits>(y.at.speed_units);
  y.accel = q.real(y.at.accel);
  y.accel_units = q.enumeration<AccelUnits>(y.at.accel_units);
  y.decel = q.real(y.at.decel);
  y.decel_units = q.enumeration<AccelUnits>(y.at.decel_units);
  if constexpr (operand_index(I, "Profile") >= 0) y.profile = q.enumeration<ProfileType>(op<I>("Profile"));
  y.accel_jerk = q.real(y.at.accel_jerk);
  y.decel_jerk = q.real(y.at.decel_jerk);
  y.jerk_units = q.enumeration<JerkUnits>(y.at.jerk_units);
  return y;
}

}  // namespace canmotion::motion

namespace canmotion::motion::units {

/// MCD and MCCD: the mode of the values they change (Change... = yes; `jerk`:
/// either jerk). All of one mode (seed 001: Accel, Decel and Jerk in the
/// Speed's units), else ERR 94 MDSC_UNITS_CONFLICT; `md`: master-driven
/// units (false when nothing changes). A move changes all its values (the
/// jerk with an S-curve): then all must be in the Speed's mode.
constexpr Err changed_units_mode(bool speed, SpeedUnits su, bool accel, AccelUnits au, bool decel, AccelUnits du,
                                 bool jerk, JerkUnits ju, bool& md) noexcept {
  md = (speed && is_master_driven(su)) || (accel && is_master_driven(au)) || (decel && is_master_driven(du)) ||
       (jerk && is_master_driven(ju));
  const bool td = (speed && !is_master_driven(su)) || (accel && !is_master_driven(au)) ||
                  (decel && !is_master_driven(du)) || (jerk && !is_master_driven(ju));
  return md && td ? Err::MdscUnitsConflict : Err::None;
}

/// `v` % of `max`. The one formula of %ofMaximum (v / 100 * max: the order
/// of the operations is part of the results).
constexpr double percent(double v, double max) noexcept { return v / 100.0 * max; }

/// A speed, acceleration or deceleration operand in axis units: % of `max`
/// for %ofMaximum, else as given.
template <class U>
constexpr double rate(double v, U u, double max) noexcept {
  return u == U::PercentOfMaximum ? percent(v, max) : v;
}

/// A converted operand, or why not: the error and the index of the operand at
/// fault (EXERR for ERR 13; 0 when the error names no operand).
struct Converted {
  double value = 0.0;
  Err err = Err::None;
  int operand = 0;
  constexpr bool ok() const noexcept { return err == Err::None; }
};

/// ERR 13 at operand `operand`.
constexpr Converted out_of_range(int operand) noexcept { return Converted{0.0, Err::ParameterOutOfRange, operand}; }

/// A rate operand that must be > 0 (ERR 13 at `operand` otherwise), in axis
/// units: rate(v, u, max).
template <class U>
constexpr Converted positive_rate(double v, U u, double max, int operand) noexcept {
  if (!(v > 0)) return out_of_range(operand);
  return Converted{rate(v, u, max), Err::None, operand};
}

/// True for the jerk units that give a jerk (not the extent of a move in
/// Seconds / MasterUnits).
constexpr bool is_jerk_rate(JerkUnits u) noexcept { return u != JerkUnits::Seconds && u != JerkUnits::MasterUnits; }

/// A jerk operand `j` (is_jerk_rate(u)) in axis units:
///  * %ofTime (time or master driven): 0 <= j <= 100, the jerk of a ramp at
///    `rate` to `speed` [UM003F p.258] (0: trapezoidal, +infinity);
///  * %ofMaximum: 0 < j <= 100, % of `max_jerk`;
///  * per second^3 or per master unit^3: j > 0, as given.
/// ERR 13 at `operand` when j is outside its range.
inline Converted jerk(double j, JerkUnits u, double rate, double speed, double max_jerk, int operand) noexcept {
  if (is_percent_of_time(u)) {
    if (!(j >= 0) || j > 100) return out_of_range(operand);
    return Converted{jerk_from_percent_of_time(rate, speed, j), Err::None, operand};
  }
  if (u == JerkUnits::PercentOfMaximum) {
    if (!(j > 0) || j > 100) return out_of_range(operand);
    return Converted{percent(j, max_jerk), Err::None, operand};
  }
  if (!(j > 0)) return out_of_range(operand);
  return Converted{j, Err::None, operand};
}

/// The ramp a %ofTime jerk refers to [UM003F p.258] when it is not the move's
/// own: MCCD's, the coordinate system's maximum accel and decel to the
/// larger of the path's speed and its maximum speed.
struct JerkRamp {
  double accel = 0.0, decel = 0.0, speed = 0.0;
};

/// What convert_rates() takes and what the operands refer to.
struct RateRule {
  /// %ofMaximum refers to these: the axis' (or, for a master offset move,
  /// its cam master's) or the coordinate system's maxima.
  double max_speed = 0.0, max_accel = 0.0, max_decel = 0.0, max_accel_jerk = 0.0, max_decel_jerk = 0.0;
  /// The maxima are an axis's, which may be 0: %ofMaximum of a zero maximum
  /// gives ERR 13 at AccelRate (accel), ERR 54 ZeroMaxDecel (decel), ERR 76
  /// ZeroMaxDecelJerk / ERR 13 at AccelJerk (jerks). A coordinate system's
  /// speed, accel and decel maxima are > 0 (its configuration), and its jerk
  /// maxima may be 0 (the path refuses a zero jerk: ERR 13).
  bool axis = false;
  /// Which values are converted: a move all of them (and the jerks, with the
  /// JerkUnits, only with an S-curve: `jerks`); MCCD those its Change
  /// operands name (`jerks`: either jerk).
  bool speed = true, accel = true, decel = true;
  bool jerks = false;
  bool accel_jerk = true, decel_jerk = true;
  /// %ofTime: the move's own ramp (its accel or decel to its speed, or to
  /// `idle_speed` when its speed is 0), unless `ramp` gives another (MCCD).
  double idle_speed = 0.0;
  std::optional<JerkRamp> ramp{};
};

/// A RateRule whose %ofMaximum refers to the maxima of `m` (an AxisConfig or
/// a CoordSystemConfig: max_speed, max_accel, max_decel, max_accel_jerk,
/// max_decel_jerk), `axis` as RateRule::axis; every value selected, the
/// jerks not (set `jerks` for an S-curve).
template <class Maxima>
constexpr RateRule rule_for(const Maxima& m, bool axis) noexcept {
  RateRule r;
  r.max_speed = m.max_speed;
  r.max_accel = m.max_accel;
  r.max_decel = m.max_decel;
  r.max_accel_jerk = m.max_accel_jerk;
  r.max_decel_jerk = m.max_decel_jerk;
  r.axis = axis;
  return r;
}

/// Step 1 of convert_rates() alone: the units of the values `r` selects all
/// of one mode (ERR 94), `md`: master driven. MAM and MAJ check it first
/// (their Lock Direction and extent rules depend on the mode).
constexpr Err rates_mode(const RateOperands& y, const RateRule& r, bool& md) noexcept {
  return changed_units_mode(r.speed, y.speed_units, r.accel, y.accel_units, r.decel, y.decel_units, r.jerks,
                            y.jerk_units, md);
}

/// Why convert_rates() failed: the error and the operand at fault (EXERR for
/// ERR 13; 0 when the error names none).
struct Checked {
  Err err = Err::None;
  int operand = 0;
  constexpr bool ok() const noexcept { return err == Err::None; }
};

/// THE decoder of a move's rate operands (MAM, MAJ, MCLM, MCCM, MCCD) into
/// the fields of `lim` that `r` selects (the others are left as they are), in
/// this order, stopping at the first error:
///  1. the units of the selected values all of one mode (ERR 94), `md`: master driven;
///  2. Speed >= 0 (ERR 13), units/s or per master unit, or %ofMaximum;
///  3. an axis: %ofMaximum decel of a zero max decel (ERR 54);
///  4. Accel, then Decel > 0 (ERR 13; an axis: also their value in units);
///  5. with `jerks`: JerkUnits a jerk rate, not Seconds / MasterUnits
///     (ERR 13), then AccelJerk, DecelJerk by units::jerk();
///  6. an axis, %ofMaximum jerk: ERR 76 without a max decel jerk, ERR 13 at
///     AccelJerk without a max accel jerk.
/// Speed, Seconds and MasterUnits as the extent of a move (MAM) are not rates:
/// the caller handles them before (units::is_extent).
Checked convert_rates(const RateOperands& y, const RateRule& r, Limits& lim, bool& md) noexcept;

}  // namespace canmotion::motion::units
