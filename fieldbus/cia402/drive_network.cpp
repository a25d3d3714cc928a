// DriveNetwork: the CANopen master plus one DriveProxy per node, the object
// the RT controller calls each cycle (drive_proxy.hpp). Set-up (the
// constructor, add_drive, receive_filters) allocates; the rest is
// realtime-safe.
#include <memory>
#include <vector>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/receive_filters.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

DriveNetwork::DriveNetwork(const NetworkConfig& cfg)
    : tx_queue_frames_(cfg.tx_queue_frames), sync_first_(cfg.sync_first), master_(cfg.master), events_(kEventCapacity) {
  index_.fill(-1);
  tpdo_owner_.fill(-1);
}

DriveProxy& DriveNetwork::add_drive(const DriveConfig& cfg) {
  drives_.push_back(std::make_unique<DriveProxy>(cfg, master_));
  index_[cfg.node] = static_cast<std::int16_t>(drives_.size() - 1);
  // Only where classify() would route the frame to this drive anyway (at most
  // 127 drives, so the index fits).
  const DriveProxy& d = *drives_.back();
  for (std::uint8_t p = 0; p < d.pdos().tpdo_count; ++p) {
    const std::uint32_t id = d.pdos().tpdo[p].cob_id & 0x7FFu;
    const canopen::CobInfo c = canopen::classify(id);
    if (c.kind == canopen::FrameKind::kTpdo && c.node == cfg.node)
      tpdo_owner_[id] = static_cast<std::int8_t>(drives_.size() - 1);
  }
  return *drives_.back();
}

DriveProxy* DriveNetwork::drive(std::uint8_t node) noexcept {
  if (node > 127 || index_[node] < 0) return nullptr;
  return drives_[static_cast<std::size_t>(index_[node])].get();
}

void DriveNetwork::on_frame(const can::TimedFrame& f) noexcept {
  // A TPDO of one of our drives (the master ignores TPDOs): straight to it.
  if ((f.frame.flags & (can::kExtended | can::kError)) == 0 && f.frame.id < tpdo_owner_.size()) {
    if (const std::int8_t k = tpdo_owner_[f.frame.id]; k >= 0) {
      drives_[static_cast<std::size_t>(k)]->on_frame(f);
      return;
    }
  }
  if (master_.on_frame(f)) return;
  const canopen::CobInfo c = canopen::classify(f.frame.id);
  if (c.kind != canopen::FrameKind::kTpdo) return;
  if (DriveProxy* d = drive(c.node)) d->on_frame(f);
}

void DriveNetwork::update(std::int64_t now_ns) noexcept {
  master_.check_heartbeats(now_ns);
  canopen::NodeEvent e;
  auto keep = [this](const canopen::NodeEvent& ev) noexcept {
    if (ev_count_ < kEventCapacity) {
      events_[(ev_head_ + ev_count_) % kEventCapacity] = ev;
      ++ev_count_;
    }
  };
  while (master_.poll_event(e)) {
    if (DriveProxy* d = drive(e.node)) d->on_node_event(e);
    keep(e);
  }
  // The optional objects the drives lacked during their boot (said once each).
  for (auto& d : drives_)
    while (d->poll_notice(e)) keep(e);
}

void DriveNetwork::sync(canopen::FrameSink& out) noexcept {
  // First in the burst, into a queue that had a whole period to drain: its
  // place in the cycle's budget is taken off in cycle().
  if (sync_first_) master_.send_sync(out);
}

void DriveNetwork::cycle(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  update(now_ns);
  // The burst: RPDOs, the SYNC, then what may wait or be repeated (SDO,
  // heartbeat); with sync_first the SYNC went out before (sync()). With a
  // transmit queue shorter than the burst (tx_queue_frames) one place stays
  // free for the SYNC: a full queue drops an RPDO or an SDO request, never
  // the SYNC that every drive needs.
  budget_.out = &out;
  budget_.left = tx_queue_frames_ == 0 ? 0xFFFFFFFFu : tx_queue_frames_ - 1;
  // With a budget the drives take turns at the front, so a queue too short
  // for every RPDO skips each drive's in turn rather than always the last one's.
  const std::size_t n = drives_.size();
  const std::size_t first = tx_queue_frames_ != 0 && n > 0 ? static_cast<std::size_t>(turn_++ % n) : 0;
  for (std::size_t i = 0; i < n; ++i) drives_[(first + i) % n]->step(now_ns, budget_);
  if (sync_first_) {
    // The SYNC of this cycle's wake-up applied the last cycle's RPDOs; its
    // TPDOs are read in the next cycle, after the next SYNC.
    for (auto& d : drives_) d->on_sync_sent(false);
  } else {
    if (tx_queue_frames_ != 0) ++budget_.left;  // the place kept for the SYNC
    master_.send_sync(budget_);
    for (auto& d : drives_) d->on_sync_sent();
  }
  // After the proxies and the SYNC, so that what they queued this cycle goes out now.
  master_.step_sdo(now_ns, budget_);
  master_.produce_heartbeat(now_ns, budget_);
}

std::vector<can::Filter> DriveNetwork::receive_filters() const {
  std::vector<std::uint8_t> nodes;
  for (const auto& d : drives_) nodes.push_back(d->node());
  return canopen::master_receive_filters(nodes);
}

bool DriveNetwork::poll_event(canopen::NodeEvent& out) noexcept {
  if (ev_count_ == 0) return false;
  out = events_[ev_head_];
  ev_head_ = (ev_head_ + 1) % kEventCapacity;
  --ev_count_;
  return true;
}

bool DriveNetwork::all_operational() const noexcept {
  for (const auto& d : drives_)
    if (d->phase() != Phase::kOperational) return false;
  return !drives_.empty();
}
bool DriveNetwork::all_enabled() const noexcept {
  for (const auto& d : drives_)
    if (!d->enabled()) return false;
  return !drives_.empty();
}
bool DriveNetwork::any_failed() const noexcept {
  for (const auto& d : drives_)
    if (d->failed()) return true;
  return false;
}
void DriveNetwork::enable_all() noexcept {
  for (auto& d : drives_) d->enable();
}
void DriveNetwork::reboot_all() noexcept {
  for (auto& d : drives_) d->reboot_node();
}
void DriveNetwork::disable_all() noexcept {
  for (auto& d : drives_) d->disable();
}

}  // namespace canmotion::cia402
