#pragma once
/// \file
/// The default PDO mappings canmotion gives a CiA 402 drive.

#include <array>
#include <cstdint>

#include "fieldbus/canopen/bus_budget.hpp"
#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::cia402 {

/// Which PDOs a CiA 402 drive gets.
enum class PdoProfile : std::uint8_t {
  /// RPDO1 = controlword + target position (6 bytes), TPDO1 = statusword +
  /// position actual (6 bytes): 2 frames per axis per cycle (CSP only).
  kCsp,
  /// kCsp plus RPDO2 = target velocity + target torque + modes of operation
  /// (7 bytes), TPDO2 = velocity actual + torque actual + modes display
  /// (7 bytes): CSP, CSV and CST with on-the-fly mode switching and the
  /// velocity/torque status, 4 frames per axis per cycle.
  kCspCsvCst,
};

/// The RPDO/TPDO maps of a profile for one node (finalized, sync type 1).
struct DrivePdoSet {
  std::array<canopen::PdoMap, 4> rpdo{};
  std::uint8_t rpdo_count = 0;
  std::array<canopen::PdoMap, 4> tpdo{};
  std::uint8_t tpdo_count = 0;
};

/// Build the default maps. With `mode` interpolated position (7) RPDO1
/// carries 0x60C1:1 (interpolation data record) where 0x607A is.
/// Realtime-safe (constexpr data only).
[[nodiscard]] DrivePdoSet default_drive_pdos(PdoProfile profile, std::uint8_t node, Mode mode = Mode::kCsp) noexcept;

/// The cyclic bus traffic of one drive with `profile` (for
/// canopen::bus_budget / canopen::max_axes), with the drive's heartbeat
/// period (0x1017, 0 = none). Realtime-safe.
[[nodiscard]] canopen::NodeTraffic node_traffic(PdoProfile profile, std::uint32_t heartbeat_ms = 0) noexcept;

}  // namespace canmotion::cia402
