#pragma once
/// \file motion/profile.hpp
/// Jerk-limited (S-curve) and trapezoidal 1-D profiles.
///
/// A Profile is a list of at most kMaxSegments constant-jerk segments
/// (trapezoidal profiles are S-curves with infinite jerk: the acceleration
/// steps). Planning is done once in `plan_move` / `plan_velocity` /
/// `plan_stop` (closed-form segment maths; the peak velocity of a short move is
/// found by a bounded bracketing solve of a monotone closed-form distance
/// function, at most kSolveIterations evaluations). Sampling (`Profile::sample`)
/// is closed-form and O(1) per call when time advances monotonically.
/// All functions are noexcept, allocate nothing and are realtime-safe.

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

namespace canmotion::motion {

/// Kinematic state: position, velocity, acceleration.
struct Kin {
  double p = 0.0;
  double v = 0.0;
  double a = 0.0;
};

/// Dynamic limits of a profile. A jerk of +infinity means trapezoidal.
struct Limits {
  double v = 0.0;   ///< maximum speed (> 0)
  double a = 0.0;   ///< maximum acceleration while speeding up (> 0)
  double d = 0.0;   ///< maximum deceleration while slowing down (> 0)
  double ja = std::numeric_limits<double>::infinity();  ///< jerk while speeding up
  double jd = std::numeric_limits<double>::infinity();  ///< jerk while slowing down
};

/// What to do when the axis cannot stop at the target with the given limits.
enum class Overshoot : std::uint8_t {
  Reverse,       ///< stop beyond the target and come back (new moves, merges)
  StopAtTarget,  ///< decelerate harder than `d` (and jerk likewise) so that the
                 ///< axis stops exactly on the target (MCD lowering limits mid-move)
};

/// One constant-jerk piece, in the profile's frame (position relative to origin).
struct Segment {
  double t0 = 0.0;  ///< start time, seconds since the profile start
  double dt = 0.0;  ///< duration (+inf for the final hold of a jog)
  double p = 0.0, v = 0.0, a = 0.0;  ///< state at t0
  double j = 0.0;   ///< jerk over the segment
};

/// A planned profile. Plain data: copyable, no heap.
class Profile {
 public:
  /// Upper bound: brake (3) + reverse speed-up (3) + cruise (1) + decel (3),
  /// plus a final hold; 16 leaves margin.
  static constexpr int kMaxSegments = 16;

  /// State at time t (seconds since the profile start). `hint` caches the
  /// segment index; pass the same variable on every call of a monotonic
  /// sequence for O(1) cost. After the end the state is the exact end
  /// position with v = a = 0 (for finite profiles). Realtime-safe.
  Kin sample(double t, int& hint) const noexcept;

  double duration() const noexcept { return duration_; }  ///< +inf for a jog
  bool finite() const noexcept { return duration_ < std::numeric_limits<double>::infinity(); }
  double origin() const noexcept { return origin_; }
  double end_position() const noexcept { return origin_ + end_x_; }  ///< absolute
  int size() const noexcept { return n_; }
  const Segment& segment(int i) const noexcept { return seg_[static_cast<std::size_t>(i)]; }
  /// Peak |jerk|, |a|, |v| over the segments (for tests and diagnostics).
  double peak_velocity() const noexcept;

 private:
  friend class ProfileBuilder;
  std::array<Segment, kMaxSegments> seg_{};
  int n_ = 0;
  double origin_ = 0.0;
  double duration_ = 0.0;
  double end_x_ = 0.0;
};

/// Plan a point-to-point move from `start` (absolute) by `distance` (target -
/// start.p). Returns false only for invalid limits (non-positive v/a/d or jerk).
/// The profile ends exactly at start.p + distance with v = a = 0. Realtime-safe.
bool plan_move(Profile& out, const Kin& start, double distance, const Limits& lim,
               Overshoot policy = Overshoot::Reverse) noexcept;

/// Plan a move that reaches start.p + distance with speed `end_velocity`
/// (>= 0, towards the target, clamped to lim.v) and a = 0: a path segment
/// that hands over to the next one at speed (coordinated Follow Contour,
/// motion/coord). end_velocity 0 is exactly plan_move. If the move is too
/// short to speed up to end_velocity it ends at the fastest reachable speed,
/// if it cannot slow down to it in time at the slowest reachable one (read
/// the end speed from the last segment); a move ending in motion never
/// reverses (a state that cannot even ramp out its acceleration in time is
/// scaled as Overshoot::StopAtTarget does). After duration() `sample`
/// reports v = 0: the caller hands over to the next profile at duration().
/// Realtime-safe.
bool plan_move_to(Profile& out, const Kin& start, double distance, double end_velocity, const Limits& lim,
                  Overshoot policy = Overshoot::StopAtTarget) noexcept;

/// Plan a velocity change to `velocity` (signed) and hold it forever (jog).
/// Uses lim.a/lim.ja while |v| grows and lim.d/lim.jd while it shrinks. Realtime-safe.
bool plan_velocity(Profile& out, const Kin& start, double velocity, const Limits& lim) noexcept;

/// Plan a stop (velocity to 0, acceleration to 0) with decel `d` and jerk `jd`
/// (+inf = trapezoidal). Realtime-safe.
bool plan_stop(Profile& out, const Kin& start, double d, double jd) noexcept;

/// Logix "% of time" jerk [UM003F p.258]: j = rate^2 / speed * (200/P - 1).
/// P = 0 returns +infinity (trapezoidal). Realtime-safe.
double jerk_from_percent_of_time(double rate, double speed, double percent) noexcept;

/// Number of distance evaluations the bracketing solve may use (bounded cost).
inline constexpr int kSolveIterations = 64;

// Inline: every generator samples its profile every cycle.
inline Kin Profile::sample(double t, int& hint) const noexcept {
  if (n_ == 0 || (t >= duration_ && finite())) return Kin{origin_ + end_x_, 0.0, 0.0};
  if (hint < 0 || hint >= n_ || t < seg_[static_cast<std::size_t>(hint)].t0) hint = 0;
  while (hint + 1 < n_ && t >= seg_[static_cast<std::size_t>(hint + 1)].t0) ++hint;
  const Segment& s = seg_[static_cast<std::size_t>(hint)];
  const double dt = std::max(0.0, t - s.t0);
  Kin k;
  k.p = origin_ + s.p + s.v * dt + s.a * dt * dt / 2 + s.j * dt * dt * dt / 6;
  k.v = s.v + s.a * dt + s.j * dt * dt / 2;
  k.a = s.a + s.j * dt;
  return k;
}

}  // namespace canmotion::motion
