#pragma once
/// \file
/// What a CANopen master receives from its nodes, as the exact-id receive
/// filters of its bus (sans-IO: plain values; SocketCanBus gives them to the
/// kernel so that it drops everything else, e.g. other masters' RPDOs). One
/// list for DriveNetwork::receive_filters() and the daemon's bus set-up
/// (config/runtime.cpp).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fieldbus/can/transport.hpp"
#include "fieldbus/canopen/cob_id.hpp"

namespace canmotion::canopen {

/// The standard identifiers the master takes from `node`: its EMCY, TPDO1..4,
/// SDO responses and NMT error control (boot-up, heartbeat), in this order.
[[nodiscard]] constexpr std::array<std::uint32_t, 7> master_receive_ids(std::uint8_t node) noexcept {
  return {cob::emcy(node),   cob::tpdo(1, node),   cob::tpdo(2, node),   cob::tpdo(3, node),
          cob::tpdo(4, node), cob::sdo_tx(node), cob::heartbeat(node)};
}

/// One exact-id filter (mask 0x7FF) per master_receive_ids() id of each of
/// `nodes`, node by node (set-up time: allocates).
[[nodiscard]] inline std::vector<can::Filter> master_receive_filters(std::span<const std::uint8_t> nodes) {
  std::vector<can::Filter> f;
  f.reserve(nodes.size() * 7);
  for (const std::uint8_t n : nodes)
    for (const std::uint32_t id : master_receive_ids(n)) f.push_back(can::Filter{id, 0x7FF, false});
  return f;
}

}  // namespace canmotion::canopen
