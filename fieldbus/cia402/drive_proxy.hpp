#pragma once
/// \file
/// Master-side CiA 402 drive proxy (one per node) and DriveNetwork (the
/// CANopen master plus its proxies), the objects the RT controller drives
/// once per cycle.
///
/// Per node: boot (wait for boot-up / heartbeat, or reset the node), SDO
/// configuration (0x6060 mode, 0x60C2 interpolation period = cycle, 0x1006 =
/// 0 then 0x1019 = the master's SYNC counter overflow and, with
/// DriveConfig::sync_watch, 0x1006 = the period; PDO maps by the CiA 301
/// procedure, heartbeat producer 0x1017, the consumer 0x1016 watching the
/// master when asked for, extra writes), NMT start, then
/// the 402 state machine through its numbered transitions with a per-node
/// timeout. Until Operation enabled is reached the targets follow the actual
/// values, so enabling never jumps. A failure explains itself
/// (Failure::describe). A boot-up while running (the drive reset or was
/// power-cycled) re-runs the boot and configuration; so does a boot-up of a
/// node whose boot failed, and fault_reset() after a failed boot.
///
/// Set-up (constructors, add_drive) allocates. on_frame(), step()/cycle(),
/// the setters and getters are realtime-safe: no allocation, no locks, no
/// exceptions, no logging.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/can/transport.hpp"  // can::Filter
#include "fieldbus/canopen/device_dictionary.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/master.hpp"
#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/cia402/boot_plan.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"

namespace canmotion::cia402 {

/// One sentence for a canopen::NodeEvent::Kind::kObjectAbsent (an optional
/// boot object the drive lacks or refused as read-only, and the fallback the
/// proxy took), e.g. "node 2: no 0x1016 (Consumer heartbeat time, SDO abort
/// 0x06020000): the drive does not watch the master's heartbeat". The
/// object is named by `dictionary` (the drive's EDS, DriveConfig::dictionary)
/// when it has a name for it, else by CiA 301/402. An event with abort 0 is
/// an object the EDS has read-only (not written). Uses snprintf: call it
/// from a non-RT thread.
[[nodiscard]] std::string describe_notice(const canopen::NodeEvent& e,
                                          const canopen::DeviceDictionary* dictionary = nullptr);

/// What the configuration expects of the drive's identity (`drive.identity`);
/// unset members are not read (0x1018:2/3 are optional in CiA 301).
struct DriveIdentity {
  bool has_device_type = false;
  std::uint32_t device_type = 0;  ///< 0x1000 (whole value); unset: the profile number must be 402
  bool has_vendor_id = false;
  std::uint32_t vendor_id = 0;    ///< 0x1018:1
  bool has_product_code = false;
  std::uint32_t product_code = 0; ///< 0x1018:2
  bool has_revision = false;
  std::uint32_t revision = 0;     ///< 0x1018:3
};

/// A mode the drive must support (0x6502) and the configuration key that needs it.
struct ModeNeed {
  Mode mode = Mode::kCsp;
  std::string key;  ///< e.g. "axes[0].drive.pdo: csp_csv_cst" (empty: the boot mode)
};

/// Homing parameters (CiA 402 mode 6) in drive units, written over SDO
/// before each homing start (DriveProxy::start_homing).
struct HomingParams {
  std::int8_t method = 35;         ///< 0x6098
  std::uint32_t speed_search = 0;  ///< 0x6099:1, counts/s (speed during search for switch)
  std::uint32_t speed_zero = 0;    ///< 0x6099:2, counts/s (speed during search for zero)
  std::uint32_t accel = 0;         ///< 0x609A, counts/s^2
  bool write_offset = false;       ///< write 0x607C (home offset) too
  std::int32_t offset = 0;         ///< 0x607C, counts
};

/// Where a homing started with DriveProxy::start_homing() is.
enum class HomingResult : std::uint8_t {
  kIdle,       ///< none requested (or cancelled)
  kBusy,       ///< parameters being written, mode 6 awaited, or the drive homing
  kCompleted,  ///< the drive reported homing completed (bits 12 + 10) after this start
  kError,      ///< the drive reported a homing error (bit 13) after this start
  kTimeout,    ///< not completed within DriveConfig::homing_timeout_ns (bit 4 dropped: homing aborted)
  kRefused,    ///< the drive refused a homing parameter write (homing_abort())
};

/// Drive units (units.hpp, README "Drive units"): what one unit of the
/// drive's velocity and acceleration values is, as the configuration knows
/// it (from the EDS/DCF or `units.velocity`), or to be read at boot.
struct DriveUnits {
  /// counts/s per unit of the drive's velocity values (0x60FF, 0x606C,
  /// 0x6099, 0x60B1, ...) and counts/s^2 per unit of its acceleration values
  /// (0x6083, 0x6084, 0x609A, ...); NaN: not known.
  double velocity_counts = 1.0;
  double acceleration_counts = 1.0;
  /// The configuration cannot tell (no EDS, or one without the values):
  /// 0x60A8, 0x608F:1/2, 0x6091:1/2, 0x6092:1/2, 0x60A9 and 0x60AA are read at boot (each
  /// optional; a drive without 0x60A9 / 0x60AA works in increments, CiA 402
  /// without the factor group), and what they give replaces the two above.
  bool read_at_boot = false;
  /// 0x60A9 written at boot before those reads (`units.velocity`): set.
  bool has_write_velocity = false;
  std::uint32_t write_velocity = 0;
  /// What needs each unit (e.g. "axes[0].direct_control (MDS in CSV)"); a
  /// unit read at boot that cannot be interpreted then fails the boot naming
  /// it (nothing is guessed). Empty: nothing needs it (the value is NaN).
  std::string velocity_needed_by;
  std::string acceleration_needed_by;
};

struct DriveConfig {
  std::uint8_t node = 1;
  Mode mode = Mode::kCsp;                  ///< written to 0x6060 at boot
  std::int64_t cycle_ns = 1'000'000;       ///< written to 0x60C2
  PdoProfile pdo_profile = PdoProfile::kCsp;
  std::uint16_t producer_heartbeat_ms = 100;  ///< drive's 0x1017 (0 = off)
  std::uint16_t consumer_heartbeat_ms = 300;  ///< drive's 0x1016:1, watching the master (0 = not written: 0x1016 is optional)
  std::int64_t heartbeat_timeout_ns = 0;      ///< master-side consumer; 0 = 3 x producer period
  std::vector<SdoWrite> extra_writes;         ///< written after the standard configuration
  /// The bytes of typed extra_writes (SdoWrite::data points into them),
  /// shared by copies of this DriveConfig so that the pointers stay valid.
  std::vector<std::shared_ptr<const std::vector<std::uint8_t>>> value_storage;
  DriveUnits units;                           ///< the velocity and acceleration units (read at boot if unknown)
  std::int64_t boot_timeout_ns = 2'000'000'000;     ///< wait for boot-up/heartbeat before resetting the node
  std::int64_t sdo_timeout_ns = 200'000'000;        ///< per SDO response
  std::int64_t start_timeout_ns = 1'000'000'000;    ///< NMT start -> first TPDO
  std::int64_t transition_timeout_ns = 500'000'000; ///< per state machine transition
  /// A drive refuses a fault reset while the fault's cause remains: the reset
  /// edge (controlword bit 7 0 -> 1) is repeated this often (one RPDO with
  /// bit 7 clear, then set again) until the drive leaves Fault or
  /// transition_timeout_ns expires. 0 = one edge only.
  std::int64_t fault_reset_repeat_ns = 50'000'000;
  std::int64_t mode_switch_timeout_ns = 500'000'000; ///< 0x6061 must show a set_mode() request within this; 0 = unchecked
  std::int64_t homing_timeout_ns = 60'000'000'000;   ///< start_homing() -> homing completed or error; 0 = unchecked
  DriveIdentity identity;         ///< checked against 0x1000 / 0x1018 at boot
  /// Modes the drive must support besides `mode` (0x6502 read at boot; a
  /// drive without 0x6502 is not checked).
  std::vector<ModeNeed> needed_modes;
  bool reset_node_first = false;  ///< send NMT reset node instead of waiting for a boot-up first
  WriteHints hints;               ///< named in the message when a configuration write is refused
  /// The drive's object dictionary from its EDS (null or not described: no
  /// EDS). Optional boot writes (unused PDOs, an optional 0x1016) to an
  /// object it lacks are left out; without a description they are tried and
  /// abort 0x06020000 / 0x06090011 is accepted.
  std::shared_ptr<const canopen::DeviceDictionary> dictionary;
  /// 0x1016:1 comes from a default, not from the configuration: a drive
  /// without 0x1016 is fine (the write is optional, see `dictionary`). True
  /// by default (consumer_heartbeat_ms's default is not a user's request);
  /// canmotiond sets it false when the file sets master_heartbeat_timeout_ms.
  bool consumer_heartbeat_optional = true;
  /// The drive watches the SYNC: 0x1006 (communication cycle period) is
  /// written with cycle_ns in us after 0x1019, and the write is required.
  /// CANopenNode-based drives then send EMCY 8100h and (their default error
  /// behaviour) leave NMT operational when no SYNC came for 1.5 periods.
  /// False: 0x1006 is left at 0 (written 0 before 0x1019 in any case, as
  /// CiA 301 allows a 0x1019 change only while 0x1006 = 0). 0x1019 gets the
  /// master's MasterConfig::sync_counter_overflow (0: no counter).
  bool sync_watch = false;
  /// `drive.dcf` with 0x1020 values (CiA 302 verify configuration): read
  /// at boot; when the drive's 0x1020:1 (date) and :2 (time) are these, the
  /// DCF's values (SdoWrite::dcf) are not written again.
  bool dcf_dated = false;
  std::uint32_t dcf_date = 0;
  std::uint32_t dcf_time = 0;
};

/// Where the proxy is in bringing its node up.
enum class Phase : std::uint8_t { kWaitBoot, kResetWait, kConfiguring, kStarting, kOperational, kFailed };
[[nodiscard]] constexpr std::string_view phase_name(Phase p) noexcept {
  switch (p) {
    case Phase::kWaitBoot: return "waiting for boot-up";
    case Phase::kResetWait: return "waiting for boot-up after NMT reset node";
    case Phase::kConfiguring: return "configuring over SDO";
    case Phase::kStarting: return "waiting for the first TPDO after NMT start";
    case Phase::kOperational: return "operational";
    case Phase::kFailed: return "failed";
  }
  return "?";
}

enum class FailureKind : std::uint8_t {
  kNone,
  kBootTimeout,        ///< no boot-up even after NMT reset node
  kSdoAbort,           ///< a configuration write was aborted (by the drive or by timeout)
  kSdoQueueFull,
  kStartTimeout,       ///< no TPDO after NMT start
  kTransitionTimeout,  ///< the drive did not make the wanted transition in time
  kDriveFault,         ///< the drive went to Fault (reaction) on its own
  kHeartbeatLost,      ///< heartbeat consumer timed out
  kUnexpectedBootUp,   ///< the drive rebooted while operational
  kModeSwitchTimeout,  ///< 0x6061 did not show the mode requested in 0x6060 in time (mode_requested / mode_shown)
  kNmtState,           ///< while operational, the node's heartbeat shows pre-operational or stopped (`nmt_state`)
  kBootCheck,          ///< a read at boot showed a drive the configuration cannot run (`check`, `read_value`, `expected`)
};

/// True for the failures of the boot itself (phase kFailed): the node never
/// booted, refused its configuration, or sent no TPDO after NMT start.
[[nodiscard]] constexpr bool is_boot_failure(FailureKind k) noexcept {
  return k == FailureKind::kBootTimeout || k == FailureKind::kSdoAbort || k == FailureKind::kSdoQueueFull ||
         k == FailureKind::kStartTimeout || k == FailureKind::kBootCheck;
}

/// A failure with everything needed to explain it.
struct Failure {
  FailureKind kind = FailureKind::kNone;
  std::uint8_t node = 0;
  Phase phase = Phase::kWaitBoot;
  std::uint8_t transition = kNoTransition;  ///< the wanted transition (0..16)
  State wanted = State::kUnknown;           ///< the state the master wanted
  State reached = State::kUnknown;          ///< the state the drive was in
  std::uint16_t statusword = 0;             ///< last statusword
  bool has_emcy = false;
  std::uint16_t emcy_code = 0;              ///< last EMCY code, if any
  std::int64_t waited_ns = 0;               ///< time waited
  std::int64_t timeout_ns = 0;              ///< the timeout that expired (0: not a timeout)
  std::uint16_t sdo_index = 0;
  std::uint8_t sdo_sub = 0;
  std::uint32_t sdo_abort = 0;
  std::int64_t t_ns = 0;                    ///< when it was detected
  std::int8_t mode_requested = 0;           ///< kModeSwitchTimeout: 0x6060 written
  std::int8_t mode_shown = 0;               ///< kModeSwitchTimeout: 0x6061 still shown
  /// kSdoAbort: what the write was for; describe() says so with its boot
  /// plan rows' sentence (boot_hint()).
  WriteOrigin sdo_origin = WriteOrigin::kMode;
  /// kSdoAbort: the configuration key the write comes from (WriteHints), or
  /// nullptr. Points into the DriveProxy's configuration: valid while it lives.
  const char* hint = nullptr;
  canopen::NmtState nmt_state = canopen::NmtState::kUnknown;  ///< kNmtState: the state shown
  /// kNmtState: `statusword` (and `reached`) were read over SDO (0x6041)
  /// after the node left NMT operational; false: they are its last TPDO's,
  /// from before it left (a Stopped node answers no SDO).
  bool statusword_read = false;
  /// kTransitionTimeout: the drive showed Operation enabled in CSP, but
  /// statusword bit 12 (drive follows the command) stayed 0: the master
  /// never took it as enabled (DriveProxy::awaiting_follow()).
  bool follow_missing = false;
  BootCheck check = BootCheck::kNone;  ///< kBootCheck: what did not match
  std::uint32_t read_value = 0;        ///< kBootCheck: what the drive has
  std::uint32_t expected = 0;          ///< kBootCheck: what the configuration expects (kSupportedModes: the missing mode)
  /// kBootCheck kVelocityUnit / kAccelerationUnit: the factor group read.
  units::FactorGroup unit_factors{};
  /// The drive's EDS (DriveConfig::dictionary), or nullptr: describe() names
  /// objects by it where it has a name. Like `hint`, valid while the
  /// DriveProxy lives.
  const canopen::DeviceDictionary* dictionary = nullptr;

  /// One sentence, e.g. "node 2: transition 4 (Switched on -> Operation
  /// enabled) timed out after 500.0 ms: drive is in Switched on, statusword
  /// 0x0233, last EMCY 0x8611 (following error)". Objects are named by the
  /// drive's EDS (`dictionary`) where it has a name, else by CiA 301/402.
  /// Writes at most out.size()-1
  /// characters plus NUL; returns the length. Uses snprintf: call it from a
  /// non-RT thread.
  std::size_t describe(std::span<char> out) const noexcept;
  [[nodiscard]] std::string to_string() const;

 private:
  // describe()'s longer cases (drive_failure.cpp); snprintf's result.
  int describe_sdo_abort(std::span<char> out, double waited_ms) const noexcept;
  int describe_transition(std::span<char> out, double waited_ms, const char* emcy) const noexcept;
  int describe_nmt_state(std::span<char> out, const char* emcy) const noexcept;
};

/// Feedback from the TPDOs, in drive units (counts).
struct Feedback {
  std::uint16_t statusword = 0;
  /// 0x6064 in the drive frame of 64-bit counts: unwrapped by int32
  /// differences (cia402::unwrap32), so it goes on past +-2^31 where the
  /// wire value wraps. The first TPDO after a boot-up (or NMT reset node)
  /// sets the base: the position is then 0x6064 sign-extended; so does the
  /// TPDO that shows a homing completed (the drive re-referenced 0x6064).
  std::int64_t position = 0;
  std::int32_t position_raw = 0;  ///< 0x6064 as the last TPDO carried it
  std::int32_t velocity = 0;     ///< 0x606C (if mapped)
  std::int16_t torque = 0;       ///< 0x6077 (if mapped)
  std::int8_t mode_display = 0;  ///< 0x6061 (if mapped; otherwise the mode last confirmed over SDO)
  std::uint64_t tpdo_count = 0;
  std::uint64_t tpdo_missed = 0;  ///< cycles in which TPDO1 did not arrive after a SYNC
  std::int64_t last_tpdo_ns = 0;
};

class DriveProxy {
 public:
  /// Registers `cfg.node` with `master` (set-up; allocates).
  DriveProxy(const DriveConfig& cfg, canopen::Master& master);

  /// Feed a received frame; consumes this node's TPDOs (returns true).
  bool on_frame(const can::TimedFrame& f) noexcept;
  /// Feed a master event concerning this node.
  void on_node_event(const canopen::NodeEvent& e) noexcept;
  /// Boot/configuration progress, state machine, then the RPDOs of this
  /// cycle (only when operational). Call before the cycle's SYNC (or, SYNC
  /// first, after it: see on_sync_sent()).
  void step(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  /// Tell the proxy about the SYNC whose TPDOs the next step() reads: it
  /// arms missed-TPDO counting, and a homing's start bit counts once a SYNC
  /// applied it. `after_rpdos` true: the SYNC followed this cycle's RPDOs
  /// (the drive applies them at it; call after the SYNC). False: the SYNC
  /// went out first, at this cycle's wake-up (NetworkConfig::sync_first),
  /// so the drive applies the previous cycle's RPDOs at it; call at the end
  /// of the cycle, after step(), since the TPDOs answering it are read in
  /// the next cycle. Realtime-safe.
  void on_sync_sent(bool after_rpdos = true) noexcept;

  /// Tag the proxy uses for its own run-time SDO writes (0x6060); the
  /// application's transfers on master().sdo(node) should use other tags and
  /// collect their results with poll_tag() once the drive is operational
  /// (during the boot configuration the proxy owns the client).
  static constexpr std::uint32_t kModeWriteTag = 0xFFFF0001u;
  /// Tag of the homing parameter writes (start_homing()).
  static constexpr std::uint32_t kHomingWriteTag = 0xFFFF0002u;
  /// Tag of the read of 0x603F (error code) when the drive is in Fault
  /// without having sent an EMCY: its code is taken as the EMCY's
  /// (last_emcy_code(), Failure::emcy_code) and passed on as a
  /// NodeEvent::Kind::kEmcy (poll_notice()).
  static constexpr std::uint32_t kErrorCodeTag = 0xFFFF0003u;
  /// Tag of the read of 0x6041 (statusword) when the node left NMT
  /// operational while running: it sends no TPDO there, so its CiA 402 state
  /// (a Fault it took with the NMT change, CiA 301 0x1029) is read over SDO,
  /// which a Pre-operational node still answers (a Stopped one does not).
  static constexpr std::uint32_t kStatuswordTag = 0xFFFF0004u;

  // ---- commands ---------------------------------------------------------
  /// Go to Operation enabled (2, 3, 4; a fault must be reset first). Clears a
  /// previous transition failure.
  void enable() noexcept;
  /// Go to Switch on disabled (disable voltage: 7, 9, 10, 12).
  void disable() noexcept;
  /// Go to Switched on (disable operation: 5).
  void disable_operation() noexcept;
  /// Quick stop (11).
  void quick_stop() noexcept;
  /// Reset a fault and clear the recorded failure: a drive in Fault gets the
  /// fault reset (15, on the 0 -> 1 edge of bit 7: in the next RPDO, since
  /// the proxy sends bit 7 clear in Fault) and ends in Switch on disabled; a
  /// drive that is not in Fault keeps its state. After a failed boot, or a
  /// node that left NMT operational, the boot and configuration run again
  /// (restart(): without NMT reset node, so the drive keeps its fault
  /// history and homing), and once the node is operational again a drive in
  /// Fault gets the fault reset as above.
  void fault_reset() noexcept;
  /// Switch between CSP, CSV, CST and homing (through RPDO2 with
  /// PdoProfile::kCspCsvCst, otherwise an SDO write of 0x6060). The new
  /// mode's target starts at the actual value. False for other modes or a
  /// full SDO queue.
  bool set_mode(Mode m) noexcept;
  /// Homing (CiA 402 §3.3): writes 0x6098, 0x6099:1/2, 0x609A (and 0x607C
  /// when asked) over SDO, switches to mode 6 (set_mode) unless there, waits
  /// for 0x6061 = 6 and Operation enabled, then raises controlword bit 4 (after
  /// at least one RPDO with it clear: a rising edge) until the drive reports
  /// completion or an error. Only statuswords of TPDOs received after the
  /// SYNC that carried bit 4 count: a "homing attained" left from an earlier
  /// homing does not end this one. DriveConfig::homing_timeout_ns bounds the
  /// whole homing (bit 4 drops: the drive aborts). False when not
  /// operational or the SDO queue has no room (try again next cycle).
  bool start_homing(const HomingParams& p) noexcept;
  /// Drop bit 4 and forget the homing (its result goes back to kIdle).
  void cancel_homing() noexcept;
  /// The homing started last (kIdle when none).
  [[nodiscard]] HomingResult homing_result() const noexcept { return homing_result_; }
  /// kRefused: the refused write (index << 8 | sub) and its abort code.
  [[nodiscard]] std::uint32_t homing_abort_object() const noexcept { return homing_abort_object_; }
  [[nodiscard]] std::uint32_t homing_abort() const noexcept { return homing_abort_; }
  /// Homing status from statusword bits 13, 12, 10 as the drive shows them
  /// now (may be left from an earlier homing: see homing_result()).
  [[nodiscard]] HomingStatus homing_status() const noexcept { return decode_homing_status(fb_.statusword); }
  /// Targets in drive units; used only while Operation enabled. The
  /// position is in the 64-bit drive frame (Feedback::position); 0x607A
  /// carries its low 32 bits (cia402::low32: it wraps, never saturates).
  void set_target_position(std::int64_t counts) noexcept { target_position_ = counts; }
  void set_target_velocity(std::int32_t counts_per_s) noexcept { target_velocity_ = counts_per_s; }
  void set_target_torque(std::int16_t per_mille) noexcept { target_torque_ = per_mille; }
  /// Restart the boot sequence from the start (wait for the node, NMT
  /// pre-operational if needed, configure, start) and clear the failure.
  void restart() noexcept;
  /// restart(), and send NMT reset node first (the node may have lost its
  /// configuration or faulted while it could not hear the master, e.g. after
  /// a bus-off): it boots and is configured again.
  void reboot_node() noexcept;

  // ---- state --------------------------------------------------------------
  [[nodiscard]] std::uint8_t node() const noexcept { return cfg_.node; }
  [[nodiscard]] Phase phase() const noexcept { return phase_; }
  [[nodiscard]] State state() const noexcept { return state_; }
  [[nodiscard]] State wanted() const noexcept { return wanted_; }
  /// True in Operation enabled with the targets taken from the setters (not
  /// while leaving_enabled() or awaiting_follow()).
  [[nodiscard]] bool enabled() const noexcept {
    return phase_ == Phase::kOperational && state_ == State::kOperationEnabled && !leaving_enabled() &&
           !awaiting_follow();
  }
  /// In CSP, Operation enabled counts as reached only once statusword bit 12
  /// (drive follows the command) shows it: until then the drive may ignore
  /// 0x607A. In IP the same with bit 12 "ip mode active" (the drive takes
  /// 0x60C1:1 once it saw controlword bit 4 in Operation enabled). True from the TPDO that shows Operation enabled in CSP without
  /// bit 12 until one shows it set (then latched while the drive stays in
  /// Operation enabled; a later bit 12 = 0 is only reported, see
  /// cia402::decode_status_bits()). The wait is timed with
  /// DriveConfig::transition_timeout_ns, then a kTransitionTimeout failure
  /// with Failure::follow_missing. Realtime-safe.
  [[nodiscard]] bool awaiting_follow() const noexcept {
    return state_ == State::kOperationEnabled && !follow_ok_ && is_position_stream(mode_) &&
           (fb_.statusword & sw::kFollowsCommand) == 0;
  }
  /// True while no transition is in progress (the state is the wanted one).
  [[nodiscard]] bool settled() const noexcept { return state_ == wanted_ && !leaving_enabled(); }
  /// The proxy told the drive to leave Operation enabled (transition 5, 8,
  /// 9 or 11) and no TPDO has shown it out of there yet: its Operation
  /// enabled may predate that controlword (a drive shows a transition a TPDO
  /// or more later: it samples at the SYNC before it acts, acts in its own
  /// cycle, or ramps down first). Until a TPDO shows another state, it is
  /// not taken as enabled, and a new enable() waits for it (then 2, 3, 4).
  /// Realtime-safe.
  [[nodiscard]] bool leaving_enabled() const noexcept { return leaving_enabled_ && state_ == State::kOperationEnabled; }
  [[nodiscard]] const Feedback& feedback() const noexcept { return fb_; }
  /// counts/s per unit of the drive's velocity values (targets, 0x606C,
  /// homing speeds) and counts/s^2 per unit of its acceleration values:
  /// DriveUnits's, or with DriveUnits::read_at_boot what this boot read
  /// (1 until then, and for a drive without 0x60A9 / 0x60AA). NaN: not known.
  [[nodiscard]] double velocity_counts() const noexcept { return units_.velocity_counts; }
  [[nodiscard]] double acceleration_counts() const noexcept { return units_.acceleration_counts; }
  [[nodiscard]] const UnitReadings& unit_readings() const noexcept { return units_; }
  [[nodiscard]] Mode mode() const noexcept { return mode_; }
  /// The position-stream mode the RPDOs carry: kCsp (0x607A) or
  /// kInterpolatedPosition (0x60C1:1, DriveConfig::mode 7). A planner's CSP
  /// is sent in this mode.
  [[nodiscard]] Mode position_mode() const noexcept { return position_mode_; }
  [[nodiscard]] std::int64_t target_position() const noexcept { return target_position_; }
  [[nodiscard]] std::int32_t target_velocity() const noexcept { return target_velocity_; }
  [[nodiscard]] std::int16_t target_torque() const noexcept { return target_torque_; }
  [[nodiscard]] std::uint16_t controlword() const noexcept { return cw_; }
  [[nodiscard]] const Failure& failure() const noexcept { return failure_; }
  /// Changes when the recorded failure gains detail after it was recorded:
  /// an EMCY that came later, 0x603F, or the statusword read over SDO from a
  /// node that left NMT operational (the controller then reports it again).
  [[nodiscard]] std::uint32_t failure_revision() const noexcept { return failure_rev_; }
  [[nodiscard]] bool failed() const noexcept { return failure_.kind != FailureKind::kNone; }
  /// The conditions behind the failures, as they are now (the planner latches
  /// them): the master's heartbeat consumer has the node lost, or the node's
  /// heartbeat shows it left NMT operational while the proxy runs it.
  [[nodiscard]] bool heartbeat_lost() const noexcept { return master_.status(cfg_.node).lost; }
  [[nodiscard]] bool left_operational() const noexcept { return nmt_left_; }
  /// Optional configuration writes and reads the drive refused because it
  /// lacks the object (unused PDOs, an optional 0x1016, no 0x6502 / 0x6061),
  /// since the last (re)start of the configuration.
  [[nodiscard]] std::size_t tolerated_aborts() const noexcept { return tolerated_; }
  /// The next optional boot object the drive lacked (or refused as
  /// read-only) and the fallback taken (NodeEvent::Kind::kObjectAbsent,
  /// describe_notice()), each object once per proxy (not again at a
  /// re-boot). DriveNetwork::update() passes them on as events. Realtime-safe.
  bool poll_notice(canopen::NodeEvent& out) noexcept;
  /// The boot configuration's SDO transfers, in order: the checking reads
  /// (BootWrite::is_read(): 0x1000, 0x1018 as configured, 0x6502 first,
  /// 0x6061 last) and the writes (built at set-up; optional ones to objects
  /// the DriveConfig::dictionary lacks are not in it).
  [[nodiscard]] std::span<const BootWrite> boot_writes() const noexcept { return writes_; }
  /// Boot-ups that (re-)ran the configuration: while running, while
  /// configuring, or after a failed boot.
  [[nodiscard]] std::uint32_t reboots() const noexcept { return reboots_; }
  /// Fault-reset rising edges (controlword bit 7 0 -> 1) sent so far
  /// (DriveConfig::fault_reset_repeat_ns).
  [[nodiscard]] std::uint32_t fault_reset_edges() const noexcept { return reset_edges_; }
  /// Clear the recorded failure (the state machine keeps its state).
  void clear_failure() noexcept { failure_ = Failure{}; }
  [[nodiscard]] std::uint16_t last_emcy_code() const noexcept { return emcy_code_; }
  [[nodiscard]] bool has_emcy() const noexcept { return has_emcy_; }
  [[nodiscard]] const DriveConfig& config() const noexcept { return cfg_; }
  [[nodiscard]] const DrivePdoSet& pdos() const noexcept { return pdos_; }

 private:
  void build_configuration();
  void forget_drive(std::int64_t now_ns) noexcept;  ///< what the proxy knew of the drive's state and configuration
  void reboot(std::int64_t now_ns) noexcept;        ///< the node booted (again): configure it from the first write
  void fail(FailureKind k, std::int64_t now_ns, std::int64_t waited, std::int64_t timeout) noexcept;
  void step_boot(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  // The configuring phase (drive_boot.cpp): the boot transfers' results, then
  // the next transfers queued; true when the boot failed.
  enum class Taken : std::uint8_t { kDone, kAgain, kFailed };
  bool step_configuring(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  Taken take_result(const canopen::SdoResult& r, std::int64_t now_ns) noexcept;
  Taken check_read(std::size_t i, std::uint32_t v, std::int64_t now_ns) noexcept;
  void fail_transfer(std::size_t i, const canopen::SdoResult& r, bool as_trigger, std::int64_t now_ns) noexcept;
  // A boot write's value as written: SdoWrite::per in the drive's unit.
  [[nodiscard]] std::uint32_t in_drive_unit(const SdoWrite& w) const noexcept;
  void queue_transfers(canopen::SdoClient& sdo) noexcept;
  void step_state_machine(std::int64_t now_ns) noexcept;
  void hold_state(State target) noexcept;            // step_state_machine(): the controlword in the wanted state
  void wait_follow(std::int64_t now_ns) noexcept;     // step_state_machine(): Operation enabled in CSP without bit 12
  void send_fault_reset(std::int64_t now_ns) noexcept;  // step_state_machine(): transition 15's bit 7 edge
  void send_rpdos(canopen::FrameSink& out) noexcept;
  void follow_actual() noexcept;
  void set_wanted(State s) noexcept;

  DriveConfig cfg_;
  canopen::Master& master_;
  DrivePdoSet pdos_;
  std::size_t leading_reads_ = 0;      // the checks that run before any write
  std::int64_t again_since_ns_ = -1;   // boot: the first read whose check answered kAgain (0x6061)
  std::vector<BootWrite> writes_;      // the whole boot configuration, built at set-up (boot_plan.hpp)
  /// Per writes_ entry, what its answer was in this boot (fallbacks run on
  /// it), and whether its notice was made (said once per proxy).
  struct TransferState {
    bool fell_back = false;   // answered with an abort its row falls back on
    bool noticed = false;
    std::uint32_t abort = 0;  // that abort
  };
  std::vector<TransferState> transfer_;
  std::size_t next_write_ = 0;
  std::size_t done_writes_ = 0;
  std::size_t tolerated_ = 0;
  std::int32_t reread_ = -1;  // a read to queue again (its check answered kAgain), or -1
  std::array<canopen::NodeEvent, 16> notices_{};  // bound: at most one per optional boot object, 16 is ample
  std::size_t notice_head_ = 0, notice_count_ = 0;
  void notice(std::size_t write, std::uint32_t abort, Fallback what, std::int32_t detail = 0) noexcept;
  std::uint32_t reboots_ = 0;
  bool nmt_left_ = false;  // heartbeat showed pre-operational / stopped while operational

  Phase phase_ = Phase::kWaitBoot;
  bool started_ = false;
  bool force_reset_ = false;  // reboot_node(): NMT reset node in kWaitBoot
  std::int64_t phase_since_ns_ = 0;
  State state_ = State::kUnknown;
  State wanted_ = State::kSwitchOnDisabled;
  bool reset_requested_ = false;
  // Homing (start_homing): the step it is at.
  enum class HomingStep : std::uint8_t { kIdle, kWriting, kWaitMode, kStarted };
  HomingStep homing_step_ = HomingStep::kIdle;
  HomingResult homing_result_ = HomingResult::kIdle;
  std::uint8_t homing_writes_ = 0;    // parameter writes not yet answered
  bool homing_sync_ = false;          // a SYNC went out after an RPDO with bit 4 set
  bool homing_fresh_ = false;         // a TPDO came after that SYNC: its homing bits are this homing's
  std::int64_t homing_since_ns_ = 0;
  std::uint32_t homing_abort_ = 0;
  std::uint32_t homing_abort_object_ = 0;
  void step_homing(std::int64_t now_ns) noexcept;
  void end_homing(HomingResult r) noexcept;
  // The transition in progress.
  bool in_flight_ = false;
  bool leaving_enabled_ = false;       // leaving_enabled(): a command out of Operation enabled went out
  bool follow_ok_ = false;             // awaiting_follow(): bit 12 (or a mode other than CSP) seen in this Operation enabled
  bool follow_waiting_ = false;        // awaiting_follow() is being timed since follow_since_ns_
  std::int64_t follow_since_ns_ = 0;
  PlanStep leave_{Command::kDisableVoltage, kNoTransition, State::kUnknown};  // that command
  PlanStep flight_{Command::kShutdown, kNoTransition, State::kUnknown};
  State flight_from_ = State::kUnknown;
  std::int64_t flight_since_ns_ = 0;
  std::uint32_t flight_cycles_ = 0;
  std::int64_t reset_edge_ns_ = 0;     // when the last fault-reset rising edge went out
  // 0x603F read (kErrorCodeTag) for a Fault without EMCY.
  bool in_fault_ = false;              // the statusword shows Fault / Fault reaction active
  bool emcy_in_fault_ = false;         // an EMCY (not 0000h) came since the last fault ended
  bool error_code_asked_ = false;      // 0x603F queued for this fault
  std::int64_t fault_since_ns_ = 0;
  void step_error_code(std::int64_t now_ns) noexcept;
  std::uint32_t reset_edges_ = 0;      // fault-reset rising edges sent (fault_reset_edges())
  std::uint32_t failure_rev_ = 0;      // failure_revision()
  // Out of NMT operational while running (nmt_left_): 0x6041 read over SDO.
  bool sw_read_out_ = false;           // the read is queued or running (its result not yet taken)
  bool sw_read_done_ = false;          // read for this departure (again while Fault reaction active)
  void step_left_operational() noexcept;
  // fault_reset() restarted the node: once it is operational again, reset
  // its CiA 402 fault (reset_requested_, the repeated bit 7 edge).
  bool reset_after_start_ = false;

  Mode mode_ = Mode::kCsp;
  Mode position_mode_ = Mode::kCsp;  // position_mode()
  Mode sdo_mode_pending_ = Mode::kNoMode;
  bool mode_switch_pending_ = false;      // set_mode() waits for 0x6061 (mode_switch_timeout_ns)
  std::int64_t mode_switch_since_ns_ = 0;
  void check_mode_switch(std::int64_t now_ns) noexcept;
  std::uint16_t cw_ = 0;
  std::uint16_t cw_sent_ = 0;  // on_sync_sent(false): the controlword of the previous cycle's RPDO
  std::int64_t target_position_ = 0;  // drive frame (64-bit counts); the RPDO carries low32()
  std::int32_t target_velocity_ = 0;
  std::int16_t target_torque_ = 0;
  Feedback fb_{};
  UnitReadings units_{};  // velocity_counts(), acceleration_counts(); read at boot with DriveUnits::read_at_boot
  std::uint8_t dcf_same_ = 0;  // 0x1020 sub-indices that matched DriveConfig::dcf_date/time this boot (2: skip the DCF)
  bool pos_base_ = false;  // fb_.position has a base (false: the next 0x6064 sets it)
  bool got_tpdo_ = false;
  bool expect_tpdo_ = false;
  bool tpdo_seen_ = false;
  bool has_emcy_ = false;
  std::uint16_t emcy_code_ = 0;
  Failure failure_{};
  std::int64_t now_ns_ = 0;
  // Offsets of the mapped objects (computed at set-up): RPDO/TPDO number
  // (0-based) and entry index, or -1.
  struct Slot {
    std::int8_t pdo = -1;
    std::int8_t entry = -1;
  };
  Slot cw_slot_, tpos_slot_, tvel_slot_, ttrq_slot_, mode_slot_;
  Slot sw_slot_, pos_slot_, vel_slot_, trq_slot_, mdisp_slot_;
  // Packing plans of pdos_.rpdo / pdos_.tpdo (made with them at set-up).
  std::array<canopen::PdoPlan, 4> rpdo_plan_{};
  std::array<canopen::PdoPlan, 4> tpdo_plan_{};
};

struct NetworkConfig {
  canopen::MasterConfig master{};
  /// Frames the interface can queue (its txqueuelen; 0 = no limit). One
  /// cycle then writes at most this many, and at most this many minus one
  /// besides the SYNC, so a burst longer than the queue never loses the SYNC
  /// (the RPDOs past the limit are left out and counted: tx_budget_skipped()).
  std::uint32_t tx_queue_frames = 0;
  /// The SYNC goes out first, at the cycle's wake-up (DriveNetwork::sync(),
  /// before receiving and planning), and cycle() sends the RPDOs computed in
  /// the cycle after it: the drives apply them at the next SYNC. The SYNC's
  /// time on the wire then no longer carries the planner's execution time,
  /// at the cost of one cycle between a command and the drive applying it.
  /// False: RPDOs, then the SYNC, in cycle() (the drives apply a cycle's
  /// RPDOs at its own SYNC).
  bool sync_first = false;
};

/// The CANopen master plus one DriveProxy per node: the object the RT
/// controller calls each cycle.
class DriveNetwork {
 public:
  /// Events kept for the application between poll_event() calls.
  static constexpr std::size_t kEventCapacity = 512;

  explicit DriveNetwork(const NetworkConfig& cfg = {});
  /// Add a drive (set-up time). Throws std::invalid_argument for an invalid
  /// or duplicate node-ID.
  DriveProxy& add_drive(const DriveConfig& cfg);

  /// Feed one received frame (heartbeat, EMCY, SDO, TPDO). Realtime-safe.
  void on_frame(const can::TimedFrame& f) noexcept;
  /// After the cycle's frames: heartbeat consumer timeouts, then the master's
  /// events (boot-up, NMT state, heartbeat lost, EMCY) to the proxies, so
  /// that their state (failure(), feedback) is this cycle's before the
  /// application reads it: a lost heartbeat reaches the planner in the cycle
  /// that detects it. cycle() does it too (a no-op when update() ran).
  /// Realtime-safe.
  void update(std::int64_t now_ns) noexcept;
  /// One cycle: update(), each proxy's step (RPDOs), the SYNC (not with
  /// NetworkConfig::sync_first: sync() sent it), SDO requests, the master's
  /// heartbeat. Realtime-safe.
  void cycle(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  /// NetworkConfig::sync_first: the cycle's SYNC, the first frame of its
  /// burst; call at wake-up, before the received frames are read, then
  /// cycle() as usual. Does nothing without sync_first. Realtime-safe.
  void sync(canopen::FrameSink& out) noexcept;
  [[nodiscard]] bool sync_first() const noexcept { return sync_first_; }

  [[nodiscard]] canopen::Master& master() noexcept { return master_; }
  [[nodiscard]] DriveProxy* drive(std::uint8_t node) noexcept;
  [[nodiscard]] std::size_t size() const noexcept { return drives_.size(); }
  [[nodiscard]] DriveProxy& at(std::size_t i) noexcept { return *drives_[i]; }
  /// All drives operational (NMT started, first TPDO seen).
  [[nodiscard]] bool all_operational() const noexcept;
  /// All drives in Operation enabled.
  [[nodiscard]] bool all_enabled() const noexcept;
  /// Any drive has a recorded failure.
  [[nodiscard]] bool any_failed() const noexcept;
  void enable_all() noexcept;
  void disable_all() noexcept;
  /// Every drive: DriveProxy::reboot_node() (after the bus was bus-off).
  void reboot_all() noexcept;
  /// The SocketCAN receive filters the master needs (set-up time): EMCY,
  /// TPDO1..4, SDO responses and heartbeats of every drive (one exact-ID
  /// filter each, so the kernel drops everything else, e.g. other masters'
  /// RPDOs).
  [[nodiscard]] std::vector<can::Filter> receive_filters() const;
  /// Master events (boot-up, heartbeat lost, EMCY, ...) for the application.
  bool poll_event(canopen::NodeEvent& out) noexcept;
  /// Frames left out of a cycle to keep within NetworkConfig::tx_queue_frames.
  [[nodiscard]] std::uint64_t tx_budget_skipped() const noexcept { return budget_.skipped; }

 private:
  /// Passes frames on while the cycle's budget lasts (NetworkConfig::tx_queue_frames).
  struct BudgetSink final : canopen::FrameSink {
    canopen::FrameSink* out = nullptr;
    std::uint32_t left = 0;  // frames this sink still passes on (0xFFFFFFFF: no limit)
    std::uint64_t skipped = 0;
    bool send(const can::Frame& f) noexcept override {
      if (left == 0) {
        ++skipped;
        return false;
      }
      if (left != 0xFFFFFFFFu) --left;
      return out->send(f);
    }
  };
  std::uint32_t tx_queue_frames_ = 0;
  bool sync_first_ = false;
  BudgetSink budget_;
  std::uint64_t turn_ = 0;
  canopen::Master master_;
  std::vector<std::unique_ptr<DriveProxy>> drives_;
  std::array<std::int16_t, 128> index_{};
  /// The drive (index in drives_) whose TPDO has this standard COB-ID, or -1:
  /// on_frame() hands TPDOs over without classifying them twice.
  std::array<std::int8_t, 2048> tpdo_owner_{};
  std::vector<canopen::NodeEvent> events_;
  std::size_t ev_head_ = 0;
  std::size_t ev_count_ = 0;
};

}  // namespace canmotion::cia402
