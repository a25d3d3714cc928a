// The DriveProxy's boot phases (DESIGN.md: one cycle; drive_proxy.hpp):
// waiting for the node, NMT reset / pre-operational, the SDO configuration
// (the boot plan's transfers, boot_plan.hpp, built once at set-up, walked
// here generically: each answer taken as its row says, the fallbacks run on
// it, the reads checked by their BootCheck rule), NMT start and the first
// TPDO; a reboot or restart from the beginning. Sans-IO and, apart from
// build_configuration(), realtime-safe.
#include <cmath>
#include <string>

#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

void DriveProxy::build_configuration() {
  writes_ = build_boot_transfers(BootInputs{cfg_, pdos_, master_.config()});
  transfer_.assign(writes_.size(), TransferState{});
  // Nothing is written before the leading reads (the checks) have passed.
  leading_reads_ = 0;
  while (leading_reads_ < writes_.size() && writes_[leading_reads_].is_read()) ++leading_reads_;
}

void DriveProxy::notice(std::size_t write, std::uint32_t abort, Fallback what, std::int32_t detail) noexcept {
  if (write >= transfer_.size() || transfer_[write].noticed) return;
  transfer_[write].noticed = true;
  if (notice_count_ == notices_.size()) return;  // cannot happen: fewer optional objects than places
  canopen::NodeEvent& e = notices_[(notice_head_ + notice_count_) % notices_.size()];
  ++notice_count_;
  e = canopen::NodeEvent{};
  e.kind = canopen::NodeEvent::Kind::kObjectAbsent;
  e.node = cfg_.node;
  e.t_ns = now_ns_;
  e.index = writes_[write].w.index;
  e.sub = writes_[write].w.sub;
  e.abort = abort;
  e.detail = detail;
  e.note = boot_note_id(writes_[write], what);
}

bool DriveProxy::poll_notice(canopen::NodeEvent& out) noexcept {
  if (notice_count_ == 0) return false;
  out = notices_[notice_head_];
  notice_head_ = (notice_head_ + 1) % notices_.size();
  --notice_count_;
  return true;
}

DriveProxy::Taken DriveProxy::check_read(std::size_t i, std::uint32_t v, std::int64_t now_ns) noexcept {
  const BootWrite& bw = writes_[i];
  const bool fallback = bw.after >= 0;
  const std::uint32_t trigger_abort = fallback ? transfer_[static_cast<std::size_t>(bw.after)].abort : 0;
  const CheckInput in{cfg_,         v,           fallback ? writes_[static_cast<std::size_t>(bw.after)].w.value : 0u,
                      &fb_.mode_display, bw.w.index, bw.w.sub, &units_, &dcf_same_};
  const CheckVerdict c = boot_check_rule(bw.check).verify(in);
  std::int64_t waited = 0, timeout = 0;
  switch (c.is) {
    case CheckVerdict::Is::kPass:
      if (c.has_next && i + 1 < writes_.size() && writes_[i + 1].row->value_from_check) writes_[i + 1].w.value = c.next_value;
      // A fallback that held: 0x60C2:2 as the refused write (abort 0: read-only in the EDS, not written).
      if (c.held) notice(i, trigger_abort, Fallback::kHeld, c.detail);
      return Taken::kDone;
    case CheckVerdict::Is::kAgain:
      if (again_since_ns_ < 0) again_since_ns_ = now_ns;
      if (c.timeout_ns <= 0 || now_ns - again_since_ns_ <= c.timeout_ns) return Taken::kAgain;
      waited = now_ns - again_since_ns_;
      timeout = c.timeout_ns;
      break;
    case CheckVerdict::Is::kFail: break;
  }
  fail(FailureKind::kBootCheck, now_ns, waited, timeout);
  failure_.check = bw.check;
  failure_.read_value = v;
  failure_.expected = c.expected;
  failure_.unit_factors = units_.factors;
  failure_.sdo_index = bw.w.index;
  failure_.sdo_sub = bw.w.sub;
  failure_.sdo_origin = WriteOrigin::kCheck;
  if (fallback) failure_.sdo_abort = trigger_abort;  // the refused write's
  failure_.hint = c.key != nullptr && !c.key->empty() ? c.key->c_str() : nullptr;
  return Taken::kFailed;
}

void DriveProxy::forget_drive(std::int64_t now_ns) noexcept {
  tpdo_seen_ = expect_tpdo_ = got_tpdo_ = false;
  state_ = State::kUnknown;
  wanted_ = State::kSwitchOnDisabled;
  in_flight_ = false;
  reset_requested_ = false;
  cancel_homing();
  homing_writes_ = 0;  // cancelled below with the rest of the SDO queue
  mode_switch_pending_ = false;
  nmt_left_ = false;
  mode_ = cfg_.mode;  // configured again with the boot mode
  next_write_ = done_writes_ = tolerated_ = 0;
  reread_ = -1;
  for (TransferState& t : transfer_) t.fell_back = false;  // (a notice stays said)
  in_fault_ = emcy_in_fault_ = error_code_asked_ = false;
  again_since_ns_ = -1;
  dcf_same_ = 0;  // 0x1020 is read again
  if (cfg_.units.read_at_boot) {  // read again by this boot (1: a drive without 0x60A9 / 0x60AA)
    units_ = UnitReadings{};
  }
  master_.sdo(cfg_.node).cancel_all();
  // A rebooted drive sends no heartbeat until 0x1017 is written again: the
  // consumer is armed again when the configuration is done.
  master_.set_heartbeat_timeout(cfg_.node, 0, now_ns);
}

void DriveProxy::restart() noexcept {
  forget_drive(now_ns_);
  phase_ = Phase::kWaitBoot;
  started_ = false;
  failure_ = Failure{};
}

void DriveProxy::reboot_node() noexcept {
  restart();
  force_reset_ = true;
}

void DriveProxy::reboot(std::int64_t now_ns) noexcept {
  ++reboots_;
  forget_drive(now_ns);
  follow_actual();
  // A boot-up leaves the node pre-operational: configure it at once.
  phase_ = Phase::kConfiguring;
  phase_since_ns_ = now_ns;
  started_ = true;
}

void DriveProxy::fail_transfer(std::size_t i, const canopen::SdoResult& r, bool as_trigger,
                               std::int64_t now_ns) noexcept {
  // Both times are on the cycle's clock (the response's receive stamp, or the timeout's cycle).
  const std::int64_t waited = r.finished_ns >= r.started_ns ? r.finished_ns - r.started_ns : now_ns - r.started_ns;
  fail(FailureKind::kSdoAbort, now_ns, waited, r.abort == canopen::SdoAbort::kTimeout ? master_.sdo(cfg_.node).timeout() : 0);
  failure_.sdo_index = r.index;
  failure_.sdo_sub = r.sub;
  failure_.sdo_abort = static_cast<std::uint32_t>(r.abort);
  std::size_t named = i;  // the transfer the failure names
  if (as_trigger && writes_[i].after >= 0) {
    // (e.g. 0x1019 could not be read back either: the refused write is the failure)
    named = static_cast<std::size_t>(writes_[i].after);
    failure_.sdo_abort = transfer_[named].abort;
  }
  const BootWrite& bw = writes_[named];
  failure_.sdo_origin = bw.origin;
  const std::string* key = write_hint_key(cfg_.hints, bw);
  failure_.hint = key != nullptr && !key->empty() ? key->c_str() : nullptr;
}

DriveProxy::Taken DriveProxy::take_result(const canopen::SdoResult& r, std::int64_t now_ns) noexcept {
  const std::size_t i = r.tag;
  if (r.ok()) return writes_[i].is_read() ? check_read(i, r.u32(), now_ns) : Taken::kDone;
  const auto abort = static_cast<std::uint32_t>(r.abort);
  switch (writes_[i].on_abort.of(r.abort)) {
    case Then::kFallBack:  // the rows that fall back from this one run (queue_transfers)
      transfer_[i].fell_back = true;
      transfer_[i].abort = abort;
      ++tolerated_;
      return Taken::kDone;
    case Then::kQuiet: ++tolerated_; return Taken::kDone;
    case Then::kNotice:
      ++tolerated_;
      notice(i, abort, r.abort == canopen::SdoAbort::kReadOnly ? Fallback::kReadOnly : Fallback::kAbsent);
      return Taken::kDone;
    case Then::kFail: fail_transfer(i, r, false, now_ns); return Taken::kFailed;
    case Then::kFailAsTrigger: fail_transfer(i, r, true, now_ns); return Taken::kFailed;
  }
  return Taken::kDone;
}

std::uint32_t DriveProxy::in_drive_unit(const SdoWrite& w) const noexcept {
  if (w.per == SdoWrite::Per::kNone) return w.value;
  const double per = w.per == SdoWrite::Per::kVelocity ? units_.velocity_counts : units_.acceleration_counts;
  // counts / (counts per unit), rounded half away from 0 (the values are
  // magnitudes); an unknown unit (NaN: the boot failed before, when needed) 0.
  const double u = std::floor(std::fabs(w.counts) / per + 0.5);
  const double top = w.size >= 4 ? 4294967295.0 : static_cast<double>((1ull << (8u * w.size)) - 1u);
  return !(u == u) ? 0u : static_cast<std::uint32_t>(u > top ? top : u);
}

void DriveProxy::queue_transfers(canopen::SdoClient& sdo) noexcept {
  if (reread_ >= 0) {
    if (!sdo.upload(writes_[static_cast<std::size_t>(reread_)].w.index, writes_[static_cast<std::size_t>(reread_)].w.sub,
                    static_cast<std::uint32_t>(reread_)))
      return;
    reread_ = -1;
  }
  while (next_write_ < writes_.size() && sdo.queued() < canopen::SdoClient::kQueueCapacity) {
    // Nothing is written before the checks have passed.
    if (next_write_ >= leading_reads_ && done_writes_ < leading_reads_) break;
    const BootWrite& bw = writes_[next_write_];
    if (bw.is_fallback()) {
      if (done_writes_ < next_write_) break;  // the answer of the transfer it falls back from decides
      if (bw.after >= 0 && !transfer_[static_cast<std::size_t>(bw.after)].fell_back) {
        ++next_write_;  // that one was written: nothing to fall back on
        ++done_writes_;
        continue;
      }
    }
    const SdoWrite& w = bw.w;
    // A value in the drive's unit waits for the answers before it (the unit reads).
    if (w.per != SdoWrite::Per::kNone && done_writes_ < next_write_) break;
    // The DCF's values wait for 0x1020's answers, and are left out when the
    // drive holds the configuration they were made for.
    if (w.dcf) {
      if (done_writes_ < next_write_ && (next_write_ == 0 || !writes_[next_write_ - 1].w.dcf)) break;
      if (cfg_.dcf_dated && dcf_same_ == 2) {
        ++next_write_;
        ++done_writes_;
        continue;
      }
    }
    const auto tag = static_cast<std::uint32_t>(next_write_);
    if (bw.is_read()) {
      if (!sdo.upload(w.index, w.sub, tag)) break;
    } else if (w.data != nullptr && w.data_len > 0) {
      // Prepared at set-up and kept by the DriveConfig: referenced, not copied.
      if (!sdo.download_ref(w.index, w.sub, std::span<const std::uint8_t>(w.data, w.data_len), tag, w.timeout_ns)) break;
    } else {
      const std::uint32_t value = in_drive_unit(w);
      std::uint8_t b[4];
      for (int i = 0; i < 4; ++i) b[i] = static_cast<std::uint8_t>(value >> (8 * i));
      if (!sdo.download(w.index, w.sub, std::span<const std::uint8_t>(b, w.size), tag, w.timeout_ns)) break;
    }
    ++next_write_;
  }
}

bool DriveProxy::step_configuring(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  canopen::SdoClient& sdo = master_.sdo(cfg_.node);
  canopen::SdoResult r;
  while (sdo.poll(r)) {
    // Not the boot's: a run-time transfer (0x6060, homing, 0x603F, 0x6041)
    // that finished, or was cancelled by the restart, before it was taken.
    if (r.tag >= writes_.size()) continue;
    switch (take_result(r, now_ns)) {
      case Taken::kDone: ++done_writes_; break;
      case Taken::kAgain: reread_ = static_cast<std::int32_t>(r.tag); break;  // queued again below
      case Taken::kFailed: sdo.cancel_all(); return true;
    }
  }
  queue_transfers(sdo);
  if (done_writes_ != writes_.size()) return false;
  if (cfg_.producer_heartbeat_ms > 0) {
    const std::int64_t hb = cfg_.heartbeat_timeout_ns > 0 ? cfg_.heartbeat_timeout_ns
                                                          : 3 * static_cast<std::int64_t>(cfg_.producer_heartbeat_ms) * 1'000'000;
    master_.set_heartbeat_timeout(cfg_.node, hb, now_ns);
  }
  master_.send_nmt(canopen::NmtCommand::kStart, cfg_.node, out);
  phase_ = Phase::kStarting;
  phase_since_ns_ = now_ns;
  return false;
}

void DriveProxy::step_boot(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  const canopen::NodeStatus& st = master_.status(cfg_.node);
  switch (phase_) {
    case Phase::kWaitBoot:
      if ((cfg_.reset_node_first && !st.booted) || force_reset_) {
        force_reset_ = false;
        master_.send_nmt(canopen::NmtCommand::kResetNode, cfg_.node, out);
        phase_ = Phase::kResetWait;
        phase_since_ns_ = now_ns;
      } else if (st.seen) {
        if (st.state == canopen::NmtState::kOperational || st.state == canopen::NmtState::kStopped) {
          master_.send_nmt(canopen::NmtCommand::kEnterPreOperational, cfg_.node, out);
        }
        phase_ = Phase::kConfiguring;
        phase_since_ns_ = now_ns;
      } else if (now_ns - phase_since_ns_ > cfg_.boot_timeout_ns) {
        master_.send_nmt(canopen::NmtCommand::kResetNode, cfg_.node, out);
        phase_ = Phase::kResetWait;
        phase_since_ns_ = now_ns;
      }
      return;
    case Phase::kResetWait:
      if (st.booted) {
        phase_ = Phase::kConfiguring;
        phase_since_ns_ = now_ns;
      } else if (now_ns - phase_since_ns_ > cfg_.boot_timeout_ns) {
        fail(FailureKind::kBootTimeout, now_ns, now_ns - phase_since_ns_, cfg_.boot_timeout_ns);
        phase_ = Phase::kFailed;
      }
      return;
    case Phase::kConfiguring:
      if (step_configuring(now_ns, out)) phase_ = Phase::kFailed;
      return;
    case Phase::kStarting:
      if (tpdo_seen_) {
        phase_ = Phase::kOperational;
        phase_since_ns_ = now_ns;
        mode_switch_since_ns_ = now_ns;  // a set_mode() before this waits from here
        state_ = decode_state(fb_.statusword);
        follow_actual();
      } else if (now_ns - phase_since_ns_ > cfg_.start_timeout_ns) {
        fail(FailureKind::kStartTimeout, now_ns, now_ns - phase_since_ns_, cfg_.start_timeout_ns);
        phase_ = Phase::kFailed;
      }
      return;
    default: return;
  }
}

}  // namespace canmotion::cia402
