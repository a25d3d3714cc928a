#pragma once
/// \file motion/instr/move.hpp
/// Move family: MAM, MAJ, MCD and the MAM EventDistance / CalculatedData
/// operands (motion/instr/move.cpp, move_events.cpp). Their motion runs in a
/// ProfileGen (motion/generator.hpp; its end in move.cpp, its step inline in
/// motion/profile_step.hpp), as do master offset moves and stop ramps.

#include <cstdint>

#include "motion/instr/common.hpp"
#include "motion/units.hpp"

namespace canmotion::motion {

/// Speed .. LockDirection of MAM and MAJ: the rate operands (converted by
/// units::convert_rates) and the merge and lock operands.
struct Dynamics : RateOperands {
  Merge merge = Merge::Disabled;
  MergeSpeed merge_speed = MergeSpeed::Programmed;
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
};

struct MajParams {
  static constexpr Instr kInstr = Instr::MAJ;
  AxisId axis = kNoAxis;
  bool reverse = false;  ///< Direction: 0 forward, 1 reverse
  Dynamics dyn{};
  static MajParams decode(const Operands& q) noexcept;
};

struct MamParams {
  static constexpr Instr kInstr = Instr::MAM;
  AxisId axis = kNoAxis;
  MoveType move_type = MoveType::Absolute;
  double position = 0.0;
  Dynamics dyn{};
  std::uint16_t event_distance = 0xFFFF;   ///< REAL[] id, 0xFFFF = none (operand 0)
  std::uint16_t calculated_data = 0xFFFF;  ///< REAL[] id, 0xFFFF = none
  double event_distance_start = 0.0;       ///< start index written with EventDistance
  double calculated_data_start = 0.0;      ///< start index written with CalculatedData
  static MamParams decode(const Operands& q) noexcept;
};

struct McdParams {
  static constexpr Instr kInstr = Instr::MCD;
  AxisId axis = kNoAxis;
  bool jog = false;  ///< MotionType 0 jog, 1 move
  bool change_speed = false, change_accel = false, change_decel = false;
  bool change_accel_jerk = false, change_decel_jerk = false;
  double speed = 0.0, accel = 0.0, decel = 0.0, accel_jerk = 0.0, decel_jerk = 0.0;
  SpeedUnits speed_units = SpeedUnits::UnitsPerSec;
  AccelUnits accel_units = AccelUnits::UnitsPerSec2, decel_units = AccelUnits::UnitsPerSec2;
  JerkUnits jerk_units = JerkUnits::UnitsPerSec3;
  static McdParams decode(const Operands& q) noexcept;
};
using MoveInstructions = TypeList<MajParams, MamParams, McdParams>;

Err start(Ctx& x, const MajParams& p) noexcept;
Err start(Ctx& x, const MamParams& p) noexcept;
Err start(Ctx& x, const McdParams& p) noexcept;

namespace move {
/// MAM EventDistance / CalculatedData (move_events.cpp): the arrays exist,
/// the distances are finite and >= 0, CalculatedData is long enough.
Err check_event_distance(Ctx& x, const MamParams& p) noexcept;
/// Write CalculatedData for the planned move `g` and set
/// CalculatedDataAvailable (nothing when the MAM has no events).
void write_calculated_data(Ctx& x, const MamParams& p, const ProfileGen& g) noexcept;
}  // namespace move

}  // namespace canmotion::motion
