#pragma once
/// \file
/// The checker: what a master intends to do with a device (SDO writes and
/// reads, objects mapped into RPDOs and TPDOs, PDO counts, bits it needs in
/// an object such as 0x6502 supported drive modes) against the device's EDS,
/// before any frame is sent. Each refusal names the object, the EDS file and
/// line, and the configuration key that asked for the use.
///
/// Not realtime: it allocates. Pure: no I/O.
///
/// ```cpp
/// eds::Requirements req;
/// req.uses.push_back({.index = 0x1016, .sub = 1, .usage = eds::Usage::kWrite, .size = 4,
///                     .key = "drives.master_heartbeat_timeout_ms"});
/// req.uses.push_back({.index = 0x607A, .usage = eds::Usage::kMapRpdo, .size = 4, .key = "drives.pdo"});
/// req.rpdos = 1; req.tpdos = 1; req.pdo_key = "drives.pdo";
/// const eds::CheckResult r = eds::check(eds::load("drive.eds"), req);
/// for (const eds::Refusal& x : r.refusals) std::cerr << x.to_string() << '\n';
/// ```

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldbus/eds/eds.hpp"

namespace canmotion::eds {

/// What the master does with an object.
enum class Usage : std::uint8_t {
  kWrite,    ///< SDO download: the object must be writable
  kRead,     ///< SDO upload: readable
  kMapRpdo,  ///< mapped into an RPDO (the master writes it every cycle)
  kMapTpdo,  ///< mapped into a TPDO (the drive sends it)
};
[[nodiscard]] std::string_view usage_name(Usage u) noexcept;

/// One object the master intends to use.
struct Use {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  Usage usage = Usage::kWrite;
  /// Bytes the master transfers or maps (1..8); 0: any (not checked).
  std::uint8_t size = 0;
  /// A value the master writes, checked against LowLimit/HighLimit (read
  /// as the object's type: INTEGERn signed, UNSIGNEDn unsigned).
  std::optional<std::int64_t> value;
  /// Bits that must be set in the object's value (its ParameterValue, else
  /// its DefaultValue; e.g. the mode bits of 0x6502 supported drive modes,
  /// cia402::supported_mode_bit()). A file that gives no value leaves the
  /// bits to the boot, which reads the object from the device
  /// (CheckResult::deferred).
  std::uint64_t required_bits = 0;
  /// The master can do without it: an object the EDS lacks is reported in
  /// CheckResult::skipped instead of refused (other refusals still apply).
  bool optional = false;
  /// The configuration key that makes the master use the object
  /// ("axes[0].drive.sdo_writes[2]"); copied into the refusal.
  std::string key;
};

/// Everything the master intends for one device.
struct Requirements {
  std::vector<Use> uses;
  std::uint16_t rpdos = 0;  ///< RPDOs it configures (numbers 1..rpdos)
  std::uint16_t tpdos = 0;  ///< TPDOs it configures
  std::string pdo_key;      ///< the configuration key that sets the PDO counts
  /// Node-ID for $NODEID-relative values (required_bits); 0: the DCF's
  /// NodeId, else values are taken without the node-ID.
  std::uint8_t node_id = 0;
};

enum class RefusalKind : std::uint8_t {
  kMissingObject,    ///< no such index in the EDS
  kMissingSubIndex,  ///< the index exists, the sub-index does not
  kNotWritable,      ///< ro or const, and the master writes it
  kNotReadable,      ///< wo, and the master reads it
  kNotMappable,      ///< PDOMapping=0, the access type is the wrong direction, or Granularity does not allow it
  kWrongSize,        ///< the master's size differs from the data type's
  kOutOfRange,       ///< the value is outside LowLimit/HighLimit
  kMissingBits,      ///< required_bits not all set in the value (ParameterValue, else DefaultValue)
  kTooFewRpdos,      ///< NrOfRXPDO (or the 0x1400/0x1600 objects) fewer than needed
  kTooFewTpdos,      ///< NrOfTXPDO (or the 0x1800/0x1A00 objects) fewer than needed
  kDefect,           ///< the object has a defect in the file (SubObject::defects, Object::defects)
};
[[nodiscard]] std::string_view refusal_kind_name(RefusalKind k) noexcept;

/// Why the master cannot do what it intends with this device.
struct Refusal {
  RefusalKind kind = RefusalKind::kMissingObject;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::string file;  ///< the EDS
  int line = 0;      ///< where in it (the object's section, the list that lacks it, NrOfRXPDO ...); 0: whole file
  std::string key;   ///< the configuration key (Use::key, Requirements::pdo_key)
  /// What is wrong, without file and key: "0x1016:01 (Consumer heartbeat
  /// time) is not in the EDS ([OptionalObjects] does not list 0x1016)".
  std::string message;
  /// "file:line: message (set by key)".
  [[nodiscard]] std::string to_string() const;
};

struct CheckResult {
  std::vector<Refusal> refusals;  ///< in the order of the uses, PDO counts first
  std::vector<Use> skipped;       ///< optional uses whose object the EDS lacks
  /// Uses with required_bits whose object the file gives no value for: the
  /// boot reads the object from the device and refuses it then.
  std::vector<Use> deferred;
  [[nodiscard]] bool ok() const noexcept { return refusals.empty(); }
};

/// Check `req` against `eds`. Every use is checked (all refusals, not the
/// first only).
[[nodiscard]] CheckResult check(const Eds& eds, const Requirements& req);

}  // namespace canmotion::eds
