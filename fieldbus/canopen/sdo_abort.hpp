#pragma once
/// \file
/// SDO abort codes (CiA 301 §7.2.4.3.17, table 22) with their texts. The enum
/// values are the spec numbers, sent little-endian in bytes 4..7 of an abort.

#include <array>
#include <cstdint>
#include <string_view>

namespace canmotion::canopen {

/// Every SDO abort code of CiA 301 (v4.2).
enum class SdoAbort : std::uint32_t {
  kNone = 0x00000000,                     ///< not a spec code: "no abort"
  kToggleBit = 0x05030000,                ///< toggle bit not alternated
  kTimeout = 0x05040000,                  ///< SDO protocol timed out
  kCommandSpecifier = 0x05040001,         ///< client/server command specifier not valid or unknown
  kBlockSize = 0x05040002,                ///< invalid block size (block mode only)
  kSequenceNumber = 0x05040003,           ///< invalid sequence number (block mode only)
  kCrc = 0x05040004,                      ///< CRC error (block mode only)
  kOutOfMemory = 0x05040005,              ///< out of memory
  kUnsupportedAccess = 0x06010000,        ///< unsupported access to an object
  kWriteOnly = 0x06010001,                ///< attempt to read a write-only object
  kReadOnly = 0x06010002,                 ///< attempt to write a read-only object
  kNoObject = 0x06020000,                 ///< object does not exist in the object dictionary
  kNotMappable = 0x06040041,              ///< object cannot be mapped to the PDO
  kPdoLength = 0x06040042,                ///< number and length of mapped objects would exceed PDO length
  kParameterIncompatible = 0x06040043,    ///< general parameter incompatibility reason
  kInternalIncompatible = 0x06040047,     ///< general internal incompatibility in the device
  kHardware = 0x06060000,                 ///< access failed due to a hardware error
  kTypeMismatch = 0x06070010,             ///< data type does not match, length of service parameter does not match
  kLengthTooHigh = 0x06070012,            ///< data type does not match, length of service parameter too high
  kLengthTooLow = 0x06070013,             ///< data type does not match, length of service parameter too low
  kNoSubindex = 0x06090011,               ///< sub-index does not exist
  kInvalidValue = 0x06090030,             ///< invalid value for parameter (download only)
  kValueTooHigh = 0x06090031,             ///< value of parameter written too high (download only)
  kValueTooLow = 0x06090032,              ///< value of parameter written too low (download only)
  kMaxLessThanMin = 0x06090036,           ///< maximum value is less than minimum value
  kNoResource = 0x060A0023,               ///< resource not available: SDO connection
  kGeneral = 0x08000000,                  ///< general error
  kDataTransfer = 0x08000020,             ///< data cannot be transferred or stored to the application
  kLocalControl = 0x08000021,             ///< ... because of local control
  kDeviceState = 0x08000022,              ///< ... because of the present device state
  kNoObjectDictionary = 0x08000023,       ///< object dictionary dynamic generation fails or no OD present
  kNoData = 0x08000024,                   ///< no data available
};

/// All spec abort codes (kNone excluded), in numeric order; for tests and tables.
inline constexpr std::array<SdoAbort, 31> kAllSdoAborts = {
    SdoAbort::kToggleBit, SdoAbort::kTimeout, SdoAbort::kCommandSpecifier, SdoAbort::kBlockSize,
    SdoAbort::kSequenceNumber, SdoAbort::kCrc, SdoAbort::kOutOfMemory, SdoAbort::kUnsupportedAccess,
    SdoAbort::kWriteOnly, SdoAbort::kReadOnly, SdoAbort::kNoObject, SdoAbort::kNotMappable,
    SdoAbort::kPdoLength, SdoAbort::kParameterIncompatible, SdoAbort::kInternalIncompatible,
    SdoAbort::kHardware, SdoAbort::kTypeMismatch, SdoAbort::kLengthTooHigh, SdoAbort::kLengthTooLow,
    SdoAbort::kNoSubindex, SdoAbort::kInvalidValue, SdoAbort::kValueTooHigh, SdoAbort::kValueTooLow,
    SdoAbort::kMaxLessThanMin, SdoAbort::kNoResource, SdoAbort::kGeneral, SdoAbort::kDataTransfer,
    SdoAbort::kLocalControl, SdoAbort::kDeviceState, SdoAbort::kNoObjectDictionary, SdoAbort::kNoData,
};

/// The CiA 301 text of an abort code; "unknown SDO abort code" for anything
/// else. Realtime-safe (returns static text).
/// True for the aborts by which a server says the object (or sub-index) does
/// not exist (CiA 301): what a master with a fallback for an optional object
/// tolerates.
[[nodiscard]] constexpr bool object_absent(SdoAbort a) noexcept {
  return a == SdoAbort::kNoObject || a == SdoAbort::kNoSubindex;
}

[[nodiscard]] constexpr std::string_view sdo_abort_text(std::uint32_t code) noexcept {
  switch (code) {
    case 0x00000000: return "no abort";
    case 0x05030000: return "toggle bit not alternated";
    case 0x05040000: return "SDO protocol timed out";
    case 0x05040001: return "client/server command specifier not valid or unknown";
    case 0x05040002: return "invalid block size";
    case 0x05040003: return "invalid sequence number";
    case 0x05040004: return "CRC error";
    case 0x05040005: return "out of memory";
    case 0x06010000: return "unsupported access to an object";
    case 0x06010001: return "attempt to read a write only object";
    case 0x06010002: return "attempt to write a read only object";
    case 0x06020000: return "object does not exist in the object dictionary";
    case 0x06040041: return "object cannot be mapped to the PDO";
    case 0x06040042: return "the number and length of the objects to be mapped would exceed PDO length";
    case 0x06040043: return "general parameter incompatibility reason";
    case 0x06040047: return "general internal incompatibility in the device";
    case 0x06060000: return "access failed due to a hardware error";
    case 0x06070010: return "data type does not match, length of service parameter does not match";
    case 0x06070012: return "data type does not match, length of service parameter too high";
    case 0x06070013: return "data type does not match, length of service parameter too low";
    case 0x06090011: return "sub-index does not exist";
    case 0x06090030: return "invalid value for parameter (download only)";
    case 0x06090031: return "value of parameter written too high (download only)";
    case 0x06090032: return "value of parameter written too low (download only)";
    case 0x06090036: return "maximum value is less than minimum value";
    case 0x060A0023: return "resource not available: SDO connection";
    case 0x08000000: return "general error";
    case 0x08000020: return "data cannot be transferred or stored to the application";
    case 0x08000021: return "data cannot be transferred or stored to the application because of local control";
    case 0x08000022: return "data cannot be transferred or stored to the application because of the present device state";
    case 0x08000023: return "object dictionary dynamic generation fails or no object dictionary is present";
    case 0x08000024: return "no data available";
    default: return "unknown SDO abort code";
  }
}

[[nodiscard]] constexpr std::string_view sdo_abort_text(SdoAbort a) noexcept {
  return sdo_abort_text(static_cast<std::uint32_t>(a));
}

}  // namespace canmotion::canopen
