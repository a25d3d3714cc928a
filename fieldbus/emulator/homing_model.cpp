// Homing of the emulated drive (CiA 402 mode 6), called from advance_motor()
// on SYNC only; realtime-safe (no allocation, no exceptions). See README.md
// "Emulator profiles".
//
// Strict model (EmulatorBehaviour::homing_takes_time), per method family:
//   35, 37      current position = home: no motion, done after 2 SYNCs;
//   17..30      home switch without index: search the switch edge at
//               EmulatorConfig::home_switch_position with 0x6099:1 (fast),
//               back off and approach the edge again with 0x6099:2 (slow);
//   1..14       as 17..30, then on at 0x6099:2 to the next index pulse (a
//               pulse at every multiple of EmulatorConfig::index_pulse_period);
//   33, 34      the next index pulse in the negative / positive direction, slow.
// Simplification: the switch search always heads towards the switch (a real
// drive's direction also depends on the method and the switch's state).
// At the home position the position becomes 0x607C (home offset); statusword
// bits 12 and 10 (attained, target reached). Bit 13 (homing error, with bit
// 10 once stopped) when a speed is 0 or no switch/index lies within
// EmulatorConfig::homing_max_travel. Other methods are refused when written
// to 0x6098 (SDO abort 0x06090030).
// Permissive model: 35/37 (or a position already at 0) complete in one SYNC,
// others search position 0 with 0x6099:1 and complete there.
#include <algorithm>
#include <cmath>

#include "fieldbus/emulator/emulator.hpp"

namespace canmotion::emulator {

namespace {
bool switch_method(std::int8_t m) { return (m >= 1 && m <= 14) || (m >= 17 && m <= 30); }
}  // namespace

bool Emulator::homing_method_supported(std::int8_t method) const noexcept {
  if (!cfg_.behaviour.homing_takes_time) return true;
  return switch_method(method) || method == 33 || method == 34 || method == 35 || method == 37;
}

void Emulator::start_homing() noexcept {
  homing_active_ = true;
  homing_done_ = false;  // a stale "attained" from a previous homing is cleared at the start
  homing_error_ = false;
  homing_travel_ = 0;
  if (!cfg_.behaviour.homing_takes_time) return;
  const auto method = static_cast<std::int8_t>(sval(hot_.homing_method));
  if (method == 35 || method == 37) {
    homing_phase_ = HomingPhase::kSettle;
    homing_settle_ = 2;
  } else if (switch_method(method)) {
    homing_phase_ = HomingPhase::kSearchSwitch;
  } else if (method == 33 || method == 34) {
    homing_phase_ = HomingPhase::kSearchIndex;
    const double period = cfg_.index_pulse_period;
    // The next pulse strictly beyond the present position in that direction.
    homing_edge_ = method == 34 ? (std::floor(pos_ / period) + 1.0) * period : (std::ceil(pos_ / period) - 1.0) * period;
  } else {
    homing_error_ = true;  // a method this drive lacks (only reachable through an RPDO)
    homing_active_ = false;
  }
}

double Emulator::homing_velocity(double dt, double& amax, bool& stop) noexcept {
  if (!homing_active_ || homing_done_ || homing_error_) return 0.0;
  const auto finish = [&] {
    pos_ = static_cast<double>(sval(hot_.home_offset));
    homing_done_ = true;
    homing_active_ = false;
    homing_phase_ = HomingPhase::kIdle;
    stop = true;
    return 0.0;
  };
  // A velocity that lands exactly on `target` (the model may accelerate at once).
  const auto move_to = [&](double target, double speed) {
    const double step = std::min(speed * dt, std::abs(target - pos_));
    const double v = (target < pos_ ? -step : step) / dt;
    amax = std::max(amax, std::abs(v - vel_) / dt);
    homing_travel_ += step;
    return v;
  };
  if (!cfg_.behaviour.homing_takes_time) {
    const auto method = static_cast<std::int8_t>(sval(hot_.homing_method));
    if (method == 35 || method == 37 || std::abs(pos_) < 1.0) return finish();
    return move_to(0.0, static_cast<double>(val(hot_.homing_speed_switch)) * vel_scale_);
  }
  const double fast = static_cast<double>(val(hot_.homing_speed_switch)) * vel_scale_;
  const double slow = static_cast<double>(get(cia402::obj::kHomingSpeeds, 2)) * vel_scale_;
  const auto fail = [&] {
    homing_error_ = true;
    homing_active_ = false;
    homing_phase_ = HomingPhase::kIdle;
    stop = true;
    return 0.0;
  };
  if (homing_travel_ > cfg_.homing_max_travel) return fail();
  const auto method = static_cast<std::int8_t>(sval(hot_.homing_method));
  constexpr double kAt = 0.5;  // counts: "at" a target
  switch (homing_phase_) {
    case HomingPhase::kSettle:
      stop = true;
      if (homing_settle_ == 0) return finish();
      --homing_settle_;
      return 0.0;
    case HomingPhase::kSearchSwitch: {
      if (fast <= 0.0 || slow <= 0.0) return fail();
      const double sw = cfg_.home_switch_position;
      if (std::abs(pos_ - sw) < kAt) {
        homing_edge_ = sw;
        homing_phase_ = HomingPhase::kBackOff;
        stop = true;
        return 0.0;
      }
      homing_dir_ = sw > pos_ ? 1.0 : -1.0;
      return move_to(sw, fast);
    }
    case HomingPhase::kBackOff: {
      // Off the switch by a few slow SYNCs, then back onto its edge.
      const double target = homing_edge_ - homing_dir_ * std::max(3.0 * slow * dt, 1.0);
      if (std::abs(pos_ - target) < kAt) {
        homing_phase_ = HomingPhase::kApproachEdge;
        return 0.0;
      }
      return move_to(target, slow);
    }
    case HomingPhase::kApproachEdge:
      if (std::abs(pos_ - homing_edge_) < kAt) {
        if (method >= 17) return finish();  // 17..30: the edge is home
        const double period = cfg_.index_pulse_period;
        homing_edge_ = homing_dir_ > 0 ? (std::floor(pos_ / period) + 1.0) * period
                                       : (std::ceil(pos_ / period) - 1.0) * period;
        homing_phase_ = HomingPhase::kSearchIndex;
        return 0.0;
      }
      return move_to(homing_edge_, slow);
    case HomingPhase::kSearchIndex:
      if (slow <= 0.0) return fail();
      if (std::abs(pos_ - homing_edge_) < kAt) return finish();
      return move_to(homing_edge_, slow);
    case HomingPhase::kIdle: break;
  }
  return 0.0;
}

}  // namespace canmotion::emulator
