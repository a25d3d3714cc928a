#pragma once
/// \file
/// CANopen COB-IDs of the CiA 301 pre-defined connection set and a classifier
/// that tells what an 11-bit identifier carries. Everything here is constexpr
/// and realtime-safe.

#include <cstdint>
#include <string_view>

namespace canmotion::canopen {

/// Function codes (base COB-IDs) of the pre-defined connection set (CiA 301 §7.3.5).
namespace cob {
inline constexpr std::uint32_t kNmt = 0x000;        ///< NMT command (master -> all)
inline constexpr std::uint32_t kSync = 0x080;       ///< SYNC
inline constexpr std::uint32_t kEmcyBase = 0x080;   ///< EMCY = 0x080 + node
inline constexpr std::uint32_t kTime = 0x100;       ///< TIME stamp
inline constexpr std::uint32_t kTpdo1Base = 0x180;  ///< TPDO1 = 0x180 + node (drive -> master)
inline constexpr std::uint32_t kRpdo1Base = 0x200;  ///< RPDO1 = 0x200 + node (master -> drive)
inline constexpr std::uint32_t kTpdo2Base = 0x280;
inline constexpr std::uint32_t kRpdo2Base = 0x300;
inline constexpr std::uint32_t kTpdo3Base = 0x380;
inline constexpr std::uint32_t kRpdo3Base = 0x400;
inline constexpr std::uint32_t kTpdo4Base = 0x480;
inline constexpr std::uint32_t kRpdo4Base = 0x500;
inline constexpr std::uint32_t kSdoTxBase = 0x580;      ///< SDO server -> client = 0x580 + node
inline constexpr std::uint32_t kSdoRxBase = 0x600;      ///< SDO client -> server = 0x600 + node
inline constexpr std::uint32_t kHeartbeatBase = 0x700;  ///< NMT error control (boot-up, heartbeat) = 0x700 + node
inline constexpr std::uint32_t kLssSlaveToMaster = 0x7E4;
inline constexpr std::uint32_t kLssMasterToSlave = 0x7E5;

/// Lowest and highest valid CANopen node-ID.
inline constexpr std::uint8_t kMinNode = 1;
inline constexpr std::uint8_t kMaxNode = 127;

[[nodiscard]] constexpr std::uint32_t emcy(std::uint8_t node) noexcept { return kEmcyBase + node; }
/// TPDO n (1..4) of `node`.
[[nodiscard]] constexpr std::uint32_t tpdo(std::uint8_t n, std::uint8_t node) noexcept {
  return kTpdo1Base + 0x100u * (n - 1u) + node;
}
/// RPDO n (1..4) of `node`.
[[nodiscard]] constexpr std::uint32_t rpdo(std::uint8_t n, std::uint8_t node) noexcept {
  return kRpdo1Base + 0x100u * (n - 1u) + node;
}
[[nodiscard]] constexpr std::uint32_t sdo_tx(std::uint8_t node) noexcept { return kSdoTxBase + node; }
[[nodiscard]] constexpr std::uint32_t sdo_rx(std::uint8_t node) noexcept { return kSdoRxBase + node; }
[[nodiscard]] constexpr std::uint32_t heartbeat(std::uint8_t node) noexcept { return kHeartbeatBase + node; }
}  // namespace cob

/// What an 11-bit COB-ID carries in the pre-defined connection set.
enum class FrameKind : std::uint8_t {
  kNmt,        ///< 0x000
  kSync,       ///< 0x080
  kEmcy,       ///< 0x081..0x0FF
  kTime,       ///< 0x100
  kTpdo,       ///< 0x181..0x4FF (odd function codes), pdo_number 1..4
  kRpdo,       ///< 0x201..0x57F (even function codes), pdo_number 1..4
  kSdoTx,      ///< 0x581..0x5FF: SDO response, server -> client
  kSdoRx,      ///< 0x601..0x67F: SDO request, client -> server
  kHeartbeat,  ///< 0x701..0x77F: boot-up / heartbeat / node guarding
  kLss,        ///< 0x7E4 / 0x7E5
  kUnknown,    ///< anything else (including extended IDs)
};

/// Result of classify(): kind, node-ID (0 for broadcast objects) and PDO number (1..4, else 0).
struct CobInfo {
  FrameKind kind = FrameKind::kUnknown;
  std::uint8_t node = 0;
  std::uint8_t pdo_number = 0;
  friend constexpr bool operator==(const CobInfo&, const CobInfo&) = default;
};

/// Classify an 11-bit COB-ID by the pre-defined connection set. Realtime-safe.
[[nodiscard]] constexpr CobInfo classify(std::uint32_t cob_id) noexcept {
  if (cob_id > 0x7FF) return {};
  const std::uint32_t fc = cob_id & 0x780u;
  const auto node = static_cast<std::uint8_t>(cob_id & 0x7Fu);
  if (cob_id == cob::kNmt) return {FrameKind::kNmt, 0, 0};
  if (cob_id == cob::kSync) return {FrameKind::kSync, 0, 0};
  if (cob_id == cob::kTime) return {FrameKind::kTime, 0, 0};
  if (cob_id == cob::kLssSlaveToMaster || cob_id == cob::kLssMasterToSlave) return {FrameKind::kLss, 0, 0};
  if (node == 0) return {};
  switch (fc) {
    case 0x080: return {FrameKind::kEmcy, node, 0};
    case 0x180: return {FrameKind::kTpdo, node, 1};
    case 0x200: return {FrameKind::kRpdo, node, 1};
    case 0x280: return {FrameKind::kTpdo, node, 2};
    case 0x300: return {FrameKind::kRpdo, node, 2};
    case 0x380: return {FrameKind::kTpdo, node, 3};
    case 0x400: return {FrameKind::kRpdo, node, 3};
    case 0x480: return {FrameKind::kTpdo, node, 4};
    case 0x500: return {FrameKind::kRpdo, node, 4};
    case 0x580: return {FrameKind::kSdoTx, node, 0};
    case 0x600: return {FrameKind::kSdoRx, node, 0};
    case 0x700: return {FrameKind::kHeartbeat, node, 0};
    default: return {};
  }
}

/// Short name of a frame kind ("NMT", "SYNC", "EMCY", "TPDO", "RPDO", "SDO-tx", ...). Realtime-safe.
[[nodiscard]] constexpr std::string_view frame_kind_name(FrameKind k) noexcept {
  switch (k) {
    case FrameKind::kNmt: return "NMT";
    case FrameKind::kSync: return "SYNC";
    case FrameKind::kEmcy: return "EMCY";
    case FrameKind::kTime: return "TIME";
    case FrameKind::kTpdo: return "TPDO";
    case FrameKind::kRpdo: return "RPDO";
    case FrameKind::kSdoTx: return "SDO-tx";
    case FrameKind::kSdoRx: return "SDO-rx";
    case FrameKind::kHeartbeat: return "HEARTBEAT";
    case FrameKind::kLss: return "LSS";
    case FrameKind::kUnknown: break;
  }
  return "UNKNOWN";
}

}  // namespace canmotion::canopen
