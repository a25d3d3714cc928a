#pragma once
/// \file
/// Running a calculated cam profile as MATC / MAPC do: distance (slave) and
/// time (master) scaling, direction, and the Once / Continuous / Persistent
/// execution modes with unwinding and pass-to-pass slave offset accumulation.
/// Pure code: the caller supplies the driving coordinate (cam time for a
/// time-driven MATC, master travel for MAPC or a master-driven MATC).
#include <cstddef>
#include <cstdint>

#include "motion/cam/cam_error.hpp"
#include "motion/cam/cam_profile.hpp"

namespace canmotion::motion::cam {

/// MATC / MAPC ExecutionMode (Logix numbers; 2 only for MAPC) [RM002H p.173, 188].
enum class ExecutionMode : std::int32_t {
  Once = 0,        ///< one pass; PC when the coordinate leaves the profile's range
  Continuous = 1,  ///< unwinds and repeats indefinitely
  Persistent = 2,  ///< MAPC: unlocks outside the range, relocks on re-entry
};

/// Profile scaling. MATC: slave = DistanceScaling, master = TimeScaling.
/// MAPC: slave = SlaveScaling, master = MasterScaling.
/// The scaled cam is  y(x) = slave * P(x / master):
///   position  scales by slave,
///   velocity  scales by slave / master,
///   accel     scales by slave / master^2,
/// and the profile's master range (time or master distance) stretches by master.
struct CamScaling {
  double slave = 1.0;   ///< distance / slave scaling: finite (0 allowed: no motion)
  double master = 1.0;  ///< time / master scaling: finite and > 0
};

/// Checks a scaling pair: slave finite, master finite and > 0. Returns
/// ParameterOutOfRange (13) and sets `bad_slave` / `bad_master` telling which
/// one failed, so the caller can put its own operand index in EXERR
/// (MATC: 4 DistanceScaling, 5 TimeScaling; MAPC: 5 SlaveScaling, 6 MasterScaling).
/// Realtime-safe.
[[nodiscard]] CamError check_scaling(const CamScaling& scaling, bool& bad_slave, bool& bad_master) noexcept;

/// Scaled sample at coordinate x of the scaled cam: y = slave * P(x / master),
/// with derivatives with respect to x. Realtime-safe.
[[nodiscard]] CamSample evaluate_scaled(const CamProfile& profile, double x, const CamScaling& scaling,
                                        CamCursor& cursor, EndBehaviour end = EndBehaviour::Clamp) noexcept;

/// Resolves the MATC/MAPC Direction operand (0 Same, 1 Opposite, 2 Reverse,
/// 3 Unchanged) into +1 / -1 [seed 004 Direction; reference §1.3].
/// `previous` is the axis' current or previous camming direction (+1 / -1),
/// or 0 when the axis has never cammed: then Reverse defaults to Opposite
/// (-1) and Unchanged to Same (+1). Returns 0 for a value outside 0..3 (the
/// caller reports ERR 13 with the Direction operand index). Realtime-safe.
[[nodiscard]] constexpr int resolve_direction(std::int32_t direction, int previous) noexcept {
  switch (direction) {
    case 0: return 1;
    case 1: return -1;
    case 2: return previous == 0 ? -1 : -previous;
    case 3: return previous == 0 ? 1 : previous;
    default: return 0;
  }
}

/// Where the driving coordinate is relative to the profile's master range.
enum class CamRange : std::uint8_t {
  Inside = 0,       ///< inside [master_start, master_end]
  BeforeStart = 1,  ///< below master_start (Once / Persistent only)
  PastEnd = 2,      ///< above master_end (Once / Persistent only)
};

/// Parameters of one running cam (one MATC / MAPC process).
struct CamMotionConfig {
  ExecutionMode mode = ExecutionMode::Once;
  CamScaling scaling{};
  /// +1 for Same (profile added to the command position), -1 for Opposite
  /// (subtracted). Reverse / Unchanged are resolved by the caller into one of
  /// these [seed 004 Direction]. Other values are refused (13).
  int direction = 1;
  /// Profile master coordinate (unscaled) where the cam starts: MAPC
  /// CamLockPosition. Must lie in [master_start, master_end], else 13.
  /// Ignored unless use_lock_position; a MATC starts at master_start.
  double lock_position = 0.0;
  bool use_lock_position = false;
};

/// One cycle's output of a running cam.
struct CamMotionOutput {
  /// Slave displacement since the start of the cam (x = 0), scaled and with
  /// the direction applied: add it to the slave command position held at start.
  double position = 0.0;
  double velocity = 0.0;      ///< d position / d x (units/s for a time cam)
  double acceleration = 0.0;  ///< d^2 position / d x^2
  /// Pass number: 0 for the first pass; counts up in Continuous mode (down
  /// when the master runs backwards past the start).
  std::int64_t pass = 0;
  double profile_master = 0.0;  ///< unwound, unscaled profile coordinate
  std::size_t segment = 0;      ///< profile segment (for MOTION_INSTRUCTION.SEGMENT)
  CamRange range = CamRange::Inside;
  /// Once mode only: the coordinate has left the profile's range (set PC,
  /// clear TimeCamStatus / PositionCamStatus; the slave holds the end position).
  bool complete = false;
};

/// A running cam. Stateless apart from its configuration, a segment cursor
/// and the last output (repeated for a non-finite x): step(x) is a pure
/// function of x, so position is exactly
/// reproducible and does not drift over long runs.
///
/// Continuous mode unwinds: with L = master_span and D = slave_span,
///   v = lock + x / master_scaling,  p = floor((v - M0) / L),
///   local = v - p * L,
///   position = dir * slave_scaling * (P(local) - P(lock) + p * D),
/// so each pass continues from where the previous one ended (no position jump
/// even when D != 0, e.g. a rotary slave advancing D per pass). Velocity and
/// acceleration are continuous across passes only if the profile's end
/// slopes/curvatures match (a profile design matter, as Logix warns).
///
/// The caller owns the profile's in-use count: call profile.acquire() before
/// start() (ERR 32 if not calculated) and profile.release() when the cam
/// completes or is terminated. The profile must outlive the CamMotion.
class CamMotion {
 public:
  /// Starts a cam on `profile`. Errors: CamProfileNotCalculated (32) when the
  /// profile is not calculated; ParameterOutOfRange (13) for bad scaling,
  /// direction or lock position (`bad_operand` says which: 1 scaling.slave,
  /// 2 scaling.master, 3 direction, 4 lock_position, 5 mode). On error the cam stays
  /// inactive. Realtime-safe.
  [[nodiscard]] CamError start(const CamProfile& profile, const CamMotionConfig& config,
                               int* bad_operand = nullptr) noexcept;

  /// Evaluates the cam at driving coordinate x, measured from the start
  /// (x = 0 at start): cam time in s for a time-driven MATC, master travel
  /// for MAPC / master-driven MATC (unwrapped; negative when the master runs
  /// backwards). Returns zeros when not active. A non-finite x (an upstream
  /// fault) repeats the last output with velocity and acceleration 0.
  /// Realtime-safe, O(1) amortised
  /// for monotonic x, O(log n) after a jump.
  [[nodiscard]] CamMotionOutput step(double x) noexcept;

  /// Driving coordinate x at which pass `pass` ends (Once: the single pass,
  /// `pass` ignored). A pending cam takes over at pass_end(current pass);
  /// the new cam's x is then (x - pass_end). Realtime-safe.
  [[nodiscard]] double pass_end(std::int64_t pass = 0) const noexcept;

  /// Driving-coordinate length of one pass: master_span * master scaling.
  [[nodiscard]] double pass_length() const noexcept { return span_ * config_.scaling.master; }

  /// Slave displacement of one full pass: dir * slave scaling * slave_span.
  [[nodiscard]] double pass_distance() const noexcept { return dir_ * config_.scaling.slave * slave_span_; }

  [[nodiscard]] bool active() const noexcept { return profile_ != nullptr; }
  /// Forget the profile (the caller releases its in-use count). Realtime-safe.
  void stop() noexcept { profile_ = nullptr; }
  [[nodiscard]] const CamMotionConfig& config() const noexcept { return config_; }
  [[nodiscard]] const CamProfile* profile() const noexcept { return profile_; }

 private:
  const CamProfile* profile_ = nullptr;
  CamMotionConfig config_{};
  CamCursor cursor_{};
  CamMotionOutput last_{};
  double m0_ = 0.0, m1_ = 0.0, span_ = 0.0, slave_span_ = 0.0;
  double lock_ = 0.0, y_lock_ = 0.0, dir_ = 1.0;
};

}  // namespace canmotion::motion::cam
