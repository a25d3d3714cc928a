#pragma once
/// \file
/// Bus budget: worst-case bits per cycle on classical CAN with worst-case bit
/// stuffing, and the bus load. Convention (shared/reference/cia402.md §6):
/// 11-bit ID frames take 8s + 47 + floor((33 + 8s)/4) bits (intermission
/// included), 29-bit ID frames 8s + 67 + floor((53 + 8s)/4).
/// constexpr and realtime-safe.

#include <cstddef>
#include <cstdint>
#include <span>

namespace canmotion::canopen {

/// Worst-case length in bits of one data frame with `payload_bytes` (0..8).
[[nodiscard]] constexpr std::uint32_t frame_bits_worst_case(std::uint32_t payload_bytes, bool extended = false) noexcept {
  const std::uint32_t s = payload_bytes > 8 ? 8 : payload_bytes;
  return extended ? 8 * s + 67 + (53 + 8 * s) / 4 : 8 * s + 47 + (33 + 8 * s) / 4;
}

/// Length in bits of one data frame without any stuff bit (best case).
[[nodiscard]] constexpr std::uint32_t frame_bits_no_stuffing(std::uint32_t payload_bytes, bool extended = false) noexcept {
  const std::uint32_t s = payload_bytes > 8 ? 8 : payload_bytes;
  return (extended ? 67 : 47) + 8 * s;
}

/// The cyclic traffic of one node: the payload sizes of the PDOs exchanged
/// every cycle.
struct NodeTraffic {
  std::uint8_t rpdo_bytes[4] = {0, 0, 0, 0};
  std::uint8_t rpdo_count = 0;
  std::uint8_t tpdo_bytes[4] = {0, 0, 0, 0};
  std::uint8_t tpdo_count = 0;
  std::uint32_t heartbeat_ms = 0;  ///< the node's heartbeat period (0 = none)
};

struct BusBudgetInput {
  std::int64_t cycle_ns = 1'000'000;
  std::uint32_t bitrate = 1'000'000;
  bool sync_counter = false;          ///< SYNC carries the 1-byte counter
  std::uint32_t master_heartbeat_ms = 0;
  std::span<const NodeTraffic> nodes;
};

struct BusBudget {
  std::uint32_t frames_per_cycle = 0;    ///< cyclic frames: SYNC + PDOs
  std::uint32_t cyclic_bits = 0;         ///< worst-case bits of those frames
  double heartbeat_bits = 0;             ///< heartbeat bits per cycle, averaged over their periods
  double bits_per_cycle = 0;             ///< cyclic_bits + heartbeat_bits
  double capacity_bits = 0;              ///< bitrate x cycle
  double load_percent = 0;               ///< 100 x bits_per_cycle / capacity_bits
  [[nodiscard]] bool fits(double max_load_percent = 100.0) const noexcept { return load_percent <= max_load_percent; }
};

/// Worst-case bus budget of one cycle. Realtime-safe.
[[nodiscard]] constexpr BusBudget bus_budget(const BusBudgetInput& in) noexcept {
  BusBudget b;
  b.frames_per_cycle = 1;
  b.cyclic_bits = frame_bits_worst_case(in.sync_counter ? 1 : 0);
  const double cycle_ms = static_cast<double>(in.cycle_ns) / 1e6;
  const double hb_bits = frame_bits_worst_case(1);
  if (in.master_heartbeat_ms > 0) b.heartbeat_bits += hb_bits * cycle_ms / in.master_heartbeat_ms;
  for (const NodeTraffic& n : in.nodes) {
    for (std::uint8_t i = 0; i < n.rpdo_count && i < 4; ++i) b.cyclic_bits += frame_bits_worst_case(n.rpdo_bytes[i]);
    for (std::uint8_t i = 0; i < n.tpdo_count && i < 4; ++i) b.cyclic_bits += frame_bits_worst_case(n.tpdo_bytes[i]);
    b.frames_per_cycle += n.rpdo_count + n.tpdo_count;
    if (n.heartbeat_ms > 0) b.heartbeat_bits += hb_bits * cycle_ms / n.heartbeat_ms;
  }
  b.bits_per_cycle = b.cyclic_bits + b.heartbeat_bits;
  b.capacity_bits = static_cast<double>(in.bitrate) * static_cast<double>(in.cycle_ns) / 1e9;
  b.load_percent = b.capacity_bits > 0 ? 100.0 * b.bits_per_cycle / b.capacity_bits : 0.0;
  return b;
}

/// How many identical axes with `per_axis` traffic fit on a bus at
/// `max_load_percent` (SYNC and master heartbeat included). Realtime-safe.
[[nodiscard]] constexpr std::uint32_t max_axes(const NodeTraffic& per_axis, std::int64_t cycle_ns, std::uint32_t bitrate,
                                               double max_load_percent = 100.0, bool sync_counter = false) noexcept {
  std::uint32_t n = 0;
  NodeTraffic arr[127]{};
  for (auto& a : arr) a = per_axis;
  while (n < 127) {
    BusBudgetInput in;
    in.cycle_ns = cycle_ns;
    in.bitrate = bitrate;
    in.sync_counter = sync_counter;
    in.nodes = std::span<const NodeTraffic>(arr, n + 1);
    if (!bus_budget(in).fits(max_load_percent)) break;
    ++n;
  }
  return n;
}

}  // namespace canmotion::canopen
