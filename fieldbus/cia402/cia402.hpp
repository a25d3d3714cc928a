#pragma once
/// \file
/// THE single definition of the CiA 402 drive profile used by both the master
/// proxy and the emulator: object indices, statusword/controlword bits, the
/// power drive system state machine with its numbered transitions (0..16),
/// controlword commands and modes of operation. Numbers follow CiA 402-2
/// (IEC 61800-7-201); see shared/reference/cia402.md §1-§3.
/// Everything here is constexpr, noexcept and realtime-safe.

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string_view>

namespace canmotion::cia402 {

/// Round to the nearest integer, halves away from zero (as std::round), without
/// the libm call: the master and the emulator use it to turn user units into
/// drive counts. Callers convert the result to an integer, so the sign of a
/// zero result does not matter. x - trunc(x) is exact below 2^52, so halves
/// are detected exactly; NaN, infinities and larger values come back unchanged.
inline double round_half_away(double x) noexcept {
  constexpr double kAllIntegral = 4503599627370496.0;  // 2^52: from here on every double is an integer
  if (!(std::abs(x) < kAllIntegral)) return x;
  const double t = static_cast<double>(static_cast<std::int64_t>(x));  // trunc
  const double d = x - t;
  if (d >= 0.5) return t + 1.0;
  if (d <= -0.5) return t - 1.0;
  return t;
}

// ============================================================================
// Object indices (CiA 402-2)
// ============================================================================
/// Device profile number of a CiA 402 drive in 0x1000 bits 0..15.
inline constexpr std::uint32_t kDeviceProfile402 = 402;

namespace obj {
inline constexpr std::uint16_t kErrorCode = 0x603F;
inline constexpr std::uint16_t kControlword = 0x6040;
inline constexpr std::uint16_t kStatusword = 0x6041;
inline constexpr std::uint16_t kQuickStopOptionCode = 0x605A;
inline constexpr std::uint16_t kShutdownOptionCode = 0x605B;
inline constexpr std::uint16_t kDisableOperationOptionCode = 0x605C;
inline constexpr std::uint16_t kHaltOptionCode = 0x605D;
inline constexpr std::uint16_t kFaultReactionOptionCode = 0x605E;
inline constexpr std::uint16_t kModesOfOperation = 0x6060;
inline constexpr std::uint16_t kModesOfOperationDisplay = 0x6061;
inline constexpr std::uint16_t kPositionDemandValue = 0x6062;
inline constexpr std::uint16_t kPositionActualInternalValue = 0x6063;
inline constexpr std::uint16_t kPositionActualValue = 0x6064;
inline constexpr std::uint16_t kFollowingErrorWindow = 0x6065;
inline constexpr std::uint16_t kFollowingErrorTimeOut = 0x6066;
inline constexpr std::uint16_t kPositionWindow = 0x6067;
inline constexpr std::uint16_t kPositionWindowTime = 0x6068;
inline constexpr std::uint16_t kVelocityDemandValue = 0x606B;
inline constexpr std::uint16_t kVelocityActualValue = 0x606C;
inline constexpr std::uint16_t kTargetTorque = 0x6071;
inline constexpr std::uint16_t kMaxTorque = 0x6072;
inline constexpr std::uint16_t kTorqueActualValue = 0x6077;
inline constexpr std::uint16_t kTargetPosition = 0x607A;
inline constexpr std::uint16_t kHomeOffset = 0x607C;
inline constexpr std::uint16_t kSoftwarePositionLimit = 0x607D;
inline constexpr std::uint16_t kPolarity = 0x607E;
inline constexpr std::uint16_t kMaxProfileVelocity = 0x607F;
inline constexpr std::uint16_t kMaxMotorSpeed = 0x6080;
inline constexpr std::uint16_t kProfileVelocity = 0x6081;
inline constexpr std::uint16_t kProfileAcceleration = 0x6083;
inline constexpr std::uint16_t kProfileDeceleration = 0x6084;
inline constexpr std::uint16_t kQuickStopDeceleration = 0x6085;
inline constexpr std::uint16_t kMotionProfileType = 0x6086;
inline constexpr std::uint16_t kHomingMethod = 0x6098;
inline constexpr std::uint16_t kHomingSpeeds = 0x6099;
inline constexpr std::uint16_t kHomingAcceleration = 0x609A;
inline constexpr std::uint16_t kPositionOffset = 0x60B0;
inline constexpr std::uint16_t kVelocityOffset = 0x60B1;
inline constexpr std::uint16_t kTorqueOffset = 0x60B2;
/// INTEGER16 interpolation sub-mode select (optional): 0 = linear
/// interpolation (the default), negative = manufacturer-specific.
inline constexpr std::uint16_t kInterpolationSubModeSelect = 0x60C0;
/// ARRAY/RECORD interpolation data record: sub1 the position set point of
/// interpolated position mode (INTEGER32, mapped synchronous like CSP's 0x607A).
inline constexpr std::uint16_t kInterpolationDataRecord = 0x60C1;
inline constexpr std::uint8_t kInterpolationDataPositionSub = 1;
inline constexpr std::uint16_t kInterpolationTimePeriod = 0x60C2;  ///< sub1 value (U8), sub2 index (I8)
inline constexpr std::uint16_t kFollowingErrorActualValue = 0x60F4;
inline constexpr std::uint16_t kDigitalInputs = 0x60FD;
inline constexpr std::uint16_t kTargetVelocity = 0x60FF;
inline constexpr std::uint16_t kSupportedDriveModes = 0x6502;
inline constexpr std::uint16_t kDeviceType = 0x1000;  ///< CiA 301; bits 0..15 the device profile number
inline constexpr std::uint16_t kIdentity = 0x1018;    ///< CiA 301; sub1 vendor, sub2 product, sub3 revision, sub4 serial
/// CiA 301, UNSIGNED32 in us: a SYNC consumer with a value other than 0
/// watches the SYNC (CANopenNode: EMCY 8100h after 1.5 x the period without one).
inline constexpr std::uint16_t kCommunicationCyclePeriod = 0x1006;
/// CiA 301, UNSIGNED8: 0 = SYNC without counter, 2..240 = the counter's
/// overflow value (the SYNC then carries it in one byte). Changes only while
/// 0x1006 is 0 (SDO abort 0x08000022 otherwise).
inline constexpr std::uint16_t kSyncCounterOverflow = 0x1019;

// ---- MDS drive-side ramps and SLAT (Logix seed 002) --------------------------
// Standard objects carry the ramp accelerations: RampAcceleration ->
// kProfileAcceleration (0x6083), RampDeceleration -> kProfileDeceleration
// (0x6084), both counts/s^2, applied by the drive to the CSV target. CiA 402
// has no direction-dependent velocity limit (0x607F is one symmetric limit for
// every mode), no "% of ramp time" jerk and no SLAT, so these are
// manufacturer-specific (0x2000-0x5FFF area):
/// RECORD: sub1 RampVelocity - Positive, sub2 RampVelocity - Negative
/// (UNSIGNED32, counts/s, magnitudes): limits of the CSV target in each direction.
inline constexpr std::uint16_t kRampVelocityLimit = 0x2010;
inline constexpr std::uint8_t kRampVelocityPositiveSub = 1;
inline constexpr std::uint8_t kRampVelocityNegativeSub = 2;
/// UNSIGNED8, 0..100: RampJerk - Control, the share (%) of a full-scale ramp
/// spent in jerk-limited (S-curve) segments; 0 = trapezoidal.
inline constexpr std::uint16_t kRampJerkControl = 0x2011;
/// UNSIGNED8: SLAT Configuration (SlatConfiguration below), used in CST.
inline constexpr std::uint16_t kSlatConfiguration = 0x2020;
/// UNSIGNED32, counts/s: SLAT Set Point (velocity-error threshold).
inline constexpr std::uint16_t kSlatSetPoint = 0x2021;
/// UNSIGNED16, ms: SLAT Time Delay (how long the error must stay beyond the
/// set point before the drive switches from torque to speed control).
inline constexpr std::uint16_t kSlatTimeDelay = 0x2022;
}  // namespace obj

// ---- where a drive keeps the MDS objects CiA 402 lacks ----------------------
/// One object of a drive's dictionary: index and sub-index.
struct ObjectAddress {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  friend constexpr bool operator==(const ObjectAddress&, const ObjectAddress&) = default;
};

/// The MDS objects above that CiA 402 does not define (the vendor-area ones;
/// 0x6083/0x6084 are standard and fixed), by what they do.
enum class MdsObject : std::uint8_t {
  kRampVelocityPositive,  ///< UNSIGNED32 counts/s (obj::kRampVelocityLimit sub 1)
  kRampVelocityNegative,  ///< UNSIGNED32 counts/s (sub 2)
  kRampJerkControl,       ///< UNSIGNED8 % 0..100
  kSlatConfiguration,     ///< UNSIGNED8 SlatConfiguration
  kSlatSetPoint,          ///< UNSIGNED32 counts/s
  kSlatTimeDelay,         ///< UNSIGNED16 ms
};
inline constexpr std::size_t kMdsObjectCount = 6;

/// Per MdsObject: its configuration key (`drive.mds_objects.<key>`, the
/// cia402-emu --mds-objects name), its size in bytes (the data type's:
/// UNSIGNED8/16/32) and the project's own address.
struct MdsObjectInfo {
  std::string_view key;
  std::uint8_t size;
  ObjectAddress standard;
};
inline constexpr std::array<MdsObjectInfo, kMdsObjectCount> kMdsObjectInfo = {{
    {"ramp_velocity_positive", 4, {obj::kRampVelocityLimit, obj::kRampVelocityPositiveSub}},
    {"ramp_velocity_negative", 4, {obj::kRampVelocityLimit, obj::kRampVelocityNegativeSub}},
    {"ramp_jerk_control", 1, {obj::kRampJerkControl, 0}},
    {"slat_configuration", 1, {obj::kSlatConfiguration, 0}},
    {"slat_set_point", 4, {obj::kSlatSetPoint, 0}},
    {"slat_time_delay", 2, {obj::kSlatTimeDelay, 0}},
}};
[[nodiscard]] constexpr const MdsObjectInfo& info(MdsObject o) noexcept { return kMdsObjectInfo[static_cast<std::size_t>(o)]; }

/// Where one drive keeps the MDS objects (issue 15 item 6): the project's
/// own vendor-area indices 0x2010..0x2022 by default; on a real drive those
/// indices may mean something else, so the master (`drive.mds_objects`) and
/// the emulator (EmulatorConfig::mds_objects, cia402-emu --mds-objects) take
/// them from here.
struct MdsObjects {
  std::array<ObjectAddress, kMdsObjectCount> at = {
      kMdsObjectInfo[0].standard, kMdsObjectInfo[1].standard, kMdsObjectInfo[2].standard,
      kMdsObjectInfo[3].standard, kMdsObjectInfo[4].standard, kMdsObjectInfo[5].standard};
  [[nodiscard]] constexpr ObjectAddress operator[](MdsObject o) const noexcept { return at[static_cast<std::size_t>(o)]; }
  [[nodiscard]] constexpr ObjectAddress& operator[](MdsObject o) noexcept { return at[static_cast<std::size_t>(o)]; }
  /// The object at index:sub, if one is there.
  [[nodiscard]] constexpr std::optional<MdsObject> find(std::uint16_t index, std::uint8_t sub) const noexcept {
    for (std::size_t i = 0; i < kMdsObjectCount; ++i)
      if (at[i] == ObjectAddress{index, sub}) return static_cast<MdsObject>(i);
    return std::nullopt;
  }
  /// True when `index` holds one of them (any sub-index).
  [[nodiscard]] constexpr bool uses_index(std::uint16_t index) const noexcept {
    for (const ObjectAddress& a : at)
      if (a.index == index) return true;
    return false;
  }
  friend constexpr bool operator==(const MdsObjects&, const MdsObjects&) = default;
};

/// "0x2010:1", "0x2011" (sub-index 0), "8208:0x01": an index 1..0xFFFF and
/// a sub-index 0..254, each decimal or 0x hex; nullopt when the text is not one.
[[nodiscard]] constexpr std::optional<ObjectAddress> parse_object_address(std::string_view s) noexcept {
  auto number = [](std::string_view t, std::uint32_t max) -> std::optional<std::uint32_t> {
    unsigned base = 10;
    if (t.size() > 2 && t[0] == '0' && (t[1] == 'x' || t[1] == 'X')) {
      base = 16;
      t.remove_prefix(2);
    }
    if (t.empty()) return std::nullopt;
    std::uint32_t v = 0;
    for (const char c : t) {
      unsigned d = 0;
      if (c >= '0' && c <= '9') d = static_cast<unsigned>(c - '0');
      else if (base == 16 && c >= 'a' && c <= 'f') d = static_cast<unsigned>(c - 'a' + 10);
      else if (base == 16 && c >= 'A' && c <= 'F') d = static_cast<unsigned>(c - 'A' + 10);
      else return std::nullopt;
      v = v * base + d;
      if (v > max) return std::nullopt;
    }
    return v;
  };
  const std::size_t colon = s.find(':');
  const auto index = number(s.substr(0, colon), 0xFFFF);
  if (!index || *index == 0) return std::nullopt;
  std::optional<std::uint32_t> sub = 0u;
  if (colon != std::string_view::npos) sub = number(s.substr(colon + 1), 254);
  if (!sub) return std::nullopt;
  return ObjectAddress{static_cast<std::uint16_t>(*index), static_cast<std::uint8_t>(*sub)};
}

/// The CiA 402 objects the master writes (boot configuration, homing, mode
/// switches), maps into its PDOs or reads (0x603F, 0x6502, 0x6061): an MDS
/// object must not be placed on one of them (config/loader.cpp). Keep in
/// step with drive_boot.cpp, drive_pdos.cpp and the homing writes.
inline constexpr std::array<std::uint16_t, 21> kMasterProfileObjects = {
    obj::kErrorCode,         obj::kControlword,          obj::kStatusword,          obj::kQuickStopOptionCode,
    obj::kModesOfOperation,  obj::kModesOfOperationDisplay, obj::kPositionActualValue, obj::kFollowingErrorWindow,
    obj::kVelocityActualValue, obj::kTargetTorque,       obj::kTorqueActualValue,   obj::kTargetPosition,
    obj::kHomeOffset,        obj::kProfileAcceleration,  obj::kProfileDeceleration, obj::kHomingMethod,
    obj::kHomingSpeeds,      obj::kHomingAcceleration,   obj::kInterpolationTimePeriod, obj::kTargetVelocity,
    obj::kSupportedDriveModes};

/// SLAT Configuration (0x2020) enumeration, numbers as in the Logix MDS page.
enum class SlatConfiguration : std::uint8_t {
  kDisabled = 0,        ///< SLAT disabled: plain torque control in CST
  kMinSpeedTorque = 1,  ///< torque -> speed if Velocity Error > set point; back if Speed Error < 0
  kMaxSpeedTorque = 2,  ///< torque -> speed if Velocity Error < -set point; back if Speed Error > 0
};

[[nodiscard]] constexpr std::string_view slat_name(SlatConfiguration c) noexcept {
  switch (c) {
    case SlatConfiguration::kDisabled: return "SLAT disabled";
    case SlatConfiguration::kMinSpeedTorque: return "SLAT Min Speed/Torque";
    case SlatConfiguration::kMaxSpeedTorque: return "SLAT Max Speed/Torque";
  }
  return "?";
}

/// The SLAT switching rule of seed 002, one SYNC at a time. `velocity_error`
/// = velocity command (0x60FF) - actual velocity (counts/s). Going from torque
/// to speed control needs the condition to hold for `delay_ns` (SLAT Time
/// Delay, counted in `held_ns`, which the caller keeps between calls); going
/// back to torque control is immediate. Returns true for speed control.
/// Realtime-safe.
[[nodiscard]] constexpr bool slat_speed_control(SlatConfiguration c, bool speed_control, double velocity_error,
                                                double set_point, std::int64_t dt_ns, std::int64_t delay_ns,
                                                std::int64_t& held_ns) noexcept {
  bool to_speed = false;
  bool to_torque = false;
  switch (c) {
    case SlatConfiguration::kDisabled: held_ns = 0; return false;
    case SlatConfiguration::kMinSpeedTorque:
      to_speed = velocity_error > set_point;
      to_torque = velocity_error < 0;
      break;
    case SlatConfiguration::kMaxSpeedTorque:
      to_speed = velocity_error < -set_point;
      to_torque = velocity_error > 0;
      break;
  }
  if (speed_control) {
    held_ns = 0;
    return !to_torque;
  }
  if (!to_speed) {
    held_ns = 0;
    return false;
  }
  held_ns += dt_ns;
  return held_ns >= delay_ns;
}

// ============================================================================
// Statusword (0x6041) and controlword (0x6040) bits
// ============================================================================
namespace sw {
inline constexpr std::uint16_t kReadyToSwitchOn = 1u << 0;
inline constexpr std::uint16_t kSwitchedOn = 1u << 1;
inline constexpr std::uint16_t kOperationEnabled = 1u << 2;
inline constexpr std::uint16_t kFault = 1u << 3;
inline constexpr std::uint16_t kVoltageEnabled = 1u << 4;
inline constexpr std::uint16_t kQuickStop = 1u << 5;          ///< 0 = quick stop active
inline constexpr std::uint16_t kSwitchOnDisabled = 1u << 6;
inline constexpr std::uint16_t kWarning = 1u << 7;
inline constexpr std::uint16_t kManufacturer8 = 1u << 8;
inline constexpr std::uint16_t kRemote = 1u << 9;
inline constexpr std::uint16_t kTargetReached = 1u << 10;
inline constexpr std::uint16_t kInternalLimitActive = 1u << 11;
inline constexpr std::uint16_t kOpMode12 = 1u << 12;  ///< CSx: drive follows the command; HM: homing attained; PP: set-point ack
inline constexpr std::uint16_t kOpMode13 = 1u << 13;  ///< CSP/PP: following error; HM: homing error
inline constexpr std::uint16_t kFollowsCommand = kOpMode12;
inline constexpr std::uint16_t kFollowingError = kOpMode13;
inline constexpr std::uint16_t kHomingAttained = kOpMode12;
inline constexpr std::uint16_t kHomingError = kOpMode13;
/// IP (mode 7): "ip mode active", the drive takes the 0x60C1 set points
/// (controlword bit 4 set in Operation enabled).
inline constexpr std::uint16_t kIpModeActive = kOpMode12;
/// Masks for state decoding (§1.1): short for states that ignore bit 5.
inline constexpr std::uint16_t kStateMaskShort = 0x004F;
inline constexpr std::uint16_t kStateMaskLong = 0x006F;
}  // namespace sw

namespace cw {
inline constexpr std::uint16_t kSwitchOn = 1u << 0;
inline constexpr std::uint16_t kEnableVoltage = 1u << 1;
inline constexpr std::uint16_t kQuickStop = 1u << 2;  ///< 0 = quick stop requested
inline constexpr std::uint16_t kEnableOperation = 1u << 3;
inline constexpr std::uint16_t kOpMode4 = 1u << 4;  ///< PP: new set-point; HM: homing operation start
inline constexpr std::uint16_t kOpMode5 = 1u << 5;  ///< PP: change set immediately
inline constexpr std::uint16_t kOpMode6 = 1u << 6;  ///< PP: relative
inline constexpr std::uint16_t kFaultReset = 1u << 7;
inline constexpr std::uint16_t kHalt = 1u << 8;
inline constexpr std::uint16_t kOpMode9 = 1u << 9;  ///< PP: change on set-point
inline constexpr std::uint16_t kHomingStart = kOpMode4;
inline constexpr std::uint16_t kNewSetPoint = kOpMode4;
/// IP (mode 7): "enable ip mode"; the drive ignores the set points while it is 0.
inline constexpr std::uint16_t kEnableIpMode = kOpMode4;
/// Bits that select the state machine command (0, 1, 2, 3, 7).
inline constexpr std::uint16_t kCommandMask = 0x008F;
}  // namespace cw

// ============================================================================
// States
// ============================================================================

/// Power drive system states (§1.1).
enum class State : std::uint8_t {
  kNotReadyToSwitchOn = 0,
  kSwitchOnDisabled = 1,
  kReadyToSwitchOn = 2,
  kSwitchedOn = 3,
  kOperationEnabled = 4,
  kQuickStopActive = 5,
  kFaultReactionActive = 6,
  kFault = 7,
  kUnknown = 8,  ///< statusword matches no state pattern
};

/// Decode the state from a statusword by the mask/value table. Realtime-safe.
[[nodiscard]] constexpr State decode_state(std::uint16_t statusword) noexcept {
  switch (statusword & sw::kStateMaskShort) {
    case 0x0000: return State::kNotReadyToSwitchOn;
    case 0x0040: return State::kSwitchOnDisabled;
    case 0x000F: return State::kFaultReactionActive;
    case 0x0008: return State::kFault;
    default: break;
  }
  switch (statusword & sw::kStateMaskLong) {
    case 0x0021: return State::kReadyToSwitchOn;
    case 0x0023: return State::kSwitchedOn;
    case 0x0027: return State::kOperationEnabled;
    case 0x0007: return State::kQuickStopActive;
    default: return State::kUnknown;
  }
}

/// The state bits (0..6) a drive reports in `s`, without voltage-enabled
/// (bit 4) or any mode bits: the exact value of the mask table. Realtime-safe.
[[nodiscard]] constexpr std::uint16_t state_bits(State s) noexcept {
  switch (s) {
    case State::kNotReadyToSwitchOn: return 0x0000;
    case State::kSwitchOnDisabled: return 0x0040;
    case State::kReadyToSwitchOn: return 0x0021;
    case State::kSwitchedOn: return 0x0023;
    case State::kOperationEnabled: return 0x0027;
    case State::kQuickStopActive: return 0x0007;
    case State::kFaultReactionActive: return 0x000F;
    case State::kFault: return 0x0008;
    case State::kUnknown: break;
  }
  return 0x0000;
}

[[nodiscard]] constexpr std::string_view state_name(State s) noexcept {
  switch (s) {
    case State::kNotReadyToSwitchOn: return "Not ready to switch on";
    case State::kSwitchOnDisabled: return "Switch on disabled";
    case State::kReadyToSwitchOn: return "Ready to switch on";
    case State::kSwitchedOn: return "Switched on";
    case State::kOperationEnabled: return "Operation enabled";
    case State::kQuickStopActive: return "Quick stop active";
    case State::kFaultReactionActive: return "Fault reaction active";
    case State::kFault: return "Fault";
    case State::kUnknown: break;
  }
  return "Unknown";
}

// ============================================================================
// Controlword commands
// ============================================================================

/// Device control commands (§1.2).
enum class Command : std::uint8_t {
  kShutdown = 0,          ///< 0x0006: transitions 2, 6, 8
  kSwitchOn = 1,          ///< 0x0007: transition 3 (same bits as disable operation)
  kEnableOperation = 2,   ///< 0x000F: transitions 4, 16 (and 3+4 from Ready to switch on)
  kDisableVoltage = 3,    ///< 0x0000: transitions 7, 9, 10, 12
  kQuickStop = 4,         ///< 0x0002: transitions 7, 10, 11
  kDisableOperation = 5,  ///< 0x0007: transition 5
  kFaultReset = 6,        ///< 0x0080 (rising edge of bit 7): transition 15
};

/// The typical controlword of a command (bits 0-3 and 7). Realtime-safe.
[[nodiscard]] constexpr std::uint16_t controlword(Command c) noexcept {
  switch (c) {
    case Command::kShutdown: return 0x0006;
    case Command::kSwitchOn: return 0x0007;
    case Command::kEnableOperation: return 0x000F;
    case Command::kDisableVoltage: return 0x0000;
    case Command::kQuickStop: return 0x0002;
    case Command::kDisableOperation: return 0x0007;
    case Command::kFaultReset: return 0x0080;
  }
  return 0x0000;
}

/// Decode the command bits of a controlword (mask/value table §1.2). Bit 7
/// set decodes as kFaultReset (the drive acts on its rising edge only).
/// 0x0007 decodes as kSwitchOn; in Operation enabled it means disable
/// operation (transition 5). Realtime-safe.
[[nodiscard]] constexpr Command decode_command(std::uint16_t controlword_value) noexcept {
  const std::uint16_t c = controlword_value;
  if ((c & cw::kFaultReset) != 0) return Command::kFaultReset;
  if ((c & cw::kEnableVoltage) == 0) return Command::kDisableVoltage;
  if ((c & cw::kQuickStop) == 0) return Command::kQuickStop;
  if ((c & cw::kSwitchOn) == 0) return Command::kShutdown;
  if ((c & cw::kEnableOperation) == 0) return Command::kSwitchOn;
  return Command::kEnableOperation;
}

[[nodiscard]] constexpr std::string_view command_name(Command c) noexcept {
  switch (c) {
    case Command::kShutdown: return "Shutdown";
    case Command::kSwitchOn: return "Switch on";
    case Command::kEnableOperation: return "Enable operation";
    case Command::kDisableVoltage: return "Disable voltage";
    case Command::kQuickStop: return "Quick stop";
    case Command::kDisableOperation: return "Disable operation";
    case Command::kFaultReset: return "Fault reset";
  }
  return "?";
}

// ============================================================================
// Transitions 0..16 (§1.3)
// ============================================================================

/// One numbered transition of the state machine.
struct TransitionInfo {
  std::uint8_t number;
  State from;  ///< kUnknown for 0 (start) and 13 (any state)
  State to;
  std::string_view trigger;
};

inline constexpr std::array<TransitionInfo, 17> kTransitions = {{
    {0, State::kUnknown, State::kNotReadyToSwitchOn, "power-on / reset (automatic)"},
    {1, State::kNotReadyToSwitchOn, State::kSwitchOnDisabled, "initialisation done (automatic)"},
    {2, State::kSwitchOnDisabled, State::kReadyToSwitchOn, "Shutdown"},
    {3, State::kReadyToSwitchOn, State::kSwitchedOn, "Switch on"},
    {4, State::kSwitchedOn, State::kOperationEnabled, "Enable operation"},
    {5, State::kOperationEnabled, State::kSwitchedOn, "Disable operation"},
    {6, State::kSwitchedOn, State::kReadyToSwitchOn, "Shutdown"},
    {7, State::kReadyToSwitchOn, State::kSwitchOnDisabled, "Disable voltage or Quick stop"},
    {8, State::kOperationEnabled, State::kReadyToSwitchOn, "Shutdown"},
    {9, State::kOperationEnabled, State::kSwitchOnDisabled, "Disable voltage"},
    {10, State::kSwitchedOn, State::kSwitchOnDisabled, "Disable voltage or Quick stop"},
    {11, State::kOperationEnabled, State::kQuickStopActive, "Quick stop"},
    {12, State::kQuickStopActive, State::kSwitchOnDisabled, "quick stop completed (automatic) or Disable voltage"},
    {13, State::kUnknown, State::kFaultReactionActive, "fault detected (any state)"},
    {14, State::kFaultReactionActive, State::kFault, "fault reaction completed (automatic)"},
    {15, State::kFault, State::kSwitchOnDisabled, "Fault reset (rising edge of bit 7)"},
    {16, State::kQuickStopActive, State::kOperationEnabled, "Enable operation (0x605A = 5..8)"},
}};

/// No transition (used where a transition number is optional).
inline constexpr std::uint8_t kNoTransition = 0xFF;

/// Result of applying a controlword in a state.
struct StepResult {
  State next;
  std::uint8_t transition;  ///< kNoTransition when the state does not change
  friend constexpr bool operator==(const StepResult&, const StepResult&) = default;
};

/// True if 0x605A (quick stop option code) keeps the drive in Quick stop
/// active after stopping (codes 5..8), which allows transition 16.
[[nodiscard]] constexpr bool quick_stop_stays(std::int16_t quick_stop_option_code) noexcept {
  return quick_stop_option_code >= 5 && quick_stop_option_code <= 8;
}

/// Drive-side rule: the state reached from `s` when the controlword changes
/// from `previous_cw` to `cw_now`. Exactly one transition per call: from
/// Ready to switch on, 0x000F gives 3 and the next call (same controlword)
/// gives 4. Automatic transitions (0, 1, 12 on completion, 13, 14) are the
/// drive's business and are not produced here. Fault reset (15) needs the
/// rising edge of bit 7; the caller checks that no fault remains.
/// Realtime-safe.
[[nodiscard]] constexpr StepResult apply_controlword(State s, std::uint16_t previous_cw, std::uint16_t cw_now,
                                                     std::int16_t quick_stop_option_code = 2) noexcept {
  const StepResult stay{s, kNoTransition};
  if (s == State::kFault) {
    const bool edge = (cw_now & cw::kFaultReset) != 0 && (previous_cw & cw::kFaultReset) == 0;
    return edge ? StepResult{State::kSwitchOnDisabled, 15} : stay;
  }
  // Outside Fault, bit 7 has no meaning: decode the remaining bits.
  const Command c = decode_command(static_cast<std::uint16_t>(cw_now & ~cw::kFaultReset));
  switch (s) {
    case State::kSwitchOnDisabled:
      return c == Command::kShutdown ? StepResult{State::kReadyToSwitchOn, 2} : stay;
    case State::kReadyToSwitchOn:
      if (c == Command::kSwitchOn || c == Command::kEnableOperation) return {State::kSwitchedOn, 3};
      if (c == Command::kDisableVoltage || c == Command::kQuickStop) return {State::kSwitchOnDisabled, 7};
      return stay;
    case State::kSwitchedOn:
      if (c == Command::kEnableOperation) return {State::kOperationEnabled, 4};
      if (c == Command::kShutdown) return {State::kReadyToSwitchOn, 6};
      if (c == Command::kDisableVoltage || c == Command::kQuickStop) return {State::kSwitchOnDisabled, 10};
      return stay;
    case State::kOperationEnabled:
      if (c == Command::kSwitchOn) return {State::kSwitchedOn, 5};  // disable operation
      if (c == Command::kShutdown) return {State::kReadyToSwitchOn, 8};
      if (c == Command::kDisableVoltage) return {State::kSwitchOnDisabled, 9};
      if (c == Command::kQuickStop) return {State::kQuickStopActive, 11};
      return stay;
    case State::kQuickStopActive:
      if (c == Command::kDisableVoltage) return {State::kSwitchOnDisabled, 12};
      if (c == Command::kEnableOperation && quick_stop_stays(quick_stop_option_code))
        return {State::kOperationEnabled, 16};
      return stay;
    default:
      return stay;
  }
}

/// One step the master takes towards a wanted state.
struct PlanStep {
  Command command;
  std::uint8_t transition;  ///< the transition the command should cause (kNoTransition: wait)
  State expect;             ///< the state it should reach
};

/// Master-side rule: the next command to send in `current` to get to
/// `target`, one transition at a time; nullopt when `current == target` or
/// when only the drive can move on (Not ready to switch on, Fault reaction
/// active, Unknown). Targets: kOperationEnabled (enable), kSwitchedOn,
/// kReadyToSwitchOn, kSwitchOnDisabled (disable), kQuickStopActive (quick
/// stop). A Fault is always reset first (15). Realtime-safe.
[[nodiscard]] constexpr std::optional<PlanStep> next_step(State current, State target) noexcept {
  using S = State;
  if (current == target) return std::nullopt;
  switch (current) {
    case S::kFault: return PlanStep{Command::kFaultReset, 15, S::kSwitchOnDisabled};
    case S::kNotReadyToSwitchOn:
    case S::kFaultReactionActive:
    case S::kUnknown: return std::nullopt;
    default: break;
  }
  if (target == S::kSwitchOnDisabled) {
    switch (current) {
      case S::kReadyToSwitchOn: return PlanStep{Command::kDisableVoltage, 7, target};
      case S::kSwitchedOn: return PlanStep{Command::kDisableVoltage, 10, target};
      case S::kOperationEnabled: return PlanStep{Command::kDisableVoltage, 9, target};
      case S::kQuickStopActive: return PlanStep{Command::kDisableVoltage, 12, target};
      default: return std::nullopt;
    }
  }
  if (target == S::kQuickStopActive) {
    // The Quick stop command is defined from Ready to switch on (7) and
    // Switched on (10), both to Switch on disabled, and from Operation
    // enabled (11) to Quick stop active.
    switch (current) {
      case S::kOperationEnabled: return PlanStep{Command::kQuickStop, 11, target};
      case S::kReadyToSwitchOn: return PlanStep{Command::kQuickStop, 7, S::kSwitchOnDisabled};
      case S::kSwitchedOn: return PlanStep{Command::kQuickStop, 10, S::kSwitchOnDisabled};
      default: return std::nullopt;
    }
  }
  // Upwards (towards Operation enabled) or down to Switched on / Ready.
  switch (current) {
    case S::kSwitchOnDisabled: return PlanStep{Command::kShutdown, 2, S::kReadyToSwitchOn};
    case S::kReadyToSwitchOn:
      if (target == S::kSwitchedOn || target == S::kOperationEnabled)
        return PlanStep{Command::kSwitchOn, 3, S::kSwitchedOn};
      return std::nullopt;
    case S::kSwitchedOn:
      if (target == S::kOperationEnabled) return PlanStep{Command::kEnableOperation, 4, S::kOperationEnabled};
      if (target == S::kReadyToSwitchOn) return PlanStep{Command::kShutdown, 6, S::kReadyToSwitchOn};
      return std::nullopt;
    case S::kOperationEnabled:
      if (target == S::kSwitchedOn) return PlanStep{Command::kDisableOperation, 5, S::kSwitchedOn};
      if (target == S::kReadyToSwitchOn) return PlanStep{Command::kShutdown, 8, S::kReadyToSwitchOn};
      return std::nullopt;
    case S::kQuickStopActive:
      // Leave quick stop through Switch on disabled (12); transition 16 is
      // optional in drives (0x605A 5..8), so the master does not rely on it.
      return PlanStep{Command::kDisableVoltage, 12, S::kSwitchOnDisabled};
    default: return std::nullopt;
  }
}

// ============================================================================
// Modes of operation (0x6060 / 0x6061, INTEGER8)
// ============================================================================
enum class Mode : std::int8_t {
  kNoMode = 0,
  kProfilePosition = 1,      ///< PP
  kVelocity = 2,             ///< VL
  kProfileVelocity = 3,      ///< PV
  kProfileTorque = 4,        ///< PT / TQ
  kHoming = 6,               ///< HM
  kInterpolatedPosition = 7, ///< IP
  kCsp = 8,                  ///< cyclic synchronous position
  kCsv = 9,                  ///< cyclic synchronous velocity
  kCst = 10,                 ///< cyclic synchronous torque
};

[[nodiscard]] constexpr std::string_view mode_name(std::int8_t m) noexcept {
  switch (m) {
    case 0: return "no mode";
    case 1: return "profile position (PP)";
    case 2: return "velocity (VL)";
    case 3: return "profile velocity (PV)";
    case 4: return "profile torque (PT)";
    case 6: return "homing (HM)";
    case 7: return "interpolated position (IP)";
    case 8: return "cyclic synchronous position (CSP)";
    case 9: return "cyclic synchronous velocity (CSV)";
    case 10: return "cyclic synchronous torque (CST)";
    case 11: return "cyclic synchronous torque with commutation angle (CSTCA)";
    default: return m < 0 ? "manufacturer-specific" : "reserved";
  }
}
[[nodiscard]] constexpr std::string_view mode_name(Mode m) noexcept { return mode_name(static_cast<std::int8_t>(m)); }

/// Short tag ("CSP", "CSV", ...) for logs and traces.
[[nodiscard]] constexpr std::string_view mode_tag(std::int8_t m) noexcept {
  switch (m) {
    case 0: return "none";
    case 1: return "PP";
    case 2: return "VL";
    case 3: return "PV";
    case 4: return "PT";
    case 6: return "HM";
    case 7: return "IP";
    case 8: return "CSP";
    case 9: return "CSV";
    case 10: return "CST";
    case 11: return "CSTCA";
    default: return "?";
  }
}

/// The 0x6502 (supported drive modes) bit of a mode; 0 for modes without one.
[[nodiscard]] constexpr std::uint32_t supported_mode_bit(Mode m) noexcept {
  switch (m) {
    case Mode::kProfilePosition: return 1u << 0;
    case Mode::kVelocity: return 1u << 1;
    case Mode::kProfileVelocity: return 1u << 2;
    case Mode::kProfileTorque: return 1u << 3;
    case Mode::kHoming: return 1u << 5;
    case Mode::kInterpolatedPosition: return 1u << 6;
    case Mode::kCsp: return 1u << 7;
    case Mode::kCsv: return 1u << 8;
    case Mode::kCst: return 1u << 9;
    default: return 0;
  }
}

/// True for the cyclic synchronous modes (8, 9, 10).
[[nodiscard]] constexpr bool is_cyclic(Mode m) noexcept {
  return m == Mode::kCsp || m == Mode::kCsv || m == Mode::kCst;
}

/// True for the modes the master sends a set point in every cycle: the cyclic
/// synchronous ones and interpolated position (7, 0x60C1:1 over 0x60C2).
[[nodiscard]] constexpr bool is_streamed(Mode m) noexcept { return is_cyclic(m) || m == Mode::kInterpolatedPosition; }

/// True for the modes whose set point is a position: CSP (0x607A) and IP (0x60C1:1).
[[nodiscard]] constexpr bool is_position_stream(Mode m) noexcept {
  return m == Mode::kCsp || m == Mode::kInterpolatedPosition;
}

// ============================================================================
// Homing status (statusword bits 13, 12, 10; mask 0x3400) §3.3
// ============================================================================
enum class HomingStatus : std::uint8_t {
  kInProgress,             ///< 0 0 0
  kInterruptedOrNotStarted,///< 0 0 1
  kAttainedNotReached,     ///< 0 1 0
  kCompleted,              ///< 0 1 1
  kErrorMoving,            ///< 1 0 x with velocity != 0
  kErrorStopped,           ///< 1 0 1
  kInvalid,                ///< 1 1 x
};
[[nodiscard]] constexpr HomingStatus decode_homing_status(std::uint16_t statusword) noexcept {
  switch (statusword & 0x3400) {
    case 0x0000: return HomingStatus::kInProgress;
    case 0x0400: return HomingStatus::kInterruptedOrNotStarted;
    case 0x1000: return HomingStatus::kAttainedNotReached;
    case 0x1400: return HomingStatus::kCompleted;
    case 0x2000: return HomingStatus::kErrorMoving;
    case 0x2400: return HomingStatus::kErrorStopped;
    default: return HomingStatus::kInvalid;
  }
}

// ============================================================================
// Statusword bits 7, 11, 12, 13 by mode of operation (§1.2, §3)
// ============================================================================
/// What statusword bits 7 (warning), 11 (internal limit active), 12 and 13
/// (operation mode specific) say in the mode 0x6061 shows. Bits 12 and 13
/// mean different things per mode: in CSP, CSV and CST bit 12 is "drive
/// follows the command value" (0: the target is ignored), in IP "ip mode
/// active" (0: the 0x60C1 set points are ignored), both decoded as
/// follows_command; in CSP bit 13 is
/// "following error" (in CSV and CST it is reserved); in homing they are
/// homing attained / homing error (decode_homing_status()), in profile
/// position set-point acknowledge / following error. Only what the master
/// uses is decoded here; other modes give follows_command and
/// following_error false.
struct StatusBits {
  bool warning = false;          ///< bit 7, every mode
  bool internal_limit = false;   ///< bit 11, every mode
  bool follows_command = false;  ///< bit 12 in CSP, CSV, CST; IP: ip mode active
  bool following_error = false;  ///< bit 13 in CSP and PP
  friend constexpr bool operator==(const StatusBits&, const StatusBits&) = default;
};
[[nodiscard]] constexpr StatusBits decode_status_bits(std::uint16_t statusword, Mode mode) noexcept {
  StatusBits b;
  b.warning = (statusword & sw::kWarning) != 0;
  b.internal_limit = (statusword & sw::kInternalLimitActive) != 0;
  b.follows_command = is_streamed(mode) && (statusword & sw::kFollowsCommand) != 0;
  b.following_error = (mode == Mode::kCsp || mode == Mode::kProfilePosition) && (statusword & sw::kFollowingError) != 0;
  return b;
}

// ============================================================================
// Positions: the drive frame is 64-bit counts, the wire carries 32 bits
// ============================================================================
/// The low 32 bits of a 64-bit position, as 0x607A / 0x6064 carry it (two's
/// complement: it wraps modulo 2^32, never saturates). Realtime-safe.
[[nodiscard]] constexpr std::int32_t low32(std::int64_t counts) noexcept {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(static_cast<std::uint64_t>(counts)));
}
/// The 64-bit position whose low 32 bits are `wire` and that is nearest to
/// `previous` (the position unwrapped by the int32 difference: previous +
/// (int32)(wire - low32(previous))). Right as long as the position moves
/// less than 2^31 counts between two readings. Realtime-safe.
[[nodiscard]] constexpr std::int64_t unwrap32(std::int64_t previous, std::int32_t wire) noexcept {
  const auto diff = static_cast<std::int32_t>(static_cast<std::uint32_t>(wire) -
                                              static_cast<std::uint32_t>(static_cast<std::uint64_t>(previous)));
  return previous + diff;
}

// ============================================================================
// Interpolation time period (0x60C2): value x 10^index seconds
// ============================================================================
struct InterpolationPeriod {
  std::uint8_t value = 1;
  std::int8_t index = -3;
  friend constexpr bool operator==(const InterpolationPeriod&, const InterpolationPeriod&) = default;
};

/// Encode a period in nanoseconds with the coarsest unit that represents it
/// exactly with value <= 255 (1 ms -> {1, -3}, 250 us -> {250, -6}); nullopt
/// when impossible. Realtime-safe.
[[nodiscard]] constexpr std::optional<InterpolationPeriod> encode_interpolation_period(std::int64_t ns) noexcept {
  if (ns <= 0) return std::nullopt;
  std::int64_t unit = 1'000'000'000;
  for (std::int8_t idx = 0; idx >= -9; --idx, unit /= 10) {
    if (ns % unit == 0 && ns / unit <= 255) return InterpolationPeriod{static_cast<std::uint8_t>(ns / unit), idx};
  }
  return std::nullopt;
}

/// Decode 0x60C2 to nanoseconds; 0 when the index is outside -9..0. Realtime-safe.
[[nodiscard]] constexpr std::int64_t interpolation_period_ns(InterpolationPeriod p) noexcept {
  if (p.index > 0 || p.index < -9) return 0;
  std::int64_t unit = 1'000'000'000;
  for (int i = 0; i > p.index; --i) unit /= 10;
  return unit * p.value;
}

}  // namespace canmotion::cia402
