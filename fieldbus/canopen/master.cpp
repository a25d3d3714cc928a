#include "fieldbus/canopen/master.hpp"

#include "fieldbus/canopen/cob_id.hpp"

namespace canmotion::canopen {

Master::Master(const MasterConfig& cfg) : cfg_(cfg), events_(kEventCapacity) {
  slot_.fill(-1);
  nodes_.reserve(kMaxNodes);
  sdo_.reserve(kMaxNodes);
}

bool Master::add_node(std::uint8_t node, std::int64_t sdo_timeout_ns) {
  if (node < cob::kMinNode || node > cob::kMaxNode || slot_[node] >= 0 || node == cfg_.node_id) return false;
  slot_[node] = static_cast<std::int16_t>(nodes_.size());
  NodeStatus st;
  st.node = node;
  nodes_.push_back(st);
  sdo_.push_back(std::make_unique<SdoClient>(node, sdo_timeout_ns));
  return true;
}

void Master::push(const NodeEvent& e) noexcept {
  if (ev_count_ == kEventCapacity) {
    ++events_dropped_;
    return;
  }
  events_[(ev_head_ + ev_count_) % kEventCapacity] = e;
  ++ev_count_;
}

bool Master::poll_event(NodeEvent& out) noexcept {
  if (ev_count_ == 0) return false;
  out = events_[ev_head_];
  ev_head_ = (ev_head_ + 1) % kEventCapacity;
  --ev_count_;
  return true;
}

bool Master::on_frame(const can::TimedFrame& tf) noexcept {
  const can::Frame& f = tf.frame;
  if (f.extended() || f.error()) return false;
  const CobInfo c = classify(f.id);
  if (c.node == 0 || !has_node(c.node)) return false;
  NodeStatus& st = nodes_[static_cast<std::size_t>(slot_[c.node])];
  switch (c.kind) {
    case FrameKind::kHeartbeat: {
      if (f.remote() || f.len < 1) return true;
      const NmtState s = nmt_state_from_byte(f.data[0]);
      st.seen = true;
      st.last_heartbeat_ns = tf.t_ns;
      if (st.lost) {
        st.lost = false;
        push(NodeEvent{NodeEvent::Kind::kHeartbeatRecovered, c.node, s, {}, tf.t_ns});
      }
      if (s == NmtState::kBootUp) {
        st.booted = true;
        ++st.boot_ups;
        st.state = NmtState::kPreOperational;  // a node enters pre-operational after boot-up
        push(NodeEvent{NodeEvent::Kind::kBootUp, c.node, s, {}, tf.t_ns});
      } else {
        ++st.heartbeats;
        if (s != st.state) {
          st.state = s;
          push(NodeEvent{NodeEvent::Kind::kStateChanged, c.node, s, {}, tf.t_ns});
        }
      }
      return true;
    }
    case FrameKind::kEmcy: {
      const auto e = decode_emcy(f);
      if (!e) return true;
      st.last_emcy = *e;
      ++st.emcy_count;
      push(NodeEvent{NodeEvent::Kind::kEmcy, c.node, st.state, *e, tf.t_ns});
      return true;
    }
    case FrameKind::kSdoTx:
      sdo(c.node).on_frame(f, tf.t_ns);
      return true;
    default:
      return false;
  }
}

void Master::set_heartbeat_timeout(std::uint8_t node, std::int64_t timeout_ns, std::int64_t now_ns) noexcept {
  if (!has_node(node)) return;
  NodeStatus& st = nodes_[static_cast<std::size_t>(slot_[node])];
  st.heartbeat_timeout_ns = timeout_ns;
  st.lost = false;
  if (st.last_heartbeat_ns < now_ns) st.last_heartbeat_ns = now_ns;  // the timer starts now
}

void Master::produce_heartbeat(std::int64_t now_ns, FrameSink& out) noexcept {
  if (cfg_.heartbeat_period_ms > 0) {
    if (!heartbeat_started_ || now_ns >= next_heartbeat_ns_) {
      // The master is always operational while it runs the cycle.
      out.send(make_heartbeat_frame(cfg_.node_id, NmtState::kOperational));
      const std::int64_t period = static_cast<std::int64_t>(cfg_.heartbeat_period_ms) * 1'000'000;
      next_heartbeat_ns_ = heartbeat_started_ ? next_heartbeat_ns_ + period : now_ns + period;
      if (next_heartbeat_ns_ <= now_ns) next_heartbeat_ns_ = now_ns + period;  // after a stall, do not burst
      heartbeat_started_ = true;
    }
  }
}

void Master::check_heartbeats(std::int64_t now_ns) noexcept {
  for (NodeStatus& st : nodes_) {
    if (st.heartbeat_timeout_ns > 0 && !st.lost && now_ns - st.last_heartbeat_ns > st.heartbeat_timeout_ns) {
      st.lost = true;
      push(NodeEvent{NodeEvent::Kind::kHeartbeatLost, st.node, st.state, {}, now_ns});
    }
  }
}

void Master::step_sdo(std::int64_t now_ns, FrameSink& out) noexcept {
  // The clients take turns at the front: when the transmit queue has room
  // for fewer requests than there are clients (see tx_queue.hpp), each waits
  // a cycle in turn and none starves.
  const std::size_t n = sdo_.size();
  const std::size_t first = n > 0 ? static_cast<std::size_t>(sdo_turn_++ % n) : 0;
  for (std::size_t i = 0; i < n; ++i) sdo_[(first + i) % n]->step(now_ns, out);
}

void Master::send_sync(FrameSink& out) noexcept {
  can::Frame f;
  f.id = cob::kSync;
  if (cfg_.sync_counter_overflow >= 2) {
    counter_ = static_cast<std::uint8_t>(counter_ >= cfg_.sync_counter_overflow ? 1 : counter_ + 1);
    f.len = 1;
    f.data[0] = counter_;
  }
  if (out.send(f)) {
    ++syncs_;
  } else {
    ++syncs_refused_;
  }
}

void Master::send_nmt(NmtCommand cs, std::uint8_t node, FrameSink& out) noexcept {
  out.send(make_nmt_frame(cs, node));
  NmtState commanded = NmtState::kUnknown;
  switch (cs) {
    case NmtCommand::kStart: commanded = NmtState::kOperational; break;
    case NmtCommand::kStop: commanded = NmtState::kStopped; break;
    case NmtCommand::kEnterPreOperational: commanded = NmtState::kPreOperational; break;
    default: break;  // resets: the node boots (boot-up), then is pre-operational on its own
  }
  const bool reset = cs == NmtCommand::kResetNode || cs == NmtCommand::kResetCommunication;
  for (NodeStatus& st : nodes_) {
    if (node != 0 && st.node != node) continue;
    st.commanded = commanded;
    // (a node-0 command of any kind has always cleared `booted`; kept so)
    if (node == 0 || reset) st.booted = false;
  }
}

}  // namespace canmotion::canopen
