#pragma once
/// \file
/// An emulated CiA 402 servo drive (CANopen slave), used by tests, the demo
/// and tools/cia402-emu. It has an object dictionary with the CiA 301
/// communication objects and the CiA 402 objects the master uses, an SDO
/// server with the right abort codes, an NMT slave with boot-up and heartbeat,
/// PDO mapping changeable only over SDO as CiA 301 says, RPDOs and TPDOs per
/// their transmission type (CiA 301), the CiA 402 state machine (modes 6, 8,
/// 9, 10) from the shared cia402.hpp, and a motor model that advances only on
/// SYNC (by the 0x60C2 period) with limited velocity/acceleration and a lag.
/// EmulatorBehaviour chooses between a strict drive (what real drives do)
/// and a permissive one (README "Emulator profiles").
///
/// Faults: following error beyond 0x6065 -> Fault + EMCY 0x8611; master
/// heartbeat lost (0x1016) -> the configured reaction + EMCY 0x8130; writing
/// an EMCY code to 0x2000 injects that fault; fail_after_syncs injects one
/// after N SYNCs.
///
/// The emulator is sans-IO like the master: it is given frames and the time
/// and emits frames through a FrameSink, so the same class runs on the SimBus
/// (in-process, virtual time) and on SocketCAN (tools/cia402-emu).
/// Not used on the master's RT path; its member functions do not allocate
/// after construction.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/can/sim_bus.hpp"
#include "fieldbus/can/transport.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/canopen/sdo_server.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::emulator {

/// What the drive does when the master's heartbeat is lost.
enum class HeartbeatLossReaction : std::uint8_t {
  kFault,      ///< Fault (via Fault reaction active), EMCY 0x8130 (default)
  kQuickStop,  ///< quick stop (if operation enabled), EMCY 0x8130
  kNone,       ///< only the EMCY 0x8130
};

/// One sub-object of the set an emulated drive serves (EmulatorConfig::served),
/// e.g. from a vendor's EDS (eds_dictionary.hpp).
struct ServedObject {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  canopen::DataType type = canopen::DataType::kUnsigned32;
  canopen::Access access = canopen::Access::kRw;
  canopen::PdoMappable pdo = canopen::PdoMappable::kNo;
  bool has_default = false;
  std::uint64_t default_value = 0;  ///< raw bits (the node-ID already added)
};

/// How closely the emulated drive behaves like a real one (README
/// "Emulator profiles"). `strict()` has every behaviour of a real drive that
/// a master must cope with; `permissive()` is the lenient drive the project
/// started with (every object exists, instant boot, same-call SDO replies, 3+4
/// in one SYNC, ...). Each field can be set on its own (cia402-emu flags).
/// Behaviours that are CiA 301/402 rules and not a drive's choice (TPDO
/// transmission types, RPDO 254/255 on receipt, EMCY 8210h/8220h/8240h once
/// with the error register and 0000h when they clear) are the same in both.
struct EmulatorBehaviour {
  /// The optional objects a drive may lack are absent: 0x1016 (consumer
  /// heartbeat) and the vendor-area MDS objects (EmulatorConfig::mds_objects,
  /// by default the project's 0x2010..0x2022; SDO abort 0x06020000).
  bool optional_objects_absent = true;
  /// 0x60C2:2 (interpolation time index) is read-only (abort 0x06010002):
  /// the drive only takes periods in milliseconds (index -3).
  bool ip_index_read_only = true;
  /// PDO parameters (0x1400..0x1BFF) change only in NMT Pre-operational;
  /// in Operational they abort with 0x08000022.
  bool remap_preoperational_only = true;
  /// CiA 402 predefined PDOs at power-on: RPDO1 = controlword only, TPDO1 =
  /// statusword only, both transmission type 255 (event-driven); PDOs 2..4
  /// invalid and unmapped. Permissive: RPDO1 = 0x6040 + 0x607A, TPDO1 =
  /// 0x6041 + 0x6064, type 1 (the master's own CSP mapping).
  bool cia402_default_pdos = true;
  /// An RPDO longer than its mapping: EMCY 8220h once (the mapped bytes are
  /// used, as CiA 301 allows). Permissive: accepted silently.
  bool rpdo_too_long_emcy = true;
  /// The SYNC's length is checked against 0x1019 (0 bytes when 0x1019 = 0,
  /// 1 byte otherwise): a SYNC of the wrong length is not processed and sends
  /// EMCY 8240h once. 0x1019 writes take only 0 and 2..240 (0x06090030), and
  /// only while 0x1006 is 0 (0x08000022), as CiA 301 and CANopenNode's
  /// CO_ODF_1019 say.
  bool check_sync_length = true;
  /// With 0x1006 (communication cycle period) not 0 the drive watches the
  /// SYNC, as CANopenNode's CO_SYNC_process: once a SYNC came, none for
  /// 1.5 x 0x1006 (in Pre-operational or Operational) sends EMCY 8100h once
  /// (error register bit 4) and takes 0x1029:1's reaction (error_behaviour:
  /// 0 leaves Operational); the next SYNC clears it (EMCY 0000h).
  bool sync_timeout = true;
  /// The SDO server refuses block transfer with 0x05040001, as a drive
  /// without it (the master then goes segmented). Off in both profiles.
  bool sdo_block_refused = false;
  /// 0x1029:1 (error behaviour, communication error) exists and acts on a
  /// communication error (lost master heartbeat, SYNC watch): 0 = Pre-operational
  /// (default), 1 = no change, 2 = Stopped.
  bool error_behaviour = true;
  /// After power-on the drive stays in Not ready to switch on (statusword
  /// 0x0000) this long while the DC bus charges (0 = transition 1 at once).
  std::int64_t boot_ns = 100'000'000;
  /// SDO replies wait at least this long, and are never sent in the call
  /// that received the request (0 = in the same call, at once).
  std::int64_t sdo_reply_delay_ns = 1;
  /// At most one commanded transition per SYNC (3 and 4 of 0x000F in two
  /// SYNCs); the controlword is evaluated again at every SYNC until the
  /// state settles. Permissive: 3 and 4 in the same call.
  bool one_transition_per_sync = true;
  /// A fault's cause outlasts the fault reaction: an injected fault's for
  /// this many SYNCs, a lost heartbeat until the master's heartbeat is seen
  /// again; a fault reset (15) meanwhile is refused (stays in Fault).
  std::uint32_t fault_cause_syncs = 20;
  /// 0x6061 shows a new 0x6060 this many SYNCs later (0 = at once).
  std::uint32_t mode_switch_syncs = 2;
  /// A mode not in 0x6502 is refused on every path: SDO abort 0x06090030,
  /// and from an RPDO 0x6061 keeps the old mode. Permissive: the RPDO's
  /// mode is shown in 0x6061.
  bool refuse_unsupported_modes = true;
  /// Homing moves per method family over several SYNCs (see
  /// homing_model.cpp); methods the drive lacks are refused (0x06090030).
  /// Permissive: 35/37 complete in one SYNC, others go straight to 0.
  bool homing_takes_time = true;

  [[nodiscard]] static EmulatorBehaviour strict() noexcept { return EmulatorBehaviour{}; }
  [[nodiscard]] static EmulatorBehaviour permissive() noexcept;
};


/// A power-on value other than the emulator's own, and optionally read-only
/// (EmulatorConfig::presets), e.g. a drive whose 0x1006 comes preset.
struct ObjectPreset {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint64_t value = 0;  ///< raw bits, in the object's size
  bool read_only = false;   ///< SDO writes abort 0x06010002
};

struct EmulatorConfig {
  std::uint8_t node = 2;
  /// Strict (default) or permissive, and the finer flags (see EmulatorBehaviour).
  EmulatorBehaviour behaviour{};
  /// Statusword bit 9 (remote): 0 = the drive is under local control and
  /// ignores the bus's controlword (as a drive with its local panel active).
  bool remote = true;
  /// 0x6502 supported drive modes (bits per CiA 402) at power-on; 0x6060
  /// values outside the 0x6502 the drive serves are refused (with `served`,
  /// an EDS's 0x6502 default wins; without any 0x6502, this mask).
  /// IP (mode 7) is modelled (0x60C0/0x60C1, controlword bit 4) but left out
  /// of the default, as the boots recorded before it (cia402-emu --modes adds it).
  std::uint32_t supported_modes = cia402::supported_mode_bit(cia402::Mode::kHoming) |
                                  cia402::supported_mode_bit(cia402::Mode::kCsp) |
                                  cia402::supported_mode_bit(cia402::Mode::kCsv) |
                                  cia402::supported_mode_bit(cia402::Mode::kCst);
  // Homing geometry of the strict model (drive counts; see homing_model.cpp).
  double home_switch_position = 0.0;     ///< edge of the home switch
  double index_pulse_period = 4096.0;    ///< an index pulse at every multiple of this
  double homing_max_travel = 10'000'000.0;  ///< no switch/index within this travel: homing error
  std::string device_name = "canmotion cia402-emu: emulated CiA 402 servo drive";  ///< 0x1008 (segmented SDO)
  std::uint32_t vendor_id = 0x00000000;  ///< 0x1018:1 (0: unassigned)
  std::uint32_t product_code = 0x00000402;
  std::uint32_t revision = 0x00010000;
  // Motor model (drive units: counts, counts/s, counts/s^2).
  double max_velocity = 2'000'000.0;       ///< 0x607F default
  double max_acceleration = 50'000'000.0;  ///< limit of the model
  std::uint32_t lag_cycles = 2;            ///< targets take effect this many SYNCs late
  double position_gain = 0.5;              ///< fraction of the position error corrected per SYNC (0..1]
  std::uint32_t following_error_window = 100'000;  ///< 0x6065 default
  std::int64_t initial_position = 0;  ///< counts (0x6064 shows its low 32 bits)
  // Fault injection.
  std::uint64_t fail_after_syncs = 0;      ///< 0 = never
  std::uint16_t fail_emcy_code = 0x2310;   ///< code used by fail_after_syncs
  HeartbeatLossReaction heartbeat_loss_reaction = HeartbeatLossReaction::kFault;
  /// Fault injection: accept 0x6060 writes but never show a new mode in
  /// 0x6061 (the drive refuses the mode switch); the master's mode-switch
  /// timeout (drive.timeouts.mode_switch_ms) must catch it.
  bool refuse_mode_switch = false;
  /// Objects (indices) this drive does not have, e.g. the optional 0x1016, or
  /// 0x1402/0x1602 for a drive with fewer PDOs: SDO access to them aborts with
  /// 0x06020000 (object does not exist), as on a real drive without them.
  /// A PDO whose communication object is absent is never valid.
  std::vector<std::uint16_t> absent_objects;
  /// Where this drive keeps the MDS objects CiA 402 lacks (ramp velocity
  /// limits, ramp jerk, SLAT): the project's 0x2010..0x2022 by default, or
  /// other indices (cia402-emu --mds-objects), as a real drive may. Nothing is
  /// then at the default indices. An address that is also one of the
  /// emulator's own objects (e.g. 0x2000 fault injection) becomes the MDS
  /// object; a record's sub-index 0 (highest sub-index) is added when an
  /// object sits at sub-index 1 or above.
  cia402::MdsObjects mds_objects{};
  /// Power-on values (and read-only objects) other than the emulator's own,
  /// e.g. {0x1006, 0, 1000}: a drive that watches the SYNC from power-on and
  /// so refuses 0x1019 writes until 0x1006 is 0; {0x1019, 0, 5, true}: a
  /// drive whose SYNC counter overflow is fixed at 5. Objects it lacks are
  /// ignored. Applied after EmulatorBehaviour's and before `served`.
  std::vector<ObjectPreset> presets;
  /// Not empty (cia402-emu --eds): the drive serves exactly these
  /// sub-objects over SDO and PDO mapping, with their access, PDO mapping
  /// flags and defaults. Its own objects not listed abort 0x06020000 /
  /// 0x06090011 and cannot be mapped (the behaviour behind them stays, e.g.
  /// the EMCY COB-ID from 0x1014's default); listed numbers it does not know
  /// are plain storage; strings and domains it does not know are left out.
  std::vector<ServedObject> served;
  // Load model of CST (see README "Motor and load model"): motor torque T
  // (per mille of rated torque, 0x6071 clamped to 0x6072) accelerates the
  // motor by (T - load_torque - viscous_friction * v) / 1000 * rated_torque_acceleration.
  double rated_torque_acceleration = 0.0;  ///< counts/s^2 at 1000 per mille; 0 = max_acceleration
  double load_torque = 0.0;                ///< constant load, per mille, against positive rotation
  double viscous_friction = 0.0;           ///< per mille per count/s
  /// SLAT speed control: fraction of the velocity error corrected per SYNC
  /// (0..1], within the torque limit 0x6072.
  double speed_loop_gain = 0.2;
};

/// Running totals, for tests and the tool's status line.
struct EmulatorCounters {
  std::uint64_t syncs = 0;
  std::uint64_t rpdos = 0;
  std::uint64_t tpdos = 0;
  std::uint64_t sdo_requests = 0;
  std::uint64_t emcys = 0;
  std::uint64_t heartbeats = 0;
  std::uint64_t boot_ups = 0;
  std::uint64_t rpdo_length_errors = 0;
  std::uint64_t sync_length_errors = 0;     ///< SYNCs dropped for their length (0x1019)
  /// SYNCs whose counter byte was not the one CiA 301 says comes next: the
  /// previous + 1, and 1 after the overflow value 0x1019 (or outside 1..0x1019).
  /// Counted only, the SYNC is processed; the first after a reset is taken as it is.
  std::uint64_t sync_counter_errors = 0;
  std::uint64_t sync_timeouts = 0;          ///< SYNC watch (0x1006) timeouts, EMCY 8100h
  std::uint64_t refused_fault_resets = 0;   ///< fault resets refused while the cause remained
  std::uint64_t sdo_replies_dropped = 0;    ///< delayed SDO replies lost to a full queue
};

class Emulator final : public canopen::SdoServerBackend {
 public:
  explicit Emulator(const EmulatorConfig& cfg);
  /// Not copyable or movable: the SDO server and the cached dictionary
  /// pointers refer to this object.
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;

  /// Power on (or reset node): dictionary to defaults, boot-up message,
  /// NMT pre-operational.
  void power_on(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  /// Handle one received frame (NMT, SYNC, SDO request, RPDO, heartbeats).
  void on_frame(const can::TimedFrame& f, canopen::FrameSink& out) noexcept;
  /// Time-driven duties: heartbeat producer, heartbeat consumer, SDO server
  /// timeout. The motor never advances here, only on SYNC.
  void step(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  /// Set the time used while handling the next frames (on_frame does not
  /// take a time: received timestamps may come from another clock).
  void set_time(std::int64_t now_ns) noexcept { now_ns_ = now_ns; }
  /// Drain `bus`, handle every frame, then step(now_ns); replies go to `bus`.
  /// This is how the emulator attaches to a SimBus endpoint or a SocketCanBus.
  void service(can::Transport& bus, std::int64_t now_ns) noexcept;
  /// The same on a SimBus endpoint (SimWorld, SimRig): the frames are
  /// handled where they wait in the endpoint's ring instead of being copied
  /// out first, and replies go straight to the endpoint. Realtime-safe.
  void service(can::SimBus::Endpoint& bus, std::int64_t now_ns) noexcept;

  /// The standard identifiers on_frame() acts on (NMT, SYNC, this node's SDO
  /// requests, heartbeats, the valid RPDOs), as bits (id % 64 of word
  /// id / 64); every other frame, and every extended or error frame, is
  /// ignored. `openers`: those of them that may change the set (NMT and SDO
  /// requests: resets, writes of 0x1005 or of the RPDO parameters), after
  /// which the set must be asked for again. For an acceptance filter in
  /// front of the emulator (SimWorld). Realtime-safe.
  void accepted_ids(std::array<std::uint64_t, 2048 / 64>& ids, std::array<std::uint64_t, 2048 / 64>& openers) const noexcept;
  /// Changes whenever the set accepted_ids() returns may have changed
  /// (any dictionary write through set(), a PDO rebuild, a reset).
  [[nodiscard]] std::uint64_t accept_generation() const noexcept { return accept_gen_; }

  /// Inject a fault with EMCY `code` (as writing 0x2000 does). Its cause
  /// lasts EmulatorBehaviour::fault_cause_syncs SYNCs.
  void inject_fault(std::uint16_t code) noexcept { pending_fault_ = code; }
  /// Keep (true) or remove (false) the cause of the present fault: a fault
  /// reset is refused while it is kept (fault injection, e.g. a DC bus that
  /// stays under-voltage).
  void hold_fault_cause(bool on) noexcept { fault_cause_held_ = on; }
  /// Statusword bit 9 at run time (see EmulatorConfig::remote).
  void set_remote(bool on) noexcept { cfg_.remote = on; }

  // ---- observation --------------------------------------------------------
  [[nodiscard]] std::uint8_t node() const noexcept { return cfg_.node; }
  [[nodiscard]] canopen::NmtState nmt_state() const noexcept { return nmt_; }
  [[nodiscard]] cia402::State state() const noexcept { return state_; }
  [[nodiscard]] std::uint16_t statusword() const noexcept;
  /// 0x6064 as the drive sends it: the low 32 bits of position_counts()
  /// (two's complement: it wraps at +-2^31 like a real drive's counter,
  /// never saturates).
  [[nodiscard]] std::int32_t position() const noexcept { return cia402::low32(position_counts()); }
  /// The motor's position in whole counts, 64 bits (the model's own frame:
  /// it never wraps).
  [[nodiscard]] std::int64_t position_counts() const noexcept {
    return static_cast<std::int64_t>(std::clamp(cia402::round_half_away(pos_), -0x1p62, 0x1p62));
  }
  [[nodiscard]] double position_exact() const noexcept { return pos_; }
  [[nodiscard]] double velocity() const noexcept { return vel_; }
  [[nodiscard]] std::int8_t mode_display() const noexcept { return mode_display_; }
  /// CST with SLAT 1/2: true while the drive is in speed control.
  [[nodiscard]] bool slat_speed_control() const noexcept { return slat_speed_; }
  /// Motor torque applied at the last SYNC (per mille of rated torque).
  [[nodiscard]] double torque() const noexcept { return torque_; }
  /// Fault injection at run time (see EmulatorConfig::refuse_mode_switch).
  void set_refuse_mode_switch(bool on) noexcept { cfg_.refuse_mode_switch = on; }
  /// Change the CST load model (see EmulatorConfig) at run time, e.g. for a
  /// drive built from a configuration file.
  void set_load_model(double rated_torque_acceleration, double load_torque, double viscous_friction) noexcept {
    cfg_.rated_torque_acceleration = rated_torque_acceleration;
    cfg_.load_torque = load_torque;
    cfg_.viscous_friction = viscous_friction;
  }
  [[nodiscard]] const EmulatorCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const EmulatorConfig& config() const noexcept { return cfg_; }
  /// Read an integer object (testing aid); 0 if absent.
  [[nodiscard]] std::int64_t read_int(std::uint16_t index, std::uint8_t sub = 0) const noexcept;

  /// One entry of the object dictionary the emulator serves.
  struct ObjectDescription {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    canopen::DataType type = canopen::DataType::kUnsigned8;
    canopen::Access access = canopen::Access::kRo;
    canopen::PdoMappable pdo = canopen::PdoMappable::kNo;
    std::uint64_t default_value = 0;  ///< raw bits, as after power-on
    std::string_view text;            ///< strings (0x1008 ...): the text
  };
  /// The whole dictionary, ascending index and sub-index (set-up / tests:
  /// allocates). tests/eds checks config/examples/cia402-emu.eds against it.
  [[nodiscard]] std::vector<ObjectDescription> dictionary() const;

  // ---- SdoServerBackend -----------------------------------------------------
  canopen::SdoAbort sdo_read(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> out,
                             std::size_t& len) noexcept override;
  canopen::SdoAbort sdo_write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) noexcept override;

 private:
  struct Entry {
    std::uint32_t key;  // index << 8 | sub
    canopen::DataType type;
    canopen::Access access;
    canopen::PdoMappable pdo;
    std::uint64_t value;      // raw little-endian bits
    std::uint64_t default_value;
    const std::string* text;  // strings (0x1008...)
    std::uint64_t mask;       // the value bits of the type's size (put; all bits for 0 or 8 bytes)
    std::uint64_t sign;       // the sign bit of a signed type shorter than 8 bytes, else 0 (sval)
    bool hidden = false;      // not in EmulatorConfig::served: used inside, not served (SDO, PDO mapping)
  };
  /// Entries the SYNC / frame path touches, resolved once after the
  /// dictionary is built (od_ never grows or reallocates afterwards, so the
  /// pointers stay valid for the emulator's lifetime).
  struct Hot {
    Entry* error_register;      // 0x1001
    Entry* sync_cob;            // 0x1005
    Entry* emcy_cob;            // 0x1014
    std::array<Entry*, 4> consumer_hb;  // 0x1016:1..4
    Entry* producer_hb;         // 0x1017
    Entry* error_code;          // 0x603F
    Entry* controlword;         // 0x6040
    Entry* statusword;          // 0x6041
    Entry* quick_stop_option;   // 0x605A
    Entry* modes;               // 0x6060
    Entry* mode_display;        // 0x6061
    Entry* position_demand;     // 0x6062
    Entry* position_internal;   // 0x6063
    Entry* position_actual;     // 0x6064
    Entry* fe_window;           // 0x6065
    Entry* fe_timeout;          // 0x6066
    Entry* velocity_actual;     // 0x606C
    Entry* target_torque;       // 0x6071
    Entry* max_torque;          // 0x6072
    Entry* torque_actual;       // 0x6077
    Entry* target_position;     // 0x607A
    Entry* home_offset;         // 0x607C
    Entry* max_profile_velocity;  // 0x607F
    Entry* quick_stop_decel;    // 0x6085
    Entry* homing_method;       // 0x6098
    Entry* homing_speed_switch; // 0x6099:1
    Entry* position_offset;     // 0x60B0
    Entry* velocity_offset;     // 0x60B1
    Entry* torque_offset;       // 0x60B2
    Entry* ip_data;             // 0x60C1:1 (IP set point)
    Entry* ip_value;            // 0x60C2:1
    Entry* ip_index;            // 0x60C2:2
    Entry* fe_actual;           // 0x60F4
    Entry* target_velocity;     // 0x60FF
    Entry* supported_modes;     // 0x6502
    // MDS ramps and SLAT (direct_model.cpp)
    Entry* profile_accel;       // 0x6083 RampAcceleration
    Entry* profile_decel;       // 0x6084 RampDeceleration
    // EmulatorConfig::mds_objects (by default 0x2010:1/2, 0x2011, 0x2020..0x2022)
    Entry* ramp_vpos;           // ramp velocity - positive
    Entry* ramp_vneg;           // ramp velocity - negative
    Entry* ramp_jerk;           // ramp jerk - control
    Entry* slat_config;         // SLAT configuration
    Entry* slat_set_point;      // SLAT set point
    Entry* slat_delay;          // SLAT time delay
  };
  /// Where an object's power-on value comes from (a column of kObjectTable).
  enum class Default : std::uint8_t {
    kValue,                 ///< the row's value
    kNodeId,                ///< EmulatorConfig::node
    kEmcyCobId,             ///< 0x80 + node
    kSdoRxCobId,            ///< 0x600 + node
    kSdoTxCobId,            ///< 0x580 + node
    kVendorId,              ///< EmulatorConfig::vendor_id
    kProductCode,           ///< EmulatorConfig::product_code
    kRevision,              ///< EmulatorConfig::revision
    kFollowingErrorWindow,  ///< EmulatorConfig::following_error_window
    kMaxVelocity,           ///< EmulatorConfig::max_velocity (counts/s)
    kMaxAcceleration,       ///< EmulatorConfig::max_acceleration (counts/s^2)
    kSupportedModes,        ///< EmulatorConfig::supported_modes
    kDeviceName,            ///< text: EmulatorConfig::device_name
    kHardwareVersion,       ///< text
    kSoftwareVersion,       ///< text
    kRpdoCobId,             ///< CiA 301 default RPDO COB-ID; PDOs 2..4 invalid (bit 31)
    kTpdoCobId,             ///< CiA 301 default TPDO COB-ID; PDOs 2..4 invalid
    kPdo1TransmissionType,  ///< PDO 1: 255 (CiA 402 predefined) or 1; others 1
    kPdo1MapCount,          ///< PDO 1: 1 (CiA 402 predefined) or 2; others 0
    kPdo1Map,               ///< PDO 1: the row's mapping entry; others 0
    kPdo1CspMap,            ///< PDO 1 without the CiA 402 predefined PDOs: the row's entry; else 0
  };
  /// One row of the object table the dictionary is built from (dictionary.cpp).
  struct ObjectRow {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t sub_last;                             ///< sub .. sub_last, the same value each
    Default from;
    std::uint64_t value;                               ///< raw bits (kValue) or PDO 1's mapping entry
    Entry* Hot::* wire = nullptr;                      ///< the Hot entry for it (one sub-index)
    std::array<Entry*, 4> Hot::* wires = nullptr;      ///< the Hot entries for sub .. sub_last
    std::uint8_t pdos = 1;                             ///< the row for indices index .. index + pdos - 1 (PDOs 1..4)
    bool error_behaviour_only = false;                 ///< only with EmulatorBehaviour::error_behaviour
  };
  /// The emulator's own objects (dictionary.cpp); data type, access and PDO
  /// mapping from canopen::object_info().
  static const ObjectRow kObjectTable[];
  [[nodiscard]] std::uint64_t default_of(const ObjectRow& r, std::uint8_t pdo) const noexcept;
  [[nodiscard]] const std::string* text_of(const ObjectRow& r) const noexcept;
  /// Per mapped PDO entry: the dictionary entry (nullptr if absent); where
  /// it sits in the payload is in the PDO's packing plan.
  struct MappedEntry {
    Entry* entry = nullptr;
    bool is_statusword = false;
    bool is_controlword = false;
  };
  /// Writing an EMCY code here injects that fault (manufacturer area).
  static constexpr std::uint16_t kFaultInjection = 0x2000;
  static constexpr std::uint32_t key(std::uint16_t index, std::uint8_t sub) noexcept {
    return (static_cast<std::uint32_t>(index) << 8) | sub;
  }
  void build_dictionary();
  /// The MDS objects at EmulatorConfig::mds_objects (and their records'
  /// sub-index 0); returns their keys (optional_objects_absent removes them).
  std::vector<std::uint32_t> add_mds_objects();
  void add(std::uint16_t index, std::uint8_t sub, std::uint64_t value, const std::string* text = nullptr);
  Entry* find(std::uint16_t index, std::uint8_t sub) noexcept;
  void resolve_hot() noexcept;  // after build_dictionary(): fills hot_
  static std::uint64_t val(const Entry* e) noexcept { return e ? e->value : 0; }
  /// The position set point of the mode shown: 0x60C1:1 in IP, else 0x607A.
  [[nodiscard]] std::int32_t position_setpoint() const noexcept {
    return static_cast<std::int32_t>(
        sval(mode_display_ == static_cast<std::int8_t>(cia402::Mode::kInterpolatedPosition) ? hot_.ip_data
                                                                                            : hot_.target_position));
  }
  /// IP (mode 7) in Operation enabled with controlword bit 4 seen: statusword bit 12.
  [[nodiscard]] bool ip_following() const noexcept {
    return ip_active_ && state_ == cia402::State::kOperationEnabled &&
           mode_display_ == static_cast<std::int8_t>(cia402::Mode::kInterpolatedPosition);
  }
  /// canopen::sign_extend(value, 8 * size) for a signed type, with the sign
  /// bit cached (0 otherwise); 0 for an absent object.
  static std::int64_t sval(const Entry* e) noexcept {
    return e ? static_cast<std::int64_t>((e->value ^ e->sign) - e->sign) : 0;
  }
  /// The low `size` bytes of v (all of v for 0 or 8); nothing for an absent object.
  static void put(Entry* e, std::uint64_t v) noexcept {
    if (e) e->value = v & e->mask;
  }
  const Entry* find(std::uint16_t index, std::uint8_t sub) const noexcept;
  bool index_exists(std::uint16_t index) const noexcept;
  std::uint64_t get(std::uint16_t index, std::uint8_t sub = 0) const noexcept;
  std::int64_t get_signed(std::uint16_t index, std::uint8_t sub = 0) const noexcept;
  void set(std::uint16_t index, std::uint8_t sub, std::uint64_t v) noexcept;
  void reset_dictionary(bool communication_only) noexcept;
  canopen::SdoAbort check_pdo_write(std::uint16_t index, std::uint8_t sub, std::uint64_t v) const noexcept;
  void rebuild_pdos() noexcept;
  // eds_dictionary.cpp: EmulatorConfig::served applied to the built dictionary.
  void apply_served();
  static void set_type(Entry& e, canopen::DataType t) noexcept;  // type, mask and sign
  [[nodiscard]] const Entry* served(std::uint16_t index, std::uint8_t sub) const noexcept;  // nullptr: absent or hidden

  void handle_nmt(const can::Frame& f, std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  // on_frame() by identifier: a SYNC (its length checked against 0x1019),
  // an SDO request to this node (sdo_server.cpp), a heartbeat (the consumer,
  // 0x1016), an RPDO (length checked, applied or latched for the SYNC).
  void on_sync_frame(const can::Frame& f, canopen::FrameSink& out) noexcept;
  void on_sdo_request(const can::Frame& f, canopen::FrameSink& out) noexcept;
  void on_heartbeat(std::uint8_t from_node) noexcept;
  void on_rpdo(const can::Frame& f, canopen::FrameSink& out) noexcept;
  void handle_sync(std::int64_t now_ns, canopen::FrameSink& out) noexcept;
  void apply_controlword(std::uint16_t cw, canopen::FrameSink& out) noexcept;
  void enter_fault(std::uint16_t code, canopen::FrameSink& out) noexcept;
  void send_emcy(std::uint16_t code, canopen::FrameSink& out) noexcept;
  void advance_motor(double dt) noexcept;
  // direct_model.cpp: MDS drive-side behaviour, kept out of the hot path's
  // common code. csv_ramp: the next velocity towards `target` with the ramp
  // objects (0x6083/0x6084/0x2010/0x2011). cst_step: SLAT switching and the
  // load model; returns the next velocity and sets `torque` to the motor torque.
  double csv_ramp(double target, double dt) noexcept;
  double cst_step(double torque_cmd, double velocity_cmd, double dt, double& torque) noexcept;
  void reset_direct_model() noexcept;
  void update_outputs() noexcept;
  /// TPDOs per transmission type (CiA 301): at a SYNC (`at_sync`) types 0
  /// (if changed) and 1..240 (every n-th); on every call 254/255 (on change,
  /// after the inhibit time 0x18xx:3, or when the event timer 0x18xx:5 ran out).
  void send_tpdos(bool at_sync, canopen::FrameSink& out) noexcept;
  std::uint64_t tpdo_payload(std::size_t p) const noexcept;
  /// Write RPDO p's payload word into the dictionary; true if it carries the controlword.
  bool apply_rpdo(std::size_t p, std::uint64_t w) noexcept;
  /// The controlword (0x6040) through the state machine, unless it is settled.
  void evaluate_controlword(canopen::FrameSink& out) noexcept;
  /// 0x6061 towards 0x6060 (at a SYNC; EmulatorBehaviour::mode_switch_syncs).
  void update_mode_display() noexcept;
  void switch_mode(std::int8_t mode) noexcept;
  /// The mode the drive runs: mode_display_ and the 0x6061 object (SDO, TPDOs) together.
  void set_mode_display(std::int8_t mode) noexcept;
  [[nodiscard]] bool mode_supported(std::int8_t mode) const noexcept;
  /// The automatic transitions, all here: 1 (initialisation done after
  /// EmulatorBehaviour::boot_ns), 12 (quick stop completed, at a SYNC),
  /// 14 (fault reaction completed, at the SYNC after 13), 13 (a pending
  /// fault). Called at each SYNC and from step().
  void automatic_transitions(bool at_sync, canopen::FrameSink& out) noexcept;
  [[nodiscard]] bool fault_cause_remains() const noexcept;
  /// 0x1001 from the present conditions (the fault's class, communication errors).
  void refresh_error_register() noexcept;
  /// A communication error condition (`flag`) appears (EMCY `code` once) or
  /// clears (EMCY 0000h with the remaining error register).
  void comm_error(bool& flag, bool active, std::uint16_t code, canopen::FrameSink& out) noexcept;
  /// 0x1029:1 on a communication error (EmulatorBehaviour::error_behaviour).
  void apply_error_behaviour() noexcept;
  // homing_model.cpp: the velocity homing asks for at this SYNC (strict:
  // per method family; permissive: the original one-step model). Sets
  // `stop` when the motor stops at once and may raise `amax`.
  double homing_velocity(double dt, double& amax, bool& stop) noexcept;
  void start_homing() noexcept;
  [[nodiscard]] bool homing_method_supported(std::int8_t method) const noexcept;
  /// Release delayed SDO replies that are due (step()).
  void flush_sdo_replies(canopen::FrameSink& out) noexcept;

  EmulatorConfig cfg_;
  std::vector<Entry> od_;
  std::string device_name_, hw_version_, sw_version_;
  canopen::SdoServer sdo_;
  canopen::NmtState nmt_ = canopen::NmtState::kBootUp;
  bool powered_ = false;
  std::int64_t now_ns_ = 0;
  std::int64_t next_heartbeat_ns_ = 0;
  // Heartbeat consumer (0x1016:1..4).
  struct Consumer {
    bool armed = false;
    bool lost = false;
    std::int64_t last_ns = 0;
  };
  std::array<Consumer, 4> consumers_{};

  // PDOs as currently mapped (rebuilt when the mapping becomes valid).
  std::array<canopen::PdoMap, 4> rpdo_{};
  std::array<bool, 4> rpdo_valid_{};
  std::array<std::uint8_t, 4> rpdo_active_{};  // numbers - 1 of the valid RPDOs, ascending
  std::uint8_t rpdo_active_count_ = 0;
  std::array<canopen::PdoMap, 4> tpdo_{};
  std::array<bool, 4> tpdo_valid_{};
  std::array<std::uint8_t, 4> tpdo_active_{};  // numbers - 1 of the valid TPDOs, ascending
  std::uint8_t tpdo_active_count_ = 0;
  std::array<std::uint64_t, 4> rpdo_latch_{};  // payload word (canopen::payload_word) of the latched RPDO
  std::uint8_t rpdo_pending_ = 0;              // bit p: RPDO p + 1 latched since the last SYNC
  std::array<std::uint32_t, 4> tpdo_sync_count_{};
  std::array<std::array<MappedEntry, canopen::kMaxPdoEntries>, 4> rpdo_entries_{};
  std::array<std::array<MappedEntry, canopen::kMaxPdoEntries>, 4> tpdo_entries_{};
  std::array<canopen::PdoPlan, 4> rpdo_plan_{};  // packing plans of rpdo_ / tpdo_ (rebuild_pdos)
  std::array<canopen::PdoPlan, 4> tpdo_plan_{};
  Hot hot_{};
  // service()'s receive buffer (a member so that it is not re-initialised
  // on every call; 64 frames per receive() call, more are drained in a loop).
  std::array<can::TimedFrame, 64> rx_buf_{};

  // CiA 402.
  cia402::State state_ = cia402::State::kNotReadyToSwitchOn;
  std::uint16_t last_cw_ = 0;
  /// A (state, controlword, 0x605A) for which the state machine was seen to
  /// make no transition with that controlword repeated (no edge):
  /// a repetition of it need not go through apply_controlword() (the RPDO brings the
  /// same controlword on nearly every SYNC; handle_sync() checks it before
  /// the call). A cache of a pure function.
  struct SettledControlword {
    bool valid = false;
    cia402::State state = cia402::State::kNotReadyToSwitchOn;
    std::uint16_t cw = 0;
    std::int16_t qs = 0;
  };
  SettledControlword settled_cw_{};
  std::int8_t mode_display_ = 0;
  std::uint16_t pending_fault_ = 0;
  std::uint16_t active_fault_ = 0;
  bool following_error_ = false;
  /// IP (mode 7): controlword bit 4 "enable ip mode" seen in Operation
  /// enabled; the 0x60C1:1 set points are taken (statusword bit 12).
  bool ip_active_ = false;
  std::uint32_t following_error_cycles_ = 0;
  bool homing_done_ = false;
  bool homing_active_ = false;
  bool homing_error_ = false;
  /// Phases of the strict homing model (homing_model.cpp).
  enum class HomingPhase : std::uint8_t { kIdle, kSettle, kSearchSwitch, kBackOff, kApproachEdge, kSearchIndex };
  HomingPhase homing_phase_ = HomingPhase::kIdle;
  double homing_travel_ = 0;        // counts moved since the start
  double homing_edge_ = 0;          // where the switch edge was found / the index pulse sought
  double homing_dir_ = 1.0;         // direction of the switch search (+1 / -1)
  std::uint32_t homing_settle_ = 0; // SYNCs left in kSettle
  // Strict behaviours (EmulatorBehaviour).
  std::int64_t boot_ready_ns_ = 0;          // transition 1 at this time
  std::uint32_t fault_cause_syncs_left_ = 0;
  bool fault_cause_held_ = false;
  std::int8_t mode_wanted_ = 0;             // the 0x6060 value 0x6061 is moving to
  std::uint32_t mode_countdown_ = 0;        // SYNCs until 0x6061 shows it
  bool rpdo_short_error_ = false;           // EMCY 8210h sent, not yet cleared
  bool rpdo_long_error_ = false;            // EMCY 8220h sent, not yet cleared
  bool sync_length_error_ = false;          // EMCY 8240h sent, not yet cleared
  bool sync_timeout_error_ = false;         // EMCY 8100h sent (no SYNC for 1.5 x 0x1006), not yet cleared
  std::int64_t last_sync_ns_ = -1;          // the last SYNC processed (-1: none since power-on / reset)
  std::uint8_t last_sync_counter_ = 0;      // the last SYNC's counter byte (0: none since power-on / reset / 0x1019 change)
  std::uint8_t rpdo_short_mask_ = 0;        // bit p: RPDO p + 1's last frame was short
  std::uint8_t rpdo_long_mask_ = 0;         // bit p: RPDO p + 1's last frame was long
  // TPDO event state (types 0, 254, 255).
  std::array<std::uint64_t, 4> tpdo_last_payload_{};
  std::array<std::int64_t, 4> tpdo_last_sent_ns_{};
  std::array<bool, 4> tpdo_sent_{};
  // Delayed SDO replies (EmulatorBehaviour::sdo_reply_delay_ns): a FIFO of
  // 16 (the master has one SDO transfer per drive in flight; a segmented
  // transfer adds one reply per request).
  struct DelayedFrame {
    can::Frame frame;
    std::int64_t due_ns;
  };
  std::array<DelayedFrame, 16> sdo_queue_{};
  std::size_t sdo_queue_head_ = 0, sdo_queue_size_ = 0;
  friend class DelayedSdoSink;
  // Motor.
  double pos_ = 0;
  double vel_ = 0;
  double acc_ = 0;
  double prev_demand_ = 0;
  double ramp_acc_ = 0;             // CSV ramp: acceleration of the S-curve (counts/s^2)
  bool slat_speed_ = false;         // CST SLAT: in speed control
  std::int64_t slat_held_ns_ = 0;   // CST SLAT: time the torque->speed condition has held
  double torque_ = 0;               // motor torque at the last SYNC (per mille)
  double torque_per_acc_ = 0;       // 1000 / cfg_.max_acceleration: torque (per mille) of an acceleration
  // Drive units (README "Drive units"): counts (position units) /s per unit
  // of 0x60FF, 0x60B1, 0x606C, 0x6099, 0x607F (0x60A9 with 0x60A8, 0x608F,
  // 0x6091, 0x6092) and counts/s^2 per unit of 0x6083..0x6085, 0x609A
  // (0x60AA); 1 without those objects (inc/s, inc/s^2). Refreshed on SYNC
  // from the dictionary (the master may write 0x60A9) when one of them changed.
  double vel_scale_ = 1.0;
  double acc_scale_ = 1.0;
  static constexpr std::size_t kUnitKeys = 9;
  std::uint64_t units_key_[kUnitKeys] = {~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull};
  void refresh_units() noexcept;
  static constexpr std::size_t kMaxLag = 64;  // bound of lag_cycles
  struct Setpoint {
    std::int32_t position;
    std::int32_t velocity;
    std::int16_t torque;
  };
  std::array<Setpoint, kMaxLag + 1> delay_{};
  std::size_t delay_head_ = 0;
  EmulatorCounters counters_{};
  canopen::FrameSink* out_ = nullptr;  // sink of the frame being handled (SDO writes of 0x6040)
  std::uint64_t accept_gen_ = 0;       // see accept_generation()
  /// 0x60C2 as last seen by handle_sync() and the period it gives (computed
  /// again only when 0x60C2 changes).
  struct SyncPeriod {
    cia402::InterpolationPeriod ip{};
    std::int64_t ns = 0;
    double dt = 0;
    double inv_dt = 0;  ///< 1 / dt, as 1e9 / ns (advance_motor multiplies by it)
    bool valid = false;
  };
  SyncPeriod sync_period_{};
};

}  // namespace canmotion::emulator
