#pragma once
/// \file motion/units.hpp
/// The one conversion of rate and jerk operands to axis units (MAM, MAJ, MAS,
/// MCD, MAG): % of maximum, % of time, and the range rule of each units
/// value. A conversion that fails returns the error with the index of the
/// operand at fault (EXERR for ERR 13). Pure; realtime-safe.

#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// Speed .. JerkUnits as a program writes them: the rate operands of MAM and
/// MAJ (`Dynamics`), MCLM and MCCM (`CoordMoveParams`) and MCCD.
struct RateOperands {
  double speed = 0.0;
  SpeedUnits speed_units = SpeedUnits::UnitsPerSec;
  double accel = 0.0;
  AccelUnits accel_units = AccelUnits::UnitsPerSec2;
  double decel = 0.0;
  AccelUnits decel_units = AccelUnits::UnitsPerSec2;
  ProfileType profile = ProfileType::Trapezoidal;
  double accel_jerk = 0.0;
  double decel_jerk = 0.0;
  JerkUnits jerk_units = JerkUnits::UnitsPerSec3;
};

}  // namespace canmotion::motion

namespace canmotion::motion::units {

/// MCD and MCCD: the mode of the values they change (Change... = yes; `jerk`:
/// either jerk). All of one mode (seed 001: Accel, Decel and Jerk in the
/// Speed's units), else ERR 94 MDSC_UNITS_CONFLICT; `md`: master-driven
/// units (false when nothing changes).
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

}  // namespace canmotion::motion::units
