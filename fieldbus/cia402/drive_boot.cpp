// The DriveProxy's boot phases (DESIGN.md: one cycle; drive_proxy.hpp): the
// configuration it writes and reads (built once at set-up), waiting for the
// node, NMT reset / pre-operational, the SDO configuration with its checks,
// NMT start and the first TPDO; a reboot or restart from the beginning.
// Sans-IO and, apart from build_configuration(), realtime-safe.
#include <string>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

void DriveProxy::build_configuration() {
  writes_.clear();
  // An optional transfer to an object the drive's EDS lacks is left out.
  auto absent = [this](const SdoWrite& w) {
    return cfg_.dictionary && cfg_.dictionary->has(w.index, w.sub) == canopen::Presence::kAbsent;
  };
  auto add = [&](WriteOrigin o, SdoWrite w, std::uint16_t extra = 0) {
    const bool optional = o == WriteOrigin::kUnusedPdo ||
                          (o == WriteOrigin::kConsumerHeartbeat && cfg_.consumer_heartbeat_optional) ||
                          ((o == WriteOrigin::kExtra || o == WriteOrigin::kSyncPeriod || o == WriteOrigin::kSyncCounter) &&
                           w.optional);
    if (optional && absent(w)) return;
    writes_.push_back(BootWrite{w, o, extra, optional});
  };
  // Checks first (reads; nothing is written before they pass): the device
  // type (mandatory in CiA 301), the identity the configuration expects
  // (0x1018:2/3 are optional: read only when expected), the supported modes.
  // 0x6502 and 0x6061 are optional: a drive without them is not checked
  // (the written mode is taken as the one it runs).
  auto check = [&](std::uint16_t index, std::uint8_t sub, BootCheck c) {
    const SdoWrite w{index, sub, 4, 0};
    const bool optional = c == BootCheck::kSupportedModes || c == BootCheck::kModeDisplay;
    if (optional && absent(w)) return;
    writes_.push_back(BootWrite{w, WriteOrigin::kCheck, 0, optional, false, c});
  };
  check(obj::kDeviceType, 0, BootCheck::kDeviceType);
  if (cfg_.identity.has_vendor_id) check(obj::kIdentity, 1, BootCheck::kVendorId);
  if (cfg_.identity.has_product_code) check(obj::kIdentity, 2, BootCheck::kProductCode);
  if (cfg_.identity.has_revision) check(obj::kIdentity, 3, BootCheck::kRevision);
  check(obj::kSupportedDriveModes, 0, BootCheck::kSupportedModes);
  leading_reads_ = writes_.size();
  add(WriteOrigin::kMode,
      SdoWrite{obj::kModesOfOperation, 0, 1, static_cast<std::uint8_t>(static_cast<std::int8_t>(cfg_.mode))});
  const auto ip = *encode_interpolation_period(cfg_.cycle_ns);
  add(WriteOrigin::kInterpolationPeriod, SdoWrite{obj::kInterpolationTimePeriod, 1, 1, ip.value});
  // 0x60C2:2 may be read-only (a drive that takes periods in one unit only)
  // or absent: then its index is read and 0x60C2:1 written again in that
  // unit (the two ip_fallback entries, skipped when :2 was written); a period
  // the drive's unit cannot express fails the boot (BootCheck::kInterpolationIndex).
  // When the drive's EDS says so already, the write it would refuse is left
  // out: read-only (ro/const), the fallback runs at once; absent, neither
  // written nor read (the drive keeps its own unit; config/eds_check warns).
  const canopen::DeviceDictionary::Entry* ip_index =
      cfg_.dictionary ? cfg_.dictionary->find(obj::kInterpolationTimePeriod, 2) : nullptr;
  ip_index_read_only_ = ip_index != nullptr && (ip_index->access == canopen::Access::kRo ||
                                                ip_index->access == canopen::Access::kConst);
  if (!absent(SdoWrite{obj::kInterpolationTimePeriod, 2, 1, 0})) {
    if (!ip_index_read_only_)
      writes_.push_back(BootWrite{SdoWrite{obj::kInterpolationTimePeriod, 2, 1, static_cast<std::uint8_t>(ip.index)},
                                  WriteOrigin::kInterpolationPeriod, 0, false});
    writes_.push_back(BootWrite{SdoWrite{obj::kInterpolationTimePeriod, 2, 1, 0}, WriteOrigin::kCheck, 0, true, true,
                                BootCheck::kInterpolationIndex});
    writes_.push_back(BootWrite{SdoWrite{obj::kInterpolationTimePeriod, 1, 1, ip.value},
                                WriteOrigin::kInterpolationPeriod, 0, false, true});
  }
  // The SYNC consumer (CiA 301): 0x1019 may change only while 0x1006 is 0
  // (abort 0x08000022 otherwise; CANopenNode's CO_ODF_1019 too), so 0x1006 is
  // written 0 first, then 0x1019 = the master's counter overflow value (0: its
  // SYNC carries no counter; a drive whose 0x1019 does not match drops every
  // SYNC, EMCY 8240h), then with sync_watch 0x1006 = the period in us (the
  // drive then watches the SYNC). A drive without 0x1006 / 0x1019 is fine
  // (said once), as is a read-only 0x1006; a 0x1019 refused otherwise is read
  // (the sync_fallback entry): it must already hold the master's value
  // (BootCheck::kSyncCounter). The period write is required: asked for.
  const std::uint8_t overflow = master_.config().sync_counter_overflow >= 2 ? master_.config().sync_counter_overflow : 0;
  add(WriteOrigin::kSyncPeriod, SdoWrite{obj::kCommunicationCyclePeriod, 0, 4, 0, true});
  add(WriteOrigin::kSyncCounter, SdoWrite{obj::kSyncCounterOverflow, 0, 1, overflow, true});
  if (!writes_.empty() && writes_.back().origin == WriteOrigin::kSyncCounter)
    writes_.push_back(BootWrite{SdoWrite{obj::kSyncCounterOverflow, 0, 1, 0}, WriteOrigin::kCheck, 0, true, false,
                                BootCheck::kSyncCounter, true});
  if (cfg_.sync_watch)
    add(WriteOrigin::kSyncPeriod,
        SdoWrite{obj::kCommunicationCyclePeriod, 0, 4, static_cast<std::uint32_t>(cfg_.cycle_ns / 1000)});
  // PDOs: the CiA 301 procedure for the used ones, COB-ID invalid for PDO 1..4 not used.
  auto add_map = [&](const canopen::PdoMap& m) {
    const std::uint32_t cob = m.cob_id & 0x7FFu;
    add(WriteOrigin::kPdo, SdoWrite{m.comm_index(), 1, 4, cob | canopen::kPdoInvalid});
    add(WriteOrigin::kPdo, SdoWrite{m.map_index(), 0, 1, 0});
    for (std::uint8_t i = 0; i < m.count; ++i)
      add(WriteOrigin::kPdo, SdoWrite{m.map_index(), static_cast<std::uint8_t>(i + 1), 4, m.entries[i].raw()});
    add(WriteOrigin::kPdo, SdoWrite{m.map_index(), 0, 1, m.count});
    add(WriteOrigin::kPdo, SdoWrite{m.comm_index(), 2, 1, m.transmission_type});
    add(WriteOrigin::kPdo, SdoWrite{m.comm_index(), 1, 4, cob});
  };
  for (std::uint8_t n = 1; n <= 4; ++n) {
    if (n <= pdos_.rpdo_count) {
      add_map(pdos_.rpdo[n - 1]);
    } else {
      add(WriteOrigin::kUnusedPdo, SdoWrite{static_cast<std::uint16_t>(0x1400 + n - 1), 1, 4,
                                            canopen::cob::rpdo(n, cfg_.node) | canopen::kPdoInvalid});
    }
  }
  for (std::uint8_t n = 1; n <= 4; ++n) {
    if (n <= pdos_.tpdo_count) {
      add_map(pdos_.tpdo[n - 1]);
    } else {
      add(WriteOrigin::kUnusedPdo, SdoWrite{static_cast<std::uint16_t>(0x1800 + n - 1), 1, 4,
                                            canopen::cob::tpdo(n, cfg_.node) | canopen::kPdoInvalid});
    }
  }
  add(WriteOrigin::kProducerHeartbeat, SdoWrite{0x1017, 0, 2, cfg_.producer_heartbeat_ms});
  // 0x1016 is optional (CiA 301): written only when the drive is to watch
  // the master's heartbeat.
  if (cfg_.consumer_heartbeat_ms > 0)
    add(WriteOrigin::kConsumerHeartbeat,
        SdoWrite{0x1016, 1, 4, (static_cast<std::uint32_t>(master_.config().node_id) << 16) | cfg_.consumer_heartbeat_ms});
  for (std::size_t i = 0; i < cfg_.extra_writes.size(); ++i)
    add(WriteOrigin::kExtra, cfg_.extra_writes[i], static_cast<std::uint16_t>(i));
  // Last: the mode the drive runs, read back (read again until it shows the
  // written mode, at most DriveConfig::mode_switch_timeout_ns).
  check(obj::kModesOfOperationDisplay, 0, BootCheck::kModeDisplay);
  noticed_.assign(writes_.size(), 0);
}

void DriveProxy::notice(std::size_t write, std::uint32_t abort, std::int32_t detail) noexcept {
  if (write >= noticed_.size() || noticed_[write] != 0) return;
  noticed_[write] = 1;
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
}

bool DriveProxy::poll_notice(canopen::NodeEvent& out) noexcept {
  if (notice_count_ == 0) return false;
  out = notices_[notice_head_];
  notice_head_ = (notice_head_ + 1) % notices_.size();
  --notice_count_;
  return true;
}

bool DriveProxy::check_read(const BootWrite& bw, std::uint32_t v, std::int64_t now_ns, bool& again) noexcept {
  again = false;
  std::uint32_t expected = 0;
  const std::string* key = nullptr;
  bool ok = true;
  switch (bw.check) {
    case BootCheck::kDeviceType:
      if (cfg_.identity.has_device_type) {
        expected = cfg_.identity.device_type;
        ok = v == expected;
        key = &cfg_.hints.identity;
      } else {
        expected = kDeviceProfile402;
        ok = (v & 0xFFFFu) == kDeviceProfile402;
      }
      break;
    case BootCheck::kVendorId: expected = cfg_.identity.vendor_id; ok = v == expected; key = &cfg_.hints.identity; break;
    case BootCheck::kProductCode: expected = cfg_.identity.product_code; ok = v == expected; key = &cfg_.hints.identity; break;
    case BootCheck::kRevision: expected = cfg_.identity.revision; ok = v == expected; key = &cfg_.hints.identity; break;
    case BootCheck::kSupportedModes: {
      if ((v & supported_mode_bit(cfg_.mode)) == 0) {
        ok = false;
        expected = static_cast<std::uint8_t>(static_cast<std::int8_t>(cfg_.mode));
        break;
      }
      for (const ModeNeed& m : cfg_.needed_modes) {
        if ((v & supported_mode_bit(m.mode)) != 0) continue;
        ok = false;
        expected = static_cast<std::uint8_t>(static_cast<std::int8_t>(m.mode));
        key = &m.key;
        break;
      }
      break;
    }
    case BootCheck::kModeDisplay: {
      const auto shown = static_cast<std::int8_t>(v & 0xFFu);
      expected = static_cast<std::uint8_t>(static_cast<std::int8_t>(cfg_.mode));
      if (shown == static_cast<std::int8_t>(cfg_.mode)) {
        fb_.mode_display = shown;  // confirmed by the drive
        break;
      }
      if (mode_shown_since_ns_ < 0) mode_shown_since_ns_ = now_ns;
      if (cfg_.mode_switch_timeout_ns <= 0 || now_ns - mode_shown_since_ns_ <= cfg_.mode_switch_timeout_ns) {
        again = true;  // the switch takes effect asynchronously (CiA 402): read it again
        return true;
      }
      ok = false;
      key = &cfg_.hints.mode_switch_timeout;
      break;
    }
    case BootCheck::kInterpolationIndex: {
      // The drive keeps its own unit 10^idx s: 0x60C2:1 (the next entry) is
      // written in it when the period is a whole number 1..255 of it.
      const auto idx = static_cast<std::int8_t>(v & 0xFFu);
      const std::int64_t unit = interpolation_period_ns(InterpolationPeriod{1, idx});
      const std::size_t at = static_cast<std::size_t>(&bw - writes_.data());
      if (unit > 0 && cfg_.cycle_ns % unit == 0 && cfg_.cycle_ns / unit >= 1 && cfg_.cycle_ns / unit <= 255) {
        writes_[at + 1].w.value = static_cast<std::uint32_t>(cfg_.cycle_ns / unit);
        notice(at, ip_abort_, idx);  // 0x60C2:2 as the refused write (abort 0: read-only in the EDS, not written)
        return true;
      }
      ok = false;
      expected = static_cast<std::uint32_t>(cfg_.cycle_ns);
      key = &cfg_.hints.interpolation_period;
      break;
    }
    case BootCheck::kSyncCounter: {
      // The drive refused 0x1019 (sync_abort_): fine when it holds the master's value.
      const auto want = static_cast<std::uint32_t>(writes_[static_cast<std::size_t>(&bw - writes_.data()) - 1].w.value);
      const std::uint32_t held = v & 0xFFu;
      if (held == want) {
        notice(static_cast<std::size_t>(&bw - writes_.data()) - 1, sync_abort_, static_cast<std::int32_t>(held));
        return true;
      }
      ok = false;
      expected = want;
      key = &cfg_.hints.sync_counter;
      break;
    }
    case BootCheck::kNone: break;
  }
  if (ok) return true;
  fail(FailureKind::kBootCheck, now_ns, bw.check == BootCheck::kModeDisplay ? now_ns - mode_shown_since_ns_ : 0,
       bw.check == BootCheck::kModeDisplay ? cfg_.mode_switch_timeout_ns : 0);
  failure_.check = bw.check;
  failure_.read_value = v;
  failure_.expected = expected;
  failure_.sdo_index = bw.w.index;
  failure_.sdo_sub = bw.w.sub;
  failure_.sdo_origin = WriteOrigin::kCheck;
  if (bw.check == BootCheck::kSyncCounter) failure_.sdo_abort = sync_abort_;  // the refused write's
  failure_.hint = key != nullptr && !key->empty() ? key->c_str() : nullptr;
  return false;
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
  ip_fallback_ = sync_fallback_ = false;
  in_fault_ = emcy_in_fault_ = error_code_asked_ = false;
  mode_shown_since_ns_ = -1;
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

void DriveProxy::step_boot(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  const canopen::NodeStatus& st = master_.status(cfg_.node);
  canopen::SdoClient& sdo = master_.sdo(cfg_.node);
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
    case Phase::kConfiguring: {
      canopen::SdoResult r;
      while (sdo.poll(r)) {
        // Not the boot's: a run-time transfer (0x6060, homing, 0x603F, 0x6041)
        // that finished, or was cancelled by the restart, before it was taken.
        if (r.tag >= writes_.size()) continue;
        const BootWrite* bw = r.tag < writes_.size() ? &writes_[r.tag] : nullptr;
        if (!r.ok() && bw != nullptr && bw->origin == WriteOrigin::kInterpolationPeriod && bw->w.sub == 2 &&
            !bw->ip_fallback && (canopen::object_absent(r.abort) || r.abort == canopen::SdoAbort::kReadOnly)) {
          // 0x60C2:2 read-only or absent: the ip_fallback entries read the
          // drive's index and write 0x60C2:1 again in it (said then, with the index).
          ip_fallback_ = true;
          ip_abort_ = static_cast<std::uint32_t>(r.abort);
          ++tolerated_;
        } else if (!r.ok() && bw != nullptr && bw->origin == WriteOrigin::kSyncCounter && !canopen::object_absent(r.abort) &&
                   r.abort != canopen::SdoAbort::kTimeout) {
          // 0x1019 refused (read-only, 0x08000022 while the drive's 0x1006 is
          // not 0, a value it cannot take): the sync_fallback read decides.
          sync_fallback_ = true;
          sync_abort_ = static_cast<std::uint32_t>(r.abort);
          ++tolerated_;
        } else if (!r.ok() && bw != nullptr && bw->origin == WriteOrigin::kSyncPeriod && bw->optional &&
                   r.abort == canopen::SdoAbort::kReadOnly) {
          // 0x1006 = 0 on a drive where it is read-only: the drive keeps its
          // own (0x1019's answer shows whether that matters). Said once.
          ++tolerated_;
          notice(r.tag, static_cast<std::uint32_t>(r.abort));
        } else if (!r.ok() && bw != nullptr && bw->optional && canopen::object_absent(r.abort)) {
          // The drive lacks an optional object: fewer PDOs than 4, no 0x1016;
          // no 0x6502 / 0x6061: the modes are not checked, the written mode is
          // taken as the one the drive runs (what a drive without them allows);
          // an optional extra write (e.g. SLAT left at its default): not written.
          // Said once per object (poll_notice), but not for unused PDOs.
          ++tolerated_;
          if (bw->origin != WriteOrigin::kUnusedPdo) {
            if (bw->check == BootCheck::kInterpolationIndex) {
              // no 0x60C2:2 at all: 0x60C2:1 keeps the master's value
              notice(r.tag, ip_abort_ != 0 ? ip_abort_ : static_cast<std::uint32_t>(r.abort), 0);
            } else {
              notice(r.tag, static_cast<std::uint32_t>(r.abort));
            }
          }
        } else if (r.ok() && bw != nullptr && bw->is_read()) {
          bool again = false;
          if (!check_read(*bw, r.u32(), now_ns, again)) {
            sdo.cancel_all();
            phase_ = Phase::kFailed;
            return;
          }
          if (again) {
            next_write_ = r.tag;  // the last entry: queued again below
            continue;
          }
        } else if (!r.ok()) {
          // Both times are on the cycle's clock (the response's receive stamp, or the timeout's cycle).
          const std::int64_t waited = r.finished_ns >= r.started_ns ? r.finished_ns - r.started_ns : now_ns - r.started_ns;
          fail(FailureKind::kSdoAbort, now_ns, waited, r.abort == canopen::SdoAbort::kTimeout ? sdo.timeout() : 0);
          failure_.sdo_index = r.index;
          failure_.sdo_sub = r.sub;
          failure_.sdo_abort = static_cast<std::uint32_t>(r.abort);
          if (bw != nullptr) {
            failure_.sdo_origin = bw->origin;
            const std::string* key = write_hint_key(cfg_.hints, *bw);
            if (bw->check == BootCheck::kSyncCounter) {
              // 0x1019 could not be read back either: the refused write is the failure.
              failure_.sdo_abort = sync_abort_;
              failure_.sdo_origin = WriteOrigin::kSyncCounter;
              key = &cfg_.hints.sync_counter;
            }
            failure_.hint = key != nullptr && !key->empty() ? key->c_str() : nullptr;
          }
          sdo.cancel_all();
          phase_ = Phase::kFailed;
          return;
        }
        ++done_writes_;
      }
      while (next_write_ < writes_.size() && sdo.queued() < canopen::SdoClient::kQueueCapacity) {
        // Nothing is written before the checks have passed.
        if (next_write_ >= leading_reads_ && done_writes_ < leading_reads_) break;
        const BootWrite& bw = writes_[next_write_];
        if (bw.ip_fallback || bw.sync_fallback) {
          if (done_writes_ < next_write_) break;  // 0x60C2:2's (0x1019's) answer decides
          // (0x60C2:2 read-only in the drive's EDS: not written, the fallback runs)
          if (!(bw.ip_fallback ? ip_fallback_ || ip_index_read_only_ : sync_fallback_)) {
            ++next_write_;  // it was written: nothing to fall back on
            ++done_writes_;
            continue;
          }
        }
        const SdoWrite& w = bw.w;
        const auto tag = static_cast<std::uint32_t>(next_write_);
        if (bw.is_read()) {
          if (!sdo.upload(w.index, w.sub, tag)) break;
        } else {
          std::uint8_t b[4];
          for (int i = 0; i < 4; ++i) b[i] = static_cast<std::uint8_t>(w.value >> (8 * i));
          if (!sdo.download(w.index, w.sub, std::span<const std::uint8_t>(b, w.size), tag)) break;
        }
        ++next_write_;
      }
      if (done_writes_ == writes_.size()) {
        if (cfg_.producer_heartbeat_ms > 0) {
          const std::int64_t hb = cfg_.heartbeat_timeout_ns > 0 ? cfg_.heartbeat_timeout_ns
                                                                : 3 * static_cast<std::int64_t>(cfg_.producer_heartbeat_ms) * 1'000'000;
          master_.set_heartbeat_timeout(cfg_.node, hb, now_ns);
        }
        master_.send_nmt(canopen::NmtCommand::kStart, cfg_.node, out);
        phase_ = Phase::kStarting;
        phase_since_ns_ = now_ns;
      }
      return;
    }
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
