#include "motion/types.hpp"

namespace canmotion::motion {

std::string_view err_name(Err e) noexcept {
  switch (e) {
    case Err::None: return "No Error";
    case Err::ExecutionCollision: return "Execution Collision";
    case Err::ServoOnState: return "Servo On State Error";
    case Err::ServoOffState: return "Servo Off State Error";
    case Err::DriveOnState: return "Drive On State Error";
    case Err::ShutdownState: return "Shutdown State Error";
    case Err::WrongAxisType: return "Wrong Axis Type";
    case Err::OvertravelCondition: return "Overtravel Condition";
    case Err::MasterAxisConflict: return "Master Axis Conflict";
    case Err::AxisNotConfigured: return "Axis Not Configured";
    case Err::ServoMessageFailure: return "Servo Message Failure";
    case Err::ParameterOutOfRange: return "Parameter Out Of Range";
    case Err::TuneProcess: return "Tune Process Error";
    case Err::TestProcess: return "Test Process Error";
    case Err::HomeInProcess: return "Home In Process Error";
    case Err::AxisModeNotRotary: return "Axis Mode Not Rotary";
    case Err::AxisTypeUnused: return "Axis Type Unused";
    case Err::GroupNotSynchronized: return "Group Not Synchronized";
    case Err::AxisInFaultedState: return "Axis In Faulted State";
    case Err::GroupInFaultedState: return "Group In Faulted State";
    case Err::AxisInMotion: return "Axis In Motion";
    case Err::IllegalDynamicChange: return "Illegal Dynamic Change";
    case Err::IllegalControllerMode: return "Illegal Controller Mode";
    case Err::IllegalInstruction: return "Illegal Instruction";
    case Err::IllegalCamLength: return "Illegal Cam Length";
    case Err::IllegalCamProfileLength: return "Illegal Cam Profile Length";
    case Err::IllegalCamType: return "Illegal Cam Type";
    case Err::IllegalCamOrder: return "Illegal Cam Order";
    case Err::CamProfileBeingCalculated: return "Cam Profile Being Calculated";
    case Err::CamProfileBeingUsed: return "Cam Profile Being Used";
    case Err::CamProfileNotCalculated: return "Cam Profile Not Calculated";
    case Err::PositionCamNotEnabled: return "Position Cam Not Enabled";
    case Err::ProcessConflict: return "Process Conflict";
    case Err::DriveLocallyDisabled: return "Drive Locally Disabled";
    case Err::IllegalHomingConfig: return "Illegal Homing Config";
    case Err::CoordinateSystemQueueFull: return "Coordinate System Queue Full";
    case Err::CircularCollinearity: return "Circular Collinearity Error";
    case Err::CircularStartEnd: return "Circular Start End Error";
    case Err::CircularR1R2Mismatch: return "Circular R1 R2 Mismatch Error";
    case Err::CircularInfiniteSolutions: return "Circular Infinite Solution Error";
    case Err::CircularNoSolutions: return "Circular No Solutions Error";
    case Err::CircularSmallR: return "Circular Small R Error";
    case Err::CoordinatedMotionInProcess: return "Coordinated Motion In Process Error";
    case Err::AxisIsInhibited: return "Axis Is Inhibited";
    case Err::ZeroMaxDecel: return "Zero Max Decel";
    case Err::InstructionNotSupported: return "Instruction Not Supported";
    case Err::ZeroMaxDecelJerk: return "Zero Max Decel Jerk";
    case Err::NotAllowedWhileStopping: return "Not Allowed While Stopping";
    case Err::CipAxisInIncorrectState: return "CIP Axis In Incorrect State";
    case Err::RedefinePositionInProcess: return "Redefine Position In Process";
    case Err::OptionalAttributeNotSupported:  // only MDS gives it (motion/instr/direct.cpp)
      return "Optional Attribute Not Supported: MDS needs the drive's ramp attributes, configure the axis' "
             "direct_control: (mode, ramp)";
    case Err::NotAllowedWhileInDirectMotion: return "Not Allowed While In Direct Motion";
    case Err::NotAllowedWhilePlannerActive: return "Not Allowed While Planner Active";
    case Err::MdscNotActivated: return "MDSC Not Activated";
    case Err::MdscUnitsConflict: return "MDSC Units Conflict";
    case Err::MdscLockDirConflict: return "MDSC Lock Direction Conflict";
    case Err::MdscMdacAllConflict: return "MDSC MDAC All Conflict";
    case Err::MdscIdleMasterSlaveMoving: return "MDSC Idle Master And Slave Moving";
    case Err::MdscInvalidModeOrMasterChange: return "MDSC Invalid Mode Or Master Change";
    case Err::FeatureNotSupported: return "Feature Not Supported";
    case Err::AxisNotAtRest: return "Axis Not At Rest";
    case Err::CalculatedDataArraySize: return "Calculated Data Array Size Error";
    case Err::MdscInvalidSlaveSpeedReduction: return "MDSC Invalid Slave Speed Reduction";
  }
  return "Unknown Error";
}

std::string_view exception_key(ExceptionKind k) noexcept {
  switch (k) {
    case ExceptionKind::PositionError: return "position_error";
    case ExceptionKind::DriveFault: return "drive_fault";
    case ExceptionKind::NodeLost: return "node_lost";
    case ExceptionKind::SoftOvertravelPos: return "soft_overtravel_positive";
    case ExceptionKind::SoftOvertravelNeg: return "soft_overtravel_negative";
    case ExceptionKind::BusOff: return "bus_off";
    case ExceptionKind::HardOvertravelPos: return "hard_overtravel_positive";
    case ExceptionKind::HardOvertravelNeg: return "hard_overtravel_negative";
    case ExceptionKind::Count: break;
  }
  return "?";
}

std::string_view exception_action_name(ExceptionAction a) noexcept {
  switch (a) {
    case ExceptionAction::Ignore: return "Ignore";
    case ExceptionAction::Alarm: return "Alarm";
    case ExceptionAction::FaultStatusOnly: return "Fault Status Only";
    case ExceptionAction::StopPlanner: return "Stop Planner";
    case ExceptionAction::StopDrive: return "Stop Drive";
    case ExceptionAction::Shutdown: return "Shutdown";
  }
  return "?";
}

}  // namespace canmotion::motion
