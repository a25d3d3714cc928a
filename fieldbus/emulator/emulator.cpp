// The emulated drive's communication (CiA 301): construction, NMT, the
// frames it receives (NMT, SYNC, SDO requests, heartbeats, RPDOs) and sends
// (boot-up, heartbeat, EMCY, TPDOs), PDO mapping in effect. The dictionary
// is built in dictionary.cpp, the SDO server is sdo_server.cpp, the CiA 402
// application cia402_application.cpp.
#include "fieldbus/emulator/emulator.hpp"

#include <algorithm>
#include <array>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/emcy.hpp"

namespace canmotion::emulator {

using cia402::State;
namespace obj = cia402::obj;

EmulatorBehaviour EmulatorBehaviour::permissive() noexcept {
  EmulatorBehaviour b;
  b.optional_objects_absent = false;
  b.ip_index_read_only = false;
  b.remap_preoperational_only = false;
  b.cia402_default_pdos = false;
  b.rpdo_too_long_emcy = false;
  b.check_sync_length = false;
  b.sync_timeout = false;
  b.error_behaviour = false;
  b.boot_ns = 0;
  b.sdo_reply_delay_ns = 0;
  b.one_transition_per_sync = false;
  b.fault_cause_syncs = 0;
  b.mode_switch_syncs = 0;
  b.refuse_unsupported_modes = false;
  b.homing_takes_time = false;
  return b;
}

Emulator::Emulator(const EmulatorConfig& cfg)
    : cfg_(cfg),
      device_name_(cfg.device_name),
      hw_version_("emulated 1.0"),
      sw_version_("canmotion 0.1"),
      sdo_(cfg.node, *this) {
  cfg_.lag_cycles = std::min<std::uint32_t>(cfg_.lag_cycles, kMaxLag);
  sdo_.set_block_transfer(!cfg_.behaviour.sdo_block_refused);
  build_dictionary();
  resolve_hot();
  pos_ = static_cast<double>(cfg_.initial_position);
  torque_per_acc_ = 1000.0 / cfg_.max_acceleration;
}

void Emulator::rebuild_pdos() noexcept {
  for (std::uint8_t p = 0; p < 4; ++p) {
    for (int dir = 0; dir < 2; ++dir) {
      const bool rx = dir == 0;
      const auto comm = static_cast<std::uint16_t>((rx ? 0x1400 : 0x1800) + p);
      const auto map = static_cast<std::uint16_t>((rx ? 0x1600 : 0x1A00) + p);
      canopen::PdoMap m;
      m.dir = rx ? canopen::PdoDir::kRpdo : canopen::PdoDir::kTpdo;
      m.number = static_cast<std::uint8_t>(p + 1);
      const auto cob = static_cast<std::uint32_t>(get(comm, 1));
      m.cob_id = cob & 0x7FFu;
      m.transmission_type = static_cast<std::uint8_t>(get(comm, 2));
      const auto count = static_cast<std::uint8_t>(get(map, 0));
      for (std::uint8_t s = 1; s <= count && s <= 8; ++s) {
        const auto e = canopen::decode_mapping_entry(static_cast<std::uint32_t>(get(map, s)));
        m.add(e.index, e.sub, e.bits);
      }
      const bool ok = m.finalize();
      const bool valid = (cob & canopen::kPdoInvalid) == 0 && ok && m.count > 0 && served(comm, 1) != nullptr;
      auto& cache = rx ? rpdo_entries_[p] : tpdo_entries_[p];
      cache = {};
      for (std::uint8_t i = 0; i < m.count; ++i) {
        const canopen::PdoEntry& pe = m.entries[i];
        MappedEntry& me = cache[i];
        me.entry = find(pe.index, pe.sub);
        me.is_statusword = pe.index == obj::kStatusword && pe.sub == 0;
        me.is_controlword = pe.index == obj::kControlword;
      }
      (rx ? rpdo_plan_[p] : tpdo_plan_[p]) = canopen::PdoPlan::of(m);
      if (rx) {
        rpdo_[p] = m;
        rpdo_valid_[p] = valid;
      } else {
        tpdo_[p] = m;
        tpdo_valid_[p] = valid;
        tpdo_sync_count_[p] = 0;
        tpdo_sent_[p] = false;  // types 0/254/255: the next chance sends it
      }
    }
  }
  rpdo_active_count_ = tpdo_active_count_ = 0;
  for (std::uint8_t p = 0; p < 4; ++p) {
    if (rpdo_valid_[p]) rpdo_active_[rpdo_active_count_++] = p;
    if (tpdo_valid_[p]) tpdo_active_[tpdo_active_count_++] = p;
  }
  ++accept_gen_;
}

// ============================================================================
// Communication
// ============================================================================
void Emulator::send_emcy(std::uint16_t code, canopen::FrameSink& out) noexcept {
  if (nmt_ == canopen::NmtState::kStopped) return;
  const auto cob = static_cast<std::uint32_t>(val(hot_.emcy_cob));
  if ((cob & canopen::kPdoInvalid) != 0) return;
  canopen::Emcy e;
  e.node = cfg_.node;
  e.code = code;
  e.error_register = static_cast<std::uint8_t>(val(hot_.error_register));
  can::Frame f = canopen::make_emcy_frame(e);
  f.id = cob & 0x7FFu;
  out.send(f);
  ++counters_.emcys;
}

void Emulator::power_on(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  now_ns_ = now_ns;
  powered_ = true;
  reset_dictionary(false);
  sdo_.reset();
  state_ = State::kNotReadyToSwitchOn;  // transition 0
  // Transition 1 when the DC bus has charged (automatic_transitions()).
  boot_ready_ns_ = now_ns + cfg_.behaviour.boot_ns;
  last_cw_ = 0;
  settled_cw_ = {};
  active_fault_ = pending_fault_ = 0;
  fault_cause_syncs_left_ = 0;
  rpdo_short_error_ = rpdo_long_error_ = sync_length_error_ = sync_timeout_error_ = false;
  last_sync_ns_ = -1;
  last_sync_counter_ = 0;
  rpdo_short_mask_ = rpdo_long_mask_ = 0;
  homing_active_ = homing_done_ = homing_error_ = false;
  homing_phase_ = HomingPhase::kIdle;
  sdo_queue_size_ = 0;
  following_error_ = false;
  vel_ = acc_ = 0;
  mode_wanted_ = static_cast<std::int8_t>(get(obj::kModesOfOperation));
  mode_countdown_ = 0;
  set_mode_display(mode_wanted_);
  set(obj::kPositionActualValue, 0, static_cast<std::uint32_t>(position()));
  set(obj::kTargetPosition, 0, static_cast<std::uint32_t>(position()));
  nmt_ = canopen::NmtState::kPreOperational;
  out.send(canopen::make_heartbeat_frame(cfg_.node, canopen::NmtState::kBootUp));
  ++counters_.boot_ups;
  next_heartbeat_ns_ = now_ns;
  automatic_transitions(false, out);  // transition 1 at once when boot_ns is 0
}

void Emulator::handle_nmt(const can::Frame& f, std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  const auto nmt = canopen::decode_nmt(f);
  if (!nmt || (nmt->node != 0 && nmt->node != cfg_.node)) return;
  switch (nmt->command) {
    case 0x01: nmt_ = canopen::NmtState::kOperational; break;
    case 0x02: nmt_ = canopen::NmtState::kStopped; break;
    case 0x80: nmt_ = canopen::NmtState::kPreOperational; break;
    case 0x81: power_on(now_ns, out); break;
    case 0x82:
      reset_dictionary(true);
      last_sync_ns_ = -1;  // 0x1006 back to its default: the SYNC watch starts again
      last_sync_counter_ = 0;
      sync_timeout_error_ = false;
      sdo_.reset();
      sdo_queue_size_ = 0;
      nmt_ = canopen::NmtState::kPreOperational;
      out.send(canopen::make_heartbeat_frame(cfg_.node, canopen::NmtState::kBootUp));
      ++counters_.boot_ups;
      next_heartbeat_ns_ = now_ns;
      break;
    default: break;
  }
}

void Emulator::on_frame(const can::TimedFrame& tf, canopen::FrameSink& out) noexcept {
  const can::Frame& f = tf.frame;
  if (!powered_ || f.extended() || f.error()) return;
  out_ = &out;
  // What classify() would say, without the full switch: an SDO request to
  // this node is 0x600 + node; a heartbeat is 0x700 + node (node 1..127).
  const std::uint32_t fc = f.id & 0x780u;
  const auto from_node = static_cast<std::uint8_t>(f.id & 0x7Fu);
  if (f.id == canopen::cob::kNmt) {
    handle_nmt(f, now_ns_, out);
  } else if (f.id == (val(hot_.sync_cob) & 0x7FFu)) {
    on_sync_frame(f, out);
  } else if (f.id == canopen::cob::sdo_rx(cfg_.node) && cfg_.node >= 1 && cfg_.node <= 127) {
    on_sdo_request(f, out);
  } else if (fc == 0x700u && from_node != 0 && f.id <= 0x7FFu) {
    on_heartbeat(from_node);
  } else if (nmt_ == canopen::NmtState::kOperational && !f.remote()) {
    on_rpdo(f, out);
  }
  out_ = nullptr;
}

void Emulator::on_sync_frame(const can::Frame& f, canopen::FrameSink& out) noexcept {
  if (nmt_ != canopen::NmtState::kOperational && nmt_ != canopen::NmtState::kPreOperational) return;
  // CiA 301: a SYNC carries the counter byte exactly when 0x1019 > 0.
  const std::uint8_t want = get(0x1019) == 0 ? 0 : 1;
  const bool bad = cfg_.behaviour.check_sync_length && f.len != want;
  comm_error(sync_length_error_, bad, canopen::emcy_code::kUnexpectedSyncLength, out);
  if (bad) {
    ++counters_.sync_length_errors;  // not processed
  } else {
    if (f.len == 1) {
      // CiA 301 7.2.5: the counter runs 1 .. 0x1019, then starts again at 1.
      const auto overflow = static_cast<std::uint8_t>(get(0x1019));
      const std::uint8_t c = f.data[0];
      const std::uint8_t next = last_sync_counter_ >= overflow ? 1 : static_cast<std::uint8_t>(last_sync_counter_ + 1);
      if (c == 0 || c > overflow || (last_sync_counter_ != 0 && c != next)) ++counters_.sync_counter_errors;
      last_sync_counter_ = c;
    } else {
      last_sync_counter_ = 0;
    }
    last_sync_ns_ = now_ns_;
    comm_error(sync_timeout_error_, false, canopen::emcy_code::kCommunication, out);
    handle_sync(now_ns_, out);
  }
}

void Emulator::on_heartbeat(std::uint8_t from_node) noexcept {
  for (std::uint8_t s = 1; s <= 4; ++s) {
    const auto v = val(hot_.consumer_hb[s - 1]);
    if ((v & 0xFFFF) != 0 && ((v >> 16) & 0xFF) == from_node) {
      Consumer& k = consumers_[s - 1];
      k.armed = true;
      k.lost = false;
      k.last_ns = now_ns_;
    }
  }
}

void Emulator::on_rpdo(const can::Frame& f, canopen::FrameSink& out) noexcept {
  for (std::uint8_t k = 0; k < rpdo_active_count_; ++k) {
    const std::size_t p = rpdo_active_[k];
    if (f.id != rpdo_[p].cob_id) continue;
    // CiA 301: a short RPDO is not processed (EMCY 8210h); a long one is
    // processed with its first bytes (EMCY 8220h, strict). Each EMCY once
    // while the error lasts, 0000h when a right one follows.
    const bool short_pdo = f.len < rpdo_[p].size_bytes;
    const bool long_pdo = cfg_.behaviour.rpdo_too_long_emcy && f.len > rpdo_[p].size_bytes;
    const auto bit = static_cast<std::uint8_t>(1u << p);
    rpdo_short_mask_ = static_cast<std::uint8_t>(short_pdo ? rpdo_short_mask_ | bit : rpdo_short_mask_ & ~bit);
    rpdo_long_mask_ = static_cast<std::uint8_t>(long_pdo ? rpdo_long_mask_ | bit : rpdo_long_mask_ & ~bit);
    comm_error(rpdo_short_error_, rpdo_short_mask_ != 0, canopen::emcy_code::kPdoLength, out);
    comm_error(rpdo_long_error_, rpdo_long_mask_ != 0, canopen::emcy_code::kPdoLengthExceeded, out);
    if (short_pdo) {
      ++counters_.rpdo_length_errors;
      continue;
    }
    ++counters_.rpdos;
    if (rpdo_[p].transmission_type >= 254) {
      // Event-driven RPDO: applied on receipt, not at the next SYNC.
      if (apply_rpdo(p, canopen::payload_word(f))) evaluate_controlword(out);
    } else {
      rpdo_latch_[p] = canopen::payload_word(f);  // all handle_sync() reads of it
      rpdo_pending_ = static_cast<std::uint8_t>(rpdo_pending_ | (1u << p));
    }
  }
}

void Emulator::accepted_ids(std::array<std::uint64_t, 2048 / 64>& ids,
                            std::array<std::uint64_t, 2048 / 64>& openers) const noexcept {
  // Keep in step with on_frame(): exactly the identifiers it can act on.
  ids = {};
  openers = {};
  auto add = [](std::array<std::uint64_t, 2048 / 64>& set, std::uint32_t id) noexcept {
    if (id < 2048) set[id >> 6] |= std::uint64_t{1} << (id & 63u);
  };
  add(ids, canopen::cob::kNmt);
  add(ids, static_cast<std::uint32_t>(val(hot_.sync_cob) & 0x7FFu));
  add(ids, canopen::cob::sdo_rx(cfg_.node));
  // Only NMT (reset: the defaults again) and SDO writes (0x1005, 0x14xx,
  // 0x16xx) change what is accepted; SYNC, RPDOs and heartbeats do not.
  add(openers, canopen::cob::kNmt);
  add(openers, canopen::cob::sdo_rx(cfg_.node));
  // Heartbeats 0x701..0x77F (any producer: the consumer entries 0x1016 pick theirs).
  static_assert(canopen::cob::kHeartbeatBase % 128 == 0);
  ids[canopen::cob::kHeartbeatBase >> 6] |= ~std::uint64_t{1};  // 0x701..0x73F
  ids[(canopen::cob::kHeartbeatBase >> 6) + 1] = ~std::uint64_t{0};  // 0x740..0x77F
  for (std::uint8_t k = 0; k < rpdo_active_count_; ++k) add(ids, rpdo_[rpdo_active_[k]].cob_id);
}

void Emulator::step(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  now_ns_ = now_ns;
  if (!powered_) return;
  out_ = &out;
  const auto hb_ms = static_cast<std::int64_t>(val(hot_.producer_hb));
  if (hb_ms > 0 && now_ns >= next_heartbeat_ns_) {
    out.send(canopen::make_heartbeat_frame(cfg_.node, nmt_));
    ++counters_.heartbeats;
    next_heartbeat_ns_ = std::max(next_heartbeat_ns_ + hb_ms * 1'000'000, now_ns + 1);
  }
  for (std::uint8_t s = 1; s <= 4; ++s) {
    Consumer& k = consumers_[s - 1];
    const auto v = val(hot_.consumer_hb[s - 1]);
    const auto ms = static_cast<std::int64_t>(v & 0xFFFF);
    if (!k.armed || k.lost || ms == 0) continue;
    if (now_ns - k.last_ns > ms * 1'000'000) {
      k.lost = true;
      refresh_error_register();  // communication error
      switch (cfg_.heartbeat_loss_reaction) {
        case HeartbeatLossReaction::kFault: pending_fault_ = canopen::emcy_code::kHeartbeatError; break;
        case HeartbeatLossReaction::kQuickStop:
          if (state_ == State::kOperationEnabled) state_ = State::kQuickStopActive;  // transition 11
          send_emcy(canopen::emcy_code::kHeartbeatError, out);
          break;
        case HeartbeatLossReaction::kNone: send_emcy(canopen::emcy_code::kHeartbeatError, out); break;
      }
      automatic_transitions(false, out);  // 13 now, not at the next SYNC (the master may be gone)
      apply_error_behaviour();
    }
  }
  // The SYNC watch (0x1006, EmulatorBehaviour::sync_timeout): 1.5 periods
  // without a SYNC, once one came (CANopenNode's CO_SYNC_process).
  const auto period_us = static_cast<std::int64_t>(get(cia402::obj::kCommunicationCyclePeriod));
  if (cfg_.behaviour.sync_timeout && period_us > 0 && last_sync_ns_ >= 0 && !sync_timeout_error_ &&
      (nmt_ == canopen::NmtState::kOperational || nmt_ == canopen::NmtState::kPreOperational) &&
      now_ns - last_sync_ns_ > period_us * 1'500) {
    ++counters_.sync_timeouts;
    comm_error(sync_timeout_error_, true, canopen::emcy_code::kCommunication, out);
    apply_error_behaviour();
  }
  automatic_transitions(false, out);
  sdo_.step(now_ns, out);
  flush_sdo_replies(out);
  if (nmt_ == canopen::NmtState::kOperational) {
    put(hot_.statusword, statusword());  // an SDO controlword or a fault may have changed it
    send_tpdos(false, out);
  }
  out_ = nullptr;
}

void Emulator::service(can::Transport& bus, std::int64_t now_ns) noexcept {
  canopen::TransportSink sink(bus);
  now_ns_ = now_ns;
  for (;;) {
    const std::size_t n = bus.receive(rx_buf_);
    for (std::size_t i = 0; i < n; ++i) on_frame(rx_buf_[i], sink);
    if (n < rx_buf_.size()) break;
  }
  step(now_ns, sink);
}

namespace {
/// FrameSink straight to a SimBus endpoint (a direct call: Endpoint is final).
class SimEndpointSink final : public canopen::FrameSink {
 public:
  explicit SimEndpointSink(can::SimBus::Endpoint& ep) noexcept : ep_(ep) {}
  bool send(const can::Frame& f) noexcept override { return ep_.send(f) == can::SendResult::kOk; }

 private:
  can::SimBus::Endpoint& ep_;
};
}  // namespace

void Emulator::service(can::SimBus::Endpoint& bus, std::int64_t now_ns) noexcept {
  SimEndpointSink sink(bus);
  now_ns_ = now_ns;
  // What this endpoint sends never comes back to it, so the frames stay put
  // while they are handled (see SimBus::Endpoint::peek).
  for (std::span<const can::TimedFrame> run = bus.peek(); !run.empty(); run = bus.peek()) {
    for (const can::TimedFrame& f : run) on_frame(f, sink);
    bus.consume(run.size());
  }
  step(now_ns, sink);
}

std::uint64_t Emulator::tpdo_payload(std::size_t p) const noexcept {
  const canopen::PdoMap& m = tpdo_[p];
  const auto& cache = tpdo_entries_[p];
  const canopen::PdoPlan& plan = tpdo_plan_[p];
  std::uint64_t w = 0;  // the payload, stored at once
  for (std::uint8_t i = 0; i < m.count; ++i) {
    const MappedEntry& me = cache[i];
    // Callers store statusword() in 0x6041 first (update_outputs(), step()).
    w = plan.put(w, i, me.is_statusword ? val(hot_.statusword) : val(me.entry));
  }
  return w;
}

void Emulator::send_tpdos(bool at_sync, canopen::FrameSink& out) noexcept {
  for (std::uint8_t k = 0; k < tpdo_active_count_; ++k) {  // the valid ones, ascending
    const std::size_t p = tpdo_active_[k];
    const canopen::PdoMap& m = tpdo_[p];
    const std::uint8_t t = m.transmission_type;
    if (t >= 241 && t <= 253) continue;  // RTR-only / reserved: never sent by themselves
    const bool event = t >= 254;
    if (!event && !at_sync) continue;  // synchronous types: only at a SYNC
    if (t >= 1 && t <= 240) {
      ++tpdo_sync_count_[p];
      if (t >= 2 && tpdo_sync_count_[p] % t != 0) continue;  // (1: every SYNC, no division)
    }
    const std::uint64_t w = tpdo_payload(p);
    if (t == 0 || event) {
      const bool changed = !tpdo_sent_[p] || w != tpdo_last_payload_[p];
      if (t == 0 && !changed) continue;  // acyclic synchronous: at the SYNC after a change
      if (event) {
        const auto comm = static_cast<std::uint16_t>(0x1800 + p);
        const std::int64_t since = now_ns_ - tpdo_last_sent_ns_[p];
        const auto event_ms = static_cast<std::int64_t>(get(comm, 5));
        const bool timer = tpdo_sent_[p] && event_ms > 0 && since >= event_ms * 1'000'000;
        if (!changed && !timer) continue;
        const auto inhibit_100us = static_cast<std::int64_t>(get(comm, 3));
        if (tpdo_sent_[p] && since < inhibit_100us * 100'000) continue;  // sent when the inhibit time is over
      }
    }
    can::Frame f;
    f.id = m.cob_id;
    f.len = m.size_bytes;
    canopen::set_payload_word(f, w);
    out.send(f);
    tpdo_last_payload_[p] = w;
    tpdo_last_sent_ns_[p] = now_ns_;
    tpdo_sent_[p] = true;
    ++counters_.tpdos;
  }
}

bool Emulator::apply_rpdo(std::size_t p, std::uint64_t w) noexcept {
  const canopen::PdoMap& m = rpdo_[p];
  const canopen::PdoPlan& plan = rpdo_plan_[p];
  const auto& cache = rpdo_entries_[p];
  bool cw_written = false;
  for (std::uint8_t i = 0; i < m.count; ++i) {
    const MappedEntry& me = cache[i];
    put(me.entry, plan.get(w, i));
    if (me.is_controlword) cw_written = true;
  }
  return cw_written;
}

}  // namespace canmotion::emulator
