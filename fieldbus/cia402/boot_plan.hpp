#pragma once
/// \file
/// The drive boot as data (DESIGN.md, drives as they are): every object the
/// DriveProxy writes or reads while it configures a node is one BootRow of
/// boot_plan(), in the order of the boot. A row says
///  - the object (index, sub-index, size) and where its value comes from;
///  - whether it applies to this drive, and whether it is required or
///    optional (Need);
///  - what each kind of SDO abort does (OnAbort: fail, tolerate quietly,
///    tolerate and say so once, or fall back on the rows that name it in
///    `falls_back_from`);
///  - what the drive's EDS decides before the boot (EdsGate);
///  - the check of the value read (BootCheck, with boot_check_rule());
///  - the sentence and configuration key that explain a refusal (BootHint,
///    WriteHints) and the sentences that say a fallback (BootNotes).
/// build_boot_transfers() expands the plan for one drive into its SDO
/// transfers (BootWrite, set-up time); DriveProxy walks them generically.
/// Adding an object to the boot is one row (and, for a new check, one
/// BootCheck with its rule) plus its test.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "fieldbus/canopen/master.hpp"  // MasterConfig
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"
#include "fieldbus/cia402/units.hpp"

namespace canmotion::cia402 {

struct DriveConfig;
struct Failure;

/// One expedited SDO write (1, 2 or 4 bytes) from the configuration.
struct SdoWrite {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t size = 4;  ///< 1, 2, 3 or 4 bytes
  std::uint32_t value = 0;
  /// DriveConfig::extra_writes: a drive without the object is fine (abort
  /// 0x06020000 / 0x06090011 accepted and said once: DriveProxy::poll_notice), e.g. a
  /// default the configuration did not ask for.
  bool optional = false;
  /// A value in the drive's velocity or acceleration unit that the
  /// configuration could not give in it (the unit is read at boot:
  /// DriveUnits::read_at_boot): `counts` holds it in counts/s (counts/s^2),
  /// and the proxy writes counts / DriveProxy::velocity_counts() (or
  /// acceleration_counts()), rounded, as UNSIGNED. `value` holds `counts`
  /// rounded (what an inc/s drive gets). kNone: `value` is written as it is.
  enum class Per : std::uint8_t { kNone, kVelocity, kAcceleration };
  Per per = Per::kNone;
  double counts = 0.0;
  /// This transfer's per-response SDO timeout (0: the client's), e.g. a
  /// store to 0x1010 that takes the drive seconds.
  std::int64_t timeout_ns = 0;
  /// A value of the drive's DCF (`drive.dcf`): left out when 0x1020 read at
  /// boot shows the configuration the DCF was made for
  /// (DriveConfig::dcf_date); the DCF's values wait for that answer.
  bool dcf = false;
  /// A typed value of any length (sdo_writes with `type:`/`file:`: strings,
  /// 64-bit, REAL, DOMAIN), prepared at set-up and only referenced by the
  /// boot (SdoClient::download_ref, block transfer when longer than 64
  /// bytes): `size`/`value` are then not written. Null: the integer form.
  /// The bytes are owned by DriveConfig::value_storage.
  const std::uint8_t* data = nullptr;
  std::uint32_t data_len = 0;
};

/// Configuration keys to name when the drive refuses a boot configuration
/// write (Failure::describe): where the value of each kind of write comes
/// from, e.g. canmotiond's YAML keys. Empty: nothing is named.
struct WriteHints {
  std::string interpolation_period;  ///< 0x60C2, e.g. "controller.period_ms"
  std::string pdo;                   ///< the PDO mapping, e.g. "axes[0].drive.pdo"
  std::string producer_heartbeat;    ///< 0x1017, e.g. "axes[0].drive.heartbeat_ms"
  std::string consumer_heartbeat;    ///< 0x1016:1, e.g. "axes[0].drive.master_heartbeat_timeout_ms" (0 leaves it out)
  std::vector<std::string> extra;    ///< one per DriveConfig::extra_writes entry, e.g. "axes[0].drive.sdo_writes[1]"
  std::string identity;              ///< DriveConfig::identity, e.g. "axes[0].drive.identity"
  std::string mode_switch_timeout;   ///< e.g. "axes[0].drive.timeouts.mode_switch_ms"
  std::string sync_counter;          ///< 0x1019, e.g. "buses[0].sync_counter_overflow"
  std::string sync_watch;            ///< 0x1006, e.g. "axes[0].drive.sync_watch"
  std::string velocity_unit;         ///< 0x60A9 written (DriveUnits::write_velocity), e.g. "axes[0].drive.units.velocity"
  std::string dcf;                   ///< 0x1020 read (DriveConfig::dcf_date), e.g. "axes[0].drive.dcf"
  std::string mode;                  ///< 0x6060 / the 0x6502 check of DriveConfig::mode, e.g. "axes[0].drive.mode: ip"
};

/// What a boot transfer is for (a label of its BootRow: Failure::sdo_origin).
enum class WriteOrigin : std::uint8_t {
  kMode,                ///< 0x6060
  kInterpolationPeriod, ///< 0x60C2:1/2
  kPdo,                 ///< communication or mapping parameter of a PDO the master uses
  kUnusedPdo,           ///< COB-ID of a PDO the master does not use, written invalid
  kProducerHeartbeat,   ///< 0x1017
  kConsumerHeartbeat,   ///< 0x1016:1
  kExtra,               ///< DriveConfig::extra_writes
  kCheck,               ///< a read at boot that checks the drive (BootCheck)
  kSyncPeriod,          ///< 0x1006 communication cycle period: 0, then the period (DriveConfig::sync_watch)
  kSyncCounter,         ///< 0x1019 synchronous counter overflow value (the master's SYNC counter)
};

/// What a read at boot checks (Failure::check for FailureKind::kBootCheck);
/// each has its rule (boot_check_rule()).
enum class BootCheck : std::uint8_t {
  kNone,
  kDeviceType,      ///< 0x1000: device profile 402 (bits 0..15), or DriveIdentity::device_type
  kVendorId,        ///< 0x1018:1 against DriveIdentity::vendor_id
  kProductCode,     ///< 0x1018:2 against DriveIdentity::product_code
  kRevision,        ///< 0x1018:3 against DriveIdentity::revision
  kSupportedModes,  ///< 0x6502 has a bit for every DriveConfig::needed_modes entry (absent: not checked)
  kModeDisplay,     ///< 0x6061 shows the mode written to 0x6060 (absent: assumed)
  /// 0x60C2:2 read after the drive refused to write it (read-only or
  /// absent): the period must be expressible in the drive's unit (`read_value`
  /// the drive's index, `expected` the period in ns).
  kInterpolationIndex,
  /// 0x1019 read after the drive refused to write it (read-only, 0x08000022
  /// while its 0x1006 != 0, ...): it must already hold the master's counter
  /// overflow value (`read_value` the drive's, `expected` the master's,
  /// `sdo_abort` the write's abort).
  kSyncCounter,
  /// 0x60A8 SI unit position, 0x608F:1/2 position encoder resolution,
  /// 0x6091:1/2 gear ratio, 0x6092:1/2 feed constant, read when the units are
  /// read at boot (DriveUnits::read_at_boot): kept for the unit checks below
  /// (absent: increments / not known / no gear / no feed). Always passes.
  kUnitFactor,
  /// 0x60A9 SI unit velocity read at boot: the counts per unit (units.hpp)
  /// with the 0x608F/0x6091 read before; a unit that cannot be interpreted
  /// fails the boot when the configuration needs it
  /// (DriveUnits::velocity_needed_by), else the velocity is not known (NaN).
  kVelocityUnit,
  kAccelerationUnit,  ///< 0x60AA SI unit acceleration, as kVelocityUnit
  /// 0x1020:1/2 verify configuration (CiA 302: configuration date and
  /// time) against the DCF's (DriveConfig::dcf_date): when both match, the
  /// drive holds that configuration and the DCF's values (SdoWrite::dcf) are
  /// not written again. Always passes (a drive without 0x1020 gets them).
  kConfigurationDate,
};

/// What the boot does with one outcome of a transfer.
enum class Then : std::uint8_t {
  kFail,           ///< the boot fails (FailureKind::kSdoAbort), naming the row's hint and key
  /// The boot fails on the transfer this one falls back from (its abort,
  /// origin, hint and key): e.g. 0x1019 that could not be read back either.
  kFailAsTrigger,
  kQuiet,          ///< tolerated (DriveProxy::tolerated_aborts()), nothing said
  kNotice,         ///< tolerated and said once (DriveProxy::poll_notice) with the row's note
  kFallBack,       ///< tolerated; the rows that fall back from this one run
};

/// A row's answer to each kind of SDO abort (CiA 301 abort codes).
struct OnAbort {
  /// 0x06020000 (object does not exist) / 0x06090011 (sub-index does not
  /// exist). kQuiet and kNotice need an optional transfer: a required one fails.
  Then absent = Then::kFail;
  Then read_only = Then::kFail;  ///< 0x06010002 attempt to write a read only object
  Then other = Then::kFail;      ///< any other abort code
  Then timeout = Then::kFail;    ///< 0x05040000 SDO protocol timed out (no answer)
  /// The answer to `a`. Realtime-safe.
  [[nodiscard]] constexpr Then of(canopen::SdoAbort a) const noexcept {
    if (a == canopen::SdoAbort::kTimeout) return timeout;
    if (canopen::object_absent(a)) return absent;
    if (a == canopen::SdoAbort::kReadOnly) return read_only;
    return other;
  }
};

/// Whether a row's transfers are required.
enum class Need : std::uint8_t {
  kRequired,    ///< a drive without the object fails its boot (unless OnAbort falls back)
  kOptional,    ///< a drive without the object is fine
  /// Optional when the configuration says so: BootRow::optional_if, or
  /// SdoWrite::optional of each transfer of an expanded row.
  kConfigured,
};

/// What the drive's EDS (DriveConfig::dictionary; none: nothing) decides
/// about a row before the boot.
enum class EdsGate : std::uint8_t {
  kOptional,  ///< an optional transfer to an object the EDS lacks is left out
  /// Left out when the EDS lacks the object, required or not, with the rows
  /// that fall back from it; when the EDS has it read-only (ro/const) not
  /// written: the rows that fall back from it run at once (reported with
  /// abort 0: "read-only in the drive's EDS").
  kWritable,
};

/// The sentence that follows a refused transfer in Failure::describe: where
/// its value comes from and what to do.
struct BootHint {
  const char* with_key = "";     ///< printf format with one %s: the key (WriteHints)
  const char* without_key = "";  ///< when no key is named
};

/// What the master does instead, said once per object (describe_notice;
/// null: "not written; the drive keeps its own setting").
struct BootNotes {
  const char* absent = nullptr;     ///< the drive lacks the object
  const char* read_only = nullptr;  ///< the drive refused the write as read-only
  /// The check of a fallback row passed: the fallback held (printf format,
  /// may hold one %d: NodeEvent::detail).
  const char* held = nullptr;
};

/// What a row's functions see of the drive: set-up time only.
struct BootInputs {
  const DriveConfig& drive;
  const DrivePdoSet& pdos;
  const canopen::MasterConfig& master;
};

/// One object the master writes or reads at boot. Rows are constant data
/// (boot_plan()); the functions run at set-up (build_boot_transfers).
struct BootRow {
  WriteOrigin origin = WriteOrigin::kMode;  ///< what it is for
  std::uint16_t index = 0;                  ///< the object (unless `expand`)
  std::uint8_t sub = 0;
  std::uint8_t size = 4;                    ///< bytes written (1, 2 or 4)
  BootCheck check = BootCheck::kNone;       ///< kNone: a write; else a read checked by its rule
  Need need = Need::kRequired;
  EdsGate gate = EdsGate::kOptional;
  OnAbort on_abort{};
  /// A fallback: the row it falls back from (relative: -1 the row before),
  /// 0 none. It runs only after that row's transfer was answered with a
  /// Then::kFallBack abort (or at once: EdsGate::kWritable), and is left out
  /// with it.
  std::int8_t falls_back_from = 0;
  /// Its value is the one the check of the transfer before it gives
  /// (CheckVerdict::next_value), e.g. 0x60C2:1 in the drive's unit.
  bool value_from_check = false;
  bool (*applies)(const BootInputs&) = nullptr;       ///< null: always
  bool (*optional_if)(const BootInputs&) = nullptr;   ///< Need::kConfigured of a one-object row
  std::uint32_t (*value)(const BootInputs&) = nullptr;  ///< the value written (null: 0)
  /// Several transfers (the PDO procedure, the extra writes): appends them
  /// instead of the one {index, sub, size, value}.
  void (*expand)(const BootInputs&, std::vector<SdoWrite>&) = nullptr;
  std::string WriteHints::* key = nullptr;               ///< the configuration key (may be null)
  std::vector<std::string> WriteHints::* keys = nullptr; ///< one key per transfer of an expanded row
  BootHint hint{};
  BootNotes notes{};
};

/// One SDO transfer of the boot configuration, in the order the proxy makes
/// them: a write (download), or with `check` set a read (upload, origin
/// WriteOrigin::kCheck) that checks the drive.
struct BootWrite {
  /// `after` of a transfer that is no fallback.
  static constexpr std::int16_t kAlways = -1;
  /// `after` of a fallback whose trigger the EDS has read-only: it runs at once.
  static constexpr std::int16_t kAtOnce = -2;

  SdoWrite w;
  WriteOrigin origin = WriteOrigin::kMode;
  std::uint16_t item = 0;   ///< its place among its row's transfers (kExtra: the DriveConfig::extra_writes entry)
  bool optional = false;    ///< a drive without the object is fine (as the row's OnAbort says)
  BootCheck check = BootCheck::kNone;  ///< not kNone: a read (upload) that checks the drive
  OnAbort on_abort{};       ///< its row's, for this transfer (an absent object fails a required one)
  /// A fallback: the transfer (index in the list) it falls back from, or
  /// kAtOnce; kAlways otherwise.
  std::int16_t after = kAlways;
  const BootRow* row = nullptr;  ///< its row (static)
  [[nodiscard]] constexpr bool is_read() const noexcept { return check != BootCheck::kNone; }
  /// Runs only after the transfer it falls back from was refused (or at once).
  [[nodiscard]] constexpr bool is_fallback() const noexcept { return after != kAlways; }
};

/// The boot plan, in boot order. Realtime-safe (constant data).
[[nodiscard]] std::span<const BootRow> boot_plan() noexcept;

/// The boot's SDO transfers for one drive: the plan's rows that apply,
/// expanded, with optional ones to objects the drive's EDS lacks left out.
/// Set-up time (allocates).
[[nodiscard]] std::vector<BootWrite> build_boot_transfers(const BootInputs& in);

/// The configuration key behind a boot transfer (from `hints`), or nullptr
/// when none is named (0x6060, unused PDOs, the checking reads). Realtime-safe.
[[nodiscard]] const std::string* write_hint_key(const WriteHints& hints, const BootWrite& w) noexcept;

/// Which of a row's BootNotes.
enum class Fallback : std::uint8_t { kAbsent, kReadOnly, kHeld };
/// The number of fallback `f` of `w` (its row and `f`; NodeEvent::note), 1..
/// Realtime-safe.
[[nodiscard]] std::uint8_t boot_note_id(const BootWrite& w, Fallback f) noexcept;
/// The note numbered `id` (boot_note_id) for object `index`: the row's
/// BootNotes, for an extra write the one of its object (e.g. SLAT), or
/// nullptr (none: "not written; the drive keeps its own setting").
/// Realtime-safe.
[[nodiscard]] const char* boot_note_text(std::uint8_t id, std::uint16_t index) noexcept;
/// True when note `id` is the kHeld note of a read that falls back from
/// nothing (e.g. a unit read at boot that nothing needs): no write was left
/// out. Realtime-safe.
[[nodiscard]] bool boot_note_of_read(std::uint8_t id) noexcept;
/// boot_note_text(boot_note_id(w, f), w.w.index). Realtime-safe.
[[nodiscard]] const char* boot_note(const BootWrite& w, Fallback f) noexcept;
/// The sentence after a refused transfer of `origin` (the rows of one origin
/// share it: plan_is_consistent). Realtime-safe.
[[nodiscard]] const BootHint& boot_hint(WriteOrigin origin) noexcept;

// ---- checks ------------------------------------------------------------------
/// The drive's factor group as read at boot (BootCheck::kUnitFactor ..
/// kAccelerationUnit) and the counts per unit it gives (DriveProxy).
struct UnitReadings {
  /// 0x60A8, 0x608F:1/2, 0x6091:1/2, 0x6092:1/2 as read (0: not read, or absent).
  units::FactorGroup factors;
  /// counts/s per unit of the velocity values, counts/s^2 per unit of the
  /// acceleration values; NaN: not known.
  double velocity_counts = 1.0;
  double acceleration_counts = 1.0;
};

/// What a check sees of a value read at boot.
struct CheckInput {
  const DriveConfig& drive;
  std::uint32_t value = 0;    ///< what the drive has
  std::uint32_t written = 0;  ///< the value of the write the row falls back from (0: none)
  std::int8_t* mode_display = nullptr;  ///< Feedback::mode_display: a check of the running mode confirms it
  std::uint16_t index = 0;    ///< the object read
  std::uint8_t sub = 0;
  UnitReadings* units = nullptr;  ///< the unit checks keep what they read here
  std::uint8_t* dcf_same = nullptr;  ///< kConfigurationDate counts the 0x1020 sub-indices that match here
};

/// A check's verdict.
struct CheckVerdict {
  enum class Is : std::uint8_t {
    kPass,
    kFail,   ///< FailureKind::kBootCheck
    /// Not yet (the drive acts asynchronously): read again, for at most
    /// `timeout_ns` since the first kAgain (<= 0: no limit), then kFail.
    kAgain,
  };
  Is is = Is::kPass;
  std::uint32_t expected = 0;        ///< kFail / kAgain: Failure::expected
  const std::string* key = nullptr;  ///< kFail / kAgain: the configuration key (Failure::hint)
  std::int64_t timeout_ns = 0;       ///< kAgain
  /// kPass of a fallback: it held; said once (BootNotes::held, NodeEvent::detail).
  bool held = false;
  std::int32_t detail = 0;
  bool has_next = false;             ///< kPass: the next transfer's value (BootRow::value_from_check)
  std::uint32_t next_value = 0;
};

/// A BootCheck: its verdict on a value and the sentence of its failure.
struct BootCheckRule {
  /// Realtime-safe.
  CheckVerdict (*verify)(const CheckInput&) noexcept = nullptr;
  /// Failure::describe for FailureKind::kBootCheck (snprintf: not realtime-safe).
  int (*describe)(const Failure&, std::span<char> out, double waited_ms) noexcept = nullptr;
};

/// The rule of `c`. Realtime-safe.
[[nodiscard]] const BootCheckRule& boot_check_rule(BootCheck c) noexcept;

}  // namespace canmotion::cia402
