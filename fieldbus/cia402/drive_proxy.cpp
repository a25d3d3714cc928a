// The DriveProxy once its node is up (drive_proxy.hpp): set-up, TPDOs in,
// node events, the CiA 402 state machine through its numbered transitions,
// mode switches, homing, the fault's error code and the RPDOs out. The boot
// is drive_boot.cpp (the plan: boot_plan.cpp), the failure texts
// drive_failure.cpp, DriveNetwork drive_network.cpp. Apart from the
// constructor, realtime-safe.
#include "fieldbus/cia402/drive_proxy.hpp"

#include <stdexcept>
#include <string>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"

namespace canmotion::cia402 {

DriveProxy::DriveProxy(const DriveConfig& cfg, canopen::Master& master) : cfg_(cfg), master_(master) {
  if (!master_.add_node(cfg_.node, cfg_.sdo_timeout_ns)) {
    throw std::invalid_argument("node-ID " + std::to_string(cfg_.node) +
                                " is invalid (1..127, not the master's own ID) or already used");
  }
  if (!is_streamed(cfg_.mode) && cfg_.mode != Mode::kHoming) {
    throw std::invalid_argument("node " + std::to_string(cfg_.node) + ": mode " + std::string(mode_name(cfg_.mode)) +
                                " is not supported by the proxy (valid: 8 CSP, 9 CSV, 10 CST, 7 IP, 6 homing)");
  }
  if (!encode_interpolation_period(cfg_.cycle_ns)) {
    throw std::invalid_argument("node " + std::to_string(cfg_.node) + ": cycle period " + std::to_string(cfg_.cycle_ns) +
                                " ns cannot be written to 0x60C2");
  }
  mode_ = cfg_.mode;
  units_.velocity_counts = cfg_.units.velocity_counts;
  units_.acceleration_counts = cfg_.units.acceleration_counts;
  pdos_ = default_drive_pdos(cfg_.pdo_profile, cfg_.node, cfg_.mode);
  auto find = [this](bool rx, std::uint16_t index, std::uint8_t sub = 0) {
    Slot s;
    const auto& arr = rx ? pdos_.rpdo : pdos_.tpdo;
    const std::uint8_t n = rx ? pdos_.rpdo_count : pdos_.tpdo_count;
    for (std::uint8_t p = 0; p < n; ++p) {
      const int e = arr[p].find(index, sub);
      if (e >= 0) return Slot{static_cast<std::int8_t>(p), static_cast<std::int8_t>(e)};
    }
    return s;
  };
  cw_slot_ = find(true, obj::kControlword);
  // The position set point: 0x607A (CSP), or in IP 0x60C1:1 in its place.
  tpos_slot_ = find(true, obj::kTargetPosition);
  if (tpos_slot_.pdo < 0) {
    tpos_slot_ = find(true, obj::kInterpolationDataRecord, obj::kInterpolationDataPositionSub);
    if (tpos_slot_.pdo >= 0) position_mode_ = Mode::kInterpolatedPosition;
  }
  tvel_slot_ = find(true, obj::kTargetVelocity);
  ttrq_slot_ = find(true, obj::kTargetTorque);
  mode_slot_ = find(true, obj::kModesOfOperation);
  sw_slot_ = find(false, obj::kStatusword);
  pos_slot_ = find(false, obj::kPositionActualValue);
  vel_slot_ = find(false, obj::kVelocityActualValue);
  trq_slot_ = find(false, obj::kTorqueActualValue);
  mdisp_slot_ = find(false, obj::kModesOfOperationDisplay);
  for (std::size_t p = 0; p < 4; ++p) {
    rpdo_plan_[p] = canopen::PdoPlan::of(pdos_.rpdo[p]);
    tpdo_plan_[p] = canopen::PdoPlan::of(pdos_.tpdo[p]);
  }
  build_configuration();
}

void DriveProxy::fail(FailureKind k, std::int64_t now_ns, std::int64_t waited, std::int64_t timeout) noexcept {
  failure_.kind = k;
  failure_.follow_missing = false;  // (wait_follow() sets it after this)
  failure_.node = cfg_.node;
  failure_.phase = phase_;
  failure_.reached = state_;
  failure_.wanted = wanted_;
  failure_.statusword = fb_.statusword;
  failure_.has_emcy = has_emcy_;
  failure_.emcy_code = emcy_code_;
  failure_.waited_ns = waited;
  failure_.timeout_ns = timeout;
  failure_.t_ns = now_ns;
  failure_.dictionary = cfg_.dictionary.get();
}

bool DriveProxy::on_frame(const can::TimedFrame& tf) noexcept {
  const can::Frame& f = tf.frame;
  if (f.extended() || f.remote() || f.error()) return false;
  for (std::uint8_t p = 0; p < pdos_.tpdo_count; ++p) {
    const canopen::PdoMap& m = pdos_.tpdo[p];
    if (f.id != (m.cob_id & 0x7FFu)) continue;
    if (f.len < m.size_bytes) return true;  // length error: ignored (the drive reports 0x8210 on its side)
    // The whole payload in one load; each mapped object is a field of it.
    const std::uint64_t w = canopen::payload_word(f);
    const canopen::PdoPlan& plan = tpdo_plan_[p];
    auto get = [&](const Slot& s) { return plan.get(w, static_cast<std::size_t>(s.entry)); };
    if (sw_slot_.pdo == p) {
      fb_.statusword = static_cast<std::uint16_t>(get(sw_slot_));
      // The state is this cycle's for whoever reads it before step() (the
      // controller's feedback to the planner), not the last cycle's.
      if (phase_ == Phase::kOperational) state_ = decode_state(fb_.statusword);
    }
    if (pos_slot_.pdo == p) {
      // The drive frame is 64-bit counts: 0x6064 unwrapped by int32 differences.
      fb_.position_raw = static_cast<std::int32_t>(canopen::sign_extend(get(pos_slot_), 32));
      fb_.position = pos_base_ ? unwrap32(fb_.position, fb_.position_raw) : fb_.position_raw;
      pos_base_ = true;
    }
    if (vel_slot_.pdo == p) fb_.velocity = static_cast<std::int32_t>(canopen::sign_extend(get(vel_slot_), 32));
    if (trq_slot_.pdo == p) fb_.torque = static_cast<std::int16_t>(canopen::sign_extend(get(trq_slot_), 16));
    if (mdisp_slot_.pdo == p) fb_.mode_display = static_cast<std::int8_t>(canopen::sign_extend(get(mdisp_slot_), 8));
    if (p == 0) {
      homing_fresh_ = homing_fresh_ || homing_sync_;
      ++fb_.tpdo_count;
      fb_.last_tpdo_ns = tf.t_ns;
      got_tpdo_ = true;
      tpdo_seen_ = true;
    }
    // The TPDO that shows this homing completed: the drive re-referenced
    // 0x6064 (to the home offset, an int32), so the position takes its base
    // again from it, and the homing ends now, so that whoever reads the
    // feedback before step() (the controller's planner) sees the completion
    // and the new frame together: the jump to the home position is neither
    // read as a move of up to 2^31 counts on top of the old frame's high
    // bits nor seen before the homing's end.
    if (homing_step_ == HomingStep::kStarted && homing_fresh_ && homing_status() == HomingStatus::kCompleted) {
      fb_.position = fb_.position_raw;
      end_homing(HomingResult::kCompleted);
    }
    return true;
  }
  return false;
}

void DriveProxy::on_node_event(const canopen::NodeEvent& e) noexcept {
  if (e.node != cfg_.node) return;
  using K = canopen::NodeEvent::Kind;
  switch (e.kind) {
    case K::kEmcy:
      if (e.emcy.code != canopen::emcy_code::kNoError) {
        has_emcy_ = true;
        emcy_code_ = e.emcy.code;
        emcy_in_fault_ = true;
        // A failure recorded before the EMCY came (e.g. at the heartbeat
        // that showed the node out of NMT operational) names it too.
        if (failed() && (!failure_.has_emcy || failure_.emcy_code != e.emcy.code)) {
          failure_.has_emcy = true;
          failure_.emcy_code = e.emcy.code;
          ++failure_rev_;
        }
      } else if (!in_fault_) {
        emcy_in_fault_ = false;  // error reset / no error: an earlier warning's EMCY is not this fault's
      }
      break;
    case K::kHeartbeatLost:
      if ((phase_ == Phase::kOperational || phase_ == Phase::kStarting) && !is_boot_failure(failure_.kind)) {
        fail(FailureKind::kHeartbeatLost, e.t_ns, 0, master_.status(cfg_.node).heartbeat_timeout_ns);
      }
      break;
    case K::kObjectAbsent: break;  // made by the proxy itself (poll_notice)
    case K::kHeartbeatRecovered:
      // The condition is gone (the planner has latched the axis fault until
      // MAFR/MASR); a node that rebooted meanwhile is being configured again.
      if (failure_.kind == FailureKind::kHeartbeatLost) failure_ = Failure{};
      break;
    case K::kStateChanged:
      if (phase_ != Phase::kOperational) break;
      if ((e.state == canopen::NmtState::kPreOperational || e.state == canopen::NmtState::kStopped) &&
          e.state != master_.status(cfg_.node).commanded) {  // not the master's own command (controlled stop)
        if (!nmt_left_) sw_read_done_ = false;  // this departure's CiA 402 state: read it (step_left_operational)
        nmt_left_ = true;
        if (failure_.kind == FailureKind::kNone || failure_.kind == FailureKind::kTransitionTimeout) {
          fail(FailureKind::kNmtState, e.t_ns, 0, 0);
          failure_.nmt_state = e.state;
        } else if (failure_.kind == FailureKind::kNmtState && failure_.nmt_state != e.state) {
          failure_.nmt_state = e.state;  // e.g. pre-operational, then stopped
          ++failure_rev_;
        }
        expect_tpdo_ = false;  // no PDOs in these states: not counted as missed
      } else if (e.state == canopen::NmtState::kOperational && nmt_left_) {
        nmt_left_ = false;  // started again (by another master or tool)
        if (failure_.kind == FailureKind::kNmtState) failure_ = Failure{};
      }
      break;
    case K::kBootUp:
      pos_base_ = false;  // a booted drive counts 0x6064 afresh: its next TPDO sets the base
      switch (phase_) {
        case Phase::kOperational:
        case Phase::kStarting:
          // The drive reset itself or was power-cycled: it lost its enable
          // and its configuration. Record it (the axis faults) and configure
          // it again right away, so that MAFR + MSO work once it is back.
          if (!failed() || failure_.kind == FailureKind::kTransitionTimeout) fail(FailureKind::kUnexpectedBootUp, e.t_ns, 0, 0);
          reboot(e.t_ns);
          break;
        case Phase::kConfiguring:
          reboot(e.t_ns);  // reset in the middle of its configuration: from the start
          break;
        case Phase::kFailed:
          // A node whose boot failed (no answer, refused write) booted (again):
          // try again, e.g. after it was repaired or replaced.
          failure_ = Failure{};
          reboot(e.t_ns);
          break;
        default: break;  // waiting for it: step_boot() sees it
      }
      break;
  }
}

void DriveProxy::follow_actual() noexcept {
  target_position_ = fb_.position;
  target_velocity_ = 0;
  target_torque_ = 0;
}

void DriveProxy::set_wanted(State s) noexcept {
  wanted_ = s;
  follow_waiting_ = false;  // a new request times its wait for bit 12 afresh
  // A fault reset under way keeps its timing (and its bit 7 edge) when the
  // target changes, e.g. enable() right after fault_reset().
  if (!(in_flight_ && flight_.command == Command::kFaultReset && state_ == State::kFault)) in_flight_ = false;
  if (failure_.kind == FailureKind::kTransitionTimeout) failure_ = Failure{};
}

void DriveProxy::enable() noexcept { set_wanted(State::kOperationEnabled); }
void DriveProxy::disable() noexcept { set_wanted(State::kSwitchOnDisabled); }
void DriveProxy::disable_operation() noexcept { set_wanted(State::kSwitchedOn); }
void DriveProxy::quick_stop() noexcept { set_wanted(State::kQuickStopActive); }
void DriveProxy::fault_reset() noexcept {
  if (phase_ == Phase::kFailed || nmt_left_ || failure_.kind == FailureKind::kNmtState) {
    // Boot and configure it again (NMT enter pre-operational when it is
    // stopped, the SDO configuration, NMT start), without NMT reset node: a
    // node that left NMT operational on its own (CiA 301 0x1029, or another
    // tool) may have kept its configuration, but what changed meanwhile is
    // not known, and writing it again costs one configuration's SDO
    // transfers; a reset would also clear the drive's fault history
    // (0x1003) and, on many drives, its homing. The fault it took with the
    // NMT change (EMCY 0x8130 on a lost master heartbeat) is reset once it
    // is operational again (step()).
    restart();
    reset_after_start_ = true;
    return;
  }
  switch (failure_.kind) {
    case FailureKind::kHeartbeatLost:
      if (!master_.status(cfg_.node).lost) failure_ = Failure{};
      break;  // still lost: the condition stays (the planner's reset waits, then fails)
    case FailureKind::kNone: break;
    default: failure_ = Failure{};  // drive fault, mode switch, transition timeout, unexpected boot-up
  }
  reset_requested_ = true;
  if (state_ == State::kFault || state_ == State::kFaultReactionActive) set_wanted(State::kSwitchOnDisabled);
}

bool DriveProxy::start_homing(const HomingParams& hp) noexcept {
  if (phase_ != Phase::kOperational || homing_writes_ > 0) return false;  // (the last start's writes still out)
  canopen::SdoClient& sdo = master_.sdo(cfg_.node);
  const std::size_t need = (hp.write_offset ? 5u : 4u) + (mode_ != Mode::kHoming && mode_slot_.pdo < 0 ? 1u : 0u);
  if (sdo.queued() + need > canopen::SdoClient::kQueueCapacity) return false;
  if (mode_ != Mode::kHoming && !set_mode(Mode::kHoming)) return false;
  bool ok = sdo.download_value<std::int8_t>(obj::kHomingMethod, 0, hp.method, kHomingWriteTag);
  ok = ok && sdo.download_value<std::uint32_t>(obj::kHomingSpeeds, 1, hp.speed_search, kHomingWriteTag);
  ok = ok && sdo.download_value<std::uint32_t>(obj::kHomingSpeeds, 2, hp.speed_zero, kHomingWriteTag);
  ok = ok && sdo.download_value<std::uint32_t>(obj::kHomingAcceleration, 0, hp.accel, kHomingWriteTag);
  if (hp.write_offset) ok = ok && sdo.download_value<std::int32_t>(obj::kHomeOffset, 0, hp.offset, kHomingWriteTag);
  // (room was checked above: every write is queued)
  homing_writes_ = static_cast<std::uint8_t>(hp.write_offset ? 5 : 4);
  homing_step_ = ok ? HomingStep::kWriting : HomingStep::kIdle;
  homing_result_ = ok ? HomingResult::kBusy : HomingResult::kRefused;
  homing_sync_ = homing_fresh_ = false;
  homing_since_ns_ = now_ns_;
  homing_abort_ = ok ? 0 : static_cast<std::uint32_t>(canopen::SdoAbort::kOutOfMemory);
  homing_abort_object_ = 0;
  return true;
}

void DriveProxy::cancel_homing() noexcept {
  homing_step_ = HomingStep::kIdle;
  homing_result_ = HomingResult::kIdle;
  homing_sync_ = homing_fresh_ = false;
}

void DriveProxy::end_homing(HomingResult r) noexcept {
  homing_step_ = HomingStep::kIdle;  // bit 4 back to 0 (on a timeout: aborts the drive's homing)
  homing_result_ = r;
  homing_sync_ = homing_fresh_ = false;
}

void DriveProxy::step_homing(std::int64_t now_ns) noexcept {
  // The parameter writes' answers (also after a cancel or a refusal: all of
  // them are collected before the next start).
  if (homing_writes_ > 0 && master_.sdo(cfg_.node).results() > 0) {
    canopen::SdoResult r;
    while (homing_writes_ > 0 && master_.sdo(cfg_.node).poll_tag(kHomingWriteTag, r)) {
      --homing_writes_;
      if (!r.ok() && homing_step_ == HomingStep::kWriting) {
        homing_abort_ = static_cast<std::uint32_t>(r.abort);
        homing_abort_object_ = (static_cast<std::uint32_t>(r.index) << 8) | r.sub;
        end_homing(HomingResult::kRefused);
      }
    }
  }
  if (homing_step_ == HomingStep::kIdle) return;
  if (homing_step_ == HomingStep::kWriting && homing_writes_ == 0) homing_step_ = HomingStep::kWaitMode;
  if (cfg_.homing_timeout_ns > 0 && now_ns - homing_since_ns_ > cfg_.homing_timeout_ns) {
    end_homing(HomingResult::kTimeout);
    return;
  }
  if (homing_step_ == HomingStep::kStarted && homing_fresh_) {
    const HomingStatus h = homing_status();
    if (h == HomingStatus::kCompleted) end_homing(HomingResult::kCompleted);  // (on_frame() ends it first)
    else if (h == HomingStatus::kErrorMoving || h == HomingStatus::kErrorStopped) end_homing(HomingResult::kError);
  }
}

bool DriveProxy::set_mode(Mode m) noexcept {
  if (!is_streamed(m) && m != Mode::kHoming) return false;
  // A position stream only on the object the RPDO carries (0x607A: CSP; 0x60C1:1: IP).
  if (is_position_stream(m) && m != position_mode_) return false;
  if (m != Mode::kHoming) cancel_homing();
  if (mode_slot_.pdo < 0) {
    if (!master_.sdo(cfg_.node).download_value<std::int8_t>(obj::kModesOfOperation, 0, static_cast<std::int8_t>(m), kModeWriteTag))
      return false;
    sdo_mode_pending_ = m;
  }
  if (m != mode_ || fb_.mode_display != static_cast<std::int8_t>(m)) {
    mode_switch_pending_ = true;
    mode_switch_since_ns_ = now_ns_;
  }
  mode_ = m;
  target_position_ = fb_.position;
  target_velocity_ = vel_slot_.pdo >= 0 ? fb_.velocity : 0;
  target_torque_ = trq_slot_.pdo >= 0 ? fb_.torque : 0;
  return true;
}

// The drive is in the state the proxy steers to: the controlword that keeps
// it there (in Operation enabled, with the homing start bit when a homing
// runs). From step_state_machine() only: inlined there.
[[gnu::always_inline]] inline void DriveProxy::hold_state(State target) noexcept {
  in_flight_ = false;
  reset_requested_ = false;
  switch (target) {
    case State::kOperationEnabled:
      cw_ = cia402::controlword(Command::kEnableOperation);
      if (homing_step_ == HomingStep::kWaitMode && mode_ == Mode::kHoming && !mode_switch_pending_ &&
          fb_.mode_display == static_cast<std::int8_t>(Mode::kHoming)) {
        // Bit 4 went out clear in the last RPDO (it is clear in every
        // other step): this one is the rising edge.
        homing_step_ = HomingStep::kStarted;
        homing_sync_ = homing_fresh_ = false;
      }
      if (homing_step_ == HomingStep::kStarted) cw_ = static_cast<std::uint16_t>(cw_ | cw::kHomingStart);
      // IP: bit 4 "enable ip mode" only in Operation enabled (every other
      // controlword goes out with it clear: disable, quick stop, fault).
      if (mode_ == Mode::kInterpolatedPosition && !mode_switch_pending_)
        cw_ = static_cast<std::uint16_t>(cw_ | cw::kEnableIpMode);
      break;
    case State::kSwitchedOn: cw_ = cia402::controlword(Command::kSwitchOn); break;
    case State::kReadyToSwitchOn: cw_ = cia402::controlword(Command::kShutdown); break;
    case State::kQuickStopActive: cw_ = cia402::controlword(Command::kQuickStop); break;
    default: cw_ = cia402::controlword(Command::kDisableVoltage); break;
  }
}

// Transition 15: the drive acts on the rising edge of bit 7. In Fault the
// proxy sends it clear, so the reset goes out in this cycle's RPDO; only
// when the last controlword had it set does one cycle without it come
// first. A drive refuses the reset while the cause remains: every
// fault_reset_repeat_ns one RPDO with bit 7 clear, then a new edge, until it
// leaves Fault or the transition times out. From step_state_machine() only:
// inlined there.
[[gnu::always_inline]] inline void DriveProxy::send_fault_reset(std::int64_t now_ns) noexcept {
  const bool set = (cw_ & cw::kFaultReset) != 0;
  if (set && (flight_cycles_ == 0 ||
              (cfg_.fault_reset_repeat_ns > 0 && now_ns - reset_edge_ns_ >= cfg_.fault_reset_repeat_ns))) {
    cw_ = 0;
  } else {
    if (!set) {
      reset_edge_ns_ = now_ns;
      ++reset_edges_;
    }
    cw_ = cia402::controlword(Command::kFaultReset);
  }
}

// Called once per drive per cycle from step() only: inlined there.
[[gnu::always_inline]] inline void DriveProxy::step_state_machine(std::int64_t now_ns) noexcept {
  state_ = decode_state(fb_.statusword);
  if (state_ != State::kOperationEnabled) leaving_enabled_ = false;  // it acted (or faulted)
  // Bit 12 in CSP or IP (awaiting_follow()): latched once seen in this Operation enabled.
  if (state_ != State::kOperationEnabled) {
    follow_ok_ = follow_waiting_ = false;
  } else if (!awaiting_follow()) {
    follow_ok_ = true;
    follow_waiting_ = false;
  }
  const bool faulted = state_ == State::kFault || state_ == State::kFaultReactionActive;
  if (faulted && !reset_requested_) {
    // (a fault reset that timed out keeps that failure: it says why the drive is still in Fault)
    if (failure_.kind == FailureKind::kNone ||
        (failure_.kind == FailureKind::kTransitionTimeout && failure_.transition != 15)) {
      fail(FailureKind::kDriveFault, now_ns, 0, 0);
    }
    wanted_ = State::kSwitchOnDisabled;
    in_flight_ = false;
    cw_ = cia402::controlword(Command::kDisableVoltage);
    follow_actual();
    return;
  }
  if (state_ != State::kOperationEnabled) follow_actual();
  // A quick stop with 0x605A = 0..4 completes in Switch on disabled (12).
  if (wanted_ == State::kQuickStopActive && state_ == State::kSwitchOnDisabled) wanted_ = State::kSwitchOnDisabled;
  // Told to leave Operation enabled, and not shown out of it yet: an
  // enable() meanwhile is not "reached" on a report that may predate that
  // command; the command goes on until the drive shows it acted (or its
  // transition times out), then the enable climbs from where it is.
  const State target = leaving_enabled() && wanted_ == State::kOperationEnabled ? leave_.expect : wanted_;
  if (state_ == target) {
    if (target == State::kOperationEnabled && awaiting_follow()) wait_follow(now_ns);
    hold_state(target);
    return;
  }
  const auto plan = next_step(state_, target);
  if (plan && state_ == State::kOperationEnabled && plan->expect != State::kOperationEnabled) {
    leaving_enabled_ = true;  // 5, 8, 9 or 11 goes out now
    leave_ = *plan;
  }
  if (!plan) {
    // Only the drive can move on (not ready, fault reaction) or the wanted
    // state cannot be reached from here: time it like a transition.
    if (!in_flight_ || flight_from_ != state_) {
      in_flight_ = true;
      flight_ = PlanStep{Command::kDisableVoltage, kNoTransition, target};
      flight_from_ = state_;
      flight_since_ns_ = now_ns;
      flight_cycles_ = 0;
    }
  } else if (!in_flight_ || flight_.transition != plan->transition || flight_from_ != state_) {
    in_flight_ = true;
    flight_ = *plan;
    flight_from_ = state_;
    flight_since_ns_ = now_ns;
    flight_cycles_ = 0;
  }
  // A node that cannot hear us (heartbeat lost, out of NMT operational) is
  // not timed: that is its own failure, and the transition starts afresh
  // when it is back.
  if (heartbeat_lost() || nmt_left_) flight_since_ns_ = now_ns;
  const std::int64_t waited = now_ns - flight_since_ns_;
  if (waited > cfg_.transition_timeout_ns) {
    fail(FailureKind::kTransitionTimeout, now_ns, waited, cfg_.transition_timeout_ns);
    failure_.transition = flight_.transition;
    failure_.wanted = target;
    wanted_ = state_;  // stop pushing; enable()/disable() try again
    in_flight_ = false;
    leaving_enabled_ = false;
    reset_requested_ = false;
    return;
  }
  if (plan) {
    if (plan->command == Command::kFaultReset) {
      send_fault_reset(now_ns);
    } else {
      cw_ = cia402::controlword(plan->command);
    }
  }
  ++flight_cycles_;
}

// Operation enabled in CSP or IP without statusword bit 12 (awaiting_follow()):
// timed like a transition (4, the one that was to make the drive follow),
// failing once with Failure::follow_missing. From step_state_machine() only.
void DriveProxy::wait_follow(std::int64_t now_ns) noexcept {
  if (!follow_waiting_ || heartbeat_lost() || nmt_left_) {  // (a node that cannot hear us is not timed)
    follow_waiting_ = true;
    follow_since_ns_ = now_ns;
  }
  const std::int64_t waited = now_ns - follow_since_ns_;
  if (waited <= cfg_.transition_timeout_ns || failure_.kind != FailureKind::kNone) return;
  fail(FailureKind::kTransitionTimeout, now_ns, waited, cfg_.transition_timeout_ns);
  failure_.transition = 4;
  failure_.wanted = State::kOperationEnabled;
  failure_.follow_missing = true;
}

void DriveProxy::send_rpdos(canopen::FrameSink& out) noexcept {
  for (std::uint8_t p = 0; p < pdos_.rpdo_count; ++p) {
    const canopen::PdoMap& m = pdos_.rpdo[p];
    can::Frame f;
    f.id = m.cob_id & 0x7FFu;
    f.len = m.size_bytes;
    const auto pi = static_cast<std::int8_t>(p);
    // The payload is built as one word (the plan's fields) and stored at once.
    const canopen::PdoPlan& plan = rpdo_plan_[p];
    auto put = [&](std::uint64_t w, const Slot& s, std::uint64_t v) { return plan.put(w, static_cast<std::size_t>(s.entry), v); };
    std::uint64_t w = 0;
    if (cw_slot_.pdo == pi) w = put(w, cw_slot_, cw_);
    if (tpos_slot_.pdo == pi) w = put(w, tpos_slot_, static_cast<std::uint32_t>(low32(target_position_)));
    if (tvel_slot_.pdo == pi) w = put(w, tvel_slot_, static_cast<std::uint32_t>(target_velocity_));
    if (ttrq_slot_.pdo == pi) w = put(w, ttrq_slot_, static_cast<std::uint16_t>(target_torque_));
    if (mode_slot_.pdo == pi) w = put(w, mode_slot_, static_cast<std::uint8_t>(static_cast<std::int8_t>(mode_)));
    canopen::set_payload_word(f, w);
    out.send(f);
  }
}

void DriveProxy::step(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  now_ns_ = now_ns;
  if (!started_) {
    started_ = true;
    phase_since_ns_ = now_ns;
  }
  if (phase_ != Phase::kOperational) {
    sw_read_out_ = sw_read_done_ = false;  // the boot owns the SDO client (a run-time read's result is dropped there)
    leaving_enabled_ = false;              // a (re)booted drive's first TPDO starts afresh
    // Several boot phases may complete in one cycle (boot-up seen ->
    // configuring queues its first writes at once).
    for (int i = 0; i < 3 && phase_ != Phase::kOperational && phase_ != Phase::kFailed; ++i) {
      const Phase before = phase_;
      step_boot(now_ns, out);
      if (phase_ == before) break;
    }
    if (phase_ == Phase::kFailed) reset_after_start_ = false;  // the boot failed: nothing to reset
    if (phase_ != Phase::kOperational) return;
    if (reset_after_start_) {
      // fault_reset() restarted the node: a drive that shows Fault in its
      // first TPDO gets the fault reset now (transition 15, the repeated edge).
      reset_after_start_ = false;
      reset_requested_ = true;
      const State s = decode_state(fb_.statusword);
      if (s == State::kFault || s == State::kFaultReactionActive) set_wanted(State::kSwitchOnDisabled);
    }
  }
  // Missed TPDO accounting: a SYNC went out last cycle and TPDO1 did not come.
  if (expect_tpdo_ && !got_tpdo_) ++fb_.tpdo_missed;
  got_tpdo_ = false;
  // Results of run-time SDO writes (mode switches without RPDO2). Other
  // results stay for whoever queued them (the application's own transfers).
  // Only set_mode() queues kModeWriteTag writes, and only when 0x6060 is not
  // in an RPDO: otherwise skip the poll (and the ~300-byte SdoResult).
  if (mode_slot_.pdo < 0 && master_.sdo(cfg_.node).results() > 0) {
    canopen::SdoResult r;
    canopen::SdoClient& sdo = master_.sdo(cfg_.node);
    while (sdo.poll_tag(kModeWriteTag, r)) {
      if (!r.upload) {
        // 0x6060 accepted: what the drive runs is what 0x6061 shows (read it).
        if (r.ok() && mdisp_slot_.pdo < 0 && !sdo.upload(obj::kModesOfOperationDisplay, 0, kModeWriteTag))
          fb_.mode_display = static_cast<std::int8_t>(sdo_mode_pending_);  // SDO queue full: assumed
      } else if (r.ok()) {
        fb_.mode_display = static_cast<std::int8_t>(r.u32() & 0xFFu);
        // Not there yet (the switch is asynchronous): read again, until
        // check_mode_switch()'s timeout ends the wait.
        if (mode_switch_pending_ && fb_.mode_display != static_cast<std::int8_t>(mode_))
          (void)sdo.upload(obj::kModesOfOperationDisplay, 0, kModeWriteTag);
      } else if (canopen::object_absent(r.abort)) {
        fb_.mode_display = static_cast<std::int8_t>(sdo_mode_pending_);  // no 0x6061: the written mode is assumed
      }
    }
  }
  if (mdisp_slot_.pdo < 0 && fb_.mode_display == 0) fb_.mode_display = static_cast<std::int8_t>(cfg_.mode);
  if (nmt_left_ || sw_read_out_) step_left_operational();
  step_error_code(now_ns);
  check_mode_switch(now_ns);
  step_homing(now_ns);
  step_state_machine(now_ns);
  send_rpdos(out);
}

// A drive in Fault that sent no EMCY (EMCY disabled, or lost): read 0x603F
// two cycles after the Fault shows (an EMCY sent with the fault has come by
// then) and take its code as the EMCY's.
void DriveProxy::step_error_code(std::int64_t now_ns) noexcept {
  const State s = decode_state(fb_.statusword);
  const bool faulted = s == State::kFault || s == State::kFaultReactionActive;
  if (!faulted) {
    // The fault ended: the next one needs its own EMCY. (An EMCY may come
    // before the statusword shows the fault: kept until then.)
    if (in_fault_) in_fault_ = emcy_in_fault_ = error_code_asked_ = false;
    return;
  }
  if (!in_fault_) {
    in_fault_ = true;
    fault_since_ns_ = now_ns;
  }
  canopen::SdoClient& sdo = master_.sdo(cfg_.node);
  if (!error_code_asked_ && !emcy_in_fault_ && now_ns - fault_since_ns_ >= 2 * cfg_.cycle_ns)
    error_code_asked_ = sdo.upload(obj::kErrorCode, 0, kErrorCodeTag);  // queue full: next cycle
  if (!error_code_asked_ || sdo.results() == 0) return;
  canopen::SdoResult r;
  if (!sdo.poll_tag(kErrorCodeTag, r) || !r.ok()) return;
  const auto code = static_cast<std::uint16_t>(r.u32() & 0xFFFFu);
  if (code == canopen::emcy_code::kNoError || emcy_in_fault_) return;
  emcy_in_fault_ = has_emcy_ = true;
  emcy_code_ = code;
  if (failure_.kind != FailureKind::kNone && !failure_.has_emcy) {
    failure_.has_emcy = true;
    failure_.emcy_code = code;
    ++failure_rev_;
  }
  if (notice_count_ < notices_.size()) {
    canopen::NodeEvent& e = notices_[(notice_head_ + notice_count_) % notices_.size()];
    ++notice_count_;
    e = canopen::NodeEvent{};
    e.kind = canopen::NodeEvent::Kind::kEmcy;
    e.node = cfg_.node;
    e.t_ns = now_ns;
    e.emcy.node = cfg_.node;
    e.emcy.code = code;
    e.index = obj::kErrorCode;  // read from 0x603F, not received as an EMCY
  }
}

// A node that left NMT operational while running sends no TPDO: the
// statusword of its last one says nothing of the fault it may have taken
// with the NMT change (CiA 301 0x1029 on a communication error, e.g. EMCY
// 0x8130 and Fault on a lost master heartbeat). A Pre-operational node still
// answers SDO: 0x6041 is read once per departure (again while it shows Fault
// reaction active, which goes on to Fault), and the state it shows is the
// proxy's (a Fault faults the axis as a drive fault too; without an EMCY,
// step_error_code() then reads 0x603F). A Stopped node answers only NMT: not
// read, the failure says so.
void DriveProxy::step_left_operational() noexcept {
  canopen::SdoClient& sdo = master_.sdo(cfg_.node);
  if (sw_read_out_ && sdo.results() > 0) {
    canopen::SdoResult r;
    if (sdo.poll_tag(kStatuswordTag, r)) {
      sw_read_out_ = false;
      sw_read_done_ = true;
      if (r.ok() && nmt_left_) {
        fb_.statusword = static_cast<std::uint16_t>(r.u32() & 0xFFFFu);
        const State s = decode_state(fb_.statusword);
        sw_read_done_ = s != State::kFaultReactionActive;
        if (failure_.kind == FailureKind::kNmtState) {
          failure_.statusword = fb_.statusword;
          failure_.reached = s;
          failure_.statusword_read = true;
          ++failure_rev_;
        }
      }
    }
  }
  if (!nmt_left_ || sw_read_out_ || sw_read_done_) return;
  if (master_.status(cfg_.node).state != canopen::NmtState::kPreOperational) return;
  sw_read_out_ = sdo.upload(obj::kStatusword, 0, kStatuswordTag);  // queue full: next cycle
}

void DriveProxy::check_mode_switch(std::int64_t now_ns) noexcept {
  if (!mode_switch_pending_) return;
  if (fb_.mode_display == static_cast<std::int8_t>(mode_)) {
    mode_switch_pending_ = false;
    return;
  }
  const std::int64_t waited = now_ns - mode_switch_since_ns_;
  if (cfg_.mode_switch_timeout_ns > 0 && waited > cfg_.mode_switch_timeout_ns) {
    mode_switch_pending_ = false;
    if (failure_.kind == FailureKind::kNone || failure_.kind == FailureKind::kTransitionTimeout) {
      fail(FailureKind::kModeSwitchTimeout, now_ns, waited, cfg_.mode_switch_timeout_ns);
      failure_.mode_requested = static_cast<std::int8_t>(mode_);
      failure_.mode_shown = fb_.mode_display;
    }
  }
}

void DriveProxy::on_sync_sent(bool after_rpdos) noexcept {
  expect_tpdo_ = phase_ == Phase::kOperational && tpdo_seen_ && !nmt_left_;
  // The controlword the drive applied at that SYNC: this cycle's, or (SYNC
  // first) the previous cycle's.
  const std::uint16_t applied = after_rpdos ? cw_ : cw_sent_;
  cw_sent_ = cw_;
  if (homing_step_ == HomingStep::kStarted && (applied & cw::kHomingStart) != 0) homing_sync_ = true;
}

}  // namespace canmotion::cia402
