#pragma once
/// \file motion/instructions.hpp
/// Typed parameters of every motion instruction ("params" of the instruction
/// shape params / state / start / step). `decode()` turns a Request whose
/// operands passed the signature table check into the instruction's params
/// struct, held in the closed variant `Params`. Operand positions come from
/// THE signature table (motion/signatures.hpp). Realtime-safe.

#include <cstdint>
#include <variant>

#include "motion/control_tag.hpp"
#include "motion/planner.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// Speed .. LockDirection, laid out identically in MAM and MAJ.
struct Dynamics {
  double speed = 0.0;
  std::uint8_t speed_units = 0;  ///< SpeedUnits numbers (0 1 3 4 7)
  double accel = 0.0;
  std::uint8_t accel_units = 0;
  double decel = 0.0;
  std::uint8_t decel_units = 0;
  ProfileType profile = ProfileType::Trapezoidal;
  double accel_jerk = 0.0;
  double decel_jerk = 0.0;
  std::uint8_t jerk_units = 0;   ///< JerkUnits numbers (0 1 2 3 4 6 7)
  Merge merge = Merge::Disabled;
  MergeSpeed merge_speed = MergeSpeed::Programmed;
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  int first_operand = 0;         ///< ST index of Speed (EXERR base)
};

struct MsoParams { AxisId axis = kNoAxis; };
struct MsfParams { AxisId axis = kNoAxis; };
struct MasdParams { AxisId axis = kNoAxis; };
struct MasrParams { AxisId axis = kNoAxis; };
struct MafrParams { AxisId axis = kNoAxis; };
struct MahParams { AxisId axis = kNoAxis; };

struct MasParams {
  AxisId axis = kNoAxis;
  StopType stop_type = StopType::All;
  bool change_decel = false;
  double decel_rate = 0.0;
  std::uint8_t decel_units = 0;
  bool change_decel_jerk = false;
  double decel_jerk = 0.0;
  std::uint8_t jerk_units = 0;
};

struct MajParams {
  AxisId axis = kNoAxis;
  bool reverse = false;  ///< Direction: 0 forward, 1 reverse
  Dynamics dyn{};
};

struct MamParams {
  AxisId axis = kNoAxis;
  MoveType move_type = MoveType::Absolute;
  double position = 0.0;
  Dynamics dyn{};
  std::uint16_t event_distance = 0xFFFF;   ///< REAL[] id, 0xFFFF = none (operand 0)
  std::uint16_t calculated_data = 0xFFFF;  ///< REAL[] id, 0xFFFF = none
};

struct MagParams {
  AxisId slave = kNoAxis, master = kNoAxis;
  CamDirection direction = CamDirection::Same;
  double ratio = 1.0;
  double slave_counts = 1.0, master_counts = 1.0;
  MasterReference master_reference = MasterReference::Actual;
  bool fractional = false;  ///< RatioFormat 1
  bool clutch = false;      ///< Clutch 0 = enabled
  double accel_rate = 0.0;
  std::uint8_t accel_units = 0;
};

struct McdParams {
  AxisId axis = kNoAxis;
  bool jog = false;  ///< MotionType 0 jog, 1 move
  bool change_speed = false, change_accel = false, change_decel = false;
  bool change_accel_jerk = false, change_decel_jerk = false;
  double speed = 0.0, accel = 0.0, decel = 0.0, accel_jerk = 0.0, decel_jerk = 0.0;
  std::uint8_t speed_units = 0, accel_units = 0, decel_units = 0, jerk_units = 0;
};

struct MrpParams {
  AxisId axis = kNoAxis;
  bool relative = false;  ///< Type 1
  bool command = false;   ///< PositionSelect 1
  double position = 0.0;
};

struct MgsParams { std::uint16_t group = 0; GroupStopMode mode = GroupStopMode::Programmed; };
struct MgsdParams { std::uint16_t group = 0; };
struct MgsrParams { std::uint16_t group = 0; };

// Issue 5 (synchronized motion): decoded here so the model hosts them.
struct MccpParams {
  std::uint16_t cam = 0xFFFF;
  std::int32_t first_point = 0;
  std::int32_t length = 0;
  double start_slope = 0.0, end_slope = 0.0;
  std::uint16_t cam_profile = 0xFFFF;
};
struct MapcParams {
  AxisId slave = kNoAxis, master = kNoAxis;
  CamDirection direction = CamDirection::Same;
  std::uint16_t cam_profile = 0xFFFF;
  double slave_scaling = 1.0, master_scaling = 1.0;
  std::uint8_t execution_mode = 0, execution_schedule = 0;
  double master_lock_position = 0.0, cam_lock_position = 0.0;
  MasterReference master_reference = MasterReference::Actual;
  std::uint8_t master_direction = 0;
};
struct MatcParams {
  AxisId axis = kNoAxis;
  CamDirection direction = CamDirection::Same;
  std::uint16_t cam_profile = 0xFFFF;
  double distance_scaling = 1.0, time_scaling = 1.0;
  std::uint8_t execution_mode = 0, execution_schedule = 0;
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  bool master_driven = false;  ///< InstructionMode 1
};
struct MdacParams {
  AxisId slave = kNoAxis, master = kNoAxis;
  std::uint8_t motion_type = 0;  ///< 0 all, 1 move, 2 jog, 3 time cam, 4 master offset move
  MasterReference master_reference = MasterReference::Actual;
};
struct MdsParams {
  AxisId axis = kNoAxis;
  double speed = 0.0;
  bool percent_of_maximum = false;  ///< SpeedUnits 0 (seed numbering)
};
/// MCLM, MCCM, MCS, MCSD, MCCD, MDCC: parsed and validated only.
struct CoordinatedParams { Instr instr = Instr::MCLM; };

/// The closed set of instruction parameters.
using Params = std::variant<MsoParams, MsfParams, MasdParams, MasrParams, MafrParams, MasParams, MahParams,
                            MajParams, MamParams, MagParams, McdParams, MrpParams, MgsParams, MgsdParams,
                            MgsrParams, MccpParams, MapcParams, MatcParams, MdacParams, MdsParams,
                            CoordinatedParams>;

/// Decode a request (operand count and values already checked against the
/// signature table). Realtime-safe.
Params decode(const Request& r) noexcept;

/// Look the operand positions up once (the Planner constructor calls it, so
/// the cyclic path never runs the one-time initialisation). Not realtime.
void init_instruction_tables() noexcept;

}  // namespace canmotion::motion
