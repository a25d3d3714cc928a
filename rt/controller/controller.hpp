#pragma once
/// \file
/// The Controller: one cycle of canmotion, joining the motion planner and the
/// CANopen drive networks (DESIGN.md, "One cycle"):
///
///   1. sync_all()       ControllerSpec::sync_first only: the SYNC on every
///                       bus, first thing after the wake-up
///   2. receive_all()    drain received frames on every bus (TPDOs, EMCY,
///                       heartbeats, SDO); heartbeat timeouts and node events
///                       reach the drive proxies (DriveNetwork::update), so
///                       the planner sees them this cycle
///   3. feedback()       convert drive feedback from counts to position units
///   4. take_commands()  take pending commands from the command ring
///   5. plan()           Planner::update (masters before slaves, inside the planner)
///   6. apply()          step each drive's CiA 402 state machine, pack its RPDOs
///   7. send_all()       send the RPDOs, then SYNC, in one burst (sync_first:
///                       the RPDOs only; the drives apply them at the next SYNC)
///      advance_halt()   (a controlled stop: NMT pre-operational after that SYNC)
///   8. publish()        publish a status snapshot; queue trace and telemetry records
///
/// cycle() is realtime-safe: no allocation, no locks, no logging, no
/// exceptions. Everything it shares with other threads goes through SPSC
/// rings (commands in; events, trace and telemetry out) and a snapshot
/// buffer (status out); the RT thread never waits on them. Construction and
/// the name-lookup functions are not realtime.

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "fieldbus/can/transport.hpp"
#include "motion/cam/cam_profile.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "motion/planner.hpp"
#include "rt/snapshot.hpp"
#include "rt/spsc_ring.hpp"
#include "rt/sync_timing.hpp"

namespace canmotion::rt {

/// Buses one controller drives. Bound: CAN interfaces on a controller board
/// (typically 1-4); 8 leaves room.
inline constexpr std::size_t kMaxBuses = 8;
/// Instruction requests taken per cycle; more wait for the next cycle. Bound:
/// a script or client issues a handful per cycle; 64 covers a burst of one
/// per axis on a full 64-axis controller.
inline constexpr std::size_t kMaxRequestsPerCycle = 64;
/// Frames read per bus per receive() call. Bound: per cycle a bus carries at
/// most ~2 TPDOs per node plus heartbeats, EMCY and SDO: 256 covers a full
/// 127-node bus at one TPDO each; more are read by further calls.
inline constexpr std::size_t kRxBatch = 256;

/// One bus: a transport (owned by the caller, who opened it) and its CANopen
/// master settings.
struct BusSpec {
  std::string name;
  can::Transport* transport = nullptr;
  cia402::NetworkConfig network{};
};

/// One axis. `bus` indexes ControllerSpec::buses for AXIS_CIP_DRIVE, -1 for
/// AXIS_VIRTUAL.
struct AxisSpec {
  std::string name;
  motion::AxisConfig config{};
  int bus = -1;
  cia402::DriveConfig drive{};
  // Drive units (README "Drive units"): drive.units, as the proxy knows them
  // (DriveProxy::velocity_counts(), read at boot when the configuration
  // cannot tell). Torque needs no factor: 0x6071/0x60B2/0x6077 are per mille
  // of 0x6076 rated torque.
};

/// A cam profile declared in the configuration: computed (MCCP) when the
/// Controller is built, and named in instructions as `name` or `name[0]`.
struct CamSpec {
  std::string name;
  std::vector<motion::cam::CamPoint> points;
  double start_slope = 0.0;
  double end_slope = 0.0;
};

/// All REAL array elements together: they are copied into every status
/// snapshot. Bound: EventDistance / CalculatedData arrays hold a few events
/// per move; 1024 covers 64 arrays of 16. The one definition: the config loader checks `arrays:` against it.
inline constexpr std::size_t kMaxRealElements = 1024;

/// An array tag declared in the configuration (`arrays:`): a CAM array (MCCP
/// input, written by programs), a CAM_PROFILE array (MCCP output) or a REAL
/// array (MAM EventDistance / CalculatedData). Storage is allocated when the
/// Controller is built; nothing is resized afterwards.
struct ArraySpec {
  enum class Type : std::uint8_t { kCam, kCamProfile, kReal };
  std::string name;
  Type type = Type::kReal;
  std::size_t size = 0;
  std::vector<motion::cam::CamPoint> cam_values;  ///< CAM: initial points (rest zero, linear)
  std::vector<double> real_values;                ///< REAL: initial values (rest zero)
};

/// A resolved array tag (Controller::find_array). `id` is the planner id of
/// its kind: CAM array id, CAM_PROFILE id (after the `cams:` profiles), REAL
/// array id. `offset` is a REAL array's first element in Status::real_values.
struct ArrayRef {
  ArraySpec::Type type = ArraySpec::Type::kReal;
  std::uint16_t id = 0;
  std::uint32_t size = 0;
  std::uint32_t offset = 0;
};

/// A COORDINATE_SYSTEM of the configuration (`coordinate_systems:`): its
/// planner id is its position in ControllerSpec::coordinate_systems.
struct CoordSystemSpec {
  std::string name;
  motion::CoordSystemConfig config{};  ///< member axis ids resolved
};

/// Everything a Controller is built from (config::build_spec makes it from a file).
struct ControllerSpec {
  std::int64_t period_ns = 1'000'000;
  /// The SYNC goes out first in each cycle, at wake-up, on every bus
  /// (cia402::NetworkConfig::sync_first, set on every bus from this), and
  /// the planner compares the actual positions with the command one cycle
  /// older (motion::Planner::set_command_lag(1)): config key
  /// `controller.sync_first`. False: RPDOs, then the SYNC, at the end of the cycle.
  bool sync_first = false;
  std::vector<BusSpec> buses;
  std::vector<AxisSpec> axes;
  std::vector<CamSpec> cams;
  std::vector<ArraySpec> arrays;
  std::vector<CoordSystemSpec> coordinate_systems;
};

/// The commands a non-RT thread gives the RT thread (Controller::submit),
/// one small trivially copyable struct each.
namespace cmd {
/// Execute `request` (one rung transition).
struct Instruction {
  motion::Request request{};
};
/// Clear control tag `control` (prescan).
struct ResetControl {
  motion::ControlId control = motion::kNoControl;
};
/// Ask every drive to enable (outside the planner; tests, bring-up).
struct EnableDrives {};
/// Controlled stop of the buses: disarm the drives' watch of the master's
/// heartbeat (0x1016:01 = 0), NMT pre-operational after the last SYNC, then
/// no more cyclic traffic (Status::halted).
struct PreOperational {};
/// MDS live command: write `value` (units/s or torque units) to axis
/// `axis`'s DirectCommandVelocity (`torque` false) or DirectCommandTorque
/// (true); no effect without an active MDS.
struct DirectCommand {
  std::uint16_t axis = 0;
  bool torque = false;
  double value = 0.0;
};
/// A program writes one array element (Controller::write_array): element
/// `element` of array `array` (ArrayRef::id of `type`; for REAL the flat
/// element index offset + i), CAM `member` 0 Master, 1 Slave, 2 SegmentType.
/// Applied in program order: never in the same cycle after an instruction.
struct WriteArray {
  ArraySpec::Type type = ArraySpec::Type::kReal;
  std::uint8_t member = 0;
  std::uint16_t array = 0;
  std::uint32_t element = 0;
  double value = 0.0;
};
/// Logix Run / Program mode (Planner::set_controller_mode, issue 16).
struct ControllerMode {
  motion::ControllerMode mode = motion::ControllerMode::Run;
};
}  // namespace cmd

/// A command to the RT thread: one of the structs of `cmd`.
using Command = std::variant<cmd::Instruction, cmd::ResetControl, cmd::EnableDrives, cmd::PreOperational,
                             cmd::DirectCommand, cmd::WriteArray, cmd::ControllerMode>;
static_assert(std::is_trivially_copyable_v<Command>, "a Command travels through an SPSC ring by copy");

/// Something the RT thread reports. Trivially copyable.
struct Event {
  enum class Kind : std::uint8_t {
    kNode,         ///< a CANopen node event (boot-up, heartbeat lost/recovered, EMCY, NMT state)
    kDriveFailed,  ///< a drive proxy recorded a failure, or it gained detail (see Status axes[].failure)
    kBusState,     ///< a bus changed error state
    kRingOverflow, ///< the trace or telemetry ring was full; `value` records were lost
    kBusError,     ///< CAN error frames of other classes (no ACK, protocol, transceiver, ...):
                   ///< `value` = the class bits (SocketCAN CAN_ERR_*); at most once a second per
                   ///< bus unless the classes change
    kBusRecovered, ///< the bus left bus-off: every node of the bus is re-booted (NMT reset node, configuration)
    kLinkDown,     ///< the bus's interface is down (`ip link set can0 down`): `value` = the errno (ENETDOWN);
                   ///< its axes see it as bus-off (exception bus_off) until it is up
    kLinkUp,       ///< the interface is up again: every node of the bus is re-booted, as after bus-off
    kAxisFault,    ///< an axis latched an exception as a fault (its rising edge in AxisTag::exception_faults):
                   ///< `value` = the motion::ExceptionKind, `detail` = the position error (PositionError) or
                   ///< the command position (soft overtravel) in the axis's units; see describe_axis_fault()
    kDriveWait,    ///< an instruction that waited on an axis's drive (MSO, MSF, MDS, MAFR, MASR, MGSR) ended
                   ///< with an error: `wait` says which and why, `drive` and `failure` what the drive
                   ///< was doing then; see describe_drive_wait()
    kDriveStatusBit,  ///< a CIP axis's statusword bit rose: `value` = 7 (warning), 11 (internal limit
                      ///< active) or 13 (following error, CSP); `drive` and `mode_display` as then
                      ///< (cia402::decode_status_bits()); see describe_drive_status_bit()
  };
  Kind kind = Kind::kNode;
  std::uint8_t bus = 0;
  std::int16_t axis = -1;
  canopen::NodeEvent node{};
  cia402::Failure failure{};
  can::BusState bus_state = can::BusState::kErrorActive;
  std::uint64_t value = 0;
  double detail = 0.0;
  std::uint64_t cycle = 0;
  motion::DriveWaitEnd wait{};  ///< kDriveWait
  /// kDriveWait on a CIP axis: the drive proxy's phase, CiA 402 state and
  /// statusword in that cycle.
  struct DriveView {
    cia402::Phase phase = cia402::Phase::kWaitBoot;
    cia402::State state = cia402::State::kUnknown;
    std::uint16_t statusword = 0;
    std::uint8_t node = 0;
  } drive{};
  std::int8_t mode_display = 0;  ///< kDriveStatusBit: 0x6061 when the bit rose
};

/// One frame on one bus, for the candump trace.
struct TraceRecord {
  can::TimedFrame frame{};
  std::uint8_t bus = 0;
  bool tx = false;
};

/// One axis in one cycle, for the CSV telemetry.
struct Sample {
  std::uint64_t cycle = 0;
  std::uint16_t axis = 0;
  double cmd_pos = 0, act_pos = 0, cmd_vel = 0, act_vel = 0;
  std::uint32_t motion_status = 0, axis_status = 0;
};

/// Per-axis status published each cycle.
struct AxisSnapshot {
  motion::AxisTag tag{};
  // CIP drive axes only:
  cia402::Phase phase = cia402::Phase::kWaitBoot;
  cia402::State drive_state = cia402::State::kUnknown;
  std::uint16_t statusword = 0;
  std::uint16_t controlword = 0;
  std::int64_t target_counts = 0;  ///< 64-bit drive frame (0x607A carries the low 32 bits)
  std::int64_t actual_counts = 0;  ///< 0x6064 unwrapped (cia402::Feedback::position)
  std::int8_t mode_display = 0;
  std::uint16_t last_emcy = 0;
  std::uint64_t tpdo_missed = 0;
  cia402::Failure failure{};
  double max_abs_position_error = 0;  ///< since start, user units
};

/// Per-bus status.
struct BusSnapshot {
  can::BusState state = can::BusState::kErrorActive;
  can::BusCounters counters{};
  std::uint64_t send_rejected = 0;  ///< frames the transport refused (all kinds)
  std::uint64_t syncs_sent = 0;     ///< SYNCs the transport took
  std::uint64_t syncs_refused = 0;  ///< SYNCs it refused: cycles the drives missed
};

/// The status snapshot (step 8). Plain data, copied by readers.
struct Status {
  std::uint64_t cycle = 0;
  std::int64_t time_ns = 0;        ///< cycle * period
  std::uint64_t done_seq = 0;      ///< every command with seq <= done_seq has been executed
  std::uint16_t axis_count = 0;
  std::uint8_t bus_count = 0;
  std::array<AxisSnapshot, motion::kMaxAxes> axes{};
  std::array<BusSnapshot, kMaxBuses> buses{};
  std::array<motion::ControlTag, motion::kMaxControlTags> controls{};
  std::uint64_t trace_dropped = 0;
  std::uint64_t telemetry_dropped = 0;
  std::uint64_t commands_deferred = 0;  ///< cycles in which requests had to wait for the next cycle
  bool halted = false;  ///< after cmd::PreOperational: nodes pre-operational, no PDO or SYNC sent any more
  motion::ControllerMode mode = motion::ControllerMode::Run;  ///< cmd::ControllerMode (issue 16)
  /// CAM_PROFILE[0].Status of each cam profile (0 not calculated, 1 calculating,
  /// 2 calculated, n = in use by n - 2 cams).
  std::array<std::int32_t, motion::kMaxCamProfiles> cam_status{};
  /// REAL array elements (ArrayRef::offset + index); only the configured ones are written.
  std::array<double, kMaxRealElements> real_values{};
  /// COORDINATE_SYSTEM tags (CS.*), by ControllerSpec::coordinate_systems index.
  std::array<motion::CoordSystemTag, motion::kMaxCoordSystems> systems{};
};

class Controller {
 public:
  static constexpr std::size_t kCommandCapacity = 256;
  static constexpr std::size_t kEventCapacity = 1024;
  /// Trace records between two drains by the writer (10 ms at 1 ms on a
  /// full bus is < 3000 frames; 16384 leaves room for SDO bursts at boot).
  static constexpr std::size_t kTraceCapacity = 16384;
  /// Telemetry samples between two drains (64 axes x 100 cycles).
  static constexpr std::size_t kTelemetryCapacity = 8192;

  /// Build planner, masters and drive proxies. Throws std::invalid_argument
  /// naming the axis or bus when the spec is inconsistent. Not realtime.
  explicit Controller(ControllerSpec spec);
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  /// Run one cycle at controller time `now_ns` (monotonic or virtual).
  /// Realtime-safe.
  void cycle(std::int64_t now_ns) noexcept;

  // ---- non-RT side ----------------------------------------------------------
  /// Queue a command; returns its sequence number (Status::done_seq reaches
  /// it when the command was taken), or 0 when the ring is full. Thread-safe
  /// among producers (a producer-side mutex; the RT side never takes it).
  std::uint64_t submit(const Command& c);
  /// Newest status (copy). Any non-RT thread (with set_deferred_publish():
  /// the thread that runs cycle(), between cycles).
  /// Returns false before the first cycle.
  bool read_status(Status& out) const {
    if (deferred_publish_ && publish_pending_) finish_publish();
    return snapshot_->read(out) != 0;
  }
  /// Drain rings (one consumer thread each).
  bool pop_event(Event& e) noexcept { return events_.try_pop(e); }
  bool pop_trace(TraceRecord& r) noexcept { return trace_.try_pop(r); }
  bool pop_sample(Sample& s) noexcept { return telemetry_.try_pop(s); }
  /// Turn trace/telemetry recording on or off (before or while running).
  void set_trace(bool on) noexcept { trace_on_.store(on, std::memory_order_relaxed); }
  void set_telemetry(bool on) noexcept { telemetry_on_.store(on, std::memory_order_relaxed); }
  /// Deferred publishing, for a caller that runs cycle() and every
  /// read_status() on ONE thread (canmotiond --sim: the script and the socket
  /// are served between cycles): cycle() then keeps only what may change
  /// between cycles (bus counters, the maximum following errors, telemetry)
  /// and read_status() copies the rest, so cycles nobody reads cost no
  /// snapshot copy. A reader sees the same Status either way. Set before the
  /// first cycle; never with a reader on another thread.
  void set_deferred_publish(bool on) noexcept { deferred_publish_ = on; }

  /// Name lookups (not realtime).
  [[nodiscard]] std::optional<motion::AxisId> axis_id(std::string_view name) const;
  [[nodiscard]] const std::string& axis_name(motion::AxisId id) const { return spec_.axes.at(id).name; }
  [[nodiscard]] std::size_t axis_count() const noexcept { return spec_.axes.size(); }
  [[nodiscard]] const AxisSpec& axis_spec(motion::AxisId id) const { return spec_.axes.at(id); }
  [[nodiscard]] const ControllerSpec& spec() const noexcept { return spec_; }
  /// The control tag called `name`, created on first use. nullopt when all
  /// kMaxControlTags are taken.
  std::optional<motion::ControlId> control_id(std::string_view name);
  [[nodiscard]] std::optional<motion::ControlId> find_control(std::string_view name) const;
  [[nodiscard]] std::vector<std::pair<std::string, motion::ControlId>> controls() const;
  /// Cam profile id of `name` (case-insensitive), or nullopt.
  [[nodiscard]] std::optional<std::uint16_t> cam_id(std::string_view name) const;
  [[nodiscard]] std::size_t cam_count() const noexcept { return cams_.size(); }
  /// The coordinate system `name` (case-insensitive), or nullopt.
  [[nodiscard]] std::optional<motion::CoordSystemId> coordinate_system_id(std::string_view name) const;
  /// The array tag `name` (case-insensitive) of the `arrays:` section, or nullopt.
  [[nodiscard]] std::optional<ArrayRef> find_array(std::string_view name) const;
  /// Write one element of an array tag (CAM: member 0 Master, 1 Slave,
  /// 2 SegmentType; REAL: member ignored) through the command ring, so the RT
  /// thread applies it in program order. Returns the command's sequence
  /// number, or 0 when the ring is full or the element does not exist.
  /// Thread-safe (non-RT).
  std::uint64_t write_array(const ArrayRef& a, std::uint32_t element, std::uint8_t member, double value);
  /// A CAM array element as last written by a program. The RT thread never
  /// writes CAM arrays, so this non-RT copy is what MCCP sees once the writes
  /// queued so far are applied. Thread-safe (non-RT).
  [[nodiscard]] double read_cam_point(const ArrayRef& a, std::uint32_t element, std::uint8_t member) const;
  [[nodiscard]] double period_s() const noexcept { return static_cast<double>(spec_.period_ns) * 1e-9; }
  [[nodiscard]] std::uint64_t cycles() const noexcept { return cycle_.load(std::memory_order_acquire); }

  /// Measure when each SYNC is handed to its transport, on `clock` (the
  /// clock whose time cycle() is given: its wake-up): sync_timing(). Set
  /// before the loop runs (allocates the histograms); nullptr = not measured
  /// (the default: one clock read per SYNC saved). Not realtime.
  void set_sync_clock(Clock* clock) {
    sync_timing_ = clock == nullptr ? nullptr : std::make_unique<SyncTiming>(*clock, spec_.period_ns);
  }
  /// The SYNC timing measured since set_sync_clock(), or null. Any thread (its histograms are lock-free).
  [[nodiscard]] const SyncTiming* sync_timing() const noexcept { return sync_timing_.get(); }

  /// The planner, for set-up before the loop runs (e.g. cams) and for tests
  /// on the loop thread. Not for other threads while running.
  motion::Planner& planner() noexcept { return planner_; }
  cia402::DriveNetwork& network(std::size_t bus) noexcept { return *buses_[bus].network; }

 private:
  struct BusRt {
    can::Transport* transport = nullptr;
    std::unique_ptr<cia402::DriveNetwork> network;
    std::unique_ptr<canopen::FrameSink> sink;
    bool bus_off = false;
    bool link_down = false;            ///< the interface is down (Transport::link_down, or kLinkDown this cycle)
    std::uint64_t rejected = 0;
    std::uint32_t err_classes = 0;     ///< error classes reported last (kBusError)
    std::int64_t err_reported_ns = 0;  ///< when
  };
  struct AxisRt {
    int bus = -1;
    cia402::DriveProxy* proxy = nullptr;
    double conv = 1.0;
    /// The drive's velocity units per user unit/s (0x60FF, 0x60B1, 0x606C,
    /// 0x6099) and acceleration units per user unit/s^2 (0x609A): conv /
    /// DriveProxy::velocity_counts(), each cycle. NaN when the unit is not
    /// known: velocities are then sent as 0 and 0x606C is not read (the
    /// velocity is differentiated from the position); what needs them is
    /// refused by the configuration or fails the drive's boot.
    double vel = 1.0;
    double acc = 1.0;
    bool have_prev = false;
    std::int64_t prev_counts = 0;
    std::uint8_t status_bits = 0;  ///< statusword bits 7, 11, 13 last cycle (1, 2, 4): kDriveStatusBit on rising edges
    bool failure_reported = false;
    std::uint32_t failure_rev = 0;  ///< DriveProxy::failure_revision() when the failure was last reported
    bool homing_out = false;  ///< the planner's homing_start as last handed to the proxy (its edges start/cancel)
    std::uint32_t exception_faults = 0;  ///< AxisTag::exception_faults last cycle (kAxisFault on its rising edges)
    std::uint32_t drive_wait_errors = 0; ///< AxisTag::drive_wait_errors last cycle (kDriveWait when it grows)
  };
  class RecordingSink;
  /// A command in the ring with its sequence number (submit()).
  struct Queued {
    Command command{};
    std::uint64_t seq = 0;
  };

  // The steps of cycle(), in order (RT).
  void sync_all(std::int64_t now_ns) noexcept;
  void receive_all(std::int64_t now_ns) noexcept;
  void receive(std::size_t b, std::int64_t now_ns) noexcept;
  void feedback(std::size_t a) noexcept;
  void take_commands(std::int64_t now_ns) noexcept;
  void plan() noexcept;
  void apply(std::size_t a, const motion::AxisOutput& out) noexcept;
  void send_all(std::int64_t now_ns) noexcept;
  void advance_halt(std::int64_t now_ns) noexcept;
  // take_commands(): whether a command waits for the next cycle, and one
  // handler per command (RT).
  bool must_wait(const Command& c) const noexcept;
  void take(const cmd::Instruction& c, std::int64_t now_ns) noexcept;
  void take(const cmd::ResetControl& c, std::int64_t now_ns) noexcept;
  void take(const cmd::EnableDrives& c, std::int64_t now_ns) noexcept;
  void take(const cmd::PreOperational& c, std::int64_t now_ns) noexcept;
  void take(const cmd::DirectCommand& c, std::int64_t now_ns) noexcept;
  void take(const cmd::WriteArray& c, std::int64_t now_ns) noexcept;  ///< controller_arrays.cpp
  void take(const cmd::ControllerMode& c, std::int64_t now_ns) noexcept;
  void publish(std::int64_t now_ns) noexcept;
  void finish_publish() const noexcept;  ///< the copies of publish() that read_status() may defer
  void record(std::uint8_t bus, const can::TimedFrame& f, bool tx) noexcept;
  void emit(const Event& e) noexcept;
  void emit_bus_event(std::size_t b, Event::Kind k, std::uint64_t value = 0,
                      can::BusState state = can::BusState::kErrorActive) noexcept;
  void emit_status_bits(std::size_t a, std::uint8_t rising) noexcept;
  void build_arrays();                              ///< controller_arrays.cpp (constructor)

  ControllerSpec spec_;
  motion::Planner planner_;
  std::vector<BusRt> buses_;
  std::vector<AxisRt> axes_;
  std::vector<std::unique_ptr<motion::cam::CamProfile>> cams_;  ///< attached to the planner, same ids
  // `arrays:` storage, sized in build_arrays(), never resized.
  std::vector<std::vector<motion::cam::CamPoint>> cam_arrays_;   ///< RT copy (planner-attached)
  std::vector<std::vector<motion::cam::CamPoint>> cam_shadow_;   ///< non-RT copy, under names_mu_
  std::vector<double> real_store_;                               ///< all REAL arrays, planner-attached spans
  std::vector<ArrayRef> array_refs_;                             ///< per spec_.arrays entry
  std::array<motion::AxisFeedback, motion::kMaxAxes> fb_{};
  std::array<motion::AxisOutput, motion::kMaxAxes> out_{};
  std::array<motion::Request, kMaxRequestsPerCycle> requests_{};
  std::array<can::TimedFrame, kRxBatch> rx_{};
  std::array<can::BusEvent, 16> bus_ev_{};  ///< receive()'s bus events (a member: not re-initialised each call)
  std::array<double, motion::kMaxAxes> max_err_{};
  std::size_t nreq_ = 0;  ///< requests_ taken this cycle (take_commands() -> plan())
  std::optional<Queued> held_;  ///< a command popped but deferred to the next cycle
  Queued popped_{};  ///< take_commands()' current command (a member: not re-initialised every cycle)
  /// Controlled stop of the buses (cmd::PreOperational).
  enum class Halt : std::uint8_t { kRunning, kDisarming, kHalted };
  Halt halt_ = Halt::kRunning;
  std::int64_t halt_since_ns_ = 0;
  static constexpr std::uint32_t kDisarmTag = 0xCA10'1016;  ///< our SDO tag for the 0x1016 writes
  /// Longest wait for the 0x1016 writes before NMT pre-operational anyway.
  static constexpr std::int64_t kDisarmTimeoutNs = 500'000'000;
  std::uint64_t done_seq_ = 0;
  std::uint64_t deferred_ = 0;
  std::uint64_t trace_dropped_ = 0;
  std::uint64_t telemetry_dropped_ = 0;
  std::uint64_t cycle_index_ = 0;
  std::atomic<std::uint64_t> cycle_{0};
  std::atomic<bool> trace_on_{false};
  std::atomic<bool> telemetry_on_{false};
  std::atomic<std::size_t> controls_in_use_{0};  ///< control ids handed out; publish copies only these
  bool deferred_publish_ = false;        ///< set_deferred_publish()
  mutable bool publish_pending_ = false;  ///< publish() left its copies to finish_publish()
  std::size_t publish_nctl_ = 0;          ///< control tags in use at the last publish()

  SpscRing<Queued, kCommandCapacity> commands_;
  SpscRing<Event, kEventCapacity> events_;
  SpscRing<TraceRecord, kTraceCapacity> trace_;
  SpscRing<Sample, kTelemetryCapacity> telemetry_;
  std::unique_ptr<SnapshotBuffer<Status>> snapshot_;  ///< heap: three Status copies are large
  std::unique_ptr<SyncTiming> sync_timing_;  ///< set_sync_clock(); null: not measured

  mutable std::mutex names_mu_;  ///< non-RT only: control names and the producer side of commands_
  std::map<std::string, motion::ControlId, std::less<>> control_names_;
  std::uint64_t next_seq_ = 1;
};

/// Map a CiA 402 state to the planner's view of the drive. Realtime-safe.
[[nodiscard]] motion::DriveState drive_state_of(cia402::State s, bool operational) noexcept;

/// The text of a kAxisFault event for a log (not RT): what the axis latched,
/// the measured value against the configuration key that bounds it, the
/// action taken and its key, and what clears it; `index` is the axis's place
/// in the configuration's `axes:` list (the key path `axes[index]`).
[[nodiscard]] std::string describe_axis_fault(const Event& e, const AxisSpec& axis, std::size_t index);
/// The log text of an Event::Kind::kDriveWait on axis `axis` (its index in
/// the configuration, for the keys named) whose control tag is called
/// `control` (empty: not known), e.g. "MSO mso1 ended with ERR 12 EXERR 16
/// after 19.500 s: the drive did not get there within its wait limit ...;
/// drive node 2: waiting for boot-up after NMT reset node, ...". Not
/// realtime (fmt).
[[nodiscard]] std::string describe_drive_wait(const Event& e, const AxisSpec& axis, std::size_t index,
                                              std::string_view control, double period_s);
/// The log text of an Event::Kind::kDriveStatusBit on axis `axis` (its
/// index in the configuration), e.g. "drive node 2 set statusword bit 11
/// (internal limit active) in CSP, statusword 0x0A37: ...". Not realtime (fmt).
[[nodiscard]] std::string describe_drive_status_bit(const Event& e, const AxisSpec& axis, std::size_t index);

}  // namespace canmotion::rt
