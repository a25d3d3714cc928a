#pragma once
/// \file motion/io.hpp
/// What crosses the planner's boundary: instruction requests (one ST
/// execution each) and the per-cycle inputs and outputs of Planner::update().
/// Plain data; realtime-safe to copy.

#include <array>
#include <cstdint>
#include <span>
#include <type_traits>

#include "motion/control_tag.hpp"
#include "motion/signatures.hpp"

namespace canmotion::motion {

// ----------------------------------------------------------------- requests
/// One operand value of a request: a number (immediates and numeric tags,
/// enumerations as their number) or a reference (axis, group, cam, ...) id.
struct Operand {
  double value = 0.0;
  std::uint16_t ref = 0xFFFF;  ///< id for Axis/Group/Cam/... operands
};

/// One instruction execution (= one false-to-true rung transition), with its
/// operands in ST order. Produced by bind_call() (motion/st_parser.hpp) or
/// built directly. Trivially copyable: fits an SPSC ring.
struct Request {
  Instr instr = Instr::MSO;
  ControlId control = kNoControl;
  std::uint8_t count = 0;  ///< number of operands given
  std::array<Operand, kMaxOperands> op{};
};
static_assert(std::is_trivially_copyable_v<Request>, "Request travels through SPSC rings by copy");

// ------------------------------------------------------------ cycle I/O
/// Drive state as the runtime reports it for an AXIS_CIP_DRIVE (from the CiA
/// 402 statusword).
enum class DriveState : std::uint8_t {
  NotReady = 0,  ///< not ready / switch on disabled / ready to switch on
  SwitchedOn = 1,
  Enabled = 2,   ///< operation enabled
  Fault = 3,     ///< fault or fault reaction active
};

/// The drive's connection as the runtime reports it for an AXIS_CIP_DRIVE
/// (Logix: the module connection and the axis configuration sent to the drive;
/// CANopen: boot-up, the SDO configuration, NMT start, cyclic data flowing).
enum class DriveLink : std::uint8_t {
  Up = 0,            ///< configured and exchanging cyclic data
  Configuring = 1,   ///< booting or being configured (at start, or again after a drive reset)
  ConfigFailed = 2,  ///< the drive refused its configuration: AxisFault.ConfigFault; MSO, MAH, MDS get ERR 11
  NoModule = 3,      ///< the drive never answered (no boot-up, no cyclic data): AxisFault.ModuleFault; ERR 11
};

/// The drive refused its configuration or never answered: its axis is not
/// configured (ERR 11) and shows a ConfigFault or ModuleFault.
constexpr bool link_failed(DriveLink l) noexcept { return l == DriveLink::ConfigFailed || l == DriveLink::NoModule; }

/// CiA 402 mode the drive should run (0x6060).
enum class DriveMode : std::int8_t { Homing = 6, CyclicPosition = 8, CyclicVelocity = 9, CyclicTorque = 10 };

/// Per-axis feedback for one cycle (CIP axes; ignored for virtual axes).
struct AxisFeedback {
  double position = 0.0;   ///< actual position in user units = counts / conversion constant (drive frame)
  double velocity = 0.0;   ///< user units/s
  DriveState drive = DriveState::NotReady;
  bool drive_fault = false;   ///< fault bit or EMCY error seen this cycle
  std::uint16_t emcy_code = 0;
  bool node_lost = false;     ///< heartbeat / cyclic data lost
  bool bus_off = false;       ///< the CAN interface is bus-off
  bool limit_positive = false;  ///< positive limit switch active (0x60FD bit 1, CiA 402 digital inputs)
  bool limit_negative = false;  ///< negative limit switch active (0x60FD bit 0)
  bool homing_attained = false;  ///< statusword bit 12 in homing mode
  bool homing_error = false;     ///< statusword bit 13 in homing mode, a homing timeout or a refused homing parameter
  /// EXERR of the MAH's ERR 12 when homing_error: 16 (device in wrong state:
  /// the drive's homing error or the runtime's homing timeout), 3 (invalid
  /// value: the drive refused a homing parameter).
  std::int8_t homing_exerr = 16;
  DriveLink link = DriveLink::Up;
  /// The drive did not make a requested state transition within the
  /// runtime's transition timeout (enabling, fault reset): a pending MSO,
  /// MDS or MAFR/MASR/MGSR ends with ERR 12 at once.
  bool transition_timeout = false;
};

/// Homing parameters to write before starting drive homing (mode 6).
struct HomingRequest {
  std::int8_t method = 0;     ///< 0x6098
  double speed_search = 0.0;  ///< 0x6099:01, user units/s
  double speed_zero = 0.0;    ///< 0x6099:02, user units/s
  double accel = 0.0;         ///< 0x609A, user units/s^2
  bool write_offset = false;  ///< write 0x607C (home offset)
  double offset = 0.0;        ///< 0x607C, user units
};

/// Per-axis output for one cycle.
struct AxisOutput {
  double position = 0.0;      ///< command position, drive frame, user units (x conversion constant = counts)
  double velocity = 0.0;      ///< command velocity, user units/s (feed-forward / CSV target)
  double acceleration = 0.0;
  double torque = 0.0;        ///< CST target (MDS torque mode)
  DriveMode mode = DriveMode::CyclicPosition;
  bool enable = false;        ///< the drive should be in Operation Enabled
  bool fault_reset = false;   ///< pulse a CiA 402 fault reset this cycle
  bool homing_start = false;  ///< mode 6: set controlword bit 4 (homing operation start)
  HomingRequest homing{};     ///< valid while mode == Homing
  bool shutdown = false;      ///< the axis is in the Logix Shutdown state
};

/// Inputs of one cycle. Spans are owned by the caller (fixed arrays).
struct Input {
  std::uint64_t cycle = 0;                   ///< cycle index; time = cycle * period
  std::span<const AxisFeedback> feedback{};  ///< indexed by AxisId (may be shorter: missing = no feedback)
  std::span<const Request> requests{};       ///< executions in program order
};

/// Outputs of one cycle.
struct Output {
  std::span<AxisOutput> axes{};  ///< indexed by AxisId; entries past the span are not written
};

/// Result of update(): >= 0 ok, < 0 caller error (ruckig style).
enum class Result : std::int8_t {
  Ok = 0,
  ErrorCycleNotIncreasing = -1,  ///< input.cycle <= previous cycle
};

}  // namespace canmotion::motion
