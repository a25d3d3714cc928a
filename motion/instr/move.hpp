#pragma once
/// \file motion/instr/move.hpp
/// Move family: MAM, MAJ, MCD and the MAM EventDistance / CalculatedData
/// operands (motion/instr/move.cpp, move_events.cpp), and ProfileGen, the
/// generator of moves, jogs, master offset moves and stop ramps.

#include <cstdint>

#include "motion/instr/common.hpp"
#include "motion/master_follow.hpp"
#include "motion/units.hpp"

namespace canmotion::motion {

enum class Slot : std::uint8_t;

/// What a profile generator is doing.
enum class GenRole : std::uint8_t { Move, Jog, Stop };

/// Generator of a profile-driven motion: MAM, MAJ, and the stop ramps of MAS,
/// MGS and exceptions. O(1) step: one Profile::sample, at time or (master
/// driven) at master travel.
struct ProfileGen : GenBase {
  GenRole role = GenRole::Move;
  Profile prof{};
  int hint = 0;
  std::uint64_t t0_cycle = 0;  ///< profile time = (cycle - t0_cycle) * period
  double total = 0.0;          ///< move: distance from the generator origin to the target
  double target_user = 0.0;    ///< move: programmed absolute target (user frame)
  bool exact_target = false;   ///< move: absolute linear target can be set exactly at the end
  MoveType move_type = MoveType::Absolute;
  Limits lim{};
  bool scurve = false;
  bool seconds = false;        ///< programmed in seconds (MCD not allowed: ERR 23)
  double speed = 0.0;          ///< programmed speed (0 = paused until MCD)
  double jog_velocity = 0.0;   ///< jog: signed programmed velocity
  std::uint8_t post_stop = 0;  ///< stop ramps of MGS: 0 none, 1 disable, 2 shutdown
  // master driven (MDSC): the profile's abscissa is master travel md.u, not
  // time; md as for a master-driven MATC (motion/master_follow.hpp)
  bool master_driven = false;
  MasterFollow md{};

  // generator interface (motion/generator.hpp)
  AxisId master() const noexcept { return master_driven ? md.master : kNoAxis; }
  /// Defined in motion/instr/move_step.hpp: inline in the cycle.
  inline void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;
  /// The profile ended (step): PC, folded; a ramp of MGS FastDisable /
  /// FastShutdown then switches the servo off / shuts the axis down.
  void finish(Core& c, AxisRt& a, Slot s, ControlTag* t) noexcept;
};

/// Speed .. LockDirection, laid out identically in MAM and MAJ.
struct Dynamics : RateOperands {
  Merge merge = Merge::Disabled;
  MergeSpeed merge_speed = MergeSpeed::Programmed;
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  int first_operand = 0;         ///< ST index of Speed (EXERR base)
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
