#pragma once
/// \file motion/types.hpp
/// Logix motion enumerations with their Logix numbers: axis types and states,
/// MotionStatus / AxisStatus / AxisFault bit numbers, the .ERR codes, and the
/// shared operand enumerations (units, profile, merge, lock direction, ...).
/// Numbers follow ../shared/reference/logix-motion.md (sections 1.3, 3, 4).
/// Everything here is constexpr data; realtime-safe.

#include <cstdint>
#include <string_view>

namespace canmotion::motion {

// ---------------------------------------------------------------- capacities
/// Fixed capacities of the planner. The planner is sized once at construction
/// and allocates nothing afterwards.
/// - kMaxAxes: a CANopen network has at most 127 nodes, one axis each; 64 leaves
///   room for virtual axes and keeps the per-cycle loop within the cycle budget
///   (~50 ns per idle axis).
/// - kMaxControlTags: one MOTION_INSTRUCTION per instruction call in the
///   program; 512 covers the ST programs this project runs (config may not exceed it).
/// - kMaxGroups: Logix allows one motion group per controller; we allow 4.
inline constexpr std::size_t kMaxAxes = 64;
inline constexpr std::size_t kMaxControlTags = 512;
inline constexpr std::size_t kMaxGroups = 4;

/// Axis data types the planner knows.
enum class AxisType : std::uint8_t {
  Virtual = 0,   ///< AXIS_VIRTUAL: planner only, actual = command
  CipDrive = 1,  ///< AXIS_CIP_DRIVE: a CiA 402 node; feedback from the drive
};

/// AxisState (GSV attribute) [RM003I p.326].
enum class AxisState : std::uint8_t {
  Ready = 0,
  DriveEnable = 1,
  ServoControl = 2,
  Faulted = 3,
  Shutdown = 4,
  Inhibited = 5,
  Ungrouped = 6,
  NoModule = 7,
  Configuring = 8,
};

/// CIP Axis State (ICS CIPAxisStateType numbering).
enum class CipAxisState : std::uint8_t {
  Initializing = 0, PreCharge = 1, Stopped = 2, Starting = 3, Running = 4,
  Testing = 5, Stopping = 6, Aborting = 7, MajorFaulted = 8, StartInhibited = 9,
  Shutdown = 10, AxisInhibited = 11, NotGrouped = 12, NoModule = 13,
  Configuring = 14, Synchronizing = 15, WaitingForGroup = 16,
};

/// MotionStatus bit numbers [RM002H p.123-124].
namespace motion_status {
inline constexpr unsigned AccelStatus = 0;
inline constexpr unsigned DecelStatus = 1;
inline constexpr unsigned MoveStatus = 2;
inline constexpr unsigned JogStatus = 3;
inline constexpr unsigned GearingStatus = 4;
inline constexpr unsigned HomingStatus = 5;
inline constexpr unsigned StoppingStatus = 6;
inline constexpr unsigned AxisHomedStatus = 7;
inline constexpr unsigned PositionCamStatus = 8;
inline constexpr unsigned TimeCamStatus = 9;
inline constexpr unsigned PositionCamPendingStatus = 10;
inline constexpr unsigned TimeCamPendingStatus = 11;
inline constexpr unsigned GearingLockStatus = 12;
inline constexpr unsigned PositionCamLockStatus = 13;
inline constexpr unsigned TimeCamLockStatus = 14;
inline constexpr unsigned MasterOffsetMoveStatus = 15;
inline constexpr unsigned CoordinatedMotionStatus = 16;
inline constexpr unsigned TransformStateStatus = 17;
inline constexpr unsigned ControlledByTransformStatus = 18;
inline constexpr unsigned DirectVelocityControlStatus = 19;
inline constexpr unsigned DirectTorqueControlStatus = 20;
inline constexpr unsigned MoveLockStatus = 22;
inline constexpr unsigned JogLockStatus = 24;
inline constexpr unsigned MasterOffsetMoveLockStatus = 26;
inline constexpr unsigned MaximumSpeedExceeded = 27;
}  // namespace motion_status

/// AxisStatus bit numbers [RM002H p.577-578].
namespace axis_status {
inline constexpr unsigned ServoActionStatus = 0;
inline constexpr unsigned DriveEnableStatus = 1;
inline constexpr unsigned ShutdownStatus = 2;
inline constexpr unsigned ConfigUpdateInProcess = 3;
inline constexpr unsigned InhibitStatus = 4;
inline constexpr unsigned DirectControlStatus = 5;
inline constexpr unsigned AxisUpdateStatus = 6;
}  // namespace axis_status

/// AxisFault bit numbers (ICS axis_cip_drive.cs).
namespace axis_fault {
inline constexpr unsigned PhysicalAxisFault = 0;
inline constexpr unsigned ModuleFault = 1;
inline constexpr unsigned ConfigFault = 2;
inline constexpr unsigned GroupFault = 3;
inline constexpr unsigned MotionFault = 4;
inline constexpr unsigned GuardFault = 5;
inline constexpr unsigned InitializationFault = 6;
inline constexpr unsigned APRFault = 7;
inline constexpr unsigned SafetyFault = 8;
}  // namespace axis_fault

/// MotionFaultStatus / MotionAlarmStatus bits [v37 Motion Fault and Alarm Exceptions].
namespace motion_fault {
inline constexpr unsigned SoftTravelLimitPositive = 1;
inline constexpr unsigned SoftTravelLimitNegative = 2;
}  // namespace motion_fault

/// Motion instruction .ERR values (reference section 3.1 / 3.3).
enum class Err : std::int16_t {
  None = 0,
  ExecutionCollision = 3,
  ServoOnState = 4,
  ServoOffState = 5,
  DriveOnState = 6,
  ShutdownState = 7,
  WrongAxisType = 8,
  OvertravelCondition = 9,
  MasterAxisConflict = 10,
  AxisNotConfigured = 11,
  ServoMessageFailure = 12,
  ParameterOutOfRange = 13,
  TuneProcess = 14,
  TestProcess = 15,
  HomeInProcess = 16,
  AxisModeNotRotary = 17,
  AxisTypeUnused = 18,
  GroupNotSynchronized = 19,
  AxisInFaultedState = 20,
  GroupInFaultedState = 21,
  AxisInMotion = 22,
  IllegalDynamicChange = 23,
  IllegalControllerMode = 24,
  IllegalInstruction = 25,
  IllegalCamLength = 26,
  IllegalCamProfileLength = 27,
  IllegalCamType = 28,
  IllegalCamOrder = 29,
  CamProfileBeingCalculated = 30,
  CamProfileBeingUsed = 31,
  CamProfileNotCalculated = 32,
  PositionCamNotEnabled = 33,
  ProcessConflict = 39,
  DriveLocallyDisabled = 40,
  IllegalHomingConfig = 41,
  CoordinateSystemQueueFull = 43,  ///< a third MCLM/MCCM behind the active and the pending one (reference 2.19 ⚠)
  CircularCollinearity = 44,       ///< MCCM: the defining points lie on one line
  CircularStartEnd = 45,           ///< MCCM: start = end of a non-full circle
  CircularR1R2Mismatch = 46,       ///< MCCM: the center is not equidistant from start and end
  CircularInfiniteSolutions = 47,  ///< MCCM: the circle or its plane is not determined
  CircularNoSolutions = 48,        ///< MCCM: no circle (zero radius)
  CircularSmallR = 49,             ///< MCCM: |Radius| smaller than half the chord
  CoordinatedMotionInProcess = 52,  ///< MRP/MAH/MDS on a member of a coordinate system while its path moves (reference ?)
  AxisIsInhibited = 53,
  ZeroMaxDecel = 54,
  InstructionNotSupported = 75,
  ZeroMaxDecelJerk = 76,
  NotAllowedWhileStopping = 78,
  CipAxisInIncorrectState = 82,
  RedefinePositionInProcess = 85,
  OptionalAttributeNotSupported = 86,
  NotAllowedWhileInDirectMotion = 87,
  NotAllowedWhilePlannerActive = 88,
  MdscNotActivated = 93,
  MdscUnitsConflict = 94,
  MdscLockDirConflict = 95,
  MdscMdacAllConflict = 96,
  MdscIdleMasterSlaveMoving = 97,
  FeatureNotSupported = 99,
  AxisNotAtRest = 100,
  CalculatedDataArraySize = 101,  ///< MAM CalculatedData shorter than EventDistance (reference 3.3)
  MdscInvalidSlaveSpeedReduction = 103,  ///< seed 001: a master change leaves < 10 % of the slave system's speed (number ⚠)
  MdscInvalidModeOrMasterChange = 105,
};

/// Human-readable name of an ERR code (for logs and the command line; not RT-relevant).
std::string_view err_name(Err e) noexcept;

/// Operand enumerations shared by several instructions (reference 1.3).
enum class SpeedUnits : std::uint8_t { UnitsPerSec = 0, PercentOfMaximum = 1, Seconds = 3, UnitsPerMasterUnit = 4, MasterUnits = 7 };
enum class AccelUnits : std::uint8_t { UnitsPerSec2 = 0, PercentOfMaximum = 1, Seconds = 3, UnitsPerMasterUnit2 = 4, MasterUnits = 7 };
enum class JerkUnits : std::uint8_t { UnitsPerSec3 = 0, PercentOfMaximum = 1, PercentOfTime = 2, Seconds = 3, UnitsPerMasterUnit3 = 4, PercentOfTimeMasterDriven = 6, MasterUnits = 7 };
enum class ProfileType : std::uint8_t { Trapezoidal = 0, SCurve = 1 };
enum class Merge : std::uint8_t { Disabled = 0, Enabled = 1 };
enum class MergeSpeed : std::uint8_t { Programmed = 0, Current = 1 };
enum class LockDirection : std::uint8_t { None = 0, ImmediateForwardOnly = 1, ImmediateReverseOnly = 2, PositionForwardOnly = 3, PositionReverseOnly = 4 };
enum class MoveType : std::uint8_t { Absolute = 0, Incremental = 1, RotaryShortest = 2, RotaryPositive = 3, RotaryNegative = 4, AbsoluteMasterOffset = 5, IncrementalMasterOffset = 6 };
enum class StopType : std::uint8_t { All = 0, Jog = 1, Move = 2, Gear = 3, Home = 4, Tune = 5, Test = 6, TimeCam = 7, PositionCam = 8, MasterOffsetMove = 9, DirectControl = 10 };
enum class MasterReference : std::uint8_t { Actual = 0, Command = 1 };
enum class CamDirection : std::uint8_t { Same = 0, Opposite = 1, Reverse = 2, Unchanged = 3 };
enum class GroupStopMode : std::uint8_t { Programmed = 0, FastStop = 1, FastDisable = 2 };

/// Master-driven units (MDSC: per master unit, or master units) [RM002H p.512].
constexpr bool is_master_driven(SpeedUnits u) noexcept {
  return u == SpeedUnits::UnitsPerMasterUnit || u == SpeedUnits::MasterUnits;
}
constexpr bool is_master_driven(AccelUnits u) noexcept {
  return u == AccelUnits::UnitsPerMasterUnit2 || u == AccelUnits::MasterUnits;
}
constexpr bool is_master_driven(JerkUnits u) noexcept {
  return u == JerkUnits::UnitsPerMasterUnit3 || u == JerkUnits::PercentOfTimeMasterDriven || u == JerkUnits::MasterUnits;
}
/// The units that give a move's extent instead of its rates (MAM): Seconds,
/// or MasterUnits when master driven.
template <class U>
constexpr bool is_extent(U u, bool master_driven) noexcept {
  return u == (master_driven ? U::MasterUnits : U::Seconds);
}
/// Jerk as a percentage of the acceleration time (time or master driven).
constexpr bool is_percent_of_time(JerkUnits u) noexcept {
  return u == JerkUnits::PercentOfTime || u == JerkUnits::PercentOfTimeMasterDriven;
}
/// A units operand compared with its Logix number (the reference tables and
/// the tests state them as numbers).
constexpr bool operator==(SpeedUnits u, int logix) noexcept { return static_cast<int>(u) == logix; }
constexpr bool operator==(AccelUnits u, int logix) noexcept { return static_cast<int>(u) == logix; }
constexpr bool operator==(JerkUnits u, int logix) noexcept { return static_cast<int>(u) == logix; }

/// ExecutionSchedule numbers of MATC (0, 1) and MAPC (all) [RM002H p.171].
namespace schedule {
inline constexpr std::uint8_t Immediate = 0, Pending = 1, ForwardOnly = 2, ReverseOnly = 3, Bidirectional = 4;
}
/// MasterDirection numbers of MAPC [RM002H p.171]. (ExecutionMode numbers:
/// cam::ExecutionMode.)
namespace master_direction {
inline constexpr std::uint8_t Bidirectional = 0, ForwardOnly = 1, ReverseOnly = 2;
}

// ------------------------------------------------------------- exceptions
/// Exception actions, in increasing severity (the numeric order IS the severity
/// order; the most severe of several simultaneous exceptions wins) [seed 002].
enum class ExceptionAction : std::uint8_t {
  Ignore = 0,
  Alarm = 1,
  FaultStatusOnly = 2,
  StopPlanner = 3,
  StopDrive = 4,
  Shutdown = 5,
};

/// The exceptions the planner detects or is told about.
enum class ExceptionKind : std::uint8_t {
  PositionError = 0,     ///< |command - actual| > position error tolerance
  DriveFault = 1,        ///< drive in Fault state / EMCY received
  NodeLost = 2,          ///< heartbeat or cyclic data lost
  SoftOvertravelPos = 3, ///< command/actual beyond the positive soft limit
  SoftOvertravelNeg = 4, ///< command/actual beyond the negative soft limit
  BusOff = 5,            ///< CAN controller bus-off
  /// Hardware overtravel: the drive's positive limit switch (0x60FD bit 1,
  /// CiA 402 digital inputs) is active (Logix PositiveOvertravelFault)
  HardOvertravelPos = 6,
  /// the negative limit switch (0x60FD bit 0) is active (NegativeOvertravelFault)
  HardOvertravelNeg = 7,
  Count = 8,
};

/// The key of an exception under an axis's `exception_actions:` in the
/// configuration (position_error, drive_fault, ...): one table for the loader
/// and the messages.
std::string_view exception_key(ExceptionKind k) noexcept;
/// The Logix text of an exception action ("Stop Drive", "Fault Status Only", ...).
std::string_view exception_action_name(ExceptionAction a) noexcept;

/// The most severe of two actions.
constexpr ExceptionAction most_severe(ExceptionAction a, ExceptionAction b) noexcept {
  return static_cast<std::uint8_t>(a) >= static_cast<std::uint8_t>(b) ? a : b;
}

/// CoordinateMotionStatus bit numbers of a COORDINATE_SYSTEM (ICS type tables;
/// reference coordinated-motion.md).
namespace coordinate_motion_status {
inline constexpr unsigned AccelStatus = 0;
inline constexpr unsigned DecelStatus = 1;
inline constexpr unsigned ActualPosToleranceStatus = 2;
inline constexpr unsigned CommandPosToleranceStatus = 3;
inline constexpr unsigned StoppingStatus = 4;
inline constexpr unsigned MoveStatus = 6;
inline constexpr unsigned MoveTransitionStatus = 7;
inline constexpr unsigned MovePendingStatus = 8;
inline constexpr unsigned MovePendingQueueFullStatus = 9;
inline constexpr unsigned CoordinateSystemLockStatus = 15;
}  // namespace coordinate_motion_status

/// CoordinateSystemStatus bit numbers [RM002H p.455; ICS].
namespace coordinate_system_status {
inline constexpr unsigned ShutdownStatus = 0;
inline constexpr unsigned ReadyStatus = 1;
inline constexpr unsigned MotionStatus = 2;
inline constexpr unsigned AxisInhibitStatus = 3;
}  // namespace coordinate_system_status

/// Controller mode (Logix Run / Program; Planner::set_controller_mode).
enum class ControllerMode : std::uint8_t { Run = 0, Program = 1 };
/// Programmed Stop Mode of an axis (used by MGS programmed).
enum class ProgrammedStopMode : std::uint8_t { FastStop = 0, FastDisable = 1, HardDisable = 2, FastShutdown = 3, HardShutdown = 4 };

}  // namespace canmotion::motion
