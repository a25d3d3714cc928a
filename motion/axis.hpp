#pragma once
/// \file motion/axis.hpp
/// Axis configuration and the axis tag (status) as the planner exposes them.
/// Plain data; realtime-safe to read and copy.

#include <array>
#include <cmath>
#include <cstdint>

#include "motion/signatures.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// Homing configuration [RM002H p.96], [v37 Motion Homing Config Attributes].
struct HomingConfig {
  enum class Mode : std::uint8_t { Passive = 0, Active = 1, Absolute = 2 };
  enum class Sequence : std::uint8_t { Immediate = 0, Switch = 1, Marker = 2, SwitchMarker = 3, TorqueLevel = 4, TorqueLevelMarker = 5 };
  Mode mode = Mode::Active;
  Sequence sequence = Sequence::Immediate;
  double home_position = 0.0;  ///< user units; in [0, unwind) for rotary axes
  /// CiA 402 homing mode (6) objects for active, non-immediate homing on a CIP drive.
  std::int8_t cia_method = 35;          ///< 0x6098 homing method (35/37: current position)
  double speed_search = 10.0;           ///< 0x6099:01, user units/s
  double speed_zero = 1.0;              ///< 0x6099:02, user units/s
  double accel = 100.0;                 ///< 0x609A, user units/s^2
  bool write_offset = false;            ///< write 0x607C home offset (only when configured: `homing.offset`)
  double offset = 0.0;                  ///< 0x607C, user units
};

/// Static configuration of one axis (from the YAML config; validated there, and
/// again by Planner::configure_axis).
struct AxisConfig {
  AxisType type = AxisType::Virtual;
  bool configured = true;          ///< false: every instruction errors with ERR 11
  bool inhibited = false;          ///< true: ERR 53
  char units_name[16] = "units";   ///< position units name (display only)
  double conversion_constant = 1.0;  ///< drive counts per position unit (> 0)
  bool rotary = false;             ///< rotary with position unwind
  double unwind = 360.0;           ///< position units per revolution (rotary only, > 0)
  double max_speed = 100.0;        ///< units/s
  double max_accel = 1000.0;       ///< units/s^2
  double max_decel = 1000.0;       ///< units/s^2
  double max_accel_jerk = 10000.0; ///< units/s^3
  double max_decel_jerk = 10000.0; ///< units/s^3
  bool soft_limits_enabled = false;
  double soft_limit_pos = 0.0;     ///< maximum positive travel (user units)
  double soft_limit_neg = 0.0;     ///< maximum negative travel (user units)
  double position_error_tolerance = 0.0;  ///< 0 disables the check
  HomingConfig homing{};
  ProgrammedStopMode programmed_stop_mode = ProgrammedStopMode::FastStop;
  /// MDS: what the drive's direct command is (CIP drives): velocity (CSV) or torque (CST).
  enum class DirectMode : std::uint8_t { Velocity = 0, Torque = 1 };
  DirectMode direct_mode = DirectMode::Velocity;
  double max_torque = 100.0;       ///< MDS torque mode: 100 % of maximum (drive torque units, e.g. per mille of rated)
  /// MDS torque mode: initial DirectVelocityControl Command (units/s) sent
  /// with the torque command, the drive's speed reference for SLAT 1/2.
  double direct_velocity_command = 0.0;
  /// MDS is allowed: the axis has `direct_control:` in the configuration (the
  /// drive's ramp attributes are written at boot). Without it MDS answers
  /// ERR 86 Optional Attribute Not Supported [seed 002: "validated if the CIP
  /// drive device supports the ramp attributes"].
  bool direct_control = false;
  /// Torque mode with SLAT configured (direct_control.slat.configuration 1 or
  /// 2): MDS's Speed is the DirectVelocityControl command (the SLAT speed), the
  /// torque command is set live; both direct status bits are set.
  bool direct_slat = false;
  std::uint8_t group = 0;          ///< motion group index (< kMaxGroups)
  /// CIP drives: the longest an instruction waits on the drive (MSO, MSF,
  /// MDS's enable, the fault reset of MAFR/MASR/MGSR), in seconds from its
  /// start, whatever happens to the drive meanwhile (a boot, a reset, a
  /// reboot, a lost node): then it ends with ERR 12, EXERR 16. The runtime
  /// sets it from the drive's timeouts (drive.timeouts.wait_ms). > 0.
  double drive_wait_limit = 5.0;
  /// Exception action per ExceptionKind. Defaults: position error and drive
  /// fault stop the drive, lost node and bus-off shut down, soft overtravel
  /// stops the planner, hardware overtravel (a limit switch) stops the drive.
  std::array<ExceptionAction, static_cast<std::size_t>(ExceptionKind::Count)> exception_actions{
      ExceptionAction::StopDrive,   ExceptionAction::StopDrive,   ExceptionAction::Shutdown,
      ExceptionAction::StopPlanner, ExceptionAction::StopPlanner, ExceptionAction::Shutdown,
      ExceptionAction::StopDrive,   ExceptionAction::StopDrive};

  /// Action configured for one exception.
  constexpr ExceptionAction action(ExceptionKind k) const noexcept {
    return exception_actions[static_cast<std::size_t>(k)];
  }
};

/// Why an instruction that waited on the drive ended with an error (for the log).
enum class DriveWaitCause : std::uint8_t {
  Limit,              ///< AxisConfig::drive_wait_limit passed (the drive never got there)
  LinkFailed,         ///< the drive's boot failed (no answer, a refused configuration)
  TransitionTimeout,  ///< the runtime's transition timeout expired (the drive did not make a state transition)
  DriveFault,         ///< the drive went to Fault
  AxisFaulted,        ///< the axis latched a fault or went to Shutdown meanwhile (its exception action)
};

/// The last instruction that waited on an axis's drive and ended with an
/// error (not a Logix attribute: what the runtime logs).
struct DriveWaitEnd {
  Instr instr = Instr::MSO;
  std::uint16_t control = 0xFFFF;  ///< its control tag (ControlId)
  DriveWaitCause cause = DriveWaitCause::Limit;
  std::int16_t err = 0;
  std::int8_t exerr = 0;
  std::uint64_t waited_cycles = 0;  ///< from its start to its end
};

/// The axis tag: what a Logix program reads from an AXIS_* tag.
struct AxisTag {
  AxisState state = AxisState::Ready;
  CipAxisState cip_state = CipAxisState::Stopped;
  std::uint32_t motion_status = 0;   ///< MotionStatus, bits in motion_status::
  std::uint32_t axis_status = 0;     ///< AxisStatus, bits in axis_status::
  std::uint32_t axis_fault = 0;      ///< AxisFault, bits in axis_fault::
  std::uint32_t motion_fault_status = 0;  ///< MotionFaultStatus (soft travel bits)
  std::uint32_t motion_alarm_status = 0;  ///< MotionAlarmStatus
  std::uint32_t exception_faults = 0;     ///< bit per ExceptionKind currently latched as fault
  std::uint32_t exception_alarms = 0;     ///< bit per ExceptionKind currently alarming
  /// Not a Logix attribute (for the log): per ExceptionKind, the value that
  /// latched it as a fault, in the cycle it latched: PositionError |command -
  /// actual|, SoftOvertravelPos/Neg the command position; the others 0.
  std::array<double, static_cast<std::size_t>(ExceptionKind::Count)> exception_fault_values{};
  /// Not Logix attributes (for the log): instructions that waited on this
  /// axis's drive and ended with an error, and the last of them.
  std::uint32_t drive_wait_errors = 0;
  DriveWaitEnd last_drive_wait{};
  double command_position = 0.0;    ///< user units (unwound for rotary)
  double command_velocity = 0.0;    ///< user units/s
  double command_acceleration = 0.0;
  double actual_position = 0.0;     ///< user units (unwound for rotary)
  double actual_velocity = 0.0;
  double position_error = 0.0;      ///< command - actual

  constexpr bool motion(unsigned bit) const noexcept { return (motion_status >> bit) & 1u; }
  constexpr bool status(unsigned bit) const noexcept { return (axis_status >> bit) & 1u; }
  constexpr bool fault(unsigned bit) const noexcept { return (axis_fault >> bit) & 1u; }
};

/// Wrap a position into [0, unwind). Realtime-safe.
inline double unwind_position(double p, double unwind) noexcept {
  double r = std::fmod(p, unwind);
  if (r < 0) r += unwind;
  if (r >= unwind) r = 0.0;  // fmod rounding at the top of the range
  return r;
}

}  // namespace canmotion::motion
