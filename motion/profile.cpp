#include "motion/profile.hpp"

#include <algorithm>
#include <cmath>

namespace canmotion::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

inline double sgn(double x) noexcept { return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0); }

/// Integrates the state without storing segments (distance evaluation).
struct Sim {
  double t = 0, x = 0, v = 0, a = 0;
  bool ok = true;
  void push(double dt, double j) noexcept {
    if (!(dt > 0)) return;
    x += v * dt + a * dt * dt / 2 + j * dt * dt * dt / 6;
    v += a * dt + j * dt * dt / 2;
    a += j * dt;
    t += dt;
  }
};

}  // namespace

/// Appends segments to a Profile while integrating the state.
class ProfileBuilder {
 public:
  ProfileBuilder(Profile& p, const Kin& s) noexcept : prof_(p) {
    prof_.n_ = 0;
    prof_.origin_ = s.p;
    v = s.v;
    a = s.a;
  }
  double t = 0, x = 0, v = 0, a = 0;
  bool ok = true;

  void push(double dt, double j) noexcept {
    if (!(dt > 0)) return;
    if (prof_.n_ >= Profile::kMaxSegments) { ok = false; return; }
    prof_.seg_[static_cast<std::size_t>(prof_.n_++)] = Segment{t, dt, x, v, a, j};
    x += v * dt + a * dt * dt / 2 + j * dt * dt * dt / 6;
    v += a * dt + j * dt * dt / 2;
    a += j * dt;
    t += dt;
  }
  Sim sim() const noexcept { return Sim{t, x, v, a, true}; }
  void finish(double end_x) noexcept {
    prof_.duration_ = t;
    prof_.end_x_ = end_x;
  }
  void finish_hold() noexcept {  // infinite cruise at the current velocity
    if (prof_.n_ < Profile::kMaxSegments) {
      prof_.seg_[static_cast<std::size_t>(prof_.n_++)] = Segment{t, kInf, x, v, 0.0, 0.0};
    } else {
      ok = false;
    }
    prof_.duration_ = kInf;
    prof_.end_x_ = x;
  }

 private:
  Profile& prof_;
};

namespace {

/// Velocity change to vt, ending with a = 0, with peak |accel| A and jerk J
/// (J = inf: trapezoidal, the acceleration steps). Closed form.
template <class B>
void vel_change(B& b, double vt, double A, double J) noexcept {
  if (std::isinf(J)) {
    const double dv = vt - b.v;
    if (dv != 0) {
      b.a = sgn(dv) * A;
      b.push(std::fabs(dv) / A, 0.0);
    }
    b.a = 0;
    b.v = vt;
    return;
  }
  const double a = b.a;
  const double vs = b.v + a * std::fabs(a) / (2 * J);
  const double diff = vt - vs;
  if (diff == 0) {
    if (a != 0) b.push(std::fabs(a) / J, -sgn(a) * J);
  } else {
    const double s = sgn(diff);
    const double a0 = s * a;
    const double dv = s * (vt - b.v);
    const double ap_tri = std::sqrt(std::max(0.0, J * dv + a0 * a0 / 2));
    if (ap_tri <= A) {
      b.push((ap_tri - a0) / J, s * J);
      b.push(ap_tri / J, -s * J);
    } else {
      const double t1 = std::fabs(A - a0) / J;
      const double dv1 = (A + a0) / 2 * t1;
      const double dv3 = A * A / (2 * J);
      const double t2 = std::max(0.0, (dv - dv1 - dv3) / A);
      b.push(t1, A >= a0 ? s * J : -s * J);
      b.push(t2, 0.0);
      b.push(A / J, -s * J);
    }
  }
  b.a = 0;
  b.v = vt;
}

inline double ramp_vel(double v, double a, double J) noexcept {
  return std::isinf(J) ? v : v + a * std::fabs(a) / (2 * J);
}

/// Velocity change choosing the limits: (a, ja) while the speed in the
/// direction of motion `sg` grows, (d, jd) while it shrinks. When the present
/// acceleration opposes the change, it is first ramped to zero with the jerk
/// of the phase it belongs to (ja if it speeds up the motion, jd if it brakes).
template <class B>
void vel_change_lim(B& b, double vt, const Limits& lim, double sg) noexcept {
  const double jc = sg * b.a >= 0 ? lim.ja : lim.jd;
  const double vs = ramp_vel(b.v, b.a, jc);
  const double s = sgn(vt - vs);
  if (b.a != 0 && sgn(b.a) != s) {
    if (!std::isinf(jc)) b.push(std::fabs(b.a) / jc, -sgn(b.a) * jc);
    b.a = 0;
    b.v = vs;
  }
  if (s == 0) {
    b.a = 0;
    b.v = vt;
    return;
  }
  const bool speedup = (s == sg) || sg == 0;
  vel_change(b, vt, speedup ? lim.a : lim.d, speedup ? lim.ja : lim.jd);
}

bool limits_valid(const Limits& l) noexcept {
  return l.v > 0 && l.a > 0 && l.d > 0 && l.ja > 0 && l.jd > 0 && std::isfinite(l.v) &&
         std::isfinite(l.a) && std::isfinite(l.d) && !std::isnan(l.ja) && !std::isnan(l.jd);
}

bool kin_valid(const Kin& k) noexcept {
  return std::isfinite(k.p) && std::isfinite(k.v) && std::isfinite(k.a);
}

}  // namespace

// Profile::sample: inline in profile.hpp (one call per generator per cycle).

double Profile::peak_velocity() const noexcept {
  double m = 0;
  for (int i = 0; i < n_; ++i) {
    const Segment& s = seg_[static_cast<std::size_t>(i)];
    const double t1 = std::isinf(s.dt) ? 0.0 : s.dt;
    m = std::max(m, std::fabs(s.v));
    m = std::max(m, std::fabs(s.v + s.a * t1 + s.j * t1 * t1 / 2));
    if (s.j != 0) {
      const double tm = -s.a / s.j;  // extremum of v inside the segment
      if (tm > 0 && tm < t1) m = std::max(m, std::fabs(s.v + s.a * tm + s.j * tm * tm / 2));
    }
  }
  return m;
}

double jerk_from_percent_of_time(double rate, double speed, double percent) noexcept {
  if (!(percent > 0) || !(speed > 0)) return kInf;
  return rate * rate / speed * (200.0 / percent - 1.0);
}

bool plan_stop(Profile& out, const Kin& start, double d, double jd) noexcept {
  if (!(d > 0) || !(jd > 0) || !kin_valid(start)) return false;
  ProfileBuilder b(out, start);
  const double sg = b.v != 0 ? sgn(b.v) : -sgn(b.a);
  Limits lim{1.0, d, d, jd, jd};
  if (sg == 0) {
    b.finish(0.0);
    return true;
  }
  vel_change_lim(b, 0.0, lim, sg);
  b.finish(b.x);
  return b.ok;
}

bool plan_velocity(Profile& out, const Kin& start, double velocity, const Limits& lim) noexcept {
  if (!limits_valid(lim) || !kin_valid(start) || !std::isfinite(velocity)) return false;
  ProfileBuilder b(out, start);
  const double cur = b.v != 0 ? sgn(b.v) : sgn(b.a);
  if (cur != 0 && sgn(velocity) == -cur) {
    vel_change_lim(b, 0.0, lim, cur);  // stop first, then reverse
  }
  const double sg = velocity != 0 ? sgn(velocity) : (b.v != 0 ? sgn(b.v) : sgn(b.a));
  if (sg != 0) vel_change_lim(b, velocity, lim, sg);
  b.finish_hold();
  return b.ok;
}

namespace {

/// Decel, accel and both jerks scaled by k (MCD: stop exactly on target).
Limits scaled(Limits l, double k) noexcept {
  l.a *= k; l.d *= k; l.ja *= k; l.jd *= k;
  return l;
}

/// The limits with decel d (a stop softer than lim.d).
Limits with_decel(Limits l, double d) noexcept {
  l.d = d;
  return l;
}

/// Peak velocity of a move of length R from velocity v0 >= 0 at zero
/// acceleration, in closed form when both ramps have a constant-acceleration
/// phase (quadratic in vp) or, from rest, when both are triangular (vp^3/2);
/// -1 for other shapes. Only peaks in [vlo, V] count.
double closed_form_peak(double v0, const Limits& lim, double R, double vlo, double V) noexcept {
  const double A = lim.a, D = lim.d;
  const double ia = std::isinf(lim.ja) ? 0.0 : 1.0 / lim.ja, id = std::isinf(lim.jd) ? 0.0 : 1.0 / lim.jd;
  double vp = -1;
  {  // both trapezoidal
    const double qa = 1 / (2 * A) + 1 / (2 * D), qb = A * ia / 2 + D * id / 2;
    const double qc = -v0 * v0 / (2 * A) + v0 * A * ia / 2 - R;
    const double disc = qb * qb - 4 * qa * qc;
    if (disc >= 0) {
      const double x = (-qb + std::sqrt(disc)) / (2 * qa);
      if (x - v0 >= A * A * ia && x >= D * D * id && x >= vlo && x <= V) vp = x;
    }
  }
  if (vp < 0 && v0 == 0 && ia > 0 && id > 0) {  // both triangular, from rest
    const double x = std::cbrt(std::pow(R / (std::sqrt(ia) + std::sqrt(id)), 2.0));
    if (x < A * A * ia && x < D * D * id && x <= V) vp = x;
  }
  return vp;
}

/// plan_move_to's end speed ve > 0 out of reach within Rabs (the stop to ve
/// is longer): end at the reachable speed closest to ve and cover the rest at
/// that speed. Too short to speed up to ve: the fastest reachable (from 0 up);
/// unable to slow down to ve in time: the slowest reachable (from the speed
/// after the present acceleration is ramped out, down) -- a faster hand-over,
/// never a harder brake. The distance to a speed is monotone on either side:
/// bounded bisection. False if it cannot even stop within Rabs (the caller
/// then plans it as plan_move).
bool fit_end_speed(ProfileBuilder& b, double ve, double Rabs, double sg, const Limits& lim) noexcept {
  const double vrel = sg * b.v, arel = sg * b.a;
  const double vs = ramp_vel(vrel, arel, arel >= 0 ? lim.ja : lim.jd);
  auto dist = [&](double v1) noexcept {
    Sim s = b.sim();
    vel_change_lim(s, sg * v1, lim, sg);
    return sg * (s.x - b.x);
  };
  const double v_fit = vs < ve ? 0.0 : vs;
  if (dist(v_fit) > Rabs) return false;
  double ok = v_fit, bad = ve;
  for (int i = 0; i < kSolveIterations && std::fabs(bad - ok) > 1e-13 * std::max(ok, bad); ++i) {
    const double mid = (ok + bad) / 2;
    if (dist(mid) <= Rabs) ok = mid; else bad = mid;
  }
  const double x0 = b.x;
  vel_change_lim(b, sg * ok, lim, sg);
  const double rest = Rabs - sg * (b.x - x0);
  if (ok > 0 && rest > 0) b.push(rest / ok, 0.0);
  return true;
}

/// Overshoot::StopAtTarget from a state that cannot stop at the target with
/// `lim` (or whose braking acceleration the decel jerk cannot ramp out before
/// the velocity reaches zero): stop with decel, accel and both jerks scaled up
/// by the smallest k >= 1 that neither reverses nor passes the target (Rabs
/// ahead in direction sg), ending at `vend` (0, or plan_move_to's end
/// velocity). True when even that stop ends short of the target
/// (a braking acceleration that cannot be ramped out): the caller goes on
/// from rest with the programmed limits; ending the profile there would leave
/// the rest to its final sample, a jump to the target.
template <class B>
bool stop_on_target(B& b, double vend, const Limits& lim, double sg, double Rabs) noexcept {
  const double vrel = sg * b.v, arel = sg * b.a;
  auto stop_dist = [&](const Limits& l) noexcept {
    Sim s = b.sim();
    vel_change_lim(s, vend, l, sg);
    return sg * (s.x - b.x);
  };
  auto reverses = [&](double jd) noexcept { return arel < 0 && vrel - arel * arel / (2 * jd) < 0; };
  double lo = 0.0, hi = std::log(1e9);  // log k
  for (int i = 0; i < kSolveIterations && hi - lo > 1e-14; ++i) {
    const double mid = (lo + hi) / 2;
    const Limits l = scaled(lim, std::exp(mid));
    if (reverses(l.jd) || stop_dist(l) > Rabs) lo = mid; else hi = mid;
  }
  const Limits k_lim = scaled(lim, std::exp(hi));
  const bool short_stop = reverses(lim.jd) && stop_dist(k_lim) < Rabs * (1 - 1e-12);
  vel_change_lim(b, vend, k_lim, sg);
  return short_stop;
}


/// dstop <= Rabs < the distance of any fuller profile: stop now with a softer
/// deceleration d' in (0, d] (bounded bisection on log(d'/d); the stop
/// distance decreases with d').
void soft_stop(ProfileBuilder& b, double vend, const Limits& lim, double sg, double Rabs) noexcept {
  auto stop_dist = [&](const Limits& l) noexcept {
    Sim s = b.sim();
    vel_change_lim(s, vend, l, sg);
    return sg * (s.x - b.x);
  };
  double lo = std::log(1e-12), hi = 0.0;
  for (int i = 0; i < kSolveIterations && hi - lo > 1e-14; ++i) {
    const double mid = (lo + hi) / 2;
    if (stop_dist(with_decel(lim, lim.d * std::exp(mid))) > Rabs) lo = mid; else hi = mid;
  }
  vel_change_lim(b, vend, with_decel(lim, lim.d * std::exp(hi)), sg);
}

/// plan_move and plan_move_to: a move ending at `distance` with velocity
/// `ve` (>= 0, towards the target; 0 = at rest). With ve == 0 every
/// expression below reduces to the original plan_move arithmetic (vend is
/// +0.0, the ve > 0 branches are skipped), so plan_move is unchanged.
bool plan_move_impl(Profile& out, const Kin& start, double distance, double ve, const Limits& lim,
                    Overshoot policy) noexcept {
  if (!limits_valid(lim) || !kin_valid(start) || !std::isfinite(distance)) return false;
  ProfileBuilder b(out, start);
  const double X = distance;
  // passes: brake away-going motion; a short stop (StopAtTarget); the move
  for (int pass = 0; pass < 4; ++pass) {
    const double R = X - b.x;
    double sg = sgn(R);
    if (sg == 0) sg = b.v != 0 ? sgn(b.v) : sgn(b.a);
    if (sg == 0) break;  // on target, at rest
    const double vend = ve > 0 ? sg * ve : 0.0;  // end velocity (signed)
    const double vrel = sg * b.v, arel = sg * b.a;
    if (vrel < 0 || (vrel == 0 && arel < 0)) {  // moving away: brake, then re-plan
      vel_change_lim(b, 0.0, lim, -sg);
      continue;
    }
    const double Rabs = std::fabs(R);
    auto stop_dist = [&](const Limits& l) noexcept {
      Sim s = b.sim();
      vel_change_lim(s, vend, l, sg);
      return sg * (s.x - b.x);
    };
    const double dstop = stop_dist(lim);
    // A braking acceleration that the jerk limit cannot ramp out before the
    // velocity reaches zero (possible after MCD lowered the decel jerk).
    auto reverses = [&](double jd) noexcept { return arel < 0 && vrel - arel * arel / (2 * jd) < 0; };
    if (ve > 0 && dstop > Rabs) {
      if (fit_end_speed(b, ve, Rabs, sg, lim)) break;
      if (ramp_vel(vrel, arel, arel >= 0 ? lim.ja : lim.jd) < ve) {  // cannot even stop in time: as plan_move
        ve = 0.0;
        continue;
      }
    }
    if (dstop > Rabs || (policy == Overshoot::StopAtTarget && reverses(lim.jd))) {
      if (policy == Overshoot::Reverse && ve == 0) {  // a move ending in motion never reverses
        vel_change_lim(b, 0.0, lim, sg);
        continue;
      }
      if (stop_on_target(b, vend, lim, sg, Rabs)) continue;  // stopped short: on from rest
      break;
    }
    auto f = [&](double vp) noexcept {
      Sim s = b.sim();
      vel_change_lim(s, sg * vp, lim, sg);
      vel_change_lim(s, vend, lim, sg);
      return sg * (s.x - b.x);
    };
    auto build = [&](double vp, double fvp) noexcept {
      vel_change_lim(b, sg * vp, lim, sg);
      const double cruise = Rabs - fvp;
      if (vp > 0 && cruise > 0) b.push(cruise / vp, 0.0);
      vel_change_lim(b, vend, lim, sg);
    };
    const double V = lim.v;
    const double vs_up = ramp_vel(vrel, arel, arel >= 0 ? lim.ja : lim.jd);
    const double fV = f(V);
    if (fV <= Rabs) {
      build(V, fV);
      break;
    }
    if (vs_up <= V) {
      const double vlo = std::max(vs_up, ve > 0 ? ve : 0.0);
      // Closed form from zero acceleration; other shapes use the bounded solve below.
      if (ve == 0 && arel == 0 && vrel >= 0) {
        const double vp = closed_form_peak(vrel, lim, Rabs, vlo, V);
        if (vp > 0) {
          const double fvp = f(vp);
          if (std::fabs(fvp - Rabs) <= 1e-9 * std::max(Rabs, 1e-300)) {
            build(vp, fvp);
            break;
          }
        }
      }
      const double flo = f(vlo);
      if (flo <= Rabs) {
        double lo = vlo, hi = V, flo_v = flo;
        for (int i = 0; i < kSolveIterations && hi - lo > 1e-13 * hi; ++i) {
          const double mid = (lo + hi) / 2;
          const double fm = f(mid);
          if (fm <= Rabs) { lo = mid; flo_v = fm; } else { hi = mid; }
        }
        build(lo, flo_v);
        break;
      }
    }
    soft_stop(b, vend, lim, sg, Rabs);  // dstop <= R < f(...)
    break;
  }
  b.finish(X);
  return b.ok;
}

}  // namespace

bool plan_move(Profile& out, const Kin& start, double distance, const Limits& lim, Overshoot policy) noexcept {
  return plan_move_impl(out, start, distance, 0.0, lim, policy);
}

bool plan_move_to(Profile& out, const Kin& start, double distance, double end_velocity, const Limits& lim,
                  Overshoot policy) noexcept {
  if (!(end_velocity >= 0) || !std::isfinite(end_velocity)) return false;
  if (distance == 0) end_velocity = 0;
  return plan_move_impl(out, start, distance, std::min(end_velocity, lim.v), lim, policy);
}

}  // namespace canmotion::motion
