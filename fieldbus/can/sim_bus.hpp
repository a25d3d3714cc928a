#pragma once
/// \file
/// SimBus: a deterministic in-process CAN bus for tests and simulations.
///
/// Several endpoints (each a can::Transport) share one broadcast medium: a
/// frame sent by one endpoint is delivered to every other endpoint (not back
/// to the sender, like a SocketCAN socket without CAN_RAW_RECV_OWN_MSGS).
/// There is no thread and no wall clock: the owner sets the virtual time with
/// set_time(); frames are stamped with it. Fault injection rules per COB-ID
/// drop, delay or corrupt frames so that tests reproduce bus faults exactly.
///
/// Threading: single-threaded by design (one simulation loop drives the
/// master and the emulated drives). Endpoint::send/receive/poll_events are
/// realtime-safe (fixed-size rings allocated when the endpoint is added).

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/can/transport.hpp"

namespace canmotion::can {

/// A fault injection rule. A rule matches frames whose id equals `cob_id`
/// (or every frame when `cob_id == kAnyId`); it skips the first `skip`
/// matches, then acts on the next `count` matches (0 = on every later match).
struct SimFault {
  static constexpr std::uint32_t kAnyId = 0xFFFFFFFF;
  enum class Action : std::uint8_t {
    kDrop,     ///< the frame never reaches the wire
    kDelay,    ///< the frame is delivered `delay_ns` later
    kCorrupt,  ///< payload byte `byte` is XORed with `xor_mask`; `len` replaced if `new_len` >= 0
  };
  std::uint32_t cob_id = kAnyId;
  Action action = Action::kDrop;
  std::uint64_t skip = 0;
  std::uint64_t count = 1;
  std::int64_t delay_ns = 0;
  std::uint8_t byte = 0;
  std::uint8_t xor_mask = 0xFF;
  int new_len = -1;
};

/// Totals of the whole bus.
struct SimBusCounters {
  std::uint64_t sent = 0;       ///< frames handed to send()
  std::uint64_t delivered = 0;  ///< frames that reached the wire (each counted once)
  std::uint64_t dropped = 0;    ///< dropped by fault injection
  std::uint64_t delayed = 0;
  std::uint64_t corrupted = 0;
};

class SimBus {
 public:
  /// Receive ring per endpoint; bounds the frames one endpoint may have
  /// pending between two receive() calls (a 127-node bus at one cycle needs
  /// < 600, 4096 leaves room for SDO bursts and delayed frames).
  static constexpr std::size_t kDefaultRxCapacity = 4096;
  static constexpr std::size_t kEventCapacity = 64;

  class Endpoint final : public Transport {
   public:
    SendResult send(const Frame& frame) noexcept override;
    std::size_t receive(std::span<TimedFrame> out) noexcept override;
    std::size_t poll_events(std::span<BusEvent> out) noexcept override;
    [[nodiscard]] BusState state() const noexcept override;
    [[nodiscard]] BusCounters counters() const noexcept override { return counters_; }
    [[nodiscard]] std::string_view name() const noexcept override { return name_; }
    /// Frames waiting in this endpoint's receive ring.
    [[nodiscard]] std::size_t pending() const noexcept { return rx_count_; }
    /// The oldest waiting frames in place (the ring's first contiguous run;
    /// empty when nothing waits), for an owner that handles them one by one
    /// without copying them out (Emulator::service); consume(n) then removes
    /// the first n, as receive() would have returned them. The span stays
    /// valid until consume() or the next receive(): what this endpoint sends
    /// meanwhile never comes back to it. Realtime-safe.
    [[nodiscard]] std::span<const TimedFrame> peek() const noexcept {
      const std::size_t run = capacity_ - rx_head_;
      return {rx_.data() + rx_head_, rx_count_ < run ? rx_count_ : run};
    }
    void consume(std::size_t n) noexcept;
    /// Acceptance filter, like a CAN controller's or a SocketCAN filter list:
    /// once set, only standard (11-bit) data frames whose id has its bit set
    /// in `ids` (bit id % 64 of word id / 64) reach this endpoint; extended
    /// and error frames never do. A frame whose id is in `openers` (e.g. an
    /// SDO request that may change what the owner listens to) lets every
    /// later frame through until receive() has emptied the ring; the owner
    /// then sets the filter again. For an owner that ignores every other
    /// frame anyway (SimWorld's emulated drives), so that they are not copied
    /// for nothing. Default: no filter. Realtime-safe.
    using IdSet = std::array<std::uint64_t, 2048 / 64>;
    void set_accept(const IdSet& ids, const IdSet& openers) noexcept {
      accept_ = ids;
      openers_ = openers;
      filtered_ = true;
      update_gate();
    }
    void clear_accept() noexcept {
      filtered_ = open_ = false;
      update_gate();
    }
    /// Take this endpoint's interface down or up, as `ip link set can0
    /// down|up` does to a SocketCAN socket's: while down nothing reaches it
    /// and send() fails (kError, counted in tx_errors); the first refused
    /// send reports kLinkDown (detail ENETDOWN) and link_down(), the first
    /// send that gets out after it is up again kLinkUp. Realtime-safe.
    void set_link(bool up) noexcept {
      cut_ = !up;
      update_gate();
    }
    [[nodiscard]] bool link_down() const noexcept override { return link_down_; }

   private:
    friend class SimBus;
    Endpoint(SimBus& bus, std::string name, std::size_t capacity);
    /// `word`/`bit`: where f's id sits in the filter sets (0 for an extended or error frame).
    void push(const Frame& f, std::int64_t t_ns, std::size_t word, std::uint64_t bit) noexcept;
    void push_event(const BusEvent& e) noexcept;
    /// gate_: the set a standard data frame's id must be in to reach the
    /// ring now: accept_ while filtered and not opened, else every id.
    void update_gate() noexcept {
      gate_ = cut_ ? kNoIds.data() : (filtered_ && !open_ ? accept_.data() : kAllIds.data());
    }
    void link_refused() noexcept;  ///< send() while cut_: out of line (rare)
    static constexpr IdSet kNoIds{};
    static constexpr IdSet kAllIds = [] {
      IdSet a{};
      for (auto& w : a) w = ~std::uint64_t{0};
      return a;
    }();
    SimBus& bus_;
    std::string name_;
    std::vector<TimedFrame> rx_;
    std::size_t capacity_ = 0;  ///< rx_.size()
    std::size_t rx_head_ = 0;
    std::size_t rx_count_ = 0;
    std::vector<BusEvent> ev_;
    std::size_t ev_head_ = 0;
    std::size_t ev_count_ = 0;
    BusCounters counters_{};
    bool filtered_ = false;
    bool open_ = false;  ///< an opener was pushed and the ring has not been emptied since
    bool cut_ = false;        ///< set_link(false): the interface is down
    bool link_down_ = false;  ///< reported: a send was refused while down, none got out since
    IdSet accept_{};
    IdSet openers_{};
    const std::uint64_t* gate_ = kAllIds.data();
  };

  /// `name` is the interface name used in traces ("sim0").
  explicit SimBus(std::string name = "sim0");
  SimBus(const SimBus&) = delete;
  SimBus& operator=(const SimBus&) = delete;

  /// Add an endpoint (set-up time: allocates its rings). The reference stays
  /// valid for the bus's lifetime.
  Endpoint& add_endpoint(std::string name, std::size_t rx_capacity = kDefaultRxCapacity);

  /// Virtual time in ns. Moving it forward delivers the delayed frames that
  /// are due. Time never goes backwards (earlier values are ignored).
  void set_time(std::int64_t now_ns) noexcept;
  [[nodiscard]] std::int64_t now_ns() const noexcept { return now_ns_; }

  /// Add a fault injection rule (set-up time). Rules are tried in order; the
  /// first one that acts on a frame wins.
  void add_fault(const SimFault& f);
  void clear_faults() noexcept { faults_.clear(); }

  /// Put every endpoint into `s` (error passive, bus-off, ...) and queue a
  /// kStateChanged event on each; kBusOff makes send() return kBusOff.
  void set_state(BusState s) noexcept;
  [[nodiscard]] BusState state() const noexcept { return state_; }

  /// Observer called once for each frame that reaches the wire (after fault
  /// injection), with its time: used for candump traces. Not realtime-safe
  /// by itself (std::function); tests and demos only.
  void set_tap(std::function<void(const TimedFrame&, std::string_view iface)> tap) { tap_ = std::move(tap); }

  [[nodiscard]] const SimBusCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] std::string_view name() const noexcept { return name_; }

 private:
  friend class Endpoint;
  struct Delayed {
    std::int64_t due_ns;
    std::uint64_t seq;
    const Endpoint* from;
    Frame frame;
  };
  struct Rule {
    SimFault fault;
    std::uint64_t seen = 0;
    std::uint64_t acted = 0;
  };
  SendResult transmit(const Endpoint& from, const Frame& f) noexcept;
  SendResult transmit_with_faults(const Endpoint& from, const Frame& f) noexcept;
  void deliver(const Endpoint* from, const Frame& f, std::int64_t t_ns) noexcept;

  std::string name_;
  std::vector<std::unique_ptr<Endpoint>> endpoints_;
  std::vector<Rule> faults_;
  std::deque<Delayed> delayed_;  // kept sorted by (due, seq); only touched when delays are injected
  std::uint64_t seq_ = 0;
  std::int64_t now_ns_ = 0;
  BusState state_ = BusState::kErrorActive;
  SimBusCounters counters_{};
  std::function<void(const TimedFrame&, std::string_view)> tap_;
};

}  // namespace canmotion::can
