// The emulated drive's CiA 402 application: the state machine (from the
// shared cia402.hpp), modes, faults and the error register, the motor model
// (advanced only at a SYNC) and the outputs it shows in the dictionary.
#include "fieldbus/emulator/emulator.hpp"
#include "fieldbus/cia402/units.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "fieldbus/canopen/emcy.hpp"

namespace canmotion::emulator {

using cia402::State;
namespace obj = cia402::obj;
using cia402::round_half_away;

namespace {
std::uint8_t error_register_for(std::uint16_t code) {
  std::uint8_t r = canopen::kErrGeneric;
  switch (code >> 12) {
    case 0x2: r |= canopen::kErrCurrent; break;
    case 0x3: r |= canopen::kErrVoltage; break;
    case 0x4: r |= canopen::kErrTemperature; break;
    case 0x8:
      if ((code >> 8) == 0x81 || (code >> 8) == 0x82) {
        r |= canopen::kErrCommunication;
      } else {
        r |= canopen::kErrDeviceProfile;
      }
      break;
    case 0xF: r |= canopen::kErrManufacturer; break;
    default: break;
  }
  return r;
}
}  // namespace

std::uint16_t Emulator::statusword() const noexcept {
  std::uint16_t sw = cia402::state_bits(state_);
  if (cfg_.remote) sw |= cia402::sw::kRemote;
  switch (state_) {
    case State::kReadyToSwitchOn:
    case State::kSwitchedOn:
    case State::kOperationEnabled:
    case State::kQuickStopActive:
    case State::kFaultReactionActive: sw |= cia402::sw::kVoltageEnabled; break;
    default: break;
  }
  if (state_ == State::kSwitchOnDisabled || state_ == State::kFault) sw |= cia402::sw::kQuickStop;
  const auto mode = static_cast<cia402::Mode>(mode_display_);
  if (state_ == State::kOperationEnabled) {
    if (cia402::is_cyclic(mode)) sw |= cia402::sw::kFollowsCommand;
    if (ip_following()) sw |= cia402::sw::kIpModeActive;  // IP: bit 4 seen, the 0x60C1:1 set points are taken
    if (mode == cia402::Mode::kHoming) {
      if (homing_done_) sw |= cia402::sw::kHomingAttained | cia402::sw::kTargetReached;
      if (homing_error_) sw |= cia402::sw::kHomingError | (vel_ == 0.0 ? cia402::sw::kTargetReached : 0);
      if (!homing_active_ && !homing_done_ && !homing_error_) sw |= cia402::sw::kTargetReached;  // interrupted / not started
    }
  }
  if (following_error_ && mode == cia402::Mode::kCsp) sw |= cia402::sw::kFollowingError;
  return sw;
}

void Emulator::enter_fault(std::uint16_t code, canopen::FrameSink& out) noexcept {
  active_fault_ = code;
  set(obj::kErrorCode, 0, code);
  refresh_error_register();
  for (std::uint8_t s = 8; s > 1; --s) set(0x1003, s, get(0x1003, static_cast<std::uint8_t>(s - 1)));
  set(0x1003, 1, code);
  set(0x1003, 0, std::min<std::uint64_t>(get(0x1003, 0) + 1, 8));
  if (state_ != State::kFault) state_ = State::kFaultReactionActive;  // transition 13
  send_emcy(code, out);
}

void Emulator::apply_controlword(std::uint16_t cw, canopen::FrameSink& out) noexcept {
  const auto qs = static_cast<std::int16_t>(sval(hot_.quick_stop_option));
  std::uint16_t prev = last_cw_;
  // Permissive: 0x000F from Ready to switch on gives 3 and 4 in this call;
  // strict: one transition, the next at the next SYNC (handle_sync()).
  const int max_transitions = cfg_.behaviour.one_transition_per_sync ? 1 : 2;
  for (int i = 0; i < max_transitions; ++i) {
    const cia402::StepResult r = cia402::apply_controlword(state_, prev, cw, qs);
    if (r.transition == cia402::kNoTransition) {
      if (prev == cw) settled_cw_ = SettledControlword{true, state_, cw, qs};
      break;
    }
    if (r.transition == 15) {
      if (fault_cause_remains()) {
        ++counters_.refused_fault_resets;  // stays in Fault; the edge is used up
        break;
      }
      active_fault_ = 0;
      following_error_ = false;
      following_error_cycles_ = 0;
      set(obj::kErrorCode, 0, 0);
      if (cfg_.behaviour.fault_cause_syncs == 0) {
        for (auto& k : consumers_) k.lost = false;  // permissive: the reset forgets a lost heartbeat
      }
      refresh_error_register();
      send_emcy(canopen::emcy_code::kNoError, out);  // error reset
    }
    if (r.next == State::kOperationEnabled) {
      // Enabling never jumps: the delay line starts at the present target.
      const Setpoint sp{position_setpoint(),
                        static_cast<std::int32_t>(sval(hot_.target_velocity)),
                        static_cast<std::int16_t>(sval(hot_.target_torque))};
      delay_.fill(sp);
      prev_demand_ = static_cast<double>(cia402::unwrap32(position_counts(), sp.position));
      if (!cfg_.refuse_mode_switch && cfg_.behaviour.mode_switch_syncs == 0 && mode_supported(static_cast<std::int8_t>(sval(hot_.modes))))
        set_mode_display(static_cast<std::int8_t>(sval(hot_.modes)));
      reset_direct_model();
    }
    state_ = r.next;
    prev = cw;
  }
  // Homing start: rising edge of bit 4 in Operation enabled, mode 6.
  if (state_ == State::kOperationEnabled && mode_display_ == static_cast<std::int8_t>(cia402::Mode::kHoming) &&
      (cw & cia402::cw::kHomingStart) != 0 && (last_cw_ & cia402::cw::kHomingStart) == 0) {
    start_homing();
  }
  if ((cw & cia402::cw::kHomingStart) == 0) homing_active_ = false;
  // IP (mode 7): bit 4 "enable ip mode" in Operation enabled; on its rising
  // edge the interpolation starts from the present set point (no jump).
  const bool ip = state_ == State::kOperationEnabled &&
                  mode_display_ == static_cast<std::int8_t>(cia402::Mode::kInterpolatedPosition) &&
                  (cw & cia402::cw::kEnableIpMode) != 0;
  if (ip && !ip_active_) {
    const auto p = static_cast<std::int32_t>(sval(hot_.ip_data));
    delay_.fill(Setpoint{p, static_cast<std::int32_t>(sval(hot_.target_velocity)),
                         static_cast<std::int16_t>(sval(hot_.target_torque))});
    prev_demand_ = static_cast<double>(cia402::unwrap32(position_counts(), p));
  }
  ip_active_ = ip;
  last_cw_ = cw;
}

void Emulator::advance_motor(double dt) noexcept {
  // 1 / dt, computed when 0x60C2 changes: multiplications instead of the
  // ~15-cycle divisions of the CSP path on every SYNC (a deliberate change
  // of the last bit of some results against dividing by dt).
  const double inv_dt = sync_period_.inv_dt;
  const bool ip_mode = mode_display_ == static_cast<std::int8_t>(cia402::Mode::kInterpolatedPosition);
  const Setpoint now_sp{static_cast<std::int32_t>(position_setpoint() + (ip_mode ? 0 : sval(hot_.position_offset))),
                        static_cast<std::int32_t>(sval(hot_.target_velocity) + sval(hot_.velocity_offset)),
                        static_cast<std::int16_t>(sval(hot_.target_torque) + sval(hot_.torque_offset))};
  // Delay line: the setpoint used now is the one received lag_cycles SYNCs ago.
  const std::size_t len = cfg_.lag_cycles + 1;
  // delay_head_ < len (lag_cycles is fixed at construction), so the slot
  // lag_cycles back, (head + len - lag_cycles) % len, is the next one: no division.
  delay_[delay_head_] = now_sp;
  const std::size_t next = delay_head_ + 1 == len ? 0 : delay_head_ + 1;
  const Setpoint sp = delay_[next];
  delay_head_ = next;

  refresh_units();
  const double vmax = std::min(cfg_.max_velocity, static_cast<double>(val(hot_.max_profile_velocity)) * vel_scale_);
  double amax = cfg_.max_acceleration;
  double v_des = 0;
  const auto mode = static_cast<cia402::Mode>(mode_display_);
  double torque = 0;
  bool stop_immediately = false;
  // CSP, and IP with linear interpolation (sub-mode 0): the demand moves
  // linearly from the last set point to this one over the period 0x60C2.
  auto follow = [&] {
        // 0x607A is 32 bits and wraps like 0x6064: the demand is the 64-bit
        // position nearest the last one with these low bits (a step of more
        // than 2^31 counts per SYNC is not a target a drive can take).
        const double demand = static_cast<double>(
            cia402::unwrap32(static_cast<std::int64_t>(std::clamp(prev_demand_, -0x1p62, 0x1p62)), sp.position));
        // Feed-forward of the demand's change plus a proportional correction
        // of the error left from the previous SYNC: a ramp is followed exactly
        // (the only following error is the lag), a step settles geometrically.
        const double v_ff = (demand - prev_demand_) * inv_dt;
        v_des = v_ff + cfg_.position_gain * (prev_demand_ - pos_) * inv_dt;
        prev_demand_ = demand;
        put(hot_.position_demand, static_cast<std::uint32_t>(sp.position));
  };
  if (state_ == State::kOperationEnabled) {
    switch (mode) {
      case cia402::Mode::kCsp: follow(); break;
      case cia402::Mode::kInterpolatedPosition:
        if (ip_following()) follow();
        else v_des = cfg_.position_gain * (prev_demand_ - pos_) * inv_dt;  // bit 4 clear: set points ignored, hold
        break;
      case cia402::Mode::kCsv: v_des = csv_ramp(sp.velocity * vel_scale_, dt); break;
      case cia402::Mode::kCst: {
        const double tmax = static_cast<double>(val(hot_.max_torque));
        v_des = cst_step(std::clamp(static_cast<double>(sp.torque), -tmax, tmax), sp.velocity * vel_scale_, dt, torque);
        break;
      }
      case cia402::Mode::kHoming: v_des = homing_velocity(dt, amax, stop_immediately); break;
      default: break;
    }
  } else if (state_ == State::kQuickStopActive) {
    amax = static_cast<double>(val(hot_.quick_stop_decel)) * acc_scale_;
    v_des = 0;
  } else {
    stop_immediately = true;  // power stage off: the model stops (brake)
  }
  if (stop_immediately) {
    acc_ = 0;
    vel_ = 0;
    reset_direct_model();
  } else {
    v_des = std::clamp(v_des, -vmax, vmax);
    const double dv = std::clamp(v_des - vel_, -amax * dt, amax * dt);
    acc_ = dv * inv_dt;
    vel_ += dv;
    pos_ += vel_ * dt;
  }
  const double trq = mode == cia402::Mode::kCst && state_ == State::kOperationEnabled ? torque : acc_ * torque_per_acc_;
  torque_ = trq;
  put(hot_.torque_actual, static_cast<std::uint16_t>(static_cast<std::int16_t>(std::clamp(round_half_away(trq), -32768.0, 32767.0))));
}

void Emulator::refresh_units() noexcept {
  namespace u = cia402::units;
  // (get() is 0 for an object the drive lacks: absent in the factor group)
  const std::uint64_t key[kUnitKeys] = {get(u::kSiUnitVelocity),          get(u::kSiUnitAcceleration),
                                        get(u::kPositionEncoderResolution, 1), get(u::kPositionEncoderResolution, 2),
                                        get(u::kSiUnitPosition),          get(u::kGearRatio, 1),
                                        get(u::kGearRatio, 2),            get(u::kFeedConstant, 1),
                                        get(u::kFeedConstant, 2)};
  if (std::equal(std::begin(key), std::end(key), std::begin(units_key_))) return;
  std::copy(std::begin(key), std::end(key), std::begin(units_key_));
  u::FactorGroup res;
  res.res = {static_cast<std::uint32_t>(key[2]), static_cast<std::uint32_t>(key[3])};
  res.position = static_cast<std::uint32_t>(key[4]);
  res.gear_motor = static_cast<std::uint32_t>(key[5]);
  res.gear_shaft = static_cast<std::uint32_t>(key[6]);
  res.feed = static_cast<std::uint32_t>(key[7]);
  res.feed_shaft = static_cast<std::uint32_t>(key[8]);
  // A drive without 0x60A9/0x60AA works in increments (CiA 402 without the
  // factor group); a code this model does not know leaves increments too
  // (the master refuses such a drive before it commands a velocity).
  const auto v = find(cia402::units::kSiUnitVelocity, 0) != nullptr
                     ? cia402::units::counts_per_unit(static_cast<std::uint32_t>(key[0]), res, false)
                     : std::optional<double>(1.0);
  const auto a = find(cia402::units::kSiUnitAcceleration, 0) != nullptr
                     ? cia402::units::counts_per_unit(static_cast<std::uint32_t>(key[1]), res, true)
                     : std::optional<double>(1.0);
  vel_scale_ = v && *v > 0 ? *v : 1.0;
  acc_scale_ = a && *a > 0 ? *a : 1.0;
}

void Emulator::update_outputs() noexcept {
  const std::int32_t p = position();
  put(hot_.position_actual, static_cast<std::uint32_t>(p));
  put(hot_.position_internal, static_cast<std::uint32_t>(p));
  put(hot_.velocity_actual, static_cast<std::uint32_t>(static_cast<std::int32_t>(
                                 std::clamp(round_half_away(vel_ / vel_scale_), -2147483648.0, 2147483647.0))));
  put(hot_.fe_actual, static_cast<std::uint32_t>(static_cast<std::int32_t>(sval(hot_.target_position) - p)));
  put(hot_.statusword, statusword());
}

void Emulator::evaluate_controlword(canopen::FrameSink& out) noexcept {
  if (!cfg_.remote) return;  // local control: the bus's controlword is ignored
  const auto cw = static_cast<std::uint16_t>(val(hot_.controlword));
  // The controlword of the last call again, in a state where it was seen
  // to cause no transition without an edge: apply_controlword() would
  // change nothing (no transition, no homing edge, homing_active_ already
  // cleared if bit 4 is 0), so it is not called (most SYNCs).
  const bool settled = cw == last_cw_ && settled_cw_.valid && settled_cw_.state == state_ && settled_cw_.cw == cw &&
                       settled_cw_.qs == static_cast<std::int16_t>(sval(hot_.quick_stop_option)) &&
                       ((cw & cia402::cw::kHomingStart) != 0 || !homing_active_);
  if (!settled) apply_controlword(cw, out);
}

bool Emulator::mode_supported(std::int8_t mode) const noexcept {
  if (mode == 0) return true;  // no mode
  // 0x6502 as the drive serves it (an EDS's value with cia402-emu --eds);
  // EmulatorConfig::supported_modes when the drive has no 0x6502.
  const std::uint64_t modes = hot_.supported_modes != nullptr ? hot_.supported_modes->value : cfg_.supported_modes;
  return (modes & cia402::supported_mode_bit(static_cast<cia402::Mode>(mode))) != 0;
}

void Emulator::set_mode_display(std::int8_t mode) noexcept {
  mode_display_ = mode;
  put(hot_.mode_display, static_cast<std::uint8_t>(mode));
}

void Emulator::switch_mode(std::int8_t mode) noexcept {
  if (state_ == State::kOperationEnabled && mode != mode_display_) {
    // Mode switch while enabled: the new mode starts from the present state.
    prev_demand_ = pos_;
    delay_.fill(Setpoint{position(), static_cast<std::int32_t>(sval(hot_.target_velocity)),
                         static_cast<std::int16_t>(sval(hot_.target_torque))});
    reset_direct_model();
  }
  set_mode_display(mode);
}

void Emulator::update_mode_display() noexcept {
  if (cfg_.refuse_mode_switch) return;  // fault injection: 0x6061 keeps showing the old mode
  const auto modes = static_cast<std::int8_t>(sval(hot_.modes));
  if (cfg_.behaviour.refuse_unsupported_modes && !mode_supported(modes)) {
    mode_wanted_ = mode_display_;  // an RPDO wrote a mode the drive lacks: not taken
    return;
  }
  if (modes != mode_wanted_) {
    mode_wanted_ = modes;
    mode_countdown_ = cfg_.behaviour.mode_switch_syncs;
  }
  if (mode_countdown_ > 0) {
    --mode_countdown_;
    return;
  }
  if (mode_wanted_ != mode_display_) switch_mode(mode_wanted_);
}

bool Emulator::fault_cause_remains() const noexcept {
  if (fault_cause_held_ || fault_cause_syncs_left_ > 0) return true;
  if (cfg_.behaviour.fault_cause_syncs == 0) return false;
  for (const Consumer& k : consumers_)
    if (k.lost) return true;  // the master's heartbeat has not come back
  return false;
}

void Emulator::refresh_error_register() noexcept {
  std::uint8_t r = active_fault_ != 0 ? error_register_for(active_fault_) : 0;
  bool comm = rpdo_short_error_ || rpdo_long_error_ || sync_length_error_ || sync_timeout_error_;
  for (const Consumer& k : consumers_) comm = comm || k.lost;
  if (comm) r |= canopen::kErrGeneric | canopen::kErrCommunication;
  put(hot_.error_register, r);
}

void Emulator::comm_error(bool& flag, bool active, std::uint16_t code, canopen::FrameSink& out) noexcept {
  if (flag == active) return;
  flag = active;
  refresh_error_register();
  send_emcy(active ? code : canopen::emcy_code::kNoError, out);
}

void Emulator::apply_error_behaviour() noexcept {
  if (!cfg_.behaviour.error_behaviour) return;
  switch (get(0x1029, 1)) {
    case 0:
      if (nmt_ == canopen::NmtState::kOperational) nmt_ = canopen::NmtState::kPreOperational;
      break;
    case 2: nmt_ = canopen::NmtState::kStopped; break;
    default: break;  // 1: no change of the NMT state
  }
}

void Emulator::automatic_transitions(bool at_sync, canopen::FrameSink& out) noexcept {
  // 1: initialisation done (the DC bus has charged).
  if (state_ == State::kNotReadyToSwitchOn && now_ns_ >= boot_ready_ns_) state_ = State::kSwitchOnDisabled;
  if (at_sync) {
    // 12: the quick stop has stopped the motor (0x605A = 1..4; 5..8 stay).
    if (state_ == State::kQuickStopActive && vel_ == 0.0 &&
        !cia402::quick_stop_stays(static_cast<std::int16_t>(sval(hot_.quick_stop_option))))
      state_ = State::kSwitchOnDisabled;
    // 14: the fault reaction, begun before this SYNC, is complete.
    if (state_ == State::kFaultReactionActive) state_ = State::kFault;
    if (fault_cause_syncs_left_ > 0) --fault_cause_syncs_left_;
  }
  // 13: a fault was detected (injected, following error, heartbeat lost).
  if (pending_fault_ != 0) {
    const std::uint16_t code = pending_fault_;
    pending_fault_ = 0;
    if (code != canopen::emcy_code::kHeartbeatError && code != canopen::emcy_code::kFollowingError)
      fault_cause_syncs_left_ = cfg_.behaviour.fault_cause_syncs;  // an injected fault's cause lasts
    enter_fault(code, out);
  }
}

void Emulator::handle_sync(std::int64_t /*now_ns*/, canopen::FrameSink& out) noexcept {
  ++counters_.syncs;
  const bool operational = nmt_ == canopen::NmtState::kOperational;
  // Synchronous RPDOs received since the last SYNC take effect now.
  bool cw_written = false;
  if (operational) {
    for (unsigned pending = rpdo_pending_; pending != 0; pending &= pending - 1) {  // ascending
      const auto p = static_cast<std::size_t>(std::countr_zero(pending));
      // The latched frame was at least rpdo_[p].size_bytes long (checked in on_frame).
      cw_written = apply_rpdo(p, rpdo_latch_[p]) || cw_written;
    }
    rpdo_pending_ = 0;
  }
  // The drive application runs in every NMT state that processes SYNC (CiA
  // 301: the NMT state gates communication, here the RPDOs above, not the
  // CiA 402 device): strict, the controlword is evaluated at every SYNC, so
  // that 4 follows 3 also for a controlword written over SDO in
  // pre-operational; and 0x6061 follows 0x6060 there too (found by
  // tests/peers/conformance.py against cia402-emu, vcan.peer.conformance_emu).
  if (cw_written || cfg_.behaviour.one_transition_per_sync) evaluate_controlword(out);
  update_mode_display();
  if (cfg_.fail_after_syncs != 0 && counters_.syncs == cfg_.fail_after_syncs) pending_fault_ = cfg_.fail_emcy_code;
  // Motor: advances by the interpolation period 0x60C2, only here.
  const cia402::InterpolationPeriod ip{static_cast<std::uint8_t>(val(hot_.ip_value)),
                                        static_cast<std::int8_t>(sval(hot_.ip_index))};
  if (!sync_period_.valid || ip.value != sync_period_.ip.value || ip.index != sync_period_.ip.index) {
    std::int64_t ns = cia402::interpolation_period_ns(ip);
    if (ns <= 0) ns = 1'000'000;
    sync_period_ = SyncPeriod{ip, ns, static_cast<double>(ns) / 1e9, 1e9 / static_cast<double>(ns), true};
  }
  const std::int64_t period_ns = sync_period_.ns;
  advance_motor(sync_period_.dt);
  // Following error monitoring (CSP, IP following, Operation enabled).
  const auto window = static_cast<std::uint32_t>(val(hot_.fe_window));
  if (state_ == State::kOperationEnabled &&
      (mode_display_ == static_cast<std::int8_t>(cia402::Mode::kCsp) || ip_following()) && window != 0xFFFFFFFFu) {
    // The error between the set point (0x607A, IP 0x60C1:1) and the position, both modulo 2^32 (as 0x60F4).
    const auto target = position_setpoint();
    const double fe = std::abs(static_cast<double>(cia402::unwrap32(position_counts(), target)) - pos_);
    if (fe > window) {
      following_error_ = true;
      ++following_error_cycles_;
      const auto timeout_ms = static_cast<double>(val(hot_.fe_timeout));
      if (static_cast<double>(following_error_cycles_) * static_cast<double>(period_ns) / 1e6 >= timeout_ms &&
          pending_fault_ == 0)
        pending_fault_ = canopen::emcy_code::kFollowingError;
    } else {
      following_error_ = false;
      following_error_cycles_ = 0;
    }
  }
  automatic_transitions(true, out);
  update_outputs();
  if (operational) send_tpdos(true, out);
}

}  // namespace canmotion::emulator
