#pragma once
/// \file
/// EMCY frames (CiA 301 §7.2.7): decode/encode, the standard error-code texts
/// (CiA 301 and the CiA 402 drive codes) and the error register (0x1001) bits.
/// Everything here is constexpr and realtime-safe.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/cob_id.hpp"

namespace canmotion::canopen {

/// Error register (0x1001) bits, byte 2 of an EMCY frame.
enum ErrorRegisterBit : std::uint8_t {
  kErrGeneric = 0x01,
  kErrCurrent = 0x02,
  kErrVoltage = 0x04,
  kErrTemperature = 0x08,
  kErrCommunication = 0x10,
  kErrDeviceProfile = 0x20,
  kErrReserved = 0x40,
  kErrManufacturer = 0x80,
};

/// Name of error register bit `bit` (0..7).
[[nodiscard]] constexpr std::string_view error_register_bit_name(unsigned bit) noexcept {
  constexpr std::array<std::string_view, 8> names = {
      "generic", "current", "voltage", "temperature", "communication", "device profile", "reserved", "manufacturer"};
  return bit < 8 ? names[bit] : std::string_view{"invalid"};
}

/// Well-known EMCY error codes used by canmotion.
namespace emcy_code {
inline constexpr std::uint16_t kNoError = 0x0000;          ///< error reset / no error
inline constexpr std::uint16_t kGeneric = 0x1000;
inline constexpr std::uint16_t kContinuousOverCurrent = 0x2310;
inline constexpr std::uint16_t kDcLinkOverVoltage = 0x3210;
inline constexpr std::uint16_t kExcessDriveTemperature = 0x4310;
inline constexpr std::uint16_t kCommunication = 0x8100;   ///< generic communication error (CANopenNode: SYNC timeout)
inline constexpr std::uint16_t kCanOverrun = 0x8110;
inline constexpr std::uint16_t kCanErrorPassive = 0x8120;
inline constexpr std::uint16_t kHeartbeatError = 0x8130;   ///< life guard / heartbeat consumer timeout
inline constexpr std::uint16_t kBusOffRecovered = 0x8140;
inline constexpr std::uint16_t kPdoLength = 0x8210;
inline constexpr std::uint16_t kPdoLengthExceeded = 0x8220;
inline constexpr std::uint16_t kUnexpectedSyncLength = 0x8240;
inline constexpr std::uint16_t kRpdoTimeout = 0x8250;
inline constexpr std::uint16_t kFollowingError = 0x8611;   ///< CiA 402
}  // namespace emcy_code

/// Standard text for an EMCY error code: an exact CiA 301 / CiA 402 code
/// when known, otherwise the text of its class (0x23xx "current, device output
/// side", 0x2xxx "current", ...). Realtime-safe.
[[nodiscard]] constexpr std::string_view emcy_code_text(std::uint16_t code) noexcept {
  switch (code) {
    case 0x0000: return "error reset or no error";
    case 0x1000: return "generic error";
    case 0x2310: return "continuous over-current";
    case 0x2320: return "short circuit/earth leakage (motor side)";
    case 0x2350: return "load level fault (I2t, thermal state)";
    case 0x3110: return "mains over-voltage";
    case 0x3120: return "mains under-voltage";
    case 0x3210: return "DC link over-voltage";
    case 0x3220: return "DC link under-voltage";
    case 0x4210: return "excess temperature device";
    case 0x4310: return "excess temperature drive";
    case 0x5113: return "supply low voltage (5 V)";
    case 0x5530: return "data storage (EEPROM) fault";
    case 0x6010: return "software reset (watchdog)";
    case 0x6320: return "parameter error";
    case 0x7121: return "motor blocked";
    case 0x7122: return "motor error or commutation malfunction";
    case 0x7303: return "resolver 1 fault";
    case 0x7305: return "incremental sensor 1 fault";
    case 0x7310: return "speed sensor error";
    case 0x7320: return "position sensor error";
    case 0x8100: return "communication (generic)";
    case 0x8110: return "CAN overrun (objects lost)";
    case 0x8120: return "CAN in error passive mode";
    case 0x8130: return "life guard error or heartbeat error";
    case 0x8140: return "recovered from bus off";
    case 0x8150: return "CAN-ID collision";
    case 0x8210: return "PDO not processed due to length error";
    case 0x8220: return "PDO length exceeded";
    case 0x8230: return "DAM MPDO not processed, destination object not available";
    case 0x8240: return "unexpected SYNC data length";
    case 0x8250: return "RPDO timeout";
    case 0x8311: return "excess torque";
    case 0x8400: return "velocity speed controller error";
    case 0x8500: return "position controller error";
    case 0x8600: return "positioning controller error";
    case 0x8611: return "following error";
    case 0x8612: return "reference limit";
    case 0xF001: return "deceleration";
    default: break;
  }
  switch (code >> 8) {
    case 0x21: return "current, device input side";
    case 0x22: return "current inside the device";
    case 0x23: return "current, device output side";
    case 0x31: return "mains voltage";
    case 0x32: return "voltage inside the device";
    case 0x33: return "output voltage";
    case 0x41: return "ambient temperature";
    case 0x42: return "device temperature";
    case 0x61: return "internal software";
    case 0x62: return "user software";
    case 0x63: return "data set";
    case 0x81: return "communication";
    case 0x82: return "protocol error";
    case 0xFF: return "device specific";
    default: break;
  }
  switch (code >> 12) {
    case 0x0: return "error reset or no error";
    case 0x1: return "generic error";
    case 0x2: return "current";
    case 0x3: return "voltage";
    case 0x4: return "temperature";
    case 0x5: return "device hardware";
    case 0x6: return "device software";
    case 0x7: return "additional modules";
    case 0x8: return "monitoring";
    case 0x9: return "external error";
    case 0xF: return "additional functions";
    default: return "unknown error code";
  }
}

/// A decoded EMCY message.
struct Emcy {
  std::uint8_t node = 0;
  std::uint16_t code = 0;           ///< emergency error code, bytes 0-1 LE
  std::uint8_t error_register = 0;  ///< 0x1001, byte 2
  std::array<std::uint8_t, 5> vendor{};  ///< manufacturer-specific, bytes 3-7
  friend constexpr bool operator==(const Emcy&, const Emcy&) = default;
};

/// Decode an EMCY frame (ID 0x081..0x0FF). Short frames are accepted with the
/// missing bytes read as 0 (some devices send DLC < 8); a frame shorter than 2
/// bytes or on another ID gives nullopt. Realtime-safe.
[[nodiscard]] constexpr std::optional<Emcy> decode_emcy(const can::Frame& f) noexcept {
  const CobInfo c = classify(f.id);
  if (f.extended() || f.remote() || c.kind != FrameKind::kEmcy || f.len < 2) return std::nullopt;
  Emcy e;
  e.node = c.node;
  e.code = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
  e.error_register = f.len > 2 ? f.data[2] : 0;
  for (std::size_t i = 0; i < 5; ++i) e.vendor[i] = (3 + i < f.len) ? f.data[3 + i] : 0;
  return e;
}

/// Build the 8-byte EMCY frame of `e` (ID 0x080 + e.node). Realtime-safe.
[[nodiscard]] constexpr can::Frame make_emcy_frame(const Emcy& e) noexcept {
  can::Frame f;
  f.id = cob::emcy(e.node);
  f.len = 8;
  f.data[0] = static_cast<std::uint8_t>(e.code & 0xFF);
  f.data[1] = static_cast<std::uint8_t>(e.code >> 8);
  f.data[2] = e.error_register;
  for (std::size_t i = 0; i < 5; ++i) f.data[3 + i] = e.vendor[i];
  return f;
}

}  // namespace canmotion::canopen
