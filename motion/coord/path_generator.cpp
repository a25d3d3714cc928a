#include "motion/coord/path_generator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "motion/master_follow.hpp"

namespace canmotion::motion::coord {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool limits_ok(const Limits& l) noexcept {
  return std::isfinite(l.v) && l.v >= 0 && std::isfinite(l.a) && l.a > 0 && std::isfinite(l.d) && l.d > 0 &&
         l.ja > 0 && l.jd > 0;  // NaN fails every comparison
}

/// Distance to stop from speed v (a = 0) with decel d and jerk jd: the closed
/// form of the profile's velocity change (triangular or trapezoidal accel).
double stop_distance(double v, double d, double jd) noexcept {
  if (!(v > 0)) return 0.0;
  if (std::isinf(jd)) return v * v / (2 * d);
  if (v >= d * d / jd) return v * (v / d + d / jd) / 2;
  return v * std::sqrt(v / jd);
}

/// Largest speed (a = 0) from which a stop fits in distance L: the inverse of stop_distance.
double stop_speed(double L, double d, double jd) noexcept {
  if (!(L > 0)) return 0.0;
  if (std::isinf(jd)) return std::sqrt(2 * d * L);
  const double b = d * d / jd;  // speed where the decel reaches d
  if (L >= b * d / jd) return (-b + std::sqrt(b * b + 8 * d * L)) / 2;
  return std::cbrt(L * L * jd);
}

/// Profile time where the final deceleration starts: the last run of segments
/// that brake (a <= 0 throughout, not a cruise). duration() if there is none.
double decel_start(const Profile& p) noexcept {
  int i = p.size();
  while (i > 0) {
    const Segment& s = p.segment(i - 1);
    const double a1 = s.a + s.j * s.dt;
    const bool braking = s.a <= 0 && a1 <= 1e-9 * std::fabs(s.a) && !(s.a == 0 && s.j == 0);
    if (!braking) break;
    --i;
  }
  return i < p.size() ? p.segment(i).t0 : p.duration();
}

/// Velocity at the end of the last segment (the end speed of plan_move_to).
double end_velocity(const Profile& p) noexcept {
  if (p.size() == 0) return 0.0;
  const Segment& s = p.segment(p.size() - 1);
  return s.v + s.a * s.dt + s.j * s.dt * s.dt / 2;
}

/// A stop from k at decel d / jerk jd that never passes the end L of the
/// segment: if plan_stop would, it stops exactly at L (decelerating harder,
/// Overshoot::StopAtTarget). Returns true in that case.
/// A braking acceleration that jerk jd cannot ramp out before the speed
/// reaches 0 (after MCCD lowered the decel jerk) would make plan_stop back
/// up: then the stop ends where the speed first reaches 0, with the jerk
/// scaled as Overshoot::StopAtTarget does (MCD's policy: never back up).
bool plan_stop_before(Profile& p, const Kin& k, double L, double d, double jd) noexcept {
  const Limits lim{std::max(std::fabs(k.v), d * 1e-9), d, d, jd, jd};
  if (k.v > 0 && k.a < 0 && std::isfinite(jd) && k.v - k.a * k.a / (2 * jd) < 0) {
    const double t = (-k.a - std::sqrt(std::max(0.0, k.a * k.a - 2 * jd * k.v))) / jd;  // v(t) = 0
    const double x = k.v * t + k.a * t * t / 2 + jd * t * t * t / 6;
    const bool at_end = k.p + x >= L && k.p <= L;
    plan_move_to(p, k, at_end ? L - k.p : x, 0.0, lim, Overshoot::StopAtTarget);
    return at_end;
  }
  plan_stop(p, k, d, jd);
  if (!(k.p <= L && p.end_position() > L)) return false;
  plan_move_to(p, k, L - k.p, 0.0, lim, Overshoot::StopAtTarget);
  return true;
}

template <class T>
bool done(const T& t) noexcept {
  return t.u - t.u0 >= t.prof.duration();
}

}  // namespace

void PathGenerator::configure(const SystemConfig& cfg) noexcept {
  *this = PathGenerator{};
  cfg_ = cfg;
  cfg_.dim = std::clamp(cfg.dim, 1, kMaxDim);
}

// ------------------------------------------------------------------ helpers

Kin PathGenerator::to_time(const Track& t) const noexcept {
  const double m = t.clock == Clock::Master ? mdot_ : 1.0;
  return Kin{t.k.p, t.k.v * m, t.k.a * m * m};
}

double PathGenerator::ct_eff(bool with_successor) const noexcept {
  const double ct = head_.rq.termination == Termination::CommandTolerance ? cfg_.command_tolerance
                                                                          : head_.rq.command_tolerance;
  const double L = ht_.path.length();
  // [RM002H p.502]: min(CT, 100 % of L) for the first and the last move of a
  // blended sequence, min(CT, 50 % of L) for the others.
  const double cap = head_.blended_into && with_successor ? L / 2 : L;
  return std::min(std::max(ct, 0.0), cap);
}

void PathGenerator::fresh_lock(const MoveRequest& rq, const Present& now) noexcept {
  lock_ = rq.lock_direction;
  lock_pos_ = rq.lock_position;
  locked_ = lock_immediate(lock_);
  following_ = locked_;
  if (now.has_master) {
    prev_mp_ = now.master_position;
    have_mp_ = true;
  }
}

void PathGenerator::start_track(const Slot& s, double u) noexcept {
  Track& h = ht_;
  h.path = s.path;
  h.clock = s.rq.master_driven ? Clock::Master : Clock::Time;
  h.lim = s.rq.limits;
  h.u = u;
  h.u0 = 0.0;
  h.hint = 0;
  h.k = Kin{};
  h.ve = 0.0;
  h.td = kInf;
  h.paused = false;
  h.resume = false;
  h.mirror = false;
}

// Plans the head from state `from` (s, ds/du, d2s/du2) to its end with end
// speed ve; the profile starts at abscissa u0. Speed 0: ramps to a halt and
// waits (paused) until MCCD gives a speed.
void PathGenerator::plan_head(const Kin& from, double ve, double u0, Overshoot policy) noexcept {
  Track& h = ht_;
  h.u0 = u0;
  h.hint = 0;
  h.mirror = false;
  h.resume = false;
  h.ve = 0.0;
  if (!(h.lim.v > 0)) {
    // Paused; a halt that would pass the end just ends the move there.
    h.paused = !plan_stop_before(h.prof, from, h.path.length(), h.lim.d, h.lim.jd);
    h.td = h.paused ? kInf : u0 + decel_start(h.prof);
    return;
  }
  h.paused = false;
  const double L = h.path.length();
  if (policy == Overshoot::StopAtTarget && from.v > 0 && from.a < 0 && std::isfinite(h.lim.jd) &&
      from.v - from.a * from.a / (2 * h.lim.jd) < 0 && from.p < L) {
    // A braking acceleration the decel jerk cannot ramp out before the speed
    // is 0 (MCCD lowered the jerk while braking): plan_move would stop short
    // of the target with its StopAtTarget scaling. Stop without backing up
    // first, then go on from rest (sample_head plans the second part).
    h.ve = ve;
    h.td = kInf;
    h.resume = !plan_stop_before(h.prof, from, L, h.lim.d, h.lim.jd);
    return;
  }
  plan_move_to(h.prof, from, L - from.p, ve, h.lim, policy);
  h.ve = ve;
  h.td = u0 + decel_start(h.prof);
}

// Follow Contour (TT4/TT5) junction speed with the pending move, and the
// head re-planned to reach it [README "Follow Contour"].
void PathGenerator::plan_junction() noexcept {
  if (!has_head_ || head_.pc || stopping_ || ht_.paused) return;
  const Termination tt = head_.rq.termination;
  if (tt != Termination::FollowContourVelocityConstrained && tt != Termination::FollowContourVelocityUnconstrained)
    return;
  double vj = 0.0;
  const Limits& lb = pending_.rq.limits;
  if (has_pending_ && pending_.rq.master_driven == (ht_.clock == Clock::Master) && lb.v > 0 &&
      pending_.path.length() > 0) {
    vj = std::min(ht_.lim.v, lb.v);
    if (tt == Termination::FollowContourVelocityConstrained)  // one-move look-ahead: the next move can stop by its end
      vj = std::min(vj, stop_speed(pending_.path.length(), lb.d, lb.jd));
    const double c = dot(ht_.path.tangent(ht_.path.length()), pending_.path.tangent(0.0));
    if (c < 1 - 1e-12) {  // a corner: the direction change may cost one cycle of acceleration
      const double half_sine = std::sqrt(std::max(0.0, (1 - c) / 2));
      vj = std::min(vj, std::min(ht_.lim.d, lb.a) * cfg_.period / (2 * half_sine));
    }
  }
  if (vj == ht_.ve) return;
  if (ht_.mirror) {  // keep the blend: re-plan only the continuation
    plan_move_to(ht_.prof, ht_.cont, ht_.path.length() - ht_.cont.p, vj, ht_.lim, Overshoot::StopAtTarget);
    ht_.hint = 0;
    ht_.ve = vj;
    ht_.td = ht_.u0 + decel_start(ht_.prof);
  } else {
    plan_head(ht_.k, vj, ht_.u, Overshoot::StopAtTarget);
  }
}

void PathGenerator::sample_head() noexcept {
  Track& h = ht_;
  if (h.mirror) {
    if (has_tail_ && !done(tt_)) {
      const Kin& t = tt_.k;
      if (tt_.u < h.mu) {
        h.k = Kin{};
      } else {
        h.k = Kin{h.mk * (h.mvm * (tt_.u - h.mu) - (t.p - h.msm)), h.mk * (h.mvm - t.v), -h.mk * t.a};
      }
      return;
    }
    h.mirror = false;  // the tail has finished: the continuation profile takes over
  }
  h.k = h.prof.sample(h.u - h.u0, h.hint);
  if (h.resume && done(h)) {  // the stop of plan_head has ended short of the target: on from rest
    plan_head(Kin{h.prof.end_position(), 0.0, 0.0}, h.ve, h.u0 + h.prof.duration(), Overshoot::StopAtTarget);
    h.k = h.prof.sample(h.u - h.u0, h.hint);
  }
}

double PathGenerator::head_s_at(double u) const noexcept {
  int hint = 0;
  if (ht_.mirror && u < ht_.u0) {
    const double ut = u + ub_;
    if (ut < ht_.mu) return 0.0;
    const Kin t = tt_.prof.sample(ut - tt_.u0, hint);
    return ht_.mk * (ht_.mvm * (ut - ht_.mu) - (t.p - ht_.msm));
  }
  return ht_.prof.sample(u - ht_.u0, hint).p;
}

// --------------------------------------------------------------- activation

void PathGenerator::activate_from_rest(const Present& now, double excess, bool chained, Events& ev) noexcept {
  // total is the system's command when the path was at pos_ (its last
  // output): a move that follows inside a step starts where the path ended
  // plus what the other motion added (superposed moves shift the rest).
  Vec3 S = now.has_total ? now.total + (rest_ - pos_) : rest_;
  for (int i = cfg_.dim; i < kMaxDim; ++i) S[i] = 0.0;
  if (!(S == pending_.path.start())) {  // a new Motion Start Point: rebuild from it
    Path p;
    const Err e = Path::build(pending_.rq.path, S, cfg_.dim, p);
    if (e != Err::None) {
      ev.push(pending_.rq.id, EventKind::Failed, e);
      has_pending_ = false;
      return;
    }
    pending_.path = p;
  }
  origin_ += S - rest_;  // the slot's offset stays continuous
  rest_ = S;
  head_ = pending_;
  head_.pc = false;
  head_.blended_into = false;
  has_pending_ = false;
  const bool master = head_.rq.master_driven;
  if (master && !(chained && last_master_)) fresh_lock(head_.rq, now);
  start_track(head_, chained && master == last_master_ ? std::max(excess, 0.0) : 0.0);
  plan_head(Kin{}, 0.0, 0.0, Overshoot::StopAtTarget);
  has_head_ = true;
  last_master_ = master;
  ev.push(head_.rq.id, EventKind::Activated);
  sample_head();
}

void PathGenerator::activate_junction(const Present& now, double v_end, double excess, Events& ev) noexcept {
  head_ = pending_;
  head_.pc = false;
  head_.blended_into = false;
  has_pending_ = false;
  const bool master = head_.rq.master_driven;
  const bool same = master == last_master_;
  if (master && !last_master_) fresh_lock(head_.rq, now);
  start_track(head_, same ? std::max(excess, 0.0) : 0.0);
  plan_head(Kin{0.0, same ? v_end : 0.0, 0.0}, 0.0, 0.0, Overshoot::StopAtTarget);
  has_head_ = true;
  last_master_ = master;
  ev.push(head_.rq.id, EventKind::Activated);
  sample_head();
}

// The pending move starts while the tail (the previous move, past its
// completion point) finishes: velocity superposition with the head's speed
// mirroring the tail's deceleration [README "Blending"].
void PathGenerator::activate_blend(Events& ev) noexcept {
  head_ = pending_;
  head_.pc = false;
  head_.blended_into = true;
  has_pending_ = false;
  start_track(head_, 0.0);
  const Profile& tp = tt_.prof;
  const double tend = tt_.u0 + tp.duration();
  const double tm = std::min(std::max(tb_, tt_.u0 + decel_start(tp)), tend);
  int hint = 0;
  const Kin km = tp.sample(tm - tt_.u0, hint);
  const double L = ht_.path.length();
  const Limits& lb = ht_.lim;
  double k = 0.0;
  double D = 0.0;
  if (km.v > 0 && lb.v > 0 && L > 0 && tm < tend) {
    D = std::max(0.0, km.v * (tend - tm) - (tt_.path.length() - km.p));
    double apk = 0.0, jpk = 0.0;  // the tail's peak |a| and |j| from tm on
    for (int i = 0; i < tp.size(); ++i) {
      const Segment& s = tp.segment(i);
      if (s.t0 + s.dt <= tm - tt_.u0) continue;
      apk = std::max({apk, std::fabs(s.a), std::fabs(s.a + s.j * s.dt)});
      jpk = std::max(jpk, std::fabs(s.j));
    }
    double kmax = lb.v / km.v;
    if (apk > 0) kmax = std::min(kmax, lb.a / apk);
    if (jpk > 0) {
      kmax = std::min(kmax, lb.ja / jpk);
    } else if (apk > 0 && std::isfinite(lb.ja)) {
      kmax = 0.0;  // a trapezoidal tail steps its acceleration: an S-curve head cannot mirror it
    }
    // The head must still stop by its end, and the blend uses at most half of it.
    auto fits = [&](double kk) noexcept {
      return kk * D <= L / 2 && kk * D + stop_distance(kk * km.v, lb.d, lb.jd) <= L;
    };
    if (kmax > 0) {
      if (fits(kmax)) {
        k = kmax;
      } else {
        double lo = 0.0, hi = kmax;
        for (int i = 0; i < kSolveIterations && hi - lo > 1e-12 * kmax; ++i) {
          const double mid = (lo + hi) / 2;
          if (fits(mid)) lo = mid; else hi = mid;
        }
        k = lo;
      }
    }
  }
  if (k > 0) {
    ht_.mirror = true;
    ht_.mk = k;
    ht_.mvm = km.v;
    ht_.msm = km.p;
    ht_.mu = tm;
    ub_ = tt_.u;
    ht_.cont = Kin{k * D, k * km.v, 0.0};
    plan_move_to(ht_.prof, ht_.cont, L - ht_.cont.p, 0.0, lb, Overshoot::StopAtTarget);
    ht_.u0 = tend - ub_;
    ht_.hint = 0;
    ht_.ve = 0.0;
    ht_.td = ht_.u0 + decel_start(ht_.prof);
  } else {
    plan_head(Kin{}, 0.0, 0.0, Overshoot::StopAtTarget);
  }
  has_head_ = true;
  last_master_ = head_.rq.master_driven;
  ev.push(head_.rq.id, EventKind::Activated);
  sample_head();
}

// ------------------------------------------------------------- per cycle

bool PathGenerator::pc_condition(const Present& now) const noexcept {
  const bool fin = !ht_.paused && !ht_.mirror && !ht_.resume && done(ht_);
  switch (head_.rq.termination) {
    case Termination::ActualTolerance:
      return fin && now.following_error <= cfg_.actual_tolerance;
    case Termination::NoSettle:
    case Termination::FollowContourVelocityConstrained:
    case Termination::FollowContourVelocityUnconstrained:
      return fin;
    case Termination::CommandTolerance:
    case Termination::CommandToleranceProgrammed:
      return ht_.path.length() - ht_.k.p <= ct_eff(has_pending_);
    case Termination::NoDecel:
      return fin || (!ht_.paused && ht_.u >= ht_.td);
  }
  return fin;
}

// Abscissa inside the last step where the head met its completion
// condition (TT2/TT6: the distance to go reached the tolerance; TT3: the
// decel point). Bounded bisection; runs once per blend.
double PathGenerator::pc_abscissa() const noexcept {
  const double u1 = ht_.u, u0 = std::max(ht_.u - du_head_, 0.0);
  const Termination tt = head_.rq.termination;
  if (tt == Termination::NoDecel) return std::clamp(ht_.td, u0, u1);
  if (tt != Termination::CommandTolerance && tt != Termination::CommandToleranceProgrammed) return u1;
  const double target = ht_.path.length() - ct_eff(has_pending_);
  if (head_s_at(u0) >= target) return u0;
  double lo = u0, hi = u1;
  for (int i = 0; i < 40 && hi - lo > 0; ++i) {
    const double mid = (lo + hi) / 2;
    if (head_s_at(mid) >= target) hi = mid; else lo = mid;
  }
  return hi;
}

bool PathGenerator::transition(const Present& now, Events& ev) noexcept {
  if (stopping_) {
    if ((!has_head_ || done(ht_)) && !has_tail_) {
      if (has_head_) rest_ = ht_.path.point(ht_.k.p);
      has_head_ = false;
      stopping_ = false;
      ev.push(stop_id_, EventKind::StopDone);
      return true;
    }
    return false;
  }
  if (has_head_) {
    bool changed = false;
    bool pc_now = false;
    if (!head_.pc && pc_condition(now)) {
      head_.pc = true;
      pc_now = true;
      ev.push(head_.rq.id, EventKind::Completed);
      changed = true;
    }
    if (!head_.pc) return changed;
    const double excess = ht_.u - ht_.u0 - ht_.prof.duration();
    switch (head_.rq.termination) {
      case Termination::ActualTolerance:
      case Termination::NoSettle:  // stops: the next move starts from rest
        rest_ = ht_.path.end();
        has_head_ = false;
        if (has_pending_) {
          activate_from_rest(now, head_.rq.termination == Termination::NoSettle ? excess : 0.0, true, ev);
        }
        return true;
      case Termination::FollowContourVelocityConstrained:
      case Termination::FollowContourVelocityUnconstrained: {  // hands over at the junction speed
        const double v_end = ht_.ve > 0 ? end_velocity(ht_.prof) : 0.0;
        rest_ = ht_.path.end();
        has_head_ = false;
        if (has_pending_) activate_junction(now, v_end, excess, ev);
        return true;
      }
      default:  // 2, 3, 6: the move finishes as the tail of a blend
        if (has_tail_ || ht_.paused) return changed;
        // The blend may start where the completion condition was met: inside
        // this cycle if it was met now (the overlap then runs as if started
        // exactly there), else now.
        tb_ = pc_now ? pc_abscissa() : ht_.u;
        tt_ = ht_;
        has_tail_ = true;
        has_head_ = false;
        return true;
    }
  }
  if (has_pending_) {
    if (has_tail_) {
      if (pending_.rq.master_driven != (tt_.clock == Clock::Master)) return false;  // waits for the tail
      activate_blend(ev);
      return true;
    }
    activate_from_rest(now, 0.0, true, ev);
    return true;
  }
  return false;
}

void PathGenerator::step(const Present& now, Output& out) noexcept {
  out.events.n = 0;
  double du_m = 0.0;
  mdot_ = 0.0;
  if (now.has_master) {
    if (!have_mp_) {
      prev_mp_ = now.master_position;
      have_mp_ = true;
    }
    du_m = master_follow_step(lock_, lock_pos_, now.master_position, prev_mp_, locked_, following_);
    if (lock_ == LockDirection::None) du_m = 0.0;  // no master-driven move has set a lock
    if (locked_ && following_ && lock_ != LockDirection::None) {
      mdot_ = std::max(0.0, lock_forward(lock_) ? now.master_velocity : -now.master_velocity);
    }
  } else {
    have_mp_ = false;
  }
  const double dt = cfg_.period;
  bool tail_done = false;
  if (has_tail_) {
    tt_.u += tt_.clock == Clock::Time ? dt : du_m;
    tt_.k = tt_.prof.sample(tt_.u - tt_.u0, tt_.hint);
    tail_done = done(tt_);
  }
  if (has_head_) {
    du_head_ = ht_.clock == Clock::Time ? dt : du_m;
    ht_.u += du_head_;
    sample_head();
  }
  if (tail_done) {
    has_tail_ = false;
    if (!has_head_) rest_ = tt_.path.end();
  }
  for (int i = 0; i < 4 && transition(now, out.events); ++i) {
  }
  outputs(now, out);
}

void PathGenerator::outputs(const Present& now, Output& out) noexcept {
  Vec3 p, v, a;
  if (has_head_) {
    const Kin k = to_time(ht_);
    ht_.path.eval(ht_.k.p, k.v, k.a, p, v, a);
  } else {
    p = has_tail_ ? tt_.path.end() : rest_;
  }
  if (has_tail_) {  // the tail adds its displacement from its own end
    const Kin k = to_time(tt_);
    Vec3 tp, tv, ta;
    tt_.path.eval(tt_.k.p, k.v, k.a, tp, tv, ta);
    p += tp - tt_.path.end();
    v += tv;
    a += ta;
  }
  pos_ = p;
  speed_ = norm(v);
  out.position = p;
  out.velocity = v;
  out.acceleration = a;
  out.offset = p - origin_;
  for (int i = 0; i < kMaxDim; ++i) {
    const std::size_t j = static_cast<std::size_t>(i);
    const double r = i < cfg_.dim ? cfg_.ratio[j] : 1.0;
    out.axis_offset[j] = out.offset[i] / r;
    out.axis_velocity[j] = v[i] / r;
    out.axis_acceleration[j] = a[i] / r;
  }
  out.speed = speed_;

  namespace cms = coordinate_motion_status;
  std::uint32_t st = 0;
  auto set = [&st](unsigned bit, bool on) noexcept {
    if (on) st |= 1u << bit;
  };
  const Kin hk = has_head_ ? to_time(ht_) : Kin{};
  const Kin tk = has_tail_ ? to_time(tt_) : Kin{};
  const bool head_accel = has_head_ && (hk.v >= 0 ? hk.a > 0 : hk.a < 0);
  const bool head_decel = has_head_ && (hk.v >= 0 ? hk.a < 0 : hk.a > 0);
  set(cms::AccelStatus, head_accel);
  set(cms::DecelStatus, (head_decel && !has_tail_) || (!has_head_ && has_tail_ && tk.a < 0));
  const bool at_target = !has_tail_ && (!has_head_ || (done(ht_) && !ht_.paused && !ht_.mirror && !ht_.resume));
  set(cms::ActualPosToleranceStatus, at_target && now.following_error <= cfg_.actual_tolerance);
  const double to_go = has_head_ ? ht_.path.length() - ht_.k.p : (has_tail_ ? tt_.path.length() - tt_.k.p : 0.0);
  set(cms::CommandPosToleranceStatus, std::fabs(to_go) <= cfg_.command_tolerance);
  set(cms::StoppingStatus, stopping_);
  set(cms::MoveStatus, has_head_ || has_tail_);
  set(cms::MoveTransitionStatus, has_head_ && has_tail_);
  set(cms::MovePendingStatus, has_pending_);
  set(cms::MovePendingQueueFullStatus, has_pending_);
  const bool locked_following = has_head_ && ht_.clock == Clock::Master && locked_ && following_;
  set(cms::CoordinateSystemLockStatus, locked_following);
  out.motion_status = st;
  out.tracking_master = locked_following && !head_.pc && !ht_.mirror && !ht_.paused && ht_.k.a == 0 &&
                        ht_.k.v >= ht_.lim.v * (1 - 1e-9);
}

// ------------------------------------------------------------- instructions

Err PathGenerator::submit(const MoveRequest& rq, const Present& now, Events& ev) noexcept {
  if (!limits_ok(rq.limits)) return Err::ParameterOutOfRange;
  if (rq.master_driven == (rq.lock_direction == LockDirection::None)) return Err::MdscLockDirConflict;
  const bool contour = rq.termination == Termination::FollowContourVelocityConstrained ||
                       rq.termination == Termination::FollowContourVelocityUnconstrained;
  if (rq.master_driven && contour) return Err::ParameterOutOfRange;  // master-driven blends: TT2, 3, 6
  if (rq.termination > Termination::CommandToleranceProgrammed ||
      (rq.termination == Termination::CommandToleranceProgrammed && !(rq.command_tolerance >= 0)))
    return Err::ParameterOutOfRange;
  if (stopping_) return Err::NotAllowedWhileStopping;
  const bool merge = rq.merge != CoordMerge::Disabled && (has_head_ || has_pending_);
  double mspeed = 0.0;  // master speed in the new move's lock direction
  if (rq.master_driven && now.has_master) {
    mspeed = lock_forward(rq.lock_direction) ? now.master_velocity : -now.master_velocity;
  }
  const bool starts_now = merge || !has_head_;
  if (rq.master_driven && starts_now && speed_ > 0 && !(std::fabs(now.master_velocity) > 0))
    return Err::MdscIdleMasterSlaveMoving;

  if (merge) {
    const Vec3 here = has_head_ ? ht_.path.point(ht_.k.p) : (has_tail_ ? tt_.path.end() : rest_);
    const bool rebase = now.has_total && !has_tail_;  // a merge sets a new Motion Start Point
    Path p;
    if (const Err e = Path::build(rq.path, rebase ? now.total : here, cfg_.dim, p); e != Err::None) return e;
    Vec3 hp, hv, ha;
    if (has_head_) {
      const Kin kt = to_time(ht_);
      ht_.path.eval(ht_.k.p, kt.v, kt.a, hp, hv, ha);
    }
    // The new move starts with the present velocity projected on its start
    // tangent (the component across it is dropped) [README "Merge"].
    const Vec3 t0 = p.tangent(0.0);
    double v0 = dot(hv, t0), a0 = dot(ha, t0), cur = norm(hv);
    if (rq.master_driven) {
      if (mspeed > 0) {
        v0 /= mspeed;
        a0 /= mspeed * mspeed;
        cur /= mspeed;
      } else {
        v0 = a0 = cur = 0.0;
      }
    }
    if (has_pending_) ev.push(pending_.rq.id, EventKind::Cancelled);
    if (has_head_ && !head_.pc) ev.push(head_.rq.id, EventKind::Cancelled);
    has_pending_ = false;
    const bool was_master = has_head_ ? ht_.clock == Clock::Master : last_master_;
    if (rebase) origin_ += p.start() - here;
    head_ = Slot{rq, p, false, false};
    start_track(head_, 0.0);
    if (rq.merge_speed == MergeSpeed::Current && cur > 0) ht_.lim.v = cur;
    if (rq.master_driven && !was_master) fresh_lock(rq, now);
    plan_head(Kin{0.0, v0, a0}, 0.0, 0.0, Overshoot::Reverse);
    has_head_ = true;
    last_master_ = rq.master_driven;
    ev.push(rq.id, EventKind::Activated);
    sample_head();
    return Err::None;
  }
  // Queued: it starts where the queue ends. Operand (geometry) errors come
  // before the queue-full check.
  const Vec3 start = has_pending_ ? pending_.path.end()
                     : has_head_  ? ht_.path.end()
                     : has_tail_  ? tt_.path.end()
                                  : (now.has_total ? now.total : rest_);
  Path p;
  if (const Err e = Path::build(rq.path, start, cfg_.dim, p); e != Err::None) return e;
  if (has_pending_) return Err::CoordinateSystemQueueFull;
  pending_ = Slot{rq, p, false, false};
  has_pending_ = true;
  if (has_head_) {
    plan_junction();
  } else if (has_tail_) {
    tb_ = tt_.u;  // blends in from now
    if (rq.master_driven == (tt_.clock == Clock::Master)) activate_blend(ev);
  } else {
    activate_from_rest(now, 0.0, false, ev);
  }
  return Err::None;
}

void PathGenerator::stop(std::uint32_t stop_id, double decel, double decel_jerk, Events& ev) noexcept {
  if (stopping_ && stop_id_ != stop_id) ev.push(stop_id_, EventKind::Cancelled);
  if (has_pending_) ev.push(pending_.rq.id, EventKind::Cancelled);
  has_pending_ = false;
  const double d = decel > 0 && std::isfinite(decel) ? decel : ht_.lim.d;
  const double jd = decel_jerk > 0 ? decel_jerk : kInf;
  if (has_head_) {
    if (!head_.pc) ev.push(head_.rq.id, EventKind::Cancelled);
    head_.pc = true;
    head_.rq.id = 0;  // the stop ramp belongs to no move
    // A master-driven stop runs time-driven [RM002H p.469].
    const Kin k = to_time(ht_);
    Track& h = ht_;
    h.clock = Clock::Time;
    h.mirror = false;
    h.paused = false;
    h.resume = false;
    h.u = 0.0;
    h.u0 = 0.0;
    h.hint = 0;
    h.ve = 0.0;
    h.td = kInf;
    h.k = k;
    plan_stop_before(h.prof, k, h.path.length(), d, jd);
  }
  if (has_tail_ && tt_.clock == Clock::Master) {  // the tail finishes time-driven, exactly at its end
    const Kin k = to_time(tt_);
    tt_.clock = Clock::Time;
    tt_.u = 0.0;
    tt_.u0 = 0.0;
    tt_.hint = 0;
    tt_.k = k;
    plan_move_to(tt_.prof, k, tt_.path.length() - k.p, 0.0, Limits{std::max(std::fabs(k.v), d * 1e-9), d, d, jd, jd},
                 Overshoot::StopAtTarget);
  }
  stopping_ = true;
  stop_id_ = stop_id;
  if (!has_head_ && !has_tail_) {
    stopping_ = false;
    ev.push(stop_id, EventKind::StopDone);
  }
}

Err PathGenerator::change_dynamics(const DynamicsChange& ch, Events& /*ev*/) noexcept {
  if (stopping_) return Err::None;
  // The active move, also past its PC while it still moves as the head (a
  // TT2/3/6 move paused inside its tolerance must be able to resume).
  const bool head_ok = has_head_;
  const bool pend_ok = ch.scope == ChangeScope::ActiveAndPendingMotion && has_pending_;
  auto apply = [&ch](Limits l) noexcept {
    if (ch.change_speed) l.v = ch.values.v;
    if (ch.change_accel) l.a = ch.values.a;
    if (ch.change_decel) l.d = ch.values.d;
    if (ch.change_accel_jerk) l.ja = ch.values.ja;
    if (ch.change_decel_jerk) l.jd = ch.values.jd;
    return l;
  };
  if (head_ok && ch.master_driven != (ht_.clock == Clock::Master)) return Err::MdscInvalidModeOrMasterChange;
  if (pend_ok && ch.master_driven != pending_.rq.master_driven) return Err::MdscInvalidModeOrMasterChange;
  if ((head_ok && !limits_ok(apply(ht_.lim))) || (pend_ok && !limits_ok(apply(pending_.rq.limits))))
    return Err::ParameterOutOfRange;
  if (pend_ok) pending_.rq.limits = apply(pending_.rq.limits);
  if (head_ok) {
    ht_.lim = apply(ht_.lim);
    head_.rq.limits = ht_.lim;
    plan_head(ht_.k, 0.0, ht_.u, Overshoot::StopAtTarget);  // from the present state: no position step
  }
  plan_junction();
  return Err::None;
}

void PathGenerator::clear(Events& ev) noexcept {
  if (has_head_ && !head_.pc) ev.push(head_.rq.id, EventKind::Cancelled);
  if (has_pending_) ev.push(pending_.rq.id, EventKind::Cancelled);
  if (stopping_) ev.push(stop_id_, EventKind::Cancelled);
  rest_ = pos_;
  has_head_ = has_tail_ = has_pending_ = stopping_ = false;
  speed_ = 0.0;
}

bool PathGenerator::calculated_data(std::span<const double> ed, std::span<double> cd) const noexcept {
  if (!has_head_ || head_.pc || ht_.paused || ht_.resume || cd.size() < ed.size()) return false;
  const double L = ht_.path.length();
  const double u_end = ht_.u0 + ht_.prof.duration();
  // First abscissa in [0, hi] where s reaches `target` (s is non-decreasing).
  auto first = [this](double target, double hi) noexcept {
    double lo = 0.0;
    for (int i = 0; i < kSolveIterations && hi - lo > 1e-12 * hi; ++i) {
      const double mid = (lo + hi) / 2;
      if (head_s_at(mid) >= target) hi = mid; else lo = mid;
    }
    return hi;
  };
  double s_pc = L, u_pc = u_end;
  switch (head_.rq.termination) {
    case Termination::CommandTolerance:
    case Termination::CommandToleranceProgrammed:
      s_pc = L - ct_eff(true);
      u_pc = first(s_pc, u_end);
      break;
    case Termination::NoDecel:
      u_pc = std::min(ht_.td, u_end);
      s_pc = head_s_at(u_pc);
      break;
    default:
      break;
  }
  for (std::size_t i = 0; i < ed.size(); ++i) {
    const double target = s_pc - ed[i];
    cd[i] = ed[i] == 0 ? u_pc : (target <= 0 ? 0.0 : first(target, u_pc));
  }
  return true;
}

}  // namespace canmotion::motion::coord
