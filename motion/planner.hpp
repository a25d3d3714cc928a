#pragma once
/// \file motion/planner.hpp
/// The motion planner: fixed-capacity axes, control tags and generators, the
/// Logix instruction model, and the one-call-per-cycle API for the runtime:
///
///     Planner p(cycle_period);                 // non-RT: construct, configure
///     p.configure_axis(0, cfg);
///     ... every cycle (RT):
///     Input in{cycle_index, feedback, requests};
///     p.update(in, out);                       // noexcept, no allocation
///
/// See motion/README.md for the full contract.

#include <array>
#include <cstdint>
#include <span>
#include <type_traits>
#include <variant>

#include "motion/axis.hpp"
#include "motion/cam/cam_motion.hpp"
#include "motion/control_tag.hpp"
#include "motion/master_follow.hpp"
#include "motion/profile.hpp"
#include "motion/signatures.hpp"
#include "motion/types.hpp"

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
  bool homing_attained = false;  ///< statusword bit 12 in homing mode
  bool homing_error = false;     ///< statusword bit 13 in homing mode
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
};

/// Per-axis output for one cycle.
struct AxisOutput {
  double position = 0.0;      ///< command position, drive frame, user units (x conversion constant = counts)
  double velocity = 0.0;      ///< command velocity, user units/s (feed-forward / CSV target)
  double acceleration = 0.0;
  double torque = 0.0;        ///< CST target (MDS torque mode, issue 5)
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

// --------------------------------------------------------------- generators
/// What a profile generator is doing.
enum class GenRole : std::uint8_t { Move, Jog, Stop };

/// State of a profile-driven instruction (MAM, MAJ, and the ramps of MAS/MGS
/// and exception stops). O(1) step: one Profile::sample.
struct ProfileGen {
  GenRole role = GenRole::Move;
  Profile prof{};
  int hint = 0;
  std::uint64_t t0_cycle = 0;  ///< profile time = (cycle - t0_cycle) * period
  Kin k{};                     ///< last sample (offset of this generator)
  double total = 0.0;          ///< move: distance from the generator origin to the target
  double target_user = 0.0;    ///< move: programmed absolute target (user frame)
  bool exact_target = false;   ///< move: absolute linear target can be set exactly at the end
  MoveType move_type = MoveType::Absolute;
  Limits lim{};
  bool scurve = false;
  bool seconds = false;        ///< programmed in seconds (MCD not allowed: ERR 23)
  double speed = 0.0;          ///< programmed speed (0 = paused until MCD)
  double jog_velocity = 0.0;   ///< jog: signed programmed velocity
  OwnerRef owner{};
  std::uint8_t post_stop = 0;  ///< stop ramps of MGS: 0 none, 1 disable, 2 shutdown
  // master driven (MDSC): the profile's abscissa is master travel md.u, not
  // time; md as for a master-driven MATC (motion/master_follow.hpp)
  bool master_driven = false;
  MasterFollow md{};
};

/// One MDAC link of a slave (per motion type).
struct MdacLink {
  AxisId master = kNoAxis;
  bool use_actual = false;
  bool all = false;            ///< set by MDAC MotionType All
  OwnerRef owner{};            ///< the MDAC execution
  constexpr bool valid() const noexcept { return master != kNoAxis; }
};

/// State of an MAG (electronic gearing). The slave offset follows the master
/// position (drive frame) at the ratio; O(1) step. No axis limits apply.
struct GearGen {
  AxisId master = kNoAxis;
  bool use_actual = false;     ///< master reference actual (CIP masters only)
  bool fractional = false;     ///< RatioFormat fraction: exact integer counts
  double ratio = 1.0;          ///< signed real ratio, direction included
  std::int64_t slave_counts = 1, master_counts = 1;  ///< signed fraction, direction included
  double cc_master = 1.0, cc_slave = 1.0;            ///< conversion constants (counts/unit)
  bool locked = false;         ///< GearingLockStatus
  double clutch_accel = 0.0;   ///< units/s^2 while clutching
  double master_ref = 0.0;     ///< master position at lock (units, drive frame)
  std::int64_t master_ref_counts = 0;
  double offset_at_lock = 0.0;
  Kin k{};                     ///< offset of this generator, velocity, acceleration (gear ramps are trapezoidal)
  OwnerRef owner{};
};

/// State of a time-driven MATC: the cam engineer's CamMotion evaluated at cam
/// time. O(1) amortised step.
struct CamGen {
  cam::CamMotion cm{};
  cam::CamProfile* profile = nullptr;  ///< in use (acquired) while the cam runs
  std::uint64_t t0_cycle = 0;
  double x_offset = 0.0;       ///< cam time = (cycle - t0_cycle) * T - x_offset (pending takeovers)
  std::int64_t last_pass = 0;  ///< pass of the last step (a pending cam waits for its end)
  Kin k{};
  OwnerRef owner{};
  /// master-driven MATC (InstructionMode masterdrivenmode): cam coordinate =
  /// master travel in the lock direction (md.u - x_offset) instead of time
  bool master_driven = false;
  MasterFollow md{};
  double md_rate = 0.0;            ///< master travel per second in the lock direction, last step
  std::uint64_t md_cycle = ~0ull;  ///< cycle md was last advanced (a takeover steps twice per cycle)
};

/// A pending MATC waiting for the end of the current pass (or for an immediate cam).
struct PendingCam {
  cam::CamProfile* profile = nullptr;
  cam::CamMotionConfig cfg{};
  OwnerRef owner{};
  constexpr bool valid() const noexcept { return profile != nullptr; }
};

/// State of an MAPC (position cam, motion/planner_mapc.cpp): the cam engineer's
/// CamMotion evaluated at the master coordinate = master travel since the
/// lock (filtered by MasterDirection) + the master offset (finished master
/// offset moves + the running one in Slot::MasterOffset). O(1) amortised step.
struct PosCamGen {
  cam::CamMotion cm{};
  cam::CamProfile* profile = nullptr;  ///< in use (acquired) while the cam runs
  AxisId master = kNoAxis;
  bool use_actual = false;      ///< MasterReference actual (CIP masters only)
  std::uint8_t schedule = 0;    ///< ExecutionSchedule: 0 immediate, 2 forward only, 3 reverse only, 4 bidirectional
  std::uint8_t master_dir = 0;  ///< MasterDirection: 0 bidirectional, 1 forward only, 2 reverse only
  double master_lock = 0.0;     ///< MasterLockPosition (master user frame)
  bool locked = false;          ///< the master crossed MasterLockPosition (immediate: at once)
  bool inside = true;           ///< the cam coordinate is inside the profile (Persistent relocks)
  bool slipping = false;        ///< the master moved against MasterDirection this cycle
  double prev_mp = 0.0;         ///< master position (drive frame) last cycle
  double lock_mp = 0.0;         ///< master position (drive frame) at the lock
  double travel = 0.0;          ///< master travel since the lock as the cam follows it
  double offset_base = 0.0;     ///< sum of the finished master offset moves (master units)
  double x_shift = 0.0;         ///< cam coordinate of the takeover (pending cams)
  std::int64_t last_pass = 0;
  Kin k{};
  OwnerRef owner{};
};

/// A pending MAPC waiting for the end of the current pass (or for a non-pending cam).
struct PendingPosCam {
  cam::CamProfile* profile = nullptr;
  cam::CamMotionConfig cfg{};
  AxisId master = kNoAxis;
  bool use_actual = false;
  std::uint8_t master_dir = 0;
  OwnerRef owner{};
  constexpr bool valid() const noexcept { return profile != nullptr; }
};

/// Capacity of the CAM_PROFILE registry (config: one entry per CAM_PROFILE array tag).
inline constexpr std::size_t kMaxCamProfiles = 64;
/// Capacity of the CAM array registry (config `arrays:` entries of type CAM,
/// the operands of MCCP). Bound: like CAM_PROFILE arrays, one per cam table.
inline constexpr std::size_t kMaxCamArrays = 64;
/// Capacity of the REAL array registry (config `arrays:` entries of type
/// REAL: MAM EventDistance / CalculatedData). Bound: one pair per axis that
/// reports events.
inline constexpr std::size_t kMaxRealArrays = 64;

/// Per-axis generator slots. Generators superpose: the command position is
/// base + the sum of the slot offsets. Bound: one slot per kind of motion
/// Logix can run at the same time on one axis (move, jog, gear, time cam,
/// position cam, master offset move) plus one for a stop of all motion.
enum class Slot : std::uint8_t { Move = 0, Jog, Gear, TimeCam, PositionCam, MasterOffset, StopAll, Count };
inline constexpr std::size_t kSlots = static_cast<std::size_t>(Slot::Count);

/// The closed set of generator states. Issue 5 adds cam and direct states here.
using Generator = std::variant<std::monostate, ProfileGen, GearGen, CamGen, PosCamGen>;

/// The master-driven following state of a generator (master-driven
/// move/jog/master offset move or time cam), or null. Realtime-safe.
inline const MasterFollow* follow_of(const Generator& s) noexcept {
  if (auto* p = std::get_if<ProfileGen>(&s); p && p->master_driven) return &p->md;
  if (auto* cg = std::get_if<CamGen>(&s); cg && cg->master_driven) return &cg->md;
  return nullptr;
}

/// The master a generator follows (gear, master-driven move/jog/time cam,
/// position cam), or kNoAxis. Realtime-safe.
inline AxisId master_of(const Generator& s) noexcept {
  if (auto* g = std::get_if<GearGen>(&s)) return g->master;
  if (auto* pc = std::get_if<PosCamGen>(&s)) return pc->master;
  if (const MasterFollow* f = follow_of(s)) return f->master;
  return kNoAxis;
}

/// Servo loop and fault state of an axis (MSO, MSF, MASD, MASR, MAFR, MGSD,
/// MGSR, exceptions).
struct ServoState {
  bool on = false;            ///< servo loop active (ServoActionStatus)
  bool enable_req = false;    ///< drive enable requested
  bool shutdown = false;      ///< Logix Shutdown state
  bool faulted = false;       ///< StopDrive/Shutdown fault latched: ERR 20 until MAFR/MASR
  bool fault_reset_pulse = false;  ///< send a CiA 402 fault reset this cycle
  /// MAFR/MASR/MGSR on a CIP drive: DN when the drive has left Fault and is
  /// connected, ER on a transition timeout or kDriveTimeout. While it waits,
  /// the drive fault and lost node conditions are not latched again.
  OwnerRef reset{};
  std::uint64_t reset_deadline = 0;
};

/// Instructions waiting for the drive (AXIS_CIP_DRIVE): the MSO/MSF enable
/// handshakes and MAH drive homing (CiA 402 mode 6).
struct Handshakes {
  OwnerRef mso{}, msf{};       ///< MSO waiting for Operation Enabled, MSF for its end
  std::uint64_t deadline = 0;  ///< cycle at which MSO/MSF/MDS stop waiting (ERR 12)
  OwnerRef mah{};              ///< MAH homing on the drive
  bool homing = false;         ///< drive homing (mode 6) in progress
  bool homing_started = false; ///< the homing request was sent
  bool homed = false;          ///< AxisHomedStatus
};

/// MDS direct velocity/torque control of an axis.
struct DirectControl {
  bool status = false;   ///< AxisStatus.DirectControlStatus (cleared only by MSO, shutdown, servo off)
  bool active = false;   ///< DirectVelocity/TorqueControlStatus: the direct command is applied
  double cmd = 0.0;      ///< velocity (units/s) or torque command
  double vel_cmd = 0.0;  ///< torque mode: velocity command for SLAT (units/s)
  OwnerRef mds{};        ///< the MDS in control
  bool waiting = false;  ///< MDS waits for the drive enable (STATE 1)
  OwnerRef stop{};       ///< MAS stopping direct motion (PC at standstill)
};

/// Cams waiting to take over (pending MATC / MAPC) and the last cam directions.
struct PendingCams {
  PendingCam time{};          ///< TimeCamPendingStatus
  int time_dir = 0;           ///< last time-cam direction (+1/-1, 0 never cammed)
  PendingPosCam position{};   ///< PositionCamPendingStatus (MAPC)
  int position_dir = 0;       ///< last position-cam direction (+1/-1, 0 never cammed)
};

/// MDAC links of a slave per motion type (0 move, 1 jog, 2 time cam, 3
/// master offset move) and the queued masters.
struct MdacLinks {
  std::array<MdacLink, 4> active{}, pending{};
};

// typed instruction parameters (motion/instructions.hpp)
struct MasParams;
struct MajParams;
struct MamParams;
struct McdParams;
struct MrpParams;
struct MagParams;
struct MdacParams;
struct MdsParams;
struct MatcParams;
struct MapcParams;
struct MccpParams;

// ------------------------------------------------------------------ planner
/// The planner. All state is inside (fixed arrays); update() is noexcept,
/// allocation-free and realtime-safe. Configuration calls are not RT.
class Planner {
 public:
  /// cycle_period in seconds (> 0), e.g. 0.001.
  explicit Planner(double cycle_period) noexcept;

  /// Configure (or reconfigure) an axis. Not realtime (call before the
  /// cyclic loop). Returns false if the id is out of range or the config is
  /// invalid (non-positive conversion constant, unwind, negative limits).
  bool configure_axis(AxisId id, const AxisConfig& cfg) noexcept;
  /// Number of configured axes (ids 0..axis_count()-1).
  std::size_t axis_count() const noexcept { return axis_count_; }

  /// Run one cycle: feedback, exceptions, requests (in order), generators,
  /// outputs. Realtime-safe.
  Result update(const Input& in, Output& out) noexcept;

  /// Execute one request right now (as part of the current cycle). update()
  /// calls this for every input request; exposed for tests. Returns the ERR
  /// (Err::None on success), also written to the control tag. Realtime-safe.
  Err execute(const Request& r) noexcept;

  /// MDS live command: write the direct velocity (units/s) or torque command
  /// of an axis in direct control, as a program writing the command tag.
  /// Returns false if the axis is not under an active MDS. Realtime-safe.
  bool set_direct_command(AxisId id, double value) noexcept;
  /// MDS torque mode: write the DirectVelocityControl Command (units/s) sent
  /// with the torque command (the drive's SLAT speed reference). False if the
  /// axis is not under an active MDS in torque mode. Realtime-safe.
  bool set_direct_velocity_command(AxisId id, double value) noexcept;

  /// Register the CAM_PROFILE array tag `id` (the binder's cam_profiles id).
  /// The profile must outlive the planner. Not realtime (configuration).
  bool attach_cam_profile(std::uint16_t id, cam::CamProfile* profile) noexcept;
  /// Register the CAM array tag `id` (the binder's cams id): MCCP reads its
  /// points. The storage must outlive the planner and is written only by the
  /// thread running update() (motion/planner_mccp.cpp). Not realtime.
  bool attach_cam_array(std::uint16_t id, std::span<cam::CamPoint> points) noexcept;
  /// Register the REAL array tag `id` (the binder's real_arrays id): MAM
  /// reads EventDistance from it and writes CalculatedData into it. Same
  /// ownership rules as attach_cam_array. Not realtime.
  bool attach_real_array(std::uint16_t id, std::span<double> values) noexcept;

  /// Axis tag (status) of an axis. Realtime-safe.
  const AxisTag& axis(AxisId id) const noexcept { return axes_[id].tag; }
  const AxisConfig& config(AxisId id) const noexcept { return axes_[id].cfg; }
  /// Control tag. Realtime-safe.
  const ControlTag& control(ControlId id) const noexcept { return controls_[id]; }
  /// Clear a control tag (prescan). Realtime-safe.
  void reset_control(ControlId id) noexcept { controls_[id] = ControlTag{}; }
  double period() const noexcept { return T_; }
  std::uint64_t cycle() const noexcept { return cycle_; }

  /// Test hook: true when the state kept incrementally for speed agrees with
  /// what it summarises: every axis's live-slot mask (AxisRt::live) with its
  /// slots, and the cached step order with one computed afresh. Not realtime
  /// critical but allocation-free.
  bool check_incremental_state() noexcept;

 private:
  struct AxisRt {
    AxisConfig cfg{};
    AxisTag tag{};
    bool present = false;
    double base = 0.0;          ///< drive-frame position with all finished motion folded in
    double frame_offset = 0.0;  ///< user = drive + frame_offset (MRP, homing)
    Kin cmd{};                  ///< total command (drive frame)
    double fb_pos = 0.0, fb_vel = 0.0;
    AxisFeedback fb{};
    std::array<Generator, kSlots> gen{};
    /// Bit per Slot: the slot holds a generator (not std::monostate). Kept by
    /// set_slot() and fold(), the only writers of `gen`, so that the cycle
    /// reads no empty slot; check_incremental_state() verifies it.
    std::uint8_t live = 0;
    double last_speed = 0.0;    ///< last non-zero programmed speed (zero-speed S-curve rule)
    int gear_dir = 0;           ///< last gearing direction (+1 same, -1 opposite, 0 never geared)
    ServoState servo{};
    Handshakes hs{};
    DirectControl direct{};
    PendingCams cams{};
    MdacLinks links{};
  };
  struct GroupOp {  ///< MGS in progress
    OwnerRef owner{};
    std::uint8_t group = 0;
    bool active = false;
  };

  // instruction start functions (validate + plan; an error changes nothing)
  Err start_mso(const Request&, AxisRt&) noexcept;
  Err start_msf(const Request&, AxisRt&) noexcept;
  Err start_masd(const Request&, AxisRt&) noexcept;
  Err start_masr(const Request&, AxisRt&) noexcept;
  Err start_mafr(const Request&, AxisRt&) noexcept;
  Err start_mas(const Request&, const MasParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_mah(const Request&, AxisRt&) noexcept;
  Err start_maj(const Request&, const MajParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_mam(const Request&, const MamParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_mcd(const Request&, const McdParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_mrp(const Request&, const MrpParams&, AxisRt&) noexcept;
  Err start_mag(const Request&, const MagParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_mdac(const Request&, const MdacParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_mds(const Request&, const MdsParams&, AxisRt&, std::int8_t& exerr) noexcept;
  Err start_matc(const Request&, const MatcParams&, AxisRt&, std::int8_t& exerr) noexcept;
  // motion/planner_mccp.cpp: MCCP, MAM EventDistance / CalculatedData
  Err start_mccp(const Request&, const MccpParams&, std::int8_t& exerr) noexcept;
  Err check_event_distance(const Request&, std::int8_t& exerr) const noexcept;
  void write_calculated_data(const Request&, const ProfileGen& g, ControlTag& c) noexcept;
  void step_cam(AxisRt& a, CamGen& g) noexcept;
  // MAPC and master offset moves (motion/planner_mapc.cpp)
  Err start_mapc(const Request&, const MapcParams&, AxisRt&, std::int8_t& exerr) noexcept;
  void step_position_cam(AxisRt& a, PosCamGen& g) noexcept;
  void drop_pending_pcam(AxisRt& a) noexcept;
  void end_position_cam(AxisRt& a, PosCamGen& g) noexcept;  ///< fold hook: release, AC, end the offset move
  void add_master_offset(AxisRt& a, double d) noexcept;     ///< fold hook of Slot::MasterOffset
  double master_offset(const AxisRt& a) const noexcept;     ///< total master offset the cam sees
  const AxisConfig* position_cam_master(const AxisRt& a) const noexcept;  ///< null: no position cam (ERR 33)
  void position_cam_status(const AxisRt& a, std::uint32_t& ms) const noexcept;
  // master-driven MATC (motion/planner_md.cpp)
  Err matc_mode_checks(const AxisRt& a, const MatcParams& p) const noexcept;
  Err matc_md_setup(const AxisRt& a, const MatcParams& p, CamGen& g) const noexcept;
  double cam_coordinate(CamGen& g) noexcept;
  void cam_output(CamGen& g, const cam::CamMotionOutput& o) noexcept;
  void drop_pending_cam(AxisRt& a) noexcept;
  void end_direct(AxisRt& a, bool keep_direct_status) noexcept;
  void break_links(AxisRt& slave) noexcept;
  void break_links_of_master(AxisId master) noexcept;
  void promote_pending(AxisRt& a, int type_index) noexcept;
  Err master_driven_setup(AxisRt& a, int type_index, ProfileGen& g, Kin& start_u, bool& ok) noexcept;
  Err start_group(const Request&, std::uint16_t group, GroupStopMode mode, std::int8_t& exerr) noexcept;

  // helpers
  Err common_checks(const AxisRt& a, bool need_servo) const noexcept;
  void step_axis(AxisRt& a, AxisOutput* out) noexcept;
  void step_gear(GearGen& g) noexcept;
  void compute_order() noexcept;
  /// The fault reset of MAFR/MASR/MGSR on axis `a` (control tag of request r):
  /// pulse the drive's fault reset; DN now unless a CIP drive still has to
  /// leave Fault or reconnect (then AxisRt::reset waits). Returns whether it is done.
  bool begin_fault_reset(const Request& r, AxisRt& a) noexcept;
  void end_fault_reset(AxisRt& a, bool ok) noexcept;
  void handle_feedback(AxisId id, AxisRt& a, const AxisFeedback* fb) noexcept;
  void handle_exceptions(AxisRt& a) noexcept;
  void fold(AxisRt& a, Slot s, bool clear_owner_ip) noexcept;
  /// Put generator g into slot s: every write of a slot goes through here or
  /// fold(), keeping AxisRt::live and the step order (order_dirty_) current.
  template <class G>
  G& set_slot(AxisRt& a, Slot s, const G& g) noexcept {
    const auto i = static_cast<std::size_t>(s);
    a.gen[i] = g;
    a.live = static_cast<std::uint8_t>(a.live | (1u << i));
    order_dirty_ = true;
    return *std::get_if<G>(&a.gen[i]);
  }
  void abort_all(AxisRt& a) noexcept;  ///< cancel every generator at once (no ramp)
  bool stop_slots(AxisRt& a, std::uint32_t slot_mask, double d, double jd, ControlId owner,
                  std::uint8_t post_stop) noexcept;
  void servo_off(AxisRt& a) noexcept;
  void do_shutdown(AxisRt& a) noexcept;
  void update_status(AxisRt& a) noexcept;
  Kin slot_kin(const AxisRt& a, Slot s) const noexcept;
  double user_command(const AxisRt& a) const noexcept;
  /// The control tag `o` names, or null when a newer execution reused it.
  ControlTag* tag(OwnerRef o) noexcept;
  bool any_stopping(const AxisRt& a) const noexcept;
  bool any_scurve(const AxisRt& a) const noexcept;

  double T_;
  std::uint64_t cycle_ = 0;
  bool started_ = false;
  std::size_t axis_count_ = 0;
  std::array<AxisRt, kMaxAxes> axes_{};
  std::array<ControlTag, kMaxControlTags> controls_{};
  std::array<GroupOp, kMaxGroups> groups_{};
  std::array<cam::CamProfile*, kMaxCamProfiles> cam_profiles_{};
  std::array<std::span<cam::CamPoint>, kMaxCamArrays> cam_arrays_{};
  std::array<std::span<double>, kMaxRealArrays> real_arrays_{};
  std::array<AxisId, kMaxAxes> order_{};  ///< step order: masters before slaves
  std::size_t order_n_ = 0;
  bool order_dirty_ = true;  ///< a slot or an axis changed since order_ was computed
};

}  // namespace canmotion::motion
