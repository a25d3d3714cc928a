#pragma once
/// \file
/// SocketCanBus: a Transport on a Linux raw CAN socket (PF_CAN/CAN_RAW).
///
/// - non-blocking socket; `send` and `receive` never block;
/// - receive filters for the COB-IDs in use (CAN_RAW_FILTER);
/// - error frames enabled (CAN_RAW_ERR_FILTER) and turned into BusEvents:
///   warning, error passive, bus-off, restarted, other error classes;
/// - a full transmit queue (ENOBUFS/EAGAIN) is counted and reported as an
///   event, never fatal;
/// - an interface that goes down (`ip link set can0 down`: ENETDOWN on a
///   write, or once on a read) is reported as kLinkDown and link_down();
///   the socket stays bound to it, every send still tries it (and fails,
///   counted in tx_errors), and the first one that gets out after
///   `ip link set can0 up` reports kLinkUp;
/// - kernel receive timestamps (SO_TIMESTAMPNS) in TimedFrame::t_ns, on
///   CLOCK_MONOTONIC by default: the kernel stamps CAN frames with
///   CLOCK_REALTIME, and receive() converts each stamp with the offset
///   between the two clocks read at that call, so a frame's time compares
///   with the cycle's clock (DESIGN.md, "Clocks"). `set_rx_clock(kRealtime)`
///   keeps the kernel's stamps (candump-compatible times for a trace tool);
/// - kernel drop counter (SO_RXQ_OVFL) reported as kRxOverflow.
///
/// `open` is not realtime-safe (it allocates and makes system calls);
/// `send`, `receive`, `poll_events`, `state` and `counters` are.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <system_error>

#include "fieldbus/can/transport.hpp"

namespace canmotion::can {

class SocketCanBus final : public Transport {
 public:
  /// The clock of TimedFrame::t_ns for received frames and of BusEvent::t_ns.
  enum class RxClock : std::uint8_t {
    kMonotonic,  ///< CLOCK_MONOTONIC (default): the clock the cyclic executive runs on
    kRealtime,   ///< CLOCK_REALTIME as stamped by the kernel (what candump prints)
  };

  /// Largest number of filters accepted by open() (the kernel allows more;
  /// 2 per node for 127 nodes plus NMT/SYNC/EMCY covers any CANopen bus).
  static constexpr std::size_t kMaxFilters = 512;
  /// Pending bus events kept between poll_events() calls; older ones are
  /// dropped (and counted in rx_dropped) when the ring is full.
  static constexpr std::size_t kEventCapacity = 64;

  /// Open `ifname` (e.g. "vcan0", "can0"). With an empty `filters` span all
  /// frames are received. On failure returns nullptr and sets `ec`; `detail`
  /// (if given) receives a sentence naming the interface and the failing call.
  static std::unique_ptr<SocketCanBus> open(std::string_view ifname, std::span<const Filter> filters,
                                            std::error_code& ec, std::string* detail = nullptr);

  /// Whether this kernel supports PF_CAN at all (false on kernels built
  /// without CAN: socket() fails with EAFNOSUPPORT).
  static bool kernel_has_can() noexcept;

  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  SendResult send(const Frame& frame) noexcept override;
  std::size_t receive(std::span<TimedFrame> out) noexcept override;
  std::size_t poll_events(std::span<BusEvent> out) noexcept override;
  [[nodiscard]] BusState state() const noexcept override { return state_; }
  [[nodiscard]] BusCounters counters() const noexcept override { return counters_; }
  [[nodiscard]] std::string_view name() const noexcept override { return name_; }
  [[nodiscard]] bool link_down() const noexcept override { return link_down_; }

  /// Choose the clock of the receive stamps (default kMonotonic). Not realtime
  /// relevant: call it once after open().
  void set_rx_clock(RxClock c) noexcept {
    rx_clock_ = c;
    last_rx_ns_ = 0;  // another scale: the order starts afresh
  }
  [[nodiscard]] RxClock rx_clock() const noexcept { return rx_clock_; }

  /// The socket, for poll()/epoll in non-RT tools that want to block.
  [[nodiscard]] int fd() const noexcept { return fd_; }
  /// The interface's transmit queue length (txqueuelen, SIOCGIFTXQLEN), or
  /// -errno. Start-up only.
  [[nodiscard]] std::int64_t tx_queue_len() const noexcept;
  /// Set txqueuelen (SIOCSIFTXQLEN; needs CAP_NET_ADMIN). 0 or errno
  /// (EPERM without the capability). Start-up only.
  int set_tx_queue_len(std::uint32_t frames) noexcept;
  /// errno of the last failed send (0 if none). Realtime-safe.
  [[nodiscard]] int last_errno() const noexcept { return last_errno_; }

  /// The error classes of an error frame (CAN_ERR_* bits) in words, e.g.
  /// "no ACK (no other node acknowledged: all drives off or unplugged, or a
  /// wrong bitrate)". Not realtime (allocates).
  static std::string error_classes_text(std::uint32_t err_class);
  /// What to do about a bus-off on `ifname` (SocketCAN keeps a bus-off
  /// interface off until it is restarted; the kernel's default restart-ms is 0).
  static std::string bus_off_advice(std::string_view ifname);
  /// Turn one error frame (id with CAN_ERR_FLAG stripped, payload) into
  /// events, updating the bus state. Exposed for golden tests. Realtime-safe.
  void handle_error_frame(std::uint32_t err_class, std::span<const std::uint8_t> data,
                          std::int64_t t_ns) noexcept;

 private:
  SocketCanBus(int fd, std::string name) noexcept;
  void push_event(const BusEvent& ev) noexcept;
  void set_state(BusState s, std::int64_t t_ns) noexcept;
  void set_link_down(bool down, int err) noexcept;

  int fd_ = -1;
  std::string name_;
  BusState state_ = BusState::kErrorActive;
  BusCounters counters_{};
  int last_errno_ = 0;
  bool link_down_ = false;  ///< ENETDOWN seen, no frame sent since
  RxClock rx_clock_ = RxClock::kMonotonic;
  std::uint32_t last_kernel_drops_ = 0;
  std::int64_t last_rx_ns_ = 0;  ///< stamp of the last frame received (receive stamps never go back)
  std::array<BusEvent, kEventCapacity> events_{};
  std::size_t ev_head_ = 0;  // next to read
  std::size_t ev_count_ = 0;
};

}  // namespace canmotion::can
