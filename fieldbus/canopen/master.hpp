#pragma once
/// \file
/// The sans-IO CANopen master core (CiA 301): NMT master, SYNC producer with
/// optional counter, the master's own heartbeat, a heartbeat consumer per
/// node with node-lost/recovered events, the EMCY consumer and one SDO client
/// per node. It is given received frames (on_frame) and the time (step),
/// and emits frames through a FrameSink.
///
/// Set-up (constructor, add_node) allocates; every other member function is
/// realtime-safe: no allocation, no locks, no exceptions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/canopen/sdo_client.hpp"

namespace canmotion::canopen {

struct MasterConfig {
  /// The master's own node-ID: its heartbeat is 0x700 + this, and drives
  /// monitor it through 0x1016. 127 by default (drives usually start at 1).
  std::uint8_t node_id = 127;
  /// Master heartbeat period; 0 = the master sends no heartbeat.
  std::uint32_t heartbeat_period_ms = 100;
  /// 0 = SYNC without counter; 2..240 = SYNC carries a counter 1..overflow.
  std::uint8_t sync_counter_overflow = 0;
};

/// Something the master noticed about a node.
struct NodeEvent {
  enum class Kind : std::uint8_t {
    kBootUp,              ///< boot-up message received
    kStateChanged,        ///< heartbeat reported a new NMT state
    kHeartbeatLost,       ///< no heartbeat within the consumer time
    kHeartbeatRecovered,  ///< heartbeat back after kHeartbeatLost
    kEmcy,                ///< EMCY received (`emcy` is set)
    /// The drive lacks an optional boot object, or refused it as read-only;
    /// the master took a fallback (`index`, `sub`, `abort`; made by
    /// cia402::DriveProxy::poll_notice, said once per node and object).
    kObjectAbsent,
  };
  Kind kind = Kind::kBootUp;
  std::uint8_t node = 0;
  NmtState state = NmtState::kUnknown;
  Emcy emcy{};
  std::int64_t t_ns = 0;
  std::uint16_t index = 0;  ///< kObjectAbsent: the object
  std::uint8_t sub = 0;
  /// kObjectAbsent: the fallback the master took, as its maker numbers it
  /// (cia402::boot_note_id: the boot plan's row and fallback, worded by
  /// cia402::describe_notice); 0: none.
  std::uint8_t note = 0;
  std::uint32_t abort = 0;  ///< kObjectAbsent: the SDO abort code
  std::int32_t detail = 0;  ///< kObjectAbsent: 0x60C2:2, the drive's own index
};

/// What the master knows about one node.
struct NodeStatus {
  std::uint8_t node = 0;
  NmtState state = NmtState::kUnknown;
  bool seen = false;         ///< any boot-up or heartbeat received
  bool booted = false;       ///< a boot-up message was received
  bool lost = false;         ///< heartbeat consumer timed out (and not recovered)
  /// The NMT state this master last commanded (start: operational, stop:
  /// stopped, enter pre-operational), kUnknown before any or after a reset:
  /// a heartbeat showing it is expected, any other change is the node's own.
  NmtState commanded = NmtState::kUnknown;
  std::int64_t last_heartbeat_ns = 0;
  std::int64_t heartbeat_timeout_ns = 0;  ///< 0 = not monitored
  std::uint64_t boot_ups = 0;
  std::uint64_t heartbeats = 0;
  std::uint64_t emcy_count = 0;
  std::optional<Emcy> last_emcy;
};

class Master {
 public:
  /// Largest number of nodes one master handles (CANopen node-IDs 1..127).
  static constexpr std::size_t kMaxNodes = 127;
  /// Events kept between poll_event() calls (a boot of 127 nodes gives ~381).
  static constexpr std::size_t kEventCapacity = 512;

  explicit Master(const MasterConfig& cfg = {});

  /// Register a node (set-up time; allocates its SDO client). Returns false
  /// for an invalid or duplicate node-ID, or the master's own ID.
  bool add_node(std::uint8_t node, std::int64_t sdo_timeout_ns = 500'000'000);
  [[nodiscard]] bool has_node(std::uint8_t node) const noexcept { return node < 128 && slot_[node] >= 0; }

  /// Feed one received frame: boot-up/heartbeat, EMCY and SDO responses of
  /// registered nodes are consumed; returns true if the frame was one of
  /// those (PDOs and unknown frames return false).
  bool on_frame(const can::TimedFrame& f) noexcept;
  /// Heartbeat production, heartbeat consumer timeouts, SDO clients
  /// (step_timers() then step_sdo()).
  void step(std::int64_t now_ns, FrameSink& out) noexcept {
    step_timers(now_ns, out);
    step_sdo(now_ns, out);
  }
  /// Heartbeat production and heartbeat consumer timeouts only.
  void step_timers(std::int64_t now_ns, FrameSink& out) noexcept {
    produce_heartbeat(now_ns, out);
    check_heartbeats(now_ns);
  }
  /// The master's own heartbeat, when it is due.
  void produce_heartbeat(std::int64_t now_ns, FrameSink& out) noexcept;
  /// Heartbeat consumer timeouts: a node is lost (kHeartbeatLost, once) when
  /// `now_ns` is more than its timeout after its last heartbeat's receive
  /// time. Both on the cycle's clock (TimedFrame::t_ns). Idempotent within a cycle.
  void check_heartbeats(std::int64_t now_ns) noexcept;
  /// Step every SDO client (start queued transfers, timeouts).
  void step_sdo(std::int64_t now_ns, FrameSink& out) noexcept;
  /// Send one SYNC (with the counter if configured). Call once per cycle,
  /// after the RPDOs.
  void send_sync(FrameSink& out) noexcept;
  /// Send an NMT command to `node` (0 = all nodes).
  void send_nmt(NmtCommand cs, std::uint8_t node, FrameSink& out) noexcept;

  /// Monitor `node`'s heartbeat: lost after `timeout_ns` without one (0 = off).
  void set_heartbeat_timeout(std::uint8_t node, std::int64_t timeout_ns, std::int64_t now_ns) noexcept;

  /// The SDO client of a registered node. Precondition: has_node(node).
  [[nodiscard]] SdoClient& sdo(std::uint8_t node) noexcept { return *sdo_[static_cast<std::size_t>(slot_[node])]; }
  [[nodiscard]] const NodeStatus& status(std::uint8_t node) const noexcept {
    return nodes_[static_cast<std::size_t>(slot_[node])];
  }
  /// Take the oldest event; false if none.
  bool poll_event(NodeEvent& out) noexcept;

  [[nodiscard]] const MasterConfig& config() const noexcept { return cfg_; }
  /// SYNCs handed to the sink (accepted by it).
  [[nodiscard]] std::uint64_t syncs_sent() const noexcept { return syncs_; }
  /// SYNCs the sink refused (a full transmit queue, bus-off): the drives
  /// missed those cycles. Realtime-safe.
  [[nodiscard]] std::uint64_t syncs_refused() const noexcept { return syncs_refused_; }
  [[nodiscard]] std::uint8_t sync_counter() const noexcept { return counter_; }
  [[nodiscard]] std::uint64_t events_dropped() const noexcept { return events_dropped_; }
  [[nodiscard]] std::size_t node_count() const noexcept { return nodes_.size(); }

 private:
  void push(const NodeEvent& e) noexcept;

  MasterConfig cfg_;
  std::array<std::int16_t, 128> slot_{};
  std::vector<NodeStatus> nodes_;
  std::vector<std::unique_ptr<SdoClient>> sdo_;
  std::vector<NodeEvent> events_;
  std::size_t ev_head_ = 0;
  std::size_t ev_count_ = 0;
  std::uint64_t events_dropped_ = 0;
  std::int64_t next_heartbeat_ns_ = 0;
  bool heartbeat_started_ = false;
  std::uint64_t syncs_ = 0;
  std::uint64_t syncs_refused_ = 0;
  std::uint8_t counter_ = 0;
  std::uint64_t sdo_turn_ = 0;  // step_sdo(): the client that goes first this cycle
};

}  // namespace canmotion::canopen
