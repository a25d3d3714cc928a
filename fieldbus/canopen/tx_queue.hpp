#pragma once
/// \file
/// Sizing the interface's transmit queue against one cycle's burst (sans-IO).
///
/// A SocketCAN interface queues the frames written to it in its qdisc,
/// txqueuelen frames deep (the kernel's default for CAN interfaces is 10);
/// a write to a full queue fails with ENOBUFS and the frame is lost. One
/// cycle writes all its RPDOs, the SYNC, and at most one SDO request per
/// node, the master's heartbeat and one NMT command in a burst: if the burst
/// is longer than the queue, frames are dropped in every busy cycle.
/// check_tx_queue() compares the two at start-up; the caller (config/runtime)
/// reads and raises txqueuelen (SocketCanBus) or refuses with the message.
///
/// Independently of the queue length, DriveNetwork::cycle() writes the RPDOs
/// first, then the SYNC, and only then the SDO, heartbeat and NMT frames, so
/// a queue that fills drops those (retried or repeated) and not the SYNC.
///
/// Not realtime: start-up only (the message allocates).

#include <cstdint>
#include <string>
#include <string_view>

namespace canmotion::canopen {

/// What one cycle may write on one bus.
struct TxBurst {
  std::uint32_t rpdos = 0;        ///< RPDOs of all the bus's drives (every cycle)
  std::uint32_t sdo_nodes = 0;    ///< nodes with an SDO client (at most one request frame each per cycle)
  bool master_heartbeat = false;  ///< the master produces a heartbeat
  /// Total: RPDOs + SYNC + one SDO frame per node + heartbeat + one NMT command.
  [[nodiscard]] constexpr std::uint32_t frames() const noexcept {
    return rpdos + 1 + sdo_nodes + (master_heartbeat ? 1u : 0u) + 1;
  }
  /// The part that must reach the bus every cycle: RPDOs + SYNC.
  [[nodiscard]] constexpr std::uint32_t cyclic_frames() const noexcept { return rpdos + 1; }
};

struct TxQueueCheck {
  enum class Action : std::uint8_t {
    kOk,      ///< txqueuelen holds the burst
    kRaise,   ///< raise txqueuelen to `needed`
    kRefuse,  ///< too short and may not be raised: refuse to start (message())
  };
  Action action = Action::kOk;
  std::uint32_t current = 0;  ///< txqueuelen now
  std::uint32_t needed = 0;   ///< the burst
  TxBurst burst{};
  /// One sentence with the numbers and what to run, e.g. "interface can0 has
  /// txqueuelen 10 but one cycle writes up to 14 frames (10 RPDOs, 1 SYNC, ...):
  /// run `ip link set can0 txqueuelen 14` as root before canmotiond (or give
  /// canmotiond CAP_NET_ADMIN to raise it itself)".
  [[nodiscard]] std::string message(std::string_view ifname) const;
};

/// Compare txqueuelen `current` with `burst`. `may_raise`: the caller can set
/// txqueuelen (CAP_NET_ADMIN). A burst that fits is kOk whatever may_raise,
/// and so is `current` 0 (no queue: a virtual interface such as vcan).
[[nodiscard]] TxQueueCheck check_tx_queue(std::uint32_t current, const TxBurst& burst, bool may_raise) noexcept;

}  // namespace canmotion::canopen
