#pragma once
/// \file
/// EDS and DCF files (CiA 306 "Electronic data sheet specification"): the
/// description of a CANopen device's object dictionary that vendors ship
/// with their drives, and the device configuration file an integrator makes
/// from it (DCF: ParameterValue, Denotation, [DeviceComissioning]).
///
/// The INI syntax is read by inih (Debian libinih-dev); this library
/// interprets the sections: [DeviceInfo], [MandatoryObjects] /
/// [OptionalObjects] / [ManufacturerObjects], one section per object
/// ([1018]) and per sub-index ([1018sub2]), compact arrays (CompactSubObj
/// with [xxxxName] / [xxxxValue]), [DummyUsage], [DeviceComissioning].
/// Data type numbers and names are the ones of fieldbus/canopen
/// (canopen::DataType, the one table of CiA 301 types).
///
/// Sans-IO apart from load(): parse() takes the text. Neither is meant for
/// the cyclic path (they allocate and throw); the Eds they return is
/// immutable data that the checker (check.hpp) and, later, the emulator read.
///
/// Defects that do not change what a master needs are warnings with the
/// file and line ("drive.eds:42: [6040] DataType=0x0040: unknown data type
/// ..."), as python-canopen's objectdictionary/eds.py reads past them; a
/// defect of an object is kept with the object (SubObject::defects) so that
/// the checker refuses only a use of it. Only a file that is not INI text
/// (a line without '=' or ']', a NUL, an over-long line) or cannot be read
/// is an error: all of them are thrown together as one ParseError.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "fieldbus/canopen/device_dictionary.hpp"
#include "fieldbus/canopen/object_names.hpp"

namespace canmotion::eds {

/// Object codes (CiA 301 table 42; the EDS key ObjectType).
enum class ObjectCode : std::uint8_t {
  kNull = 0x0,
  kDomain = 0x2,
  kDeftype = 0x5,
  kDefstruct = 0x6,
  kVar = 0x7,
  kArray = 0x8,
  kRecord = 0x9,
};
[[nodiscard]] std::string_view object_code_name(ObjectCode c) noexcept;

/// CiA 306 access types. rwr and rww are read-write with a hint for PDO
/// mapping: rwr is mapped into TPDOs (the device writes it), rww into RPDOs.
enum class AccessType : std::uint8_t { kRo, kWo, kRw, kRwr, kRww, kConst };
/// "ro", "wo", "rw", "rwr", "rww", "const".
[[nodiscard]] std::string_view access_type_name(AccessType a) noexcept;
/// The access an SDO client sees (rwr and rww are read-write).
[[nodiscard]] canopen::Access to_canopen(AccessType a) noexcept;
[[nodiscard]] constexpr bool readable(AccessType a) noexcept { return a != AccessType::kWo; }
[[nodiscard]] constexpr bool writable(AccessType a) noexcept {
  return a == AccessType::kWo || a == AccessType::kRw || a == AccessType::kRwr || a == AccessType::kRww;
}

/// Which object list of the file names an object.
enum class ObjectList : std::uint8_t { kNone, kMandatory, kOptional, kManufacturer };
/// "MandatoryObjects", "OptionalObjects", "ManufacturerObjects" ("" for kNone).
[[nodiscard]] std::string_view object_list_name(ObjectList l) noexcept;

/// A file position and what is wrong or notable there.
struct Diagnostic {
  std::string file;
  int line = 0;  ///< 1-based; 0 when the whole file is meant
  std::string message;
  /// "file:line: message" ("file: message" for line 0).
  [[nodiscard]] std::string to_string() const;
};

/// One value of the file (DefaultValue, ParameterValue, LowLimit, HighLimit)
/// read for its object's data type.
struct Value {
  std::string text;               ///< as written in the file
  bool node_id_relative = false;  ///< "$NODEID+0x180": the node-ID is added (integer types only)
  /// Numbers: the bit pattern in the type's width (two's complement for
  /// INTEGERn, IEEE 754 for REAL32/REAL64), without the node-ID.
  std::uint64_t bits = 0;
  /// VISIBLE_STRING and UNICODE_STRING: the text; OCTET_STRING and DOMAIN:
  /// the bytes (hex digits in the file).
  std::string data;

  /// The bits with the node-ID added when node-relative, in the type's
  /// width (`bytes`, 1..8).
  [[nodiscard]] std::uint64_t resolve(std::uint8_t node_id, std::size_t bytes) const noexcept;
  friend bool operator==(const Value&, const Value&) = default;
};

/// One sub-index (a VAR object is one SubObject with sub 0).
struct SubObject {
  std::uint8_t sub = 0;
  std::string name;  ///< ParameterName
  canopen::DataType type = canopen::DataType::kUnsigned8;
  AccessType access = AccessType::kRo;
  bool pdo_mapping = false;  ///< PDOMapping=1 (the direction follows from the access type)
  std::optional<Value> default_value;
  std::optional<Value> low_limit;
  std::optional<Value> high_limit;
  std::optional<Value> parameter_value;  ///< DCF
  std::string denotation;                ///< DCF
  std::uint32_t obj_flags = 0;
  int line = 0;  ///< its section's header line ([1018sub2], or [1000] for a VAR, [1003] for a compact entry)
  /// What makes it unusable (an unknown or missing DataType or AccessType, a
  /// malformed PDOMapping, an unreadable DefaultValue or ParameterValue):
  /// also in Eds::warnings; check() refuses a use of it naming these.
  std::vector<Diagnostic> defects;

  /// The value the device holds after configuration: the ParameterValue
  /// (DCF) when there is one, else the DefaultValue; null when neither.
  [[nodiscard]] const Value* value() const noexcept {
    return parameter_value ? &*parameter_value : (default_value ? &*default_value : nullptr);
  }

  /// Mappable into an RPDO (PDOMapping=1 and written by the master: wo, rw, rww).
  [[nodiscard]] bool rpdo_mappable() const noexcept;
  /// Mappable into a TPDO (PDOMapping=1 and read by the master: ro, rw, rwr, const).
  [[nodiscard]] bool tpdo_mappable() const noexcept;
  /// The directions it can be mapped in, as canopen's object table says it
  /// (kNo, kRpdo, kTpdo or kBoth).
  [[nodiscard]] canopen::PdoMappable pdo_direction() const noexcept;
  /// Size in bytes of the data type (0 for strings and domains).
  [[nodiscard]] std::size_t size() const noexcept { return canopen::data_type_size(type); }
};

/// One object (an index).
struct Object {
  std::uint16_t index = 0;
  std::string name;  ///< ParameterName
  ObjectCode code = ObjectCode::kVar;
  ObjectList list = ObjectList::kNone;
  std::uint16_t sub_number = 0;      ///< SubNumber: sub-index sections (ARRAY/RECORD; 0 when absent)
  std::uint8_t compact_sub_obj = 0;  ///< CompactSubObj (0 when absent)
  std::uint32_t obj_flags = 0;
  std::string denotation;  ///< DCF
  int line = 0;            ///< header line of [xxxx]
  /// What makes the whole object unusable (an unknown ObjectType): also in
  /// Eds::warnings; check() refuses a use of any of its sub-indices.
  std::vector<Diagnostic> defects;
  std::vector<SubObject> subs;  ///< ascending sub-index; a VAR or DOMAIN has sub 0 only

  [[nodiscard]] const SubObject* find(std::uint8_t sub) const noexcept;
};

/// [DeviceInfo].
struct DeviceInfo {
  std::string vendor_name;
  std::uint32_t vendor_number = 0;
  std::string product_name;
  std::uint32_t product_number = 0;
  std::uint32_t revision_number = 0;
  std::string order_code;
  std::vector<std::uint16_t> baud_rates;  ///< kbit/s with BaudRate_<n>=1, ascending
  bool simple_boot_up_master = false;
  bool simple_boot_up_slave = false;
  std::uint8_t granularity = 8;  ///< bits; 0: the PDO mapping cannot be changed
  bool dynamic_channels_supported = false;
  bool group_messaging = false;
  std::uint16_t nr_of_rxpdo = 0;
  std::uint16_t nr_of_txpdo = 0;
  bool lss_supported = false;
  int line = 0;              ///< header line of [DeviceInfo]
  int granularity_line = 0;  ///< line of Granularity= (0: absent, the default 8 applies)
  int nr_of_rxpdo_line = 0;  ///< line of NrOfRXPDO= (0: absent)
  int nr_of_txpdo_line = 0;  ///< line of NrOfTXPDO= (0: absent)
};

/// [DeviceComissioning] of a DCF (spelled so in CiA 306).
struct DeviceComissioning {
  std::uint8_t node_id = 0;   ///< NodeId 1..127 (0: absent)
  std::uint16_t baudrate = 0; ///< kbit/s (0: absent)
  std::string node_name;
  std::uint32_t net_number = 0;
  std::string network_name;
  bool canopen_manager = false;
  std::uint32_t lss_serial_number = 0;
  int line = 0;
};

/// [FileInfo] (informative).
struct FileInfo {
  std::string file_name;
  std::string file_version;
  std::string file_revision;
  std::string eds_version;
  std::string description;
  std::string created_by;
  std::string modified_by;
};

/// A malformed file: every error found, in line order. what() is their
/// to_string()s, one per line.
class ParseError : public std::runtime_error {
 public:
  explicit ParseError(std::vector<Diagnostic> errors);
  [[nodiscard]] const std::vector<Diagnostic>& errors() const noexcept { return errors_; }

 private:
  std::vector<Diagnostic> errors_;
};

/// A parsed EDS or DCF.
struct Eds {
  std::string file;  ///< the name given to parse() / the path given to load()
  FileInfo file_info;
  DeviceInfo device_info;
  std::optional<DeviceComissioning> comissioning;  ///< DCF
  std::uint32_t dummy_usage = 0;  ///< bit n: Dummy000n=1 (dummy objects 0x0001..0x0007 mappable)
  std::vector<Object> objects;    ///< ascending index
  /// Line of each list's header, [0] unused (kNone), [1] Mandatory, [2]
  /// Optional, [3] Manufacturer; 0 when the file has no such list.
  int list_lines[4] = {0, 0, 0, 0};
  /// Defects read past, as python-canopen reads past them (commissioning
  /// values, limits outside the type's range, SubNumber mismatches, keys or
  /// sections given twice, missing lists ...), each once, in line order.
  /// Defects of an object (SubObject::defects, Object::defects) are here
  /// too; check() refuses a use of such an object.
  std::vector<Diagnostic> warnings;

  [[nodiscard]] const Object* find(std::uint16_t index) const noexcept;
  [[nodiscard]] const SubObject* find(std::uint16_t index, std::uint8_t sub) const noexcept;
  /// True when the file carries DCF data ([DeviceComissioning] or a ParameterValue).
  [[nodiscard]] bool is_dcf() const noexcept;
  /// The list an object with this index belongs in by CiA 306 (0x1000,
  /// 0x1001, 0x1018 mandatory; 0x2000..0x5FFF manufacturer; others optional).
  [[nodiscard]] static ObjectList expected_list(std::uint16_t index) noexcept;
};

/// Parse EDS/DCF text; `file` names it in diagnostics. Throws ParseError.
[[nodiscard]] Eds parse(std::string_view text, std::string file = "<string>");
/// Read and parse a file. Throws ParseError (an unreadable file is one
/// Diagnostic with line 0).
[[nodiscard]] Eds load(const std::filesystem::path& path);

/// The file's objects as the master's "does the drive have it?" query sees
/// them (every sub-index with its ParameterName, data type and SDO access);
/// source() is `e.file`. Set-up only (allocates).
[[nodiscard]] canopen::DeviceDictionary device_dictionary(const Eds& e);

/// Read `text` as a value of type `t` ("0x1F", "-5", "$NODEID+0x180",
/// "1.5", hex bytes for OCTET_STRING/DOMAIN ...). On failure returns
/// nullopt and says why in `why` (e.g. "300 does not fit UNSIGNED8 (0 .. 255)").
[[nodiscard]] std::optional<Value> parse_value(std::string_view text, canopen::DataType t, std::string& why);

/// Compare two numbers of type `t` (bits as in Value): <0, 0, >0. Strings
/// and domains compare equal.
[[nodiscard]] int compare_values(canopen::DataType t, std::uint64_t a, std::uint64_t b) noexcept;

/// A number of type `t` as text: decimal for integers (signed for
/// INTEGERn), shortest round-trip decimal for REAL32/REAL64.
[[nodiscard]] std::string format_number(canopen::DataType t, std::uint64_t bits);

}  // namespace canmotion::eds
