#pragma once
/// \file
/// Names, data types, access and PDO mappability of the CiA 301 communication
/// objects and the CiA 402 objects canmotion uses (see
/// shared/reference/cia402.md §2 and §4). Used to decode SDO values and PDO
/// mapping entries in traces, and by the emulator to build its dictionary.
/// Everything here is constexpr, allocation-free and realtime-safe.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace canmotion::canopen {

/// CiA 301 static data types (the numbers are the spec's data type indices,
/// CiA 301 table 44; 0x000E and 0x0017 are reserved). Every basic type is
/// here: the EDS reader (fieldbus/eds) takes its data types from this enum.
enum class DataType : std::uint16_t {
  kBoolean = 0x0001,
  kInteger8 = 0x0002,
  kInteger16 = 0x0003,
  kInteger32 = 0x0004,
  kUnsigned8 = 0x0005,
  kUnsigned16 = 0x0006,
  kUnsigned32 = 0x0007,
  kReal32 = 0x0008,
  kVisibleString = 0x0009,
  kOctetString = 0x000A,
  kUnicodeString = 0x000B,
  kTimeOfDay = 0x000C,
  kTimeDifference = 0x000D,
  kDomain = 0x000F,
  kInteger24 = 0x0010,
  kReal64 = 0x0011,
  kInteger40 = 0x0012,
  kInteger48 = 0x0013,
  kInteger56 = 0x0014,
  kInteger64 = 0x0015,
  kUnsigned24 = 0x0016,
  kUnsigned40 = 0x0018,
  kUnsigned48 = 0x0019,
  kUnsigned56 = 0x001A,
  kUnsigned64 = 0x001B,
};

/// Every DataType above, in the order of their numbers.
inline constexpr DataType kAllDataTypes[] = {
    DataType::kBoolean,    DataType::kInteger8,      DataType::kInteger16,       DataType::kInteger32,
    DataType::kUnsigned8,  DataType::kUnsigned16,    DataType::kUnsigned32,      DataType::kReal32,
    DataType::kVisibleString, DataType::kOctetString, DataType::kUnicodeString,  DataType::kTimeOfDay,
    DataType::kTimeDifference, DataType::kDomain,    DataType::kInteger24,       DataType::kReal64,
    DataType::kInteger40,  DataType::kInteger48,     DataType::kInteger56,       DataType::kInteger64,
    DataType::kUnsigned24, DataType::kUnsigned40,    DataType::kUnsigned48,      DataType::kUnsigned56,
    DataType::kUnsigned64,
};

/// The DataType with CiA 301 number `code`, or nullopt (reserved, a
/// complex type such as 0x0020 PDO_COMMUNICATION_PARAMETER, or
/// manufacturer-specific). Realtime-safe.
[[nodiscard]] constexpr std::optional<DataType> data_type_of(std::uint16_t code) noexcept {
  for (DataType t : kAllDataTypes)
    if (static_cast<std::uint16_t>(t) == code) return t;
  return std::nullopt;
}

/// Size in bytes of a fixed-size data type; 0 for strings and domains.
[[nodiscard]] constexpr std::size_t data_type_size(DataType t) noexcept {
  switch (t) {
    case DataType::kBoolean: case DataType::kInteger8: case DataType::kUnsigned8: return 1;
    case DataType::kInteger16: case DataType::kUnsigned16: return 2;
    case DataType::kInteger24: case DataType::kUnsigned24: return 3;
    case DataType::kInteger32: case DataType::kUnsigned32: case DataType::kReal32: return 4;
    case DataType::kInteger40: case DataType::kUnsigned40: return 5;
    case DataType::kTimeOfDay: case DataType::kTimeDifference: return 6;
    case DataType::kInteger48: case DataType::kUnsigned48: return 6;
    case DataType::kInteger56: case DataType::kUnsigned56: return 7;
    case DataType::kReal64: case DataType::kInteger64: case DataType::kUnsigned64: return 8;
    default: return 0;
  }
}

/// True for the signed integer types.
[[nodiscard]] constexpr bool data_type_signed(DataType t) noexcept {
  return t == DataType::kInteger8 || t == DataType::kInteger16 || t == DataType::kInteger24 ||
         t == DataType::kInteger32 || t == DataType::kInteger40 || t == DataType::kInteger48 ||
         t == DataType::kInteger56 || t == DataType::kInteger64;
}

[[nodiscard]] constexpr std::string_view data_type_name(DataType t) noexcept {
  switch (t) {
    case DataType::kBoolean: return "BOOLEAN";
    case DataType::kInteger8: return "INTEGER8";
    case DataType::kInteger16: return "INTEGER16";
    case DataType::kInteger32: return "INTEGER32";
    case DataType::kUnsigned8: return "UNSIGNED8";
    case DataType::kUnsigned16: return "UNSIGNED16";
    case DataType::kUnsigned32: return "UNSIGNED32";
    case DataType::kReal32: return "REAL32";
    case DataType::kVisibleString: return "VISIBLE_STRING";
    case DataType::kOctetString: return "OCTET_STRING";
    case DataType::kUnicodeString: return "UNICODE_STRING";
    case DataType::kTimeOfDay: return "TIME_OF_DAY";
    case DataType::kTimeDifference: return "TIME_DIFFERENCE";
    case DataType::kDomain: return "DOMAIN";
    case DataType::kInteger24: return "INTEGER24";
    case DataType::kReal64: return "REAL64";
    case DataType::kInteger40: return "INTEGER40";
    case DataType::kInteger48: return "INTEGER48";
    case DataType::kInteger56: return "INTEGER56";
    case DataType::kInteger64: return "INTEGER64";
    case DataType::kUnsigned24: return "UNSIGNED24";
    case DataType::kUnsigned40: return "UNSIGNED40";
    case DataType::kUnsigned48: return "UNSIGNED48";
    case DataType::kUnsigned56: return "UNSIGNED56";
    case DataType::kUnsigned64: return "UNSIGNED64";
  }
  return "?";
}

/// Object access.
enum class Access : std::uint8_t { kRo, kRw, kWo, kConst };
/// PDO mappability.
enum class PdoMappable : std::uint8_t { kNo, kRpdo, kTpdo, kBoth };

/// One entry (or a range of entries) of the known-object table.
struct ObjectInfo {
  std::uint16_t index_first;
  std::uint16_t index_last;  ///< ranges such as 0x1400..0x15FF
  std::uint8_t sub_first;
  std::uint8_t sub_last;
  DataType type;
  Access access;
  PdoMappable pdo;
  std::string_view name;
};

namespace detail {
using DT = DataType;
using AC = Access;
using PM = PdoMappable;
// clang-format off
inline constexpr ObjectInfo kObjects[] = {
  // ---- CiA 301 communication profile ---------------------------------------
  {0x1000, 0x1000, 0, 0, DT::kUnsigned32, AC::kRo, PM::kNo, "Device type"},
  {0x1001, 0x1001, 0, 0, DT::kUnsigned8, AC::kRo, PM::kTpdo, "Error register"},
  {0x1003, 0x1003, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "Pre-defined error field: number of errors"},
  {0x1003, 0x1003, 1, 254, DT::kUnsigned32, AC::kRo, PM::kNo, "Pre-defined error field: standard error field"},
  {0x1005, 0x1005, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "COB-ID SYNC"},
  {0x1006, 0x1006, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "Communication cycle period"},
  {0x1007, 0x1007, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "Synchronous window length"},
  {0x1008, 0x1008, 0, 0, DT::kVisibleString, AC::kConst, PM::kNo, "Manufacturer device name"},
  {0x1009, 0x1009, 0, 0, DT::kVisibleString, AC::kConst, PM::kNo, "Manufacturer hardware version"},
  {0x100A, 0x100A, 0, 0, DT::kVisibleString, AC::kConst, PM::kNo, "Manufacturer software version"},
  {0x100C, 0x100C, 0, 0, DT::kUnsigned16, AC::kRw, PM::kNo, "Guard time"},
  {0x100D, 0x100D, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "Life time factor"},
  {0x1010, 0x1010, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Store parameters: highest sub-index supported"},
  {0x1010, 0x1010, 1, 127, DT::kUnsigned32, AC::kRw, PM::kNo, "Store parameters"},
  {0x1011, 0x1011, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Restore default parameters: highest sub-index supported"},
  {0x1011, 0x1011, 1, 127, DT::kUnsigned32, AC::kRw, PM::kNo, "Restore default parameters"},
  {0x1012, 0x1012, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "COB-ID time stamp"},
  {0x1014, 0x1014, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "COB-ID EMCY"},
  {0x1015, 0x1015, 0, 0, DT::kUnsigned16, AC::kRw, PM::kNo, "Inhibit time EMCY"},
  {0x1016, 0x1016, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Consumer heartbeat time: highest sub-index supported"},
  {0x1016, 0x1016, 1, 127, DT::kUnsigned32, AC::kRw, PM::kNo, "Consumer heartbeat time"},
  {0x1017, 0x1017, 0, 0, DT::kUnsigned16, AC::kRw, PM::kNo, "Producer heartbeat time"},
  {0x1018, 0x1018, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Identity object: highest sub-index supported"},
  {0x1018, 0x1018, 1, 1, DT::kUnsigned32, AC::kRo, PM::kNo, "Identity object: vendor-ID"},
  {0x1018, 0x1018, 2, 2, DT::kUnsigned32, AC::kRo, PM::kNo, "Identity object: product code"},
  {0x1018, 0x1018, 3, 3, DT::kUnsigned32, AC::kRo, PM::kNo, "Identity object: revision number"},
  {0x1018, 0x1018, 4, 4, DT::kUnsigned32, AC::kRo, PM::kNo, "Identity object: serial number"},
  {0x1019, 0x1019, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "Synchronous counter overflow value"},
  {0x1029, 0x1029, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Error behaviour: highest sub-index supported"},
  {0x1029, 0x1029, 1, 1, DT::kUnsigned8, AC::kRw, PM::kNo, "Error behaviour: communication error"},
  {0x1200, 0x1200, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "SDO server parameter: highest sub-index supported"},
  {0x1200, 0x1200, 1, 1, DT::kUnsigned32, AC::kRo, PM::kNo, "SDO server parameter: COB-ID client to server"},
  {0x1200, 0x1200, 2, 2, DT::kUnsigned32, AC::kRo, PM::kNo, "SDO server parameter: COB-ID server to client"},
  {0x1400, 0x15FF, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "RPDO communication parameter: highest sub-index supported"},
  {0x1400, 0x15FF, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "RPDO communication parameter: COB-ID"},
  {0x1400, 0x15FF, 2, 2, DT::kUnsigned8, AC::kRw, PM::kNo, "RPDO communication parameter: transmission type"},
  {0x1400, 0x15FF, 3, 3, DT::kUnsigned16, AC::kRw, PM::kNo, "RPDO communication parameter: inhibit time"},
  {0x1400, 0x15FF, 5, 5, DT::kUnsigned16, AC::kRw, PM::kNo, "RPDO communication parameter: event timer"},
  {0x1600, 0x17FF, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "RPDO mapping parameter: number of mapped objects"},
  {0x1600, 0x17FF, 1, 64, DT::kUnsigned32, AC::kRw, PM::kNo, "RPDO mapping parameter: mapped object"},
  {0x1800, 0x19FF, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "TPDO communication parameter: highest sub-index supported"},
  {0x1800, 0x19FF, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "TPDO communication parameter: COB-ID"},
  {0x1800, 0x19FF, 2, 2, DT::kUnsigned8, AC::kRw, PM::kNo, "TPDO communication parameter: transmission type"},
  {0x1800, 0x19FF, 3, 3, DT::kUnsigned16, AC::kRw, PM::kNo, "TPDO communication parameter: inhibit time"},
  {0x1800, 0x19FF, 5, 5, DT::kUnsigned16, AC::kRw, PM::kNo, "TPDO communication parameter: event timer"},
  {0x1800, 0x19FF, 6, 6, DT::kUnsigned8, AC::kRw, PM::kNo, "TPDO communication parameter: SYNC start value"},
  {0x1A00, 0x1BFF, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "TPDO mapping parameter: number of mapped objects"},
  {0x1A00, 0x1BFF, 1, 64, DT::kUnsigned32, AC::kRw, PM::kNo, "TPDO mapping parameter: mapped object"},
  // ---- canmotion emulator (manufacturer-specific area) ----------------------
  {0x2000, 0x2000, 0, 0, DT::kUnsigned16, AC::kRw, PM::kNo, "canmotion emulator: inject fault (EMCY code, 0 = none)"},
  // ---- canmotion drive extensions for MDS (cia402.hpp obj::kRamp* / kSlat*) ----
  {0x2010, 0x2010, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Ramp velocity limits: highest sub-index supported"},
  {0x2010, 0x2010, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Ramp velocity - positive"},
  {0x2010, 0x2010, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Ramp velocity - negative"},
  {0x2011, 0x2011, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "Ramp jerk - control (% of ramp time)"},
  {0x2020, 0x2020, 0, 0, DT::kUnsigned8, AC::kRw, PM::kNo, "SLAT configuration"},
  {0x2021, 0x2021, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "SLAT set point"},
  {0x2022, 0x2022, 0, 0, DT::kUnsigned16, AC::kRw, PM::kNo, "SLAT time delay (ms)"},
  // ---- CiA 402 drive profile --------------------------------------------------
  {0x603F, 0x603F, 0, 0, DT::kUnsigned16, AC::kRo, PM::kTpdo, "Error code"},
  {0x6040, 0x6040, 0, 0, DT::kUnsigned16, AC::kRw, PM::kRpdo, "Controlword"},
  {0x6041, 0x6041, 0, 0, DT::kUnsigned16, AC::kRo, PM::kTpdo, "Statusword"},
  {0x605A, 0x605A, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Quick stop option code"},
  {0x605B, 0x605B, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Shutdown option code"},
  {0x605C, 0x605C, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Disable operation option code"},
  {0x605D, 0x605D, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Halt option code"},
  {0x605E, 0x605E, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Fault reaction option code"},
  {0x6060, 0x6060, 0, 0, DT::kInteger8, AC::kRw, PM::kRpdo, "Modes of operation"},
  {0x6061, 0x6061, 0, 0, DT::kInteger8, AC::kRo, PM::kTpdo, "Modes of operation display"},
  {0x6062, 0x6062, 0, 0, DT::kInteger32, AC::kRo, PM::kTpdo, "Position demand value"},
  {0x6063, 0x6063, 0, 0, DT::kInteger32, AC::kRo, PM::kTpdo, "Position actual internal value"},
  {0x6064, 0x6064, 0, 0, DT::kInteger32, AC::kRo, PM::kTpdo, "Position actual value"},
  {0x6065, 0x6065, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Following error window"},
  {0x6066, 0x6066, 0, 0, DT::kUnsigned16, AC::kRw, PM::kRpdo, "Following error time out"},
  {0x6067, 0x6067, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Position window"},
  {0x6068, 0x6068, 0, 0, DT::kUnsigned16, AC::kRw, PM::kRpdo, "Position window time"},
  {0x606B, 0x606B, 0, 0, DT::kInteger32, AC::kRo, PM::kTpdo, "Velocity demand value"},
  {0x606C, 0x606C, 0, 0, DT::kInteger32, AC::kRo, PM::kTpdo, "Velocity actual value"},
  {0x6071, 0x6071, 0, 0, DT::kInteger16, AC::kRw, PM::kRpdo, "Target torque"},
  {0x6072, 0x6072, 0, 0, DT::kUnsigned16, AC::kRw, PM::kRpdo, "Max torque"},
  {0x6074, 0x6074, 0, 0, DT::kInteger16, AC::kRo, PM::kTpdo, "Torque demand"},
  {0x6076, 0x6076, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "Motor rated torque"},
  {0x6077, 0x6077, 0, 0, DT::kInteger16, AC::kRo, PM::kTpdo, "Torque actual value"},
  {0x6078, 0x6078, 0, 0, DT::kInteger16, AC::kRo, PM::kTpdo, "Current actual value"},
  {0x607A, 0x607A, 0, 0, DT::kInteger32, AC::kRw, PM::kRpdo, "Target position"},
  {0x607C, 0x607C, 0, 0, DT::kInteger32, AC::kRw, PM::kRpdo, "Home offset"},
  {0x607D, 0x607D, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Software position limit: highest sub-index supported"},
  {0x607D, 0x607D, 1, 1, DT::kInteger32, AC::kRw, PM::kNo, "Software position limit: min position limit"},
  {0x607D, 0x607D, 2, 2, DT::kInteger32, AC::kRw, PM::kNo, "Software position limit: max position limit"},
  {0x607E, 0x607E, 0, 0, DT::kUnsigned8, AC::kRw, PM::kRpdo, "Polarity"},
  {0x607F, 0x607F, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Max profile velocity"},
  {0x6080, 0x6080, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Max motor speed"},
  {0x6081, 0x6081, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Profile velocity"},
  {0x6083, 0x6083, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Profile acceleration"},
  {0x6084, 0x6084, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Profile deceleration"},
  {0x6085, 0x6085, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Quick stop deceleration"},
  {0x6086, 0x6086, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Motion profile type"},
  {0x608F, 0x608F, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Position encoder resolution: highest sub-index supported"},
  {0x608F, 0x608F, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Position encoder resolution: encoder increments"},
  {0x608F, 0x608F, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Position encoder resolution: motor revolutions"},
  {0x6091, 0x6091, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Gear ratio: highest sub-index supported"},
  {0x6091, 0x6091, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Gear ratio: motor shaft revolutions"},
  {0x6091, 0x6091, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Gear ratio: driving shaft revolutions"},
  {0x6092, 0x6092, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Feed constant: highest sub-index supported"},
  {0x6092, 0x6092, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Feed constant: feed"},
  {0x6092, 0x6092, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Feed constant: driving shaft revolutions"},
  {0x6093, 0x6093, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Position factor: highest sub-index supported"},
  {0x6093, 0x6093, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Position factor: numerator"},
  {0x6093, 0x6093, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Position factor: divisor"},
  {0x6094, 0x6094, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Velocity encoder factor: highest sub-index supported"},
  {0x6094, 0x6094, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Velocity encoder factor: numerator"},
  {0x6094, 0x6094, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Velocity encoder factor: divisor"},
  {0x6095, 0x6095, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Velocity factor 1: highest sub-index supported"},
  {0x6095, 0x6095, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Velocity factor 1: numerator"},
  {0x6095, 0x6095, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Velocity factor 1: divisor"},
  {0x6096, 0x6096, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Velocity factor 2: highest sub-index supported"},
  {0x6096, 0x6096, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Velocity factor 2: numerator"},
  {0x6096, 0x6096, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Velocity factor 2: divisor"},
  {0x6097, 0x6097, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Acceleration factor: highest sub-index supported"},
  {0x6097, 0x6097, 1, 1, DT::kUnsigned32, AC::kRw, PM::kNo, "Acceleration factor: numerator"},
  {0x6097, 0x6097, 2, 2, DT::kUnsigned32, AC::kRw, PM::kNo, "Acceleration factor: divisor"},
  {0x6098, 0x6098, 0, 0, DT::kInteger8, AC::kRw, PM::kRpdo, "Homing method"},
  {0x6099, 0x6099, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Homing speeds: highest sub-index supported"},
  {0x6099, 0x6099, 1, 1, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Homing speeds: speed during search for switch"},
  {0x6099, 0x6099, 2, 2, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Homing speeds: speed during search for zero"},
  {0x609A, 0x609A, 0, 0, DT::kUnsigned32, AC::kRw, PM::kRpdo, "Homing acceleration"},
  {0x60A8, 0x60A8, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "SI unit position"},
  {0x60A9, 0x60A9, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "SI unit velocity"},
  {0x60AA, 0x60AA, 0, 0, DT::kUnsigned32, AC::kRw, PM::kNo, "SI unit acceleration"},
  {0x60B0, 0x60B0, 0, 0, DT::kInteger32, AC::kRw, PM::kRpdo, "Position offset"},
  {0x60B1, 0x60B1, 0, 0, DT::kInteger32, AC::kRw, PM::kRpdo, "Velocity offset"},
  {0x60B2, 0x60B2, 0, 0, DT::kInteger16, AC::kRw, PM::kRpdo, "Torque offset"},
  {0x60C0, 0x60C0, 0, 0, DT::kInteger16, AC::kRw, PM::kNo, "Interpolation sub mode select"},
  {0x60C1, 0x60C1, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Interpolation data record: highest sub-index supported"},
  {0x60C1, 0x60C1, 1, 1, DT::kInteger32, AC::kRw, PM::kRpdo, "Interpolation data record: position set point"},
  {0x60C2, 0x60C2, 0, 0, DT::kUnsigned8, AC::kRo, PM::kNo, "Interpolation time period: highest sub-index supported"},
  {0x60C2, 0x60C2, 1, 1, DT::kUnsigned8, AC::kRw, PM::kNo, "Interpolation time period: value"},
  {0x60C2, 0x60C2, 2, 2, DT::kInteger8, AC::kRw, PM::kNo, "Interpolation time period: index"},
  {0x60F4, 0x60F4, 0, 0, DT::kInteger32, AC::kRo, PM::kTpdo, "Following error actual value"},
  {0x60FD, 0x60FD, 0, 0, DT::kUnsigned32, AC::kRo, PM::kTpdo, "Digital inputs"},
  {0x60FF, 0x60FF, 0, 0, DT::kInteger32, AC::kRw, PM::kRpdo, "Target velocity"},
  {0x6502, 0x6502, 0, 0, DT::kUnsigned32, AC::kRo, PM::kNo, "Supported drive modes"},
};
// clang-format on
}  // namespace detail

/// The known-object table (entries may cover index and sub-index ranges).
[[nodiscard]] constexpr std::span<const ObjectInfo> known_objects() noexcept { return detail::kObjects; }

/// Description of index:sub, or nullptr when the object is not in the table.
/// Realtime-safe (linear scan of a constexpr table).
[[nodiscard]] constexpr const ObjectInfo* object_info(std::uint16_t index, std::uint8_t sub) noexcept {
  for (const ObjectInfo& o : detail::kObjects) {
    if (index >= o.index_first && index <= o.index_last && sub >= o.sub_first && sub <= o.sub_last) return &o;
  }
  return nullptr;
}

/// Name of index:sub ("Controlword", "TPDO mapping parameter: mapped object",
/// ...); "" when unknown. Realtime-safe.
[[nodiscard]] constexpr std::string_view object_name(std::uint16_t index, std::uint8_t sub) noexcept {
  const ObjectInfo* o = object_info(index, sub);
  return o != nullptr ? o->name : std::string_view{};
}

/// A decoded PDO mapping entry `(index << 16) | (sub << 8) | bits`.
struct MappingEntry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
  [[nodiscard]] constexpr std::uint32_t raw() const noexcept {
    return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(sub) << 8) | bits;
  }
  friend constexpr bool operator==(const MappingEntry&, const MappingEntry&) = default;
};

[[nodiscard]] constexpr MappingEntry decode_mapping_entry(std::uint32_t raw) noexcept {
  return MappingEntry{static_cast<std::uint16_t>(raw >> 16), static_cast<std::uint8_t>((raw >> 8) & 0xFF),
                      static_cast<std::uint8_t>(raw & 0xFF)};
}

}  // namespace canmotion::canopen
