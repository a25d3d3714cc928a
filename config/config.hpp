#pragma once
/// \file
/// canmotion configuration: the YAML file's data model, loading and
/// validation. Nothing here touches a bus: a configuration is fully validated
/// (keys, types, ranges, names, node ids, COB-IDs, 0x60C2 against the period,
/// bus budget) before the runtime opens anything.
///
/// Not realtime-safe: everything here runs at start-up.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "fieldbus/canopen/device_dictionary.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"
#include "fieldbus/eds/eds.hpp"
#include "motion/axis.hpp"

namespace canmotion::config {

/// Where a value came from: 1-based line and column (0 = unknown).
struct Location {
  int line = 0;
  int column = 0;
};

/// One finding of the validator. `key` is the dotted path, e.g. `axes[2].max_speed`.
struct Diagnostic {
  enum class Severity : std::uint8_t { kError, kWarning };
  Severity severity = Severity::kError;
  std::string file;
  Location where;
  std::string key;
  std::string message;
  /// `file:line:column: error: key: message`
  [[nodiscard]] std::string str() const;
};

/// Thrown by load_file/load_string when the configuration has errors. what()
/// lists every error, one per line; diagnostics() has them as data.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Diagnostic> diags);
  [[nodiscard]] const std::vector<Diagnostic>& diagnostics() const noexcept { return diags_; }

 private:
  std::vector<Diagnostic> diags_;
};

/// The period's unit conversions, here and nowhere else in config/ and
/// tools/canmotiond/: the file writes milliseconds (`controller.period_ms`),
/// the configuration keeps seconds (ControllerSettings::period_s), and the
/// controller (rt::ControllerSpec::period_ns), the drives (DriveConfig::
/// cycle_ns, 0x60C2) and the bus budget take nanoseconds, rounded to 1 ns.
[[nodiscard]] std::int64_t period_ns(double period_s) noexcept;
/// Seconds to milliseconds (`period_ms:` and the messages that name it).
[[nodiscard]] double period_ms(double period_s) noexcept;
/// `period_ms:` as read from the file, to seconds.
[[nodiscard]] double period_s_from_ms(double ms) noexcept;

/// `controller:` section.
struct ControllerSettings {
  double period_s = 0.001;  ///< cycle period; 0.25 ms .. 100 ms
  /// The period in ns (config::period_ns()).
  [[nodiscard]] std::int64_t period_ns() const noexcept { return config::period_ns(period_s); }
  /// The period in ms (config::period_ms()).
  [[nodiscard]] double period_ms() const noexcept { return config::period_ms(period_s); }
  int priority = 80;        ///< SCHED_FIFO priority 1..99; 0 = run without real-time scheduling
  int cpu = -1;             ///< CPU to pin the cyclic thread to; -1 = no affinity
  bool lock_memory = true;  ///< mlockall + stack prefault
  /// PM QoS request held on /dev/cpu_dma_latency while the cycle runs, in
  /// microseconds (0 = shallowest CPU idle state only); -1 = do not ask.
  std::int32_t cpu_dma_latency_us = 0;
  /// The SYNC first in each cycle, at wake-up, before receiving and planning
  /// (rt::ControllerSpec::sync_first); false = RPDOs, then the SYNC.
  bool sync_first = false;
  Location where;
};

/// One `buses:` entry.
struct BusSettings {
  std::string name;
  std::string interface = "sim";     ///< "sim" (in-process SimBus) or a SocketCAN interface (vcan0, can0)
  std::uint32_t bitrate = 1'000'000;  ///< bit/s, for the bus budget
  std::uint8_t master_node = 127;     ///< node id of the master's own heartbeat (0x700 + id)
  std::uint16_t master_heartbeat_ms = 100;  ///< master heartbeat producer period; 0 = off
  std::uint8_t sync_counter_overflow = 0;   ///< 0 = SYNC without counter, else 2..240
  Location where;
  [[nodiscard]] bool is_sim() const noexcept { return interface == "sim"; }
};

/// Per-node timeouts.
struct DriveTimeouts {
  std::uint32_t sdo_ms = 200;          ///< one SDO transfer
  std::uint32_t boot_ms = 5000;        ///< boot-up through configuration to NMT operational
  std::uint32_t transition_ms = 1000;  ///< one CiA 402 state transition
  std::uint32_t mode_switch_ms = 500;  ///< 0x6061 following a 0x6060 change
  std::uint32_t homing_ms = 60'000;    ///< MAH on the drive (mode 6): start to homing completed; 0 = no limit
  /// The longest an instruction waits on the drive (MSO, MSF, MDS's enable,
  /// MAFR/MASR/MGSR's fault reset) before ERR 12; 0 = drive_wait_limit_s()'s default.
  std::uint32_t wait_ms = 0;
};

/// The planner's wait limit for instructions that wait on a drive
/// (motion::AxisConfig::drive_wait_limit), in seconds: `wait_ms`, or when 0
/// the longest a drive may take with these timeouts to boot (the boot-up,
/// again after NMT reset node, the configuration to the first TPDO: 3 x
/// boot_ms), to show its mode (mode_switch_ms) and to make the enable's
/// transitions (at most 4: one out of Operation enabled, 2, 3, 4:
/// 4 x transition_ms). With the defaults 19.5 s.
[[nodiscard]] double drive_wait_limit_s(const DriveTimeouts& t) noexcept;

/// One extra SDO download done at boot, after canmotion's own configuration.
struct SdoWrite {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t size = 4;  ///< bytes: 1, 2 or 4 (integer path, `bytes` empty)
  std::int64_t value = 0;
  Location where;
  std::string type;                 ///< CiA 301 type name when given or taken from the object table ("" = integer path)
  std::vector<std::uint8_t> bytes;  ///< typed entries: the value's bytes, prepared at load (little endian)
};

/// One ParameterValue of a drive's DCF (`drive.dcf`) written at boot.
struct DcfValue {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t size = 4;      ///< bytes: 1..4
  std::uint32_t value = 0;    ///< the bits (REAL32 as IEEE 754), $NODEID resolved
  /// Longer values, strings and domains: the bytes as sent (UNICODE_STRING
  /// as UTF-16LE); empty for the 1..4-byte values above.
  std::vector<std::uint8_t> bytes;
  int line = 0;               ///< its section's line in the DCF
};

/// `drive.dcf`: the commissioning engineer's DCF (CiA 306), the drive's
/// description and the values written at boot (README "DCF download").
struct DcfSettings {
  std::string file;      ///< as written
  std::string key;       ///< "axes[0].drive.dcf" (or "drives.dcf")
  Location where;
  bool store = false;    ///< `store: true`: 0x1010:1 = "save" after the values
  std::uint32_t store_timeout_ms = 5000;
  /// Filled by check_drive_descriptions: the values written, in file order
  /// (0x1020 last), and 0x1020:1/2 when the file has both.
  std::vector<DcfValue> writes;
  bool dated = false;
  std::uint32_t date = 0;
  std::uint32_t time = 0;
};

/// `drive.identity`: what 0x1000 and 0x1018:1..3 must read at boot (unset: not compared).
struct DriveIdentitySettings {
  std::optional<std::uint32_t> device_type;
  std::optional<std::uint32_t> vendor_id;
  std::optional<std::uint32_t> product_code;
  std::optional<std::uint32_t> revision;
};

/// Drive settings: top-level `drives:` gives the defaults, an axis's own
/// `drive:` block overrides them key by key.
struct DriveSettings {
  DriveTimeouts timeouts;
  cia402::PdoProfile pdo = cia402::PdoProfile::kCsp;
  /// `mode:` the position stream's mode of operation: csp (0x6060 = 8,
  /// 0x607A, default) or ip (0x6060 = 7 interpolated position, 0x60C0 = 0
  /// linear when the drive has it, 0x60C1:1 in 0x607A's place, controlword
  /// bit 4). `mode_where`: its line (line 0: not written).
  cia402::Mode mode = cia402::Mode::kCsp;
  Location mode_where;
  std::uint16_t heartbeat_ms = 50;                ///< drive heartbeat producer (0x1017)
  std::uint16_t master_heartbeat_timeout_ms = 300;  ///< drive's consumer of the master's heartbeat (0x1016); 0 = off
  std::uint16_t following_error_window = 0;       ///< written to 0x6065 when non-zero (counts)
  std::optional<std::int16_t> quick_stop_option;  ///< written to 0x605A when given (CiA 402: 0..8 or manufacturer-specific < 0)
  std::vector<SdoWrite> sdo_writes;
  DriveIdentitySettings identity;
  /// `sync_watch:` the drive watches the master's SYNC: 0x1006 = the period
  /// (us) is written after 0x1019, and a drive that refuses it fails its
  /// boot. False (default): 0x1006 is written 0 (before 0x1019) and left so,
  /// as a drive that watches the SYNC leaves NMT operational when one cycle
  /// comes more than half a period late (CANopenNode: 1.5 x 0x1006, EMCY
  /// 8100h); the drive watches the master's heartbeat (0x1016) instead.
  bool sync_watch = false;
  /// `mds_objects:` where the drive keeps the MDS objects CiA 402 lacks
  /// (ramp velocity limits, ramp jerk, SLAT), written with `direct_control:`;
  /// the project's own 0x2010..0x2022 by default. Per object the key that
  /// placed it ("drives.mds_objects.slat_set_point", "axes[1].drive.
  /// mds_objects.slat_set_point"; empty: the default) and its location.
  cia402::MdsObjects mds_objects;
  std::array<std::string, cia402::kMdsObjectCount> mds_object_keys;
  std::array<Location, cia402::kMdsObjectCount> mds_object_where;
  /// Per MDS object: the drive's EDS has another object where this one
  /// would go (a vendor object of another name or of a non-integer type at
  /// the default 0x2010..0x2022, or at the placed address): it is not
  /// written (check_mds_objects_in_eds; a needed one refuses the file).
  std::array<bool, cia402::kMdsObjectCount> mds_not_in_eds{};
  /// master_heartbeat_timeout_ms is written in the file (not the default):
  /// then 0x1016 is required, else optional (left out for a drive whose EDS
  /// lacks it, accepted missing without an EDS).
  bool master_heartbeat_timeout_set = false;
  /// `eds:`: the drive's EDS or DCF (CiA 306) as written; `eds_path`: it
  /// resolved against the YAML file's folder; `eds_key`: "drives.eds" or
  /// "axes[i].drive.eds"; empty without one.
  std::string eds;
  std::string eds_path;
  std::string eds_key;
  Location eds_where;
  /// The parsed file and its object dictionary, filled by load_file /
  /// load_string after the check (config/eds_check.hpp); shared by the axes
  /// naming the same file. Null without `eds:`.
  std::shared_ptr<const eds::Eds> eds_data;
  std::shared_ptr<const canopen::DeviceDictionary> dictionary;
  /// `dcf:` (empty file: none). Its file is also the drive's description
  /// (eds_path and the rest above name it).
  DcfSettings dcf;
  /// `units: {velocity: inc/s | rpm}`: 0x60A9 (SI unit velocity) written at
  /// boot; the EDS must have a writable 0x60A9. `units_key` names it.
  std::optional<std::uint32_t> velocity_unit;
  std::string units_key;
  Location units_where;
  /// Drive units (README "Drive units"), set by check_drive_descriptions from
  /// the EDS/DCF (ParameterValue before DefaultValue) and `units:`: counts/s
  /// per unit of the drive's velocity values (0x60FF, 0x60B1, 0x606C, 0x6099,
  /// 0x607F, 0x6080) and counts/s^2 per unit of its acceleration values
  /// (0x6083..0x6085, 0x609A). 1 for an EDS without the object
  /// (increments); nothing when the file cannot tell: then either
  /// `units_at_boot` (no EDS, or the drive has what the file lacks: read at
  /// boot) or the unit cannot be known (`*_unknown` says why, and what needs
  /// it is refused).
  std::optional<double> velocity_counts = 1.0;
  std::string velocity_unknown;
  std::optional<double> acceleration_counts = 1.0;
  std::string acceleration_unknown;
  bool units_at_boot = false;
};

/// An axis's `direct_control:` block (MDS, seed 002): the direct command's
/// kind and the drive-side ramps and SLAT, in user units; written to the
/// drive at boot (0x6083/0x6084 and the MDS objects at DriveSettings::mds_objects,
/// by default cia402.hpp obj::kRampVelocityLimit .. kSlatTimeDelay).
/// The planner part (mode, max_torque, velocity_command) is in AxisSettings::axis.
struct DirectControlSettings {
  bool present = false;
  std::optional<double> ramp_acceleration;       ///< units/s^2 -> 0x6083
  std::optional<double> ramp_deceleration;       ///< units/s^2 -> 0x6084
  // The objects below are at DriveSettings::mds_objects (default addresses shown).
  std::optional<double> ramp_velocity_positive;  ///< units/s -> 0x2010:1
  std::optional<double> ramp_velocity_negative;  ///< units/s -> 0x2010:2
  std::optional<std::uint8_t> ramp_jerk_control; ///< % 0..100 -> 0x2011
  std::uint8_t slat_configuration = 0;           ///< 0 disabled, 1 min speed/torque, 2 max speed/torque -> 0x2020
  double slat_set_point = 0.0;                   ///< units/s -> 0x2021
  std::uint16_t slat_time_delay_ms = 0;          ///< ms -> 0x2022
  /// `slat:` is in the file. Without it the SLAT writes (SLAT disabled) are
  /// optional: a drive without 0x2020..0x2022 has no SLAT, which is what
  /// they ask for, and MDS runs with the drive's other objects.
  bool slat_set = false;
  Location where;
};

/// One `axes:` entry.
struct AxisSettings {
  std::string name;
  motion::AxisConfig axis;  ///< planner configuration (type, units, limits, homing, exception actions)
  std::string bus;          ///< AXIS_CIP_DRIVE only
  std::uint8_t node = 0;    ///< AXIS_CIP_DRIVE only: CANopen node id 1..127
  DriveSettings drive;      ///< AXIS_CIP_DRIVE only
  DirectControlSettings direct;  ///< AXIS_CIP_DRIVE only: `direct_control:` (MDS)
  Location where;
};

/// One cam point as in a Logix CAM array.
struct CamPoint {
  double master = 0.0;
  double slave = 0.0;
  bool cubic = false;  ///< segment type: false linear, true cubic
};

/// One `cams:` entry; computed (MCCP) at load by the runtime.
struct CamSettings {
  std::string name;
  std::vector<CamPoint> points;
  double start_slope = 0.0;
  double end_slope = 0.0;
  Location where;
};

/// One `arrays:` entry: a Logix array tag that programs read and write at
/// run time. CAM arrays hold MCCP's input points, CAM_PROFILE arrays receive
/// MCCP's result, REAL arrays are MAM EventDistance / CalculatedData operands.
struct ArraySettings {
  enum class Type : std::uint8_t { kCam, kCamProfile, kReal };
  /// Largest CAM / CAM_PROFILE array: bounds MCCP's run time in the cycle
  /// (O(points), ~25 ns per point measured: 4096 points ~0.1 ms, a tenth of
  /// a 1 ms cycle; see motion/cam/README.md "MCCP as an instruction").
  static constexpr std::size_t kMaxCamElements = 4096;
  // All REAL array elements together: at most rt::kMaxRealElements
  // (rt/controller/controller.hpp; they are in every status snapshot).
  std::string name;
  Type type = Type::kReal;
  std::size_t size = 0;                ///< declared dimension (elements)
  std::vector<CamPoint> cam_values;    ///< CAM: initial points (the rest are 0, linear)
  std::vector<double> real_values;     ///< REAL: initial values (the rest are 0)
  Location where;
};

/// One `coordinate_systems:` entry: a COORDINATE_SYSTEM tag (issue 14,
/// motion/instr/coord.hpp). Members are axis names, in order (1..3, distinct);
/// an axis may be a member of several systems, but only one of them may move
/// it at a time (ERR 39 at run time).
struct CoordinateSystemSettings {
  std::string name;
  std::vector<std::string> axes;
  std::vector<Location> axes_where;       ///< where each member name is
  std::vector<double> conversion_ratios;  ///< coordination units per axis unit, per member (default 1)
  std::string units = "units";            ///< coordination units name (display only)
  double max_speed = 0.0, max_accel = 0.0, max_decel = 0.0;  ///< required, > 0
  double max_accel_jerk = 0.0, max_decel_jerk = 0.0;        ///< optional (0: %ofMaximum jerk refused)
  double actual_position_tolerance = 0.0, command_position_tolerance = 0.0;
  Location where;
};

/// A whole, validated configuration.
struct Config {
  std::string path;
  ControllerSettings controller;
  std::vector<BusSettings> buses;
  std::vector<AxisSettings> axes;
  std::vector<CamSettings> cams;
  std::vector<ArraySettings> arrays;  ///< `arrays:` (CAM, CAM_PROFILE and REAL array tags)
  std::vector<CoordinateSystemSettings> coordinate_systems;  ///< `coordinate_systems:`
  std::vector<Diagnostic> warnings;  ///< e.g. bus load over 70 %

  [[nodiscard]] const BusSettings* find_bus(std::string_view name) const noexcept;
  [[nodiscard]] const AxisSettings* find_axis(std::string_view name) const noexcept;
};

/// Load and validate a file. Throws ConfigError (all errors at once) or
/// std::system_error when the file cannot be read.
[[nodiscard]] Config load_file(const std::string& path);

/// Load and validate YAML text; `name` stands for the file in messages.
[[nodiscard]] Config load_string(std::string_view yaml, const std::string& name = "<string>");

/// The closest of `candidates` to `word` by edit distance, if close enough to
/// be a plausible typo (at most a third of the word's length, min 2).
[[nodiscard]] std::optional<std::string> nearest(std::string_view word, const std::vector<std::string_view>& candidates);

/// 0x60C2 representation of a period: mantissa (0x60C2:01, 1..255) and
/// exponent (0x60C2:02, -128..63) with mantissa * 10^exponent == period
/// exactly (to 1 ns). nullopt when the period has no such form.
struct InterpolationPeriod {
  std::uint8_t mantissa = 1;
  std::int8_t exponent = -3;
};
[[nodiscard]] std::optional<InterpolationPeriod> interpolation_period(double period_s) noexcept;

}  // namespace canmotion::config
