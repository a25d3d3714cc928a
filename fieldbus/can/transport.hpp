#pragma once
/// \file
/// The transport interface every CAN bus implements: SocketCanBus (a raw
/// SocketCAN socket) and the in-process SimBus endpoints. The controller's
/// cyclic thread calls only `send`, `receive` and `poll_events`, all
/// realtime-safe: no allocation, no locks, no exceptions, never blocking.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "fieldbus/can/frame.hpp"

namespace canmotion::can {

/// Result of queuing one frame for transmission.
enum class SendResult : std::uint8_t {
  kOk = 0,
  kQueueFull = 1,  ///< transmit queue full (ENOBUFS/EAGAIN): counted, not fatal
  kBusOff = 2,     ///< controller is bus-off; frame dropped
  kError = 3,      ///< any other failure (ENETDOWN: the interface is down, see Transport::link_down())
};

/// Controller error state, from error frames (SocketCAN) or fault injection (SimBus).
enum class BusState : std::uint8_t {
  kErrorActive = 0,
  kErrorWarning = 1,
  kErrorPassive = 2,
  kBusOff = 3,
};

/// Something that happened on a bus other than a data frame.
struct BusEvent {
  enum class Kind : std::uint8_t {
    kStateChanged,   ///< `state` holds the new BusState
    kRestarted,      ///< controller restarted after bus-off
    kTxQueueFull,    ///< a send hit ENOBUFS/EAGAIN
    kRxOverflow,     ///< frames lost in the receive path (kernel drop counter or ring full)
    kErrorFrame,     ///< other error-frame class bits in `detail` (CAN_ERR_* mask)
    kLinkDown,       ///< the interface is down (`ip link set can0 down`): a send or receive failed
                     ///< with ENETDOWN, whose value is in `detail`; see Transport::link_down()
    kLinkUp,         ///< the first frame sent since kLinkDown went out: the interface is up again
  };
  Kind kind = Kind::kStateChanged;
  BusState state = BusState::kErrorActive;
  std::uint32_t detail = 0;
  std::int64_t t_ns = 0;
};

/// Running totals for one bus endpoint.
struct BusCounters {
  std::uint64_t tx_frames = 0;
  std::uint64_t rx_frames = 0;
  std::uint64_t tx_queue_full = 0;
  std::uint64_t tx_errors = 0;
  std::uint64_t rx_dropped = 0;
  std::uint64_t error_frames = 0;
};

/// One receive filter: a frame passes when (id & mask) == (filter.id & mask).
/// `extended` selects 29-bit ids. Mirrors struct can_filter (SocketCanBus
/// hands it to the kernel); a plain value type, no socket header.
struct Filter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0x7FF;
  bool extended = false;
};

/// One endpoint on a CAN bus.
class Transport {
 public:
  virtual ~Transport() = default;

  /// Queue one frame. Realtime-safe, never blocks.
  virtual SendResult send(const Frame& frame) noexcept = 0;

  /// Move up to `out.size()` received data frames into `out`, oldest first,
  /// and return how many. Error frames are not returned here: they update the
  /// bus state and appear in poll_events(). Realtime-safe, never blocks.
  virtual std::size_t receive(std::span<TimedFrame> out) noexcept = 0;

  /// Move up to `out.size()` pending bus events into `out`; returns the count.
  /// Realtime-safe.
  virtual std::size_t poll_events(std::span<BusEvent> out) noexcept = 0;

  [[nodiscard]] virtual BusState state() const noexcept = 0;
  [[nodiscard]] virtual BusCounters counters() const noexcept = 0;
  /// Interface name as it appears in traces ("vcan0", "sim0").
  [[nodiscard]] virtual std::string_view name() const noexcept = 0;
  /// Whether the interface is down: a send (or receive) failed with
  /// ENETDOWN and no send has succeeded since. send() keeps trying the
  /// interface (and fails) while it is down; the first frame it gets out
  /// again ends it (kLinkUp). Realtime-safe.
  [[nodiscard]] virtual bool link_down() const noexcept { return false; }
};

}  // namespace canmotion::can
