// MAM EventDistance / CalculatedData (reference 2.9 and section 5), part of
// the move family (motion/instr/move.hpp). The calculation runs in the
// cycle, into the REAL arrays registered at configuration. Realtime-safe.
#include <algorithm>
#include <cmath>
#include <span>

#include "motion/instr/ctx.hpp"
#include "motion/instr/move.hpp"

namespace canmotion::motion {
namespace {

/// Elements of a REAL array operand from its start index to the array's end
/// (empty for the literal 0 = "none", or an index past the end).
std::span<double> array_from(const Core& c, std::uint16_t ref, double start) noexcept {
  if (ref >= kMaxRealArrays) return {};
  const std::span<double> a = c.real_arrays[ref];
  if (!(start >= 0) || start >= static_cast<double>(a.size())) return {};
  return a.subspan(static_cast<std::size_t>(start));
}

/// Earliest abscissa (time, or master travel for master-driven moves) at which
/// the signed travel sgn * (p - origin) of `prof` reaches `target`
/// (0 < target <= |distance|). Between the breakpoints used here (segment ends
/// and the instants where the velocity crosses zero) the travel is monotone, so
/// a safeguarded Newton iteration finds the crossing. Bounded cost:
/// kMaxSegments * 3 intervals and at most 64 iterations (typically < 8).
/// Realtime-safe.
double first_reach(const Profile& prof, double sgn, double target) noexcept {
  auto travel = [&](const Segment& s, double tau) noexcept {
    return sgn * (s.p + s.v * tau + s.a * tau * tau / 2 + s.j * tau * tau * tau / 6);
  };
  for (int i = 0; i < prof.size(); ++i) {
    const Segment& s = prof.segment(i);
    if (!std::isfinite(s.dt)) break;  // a hold (jog): never reached
    // breakpoints inside the segment: roots of v(tau) = v + a tau + j tau^2 / 2
    double bp[3] = {s.dt, s.dt, s.dt};
    int nb = 0;
    if (s.j != 0) {
      const double disc = s.a * s.a - 2 * s.j * s.v;
      if (disc >= 0) {
        const double r = std::sqrt(disc);
        double t1 = (-s.a - r) / s.j, t2 = (-s.a + r) / s.j;
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > 0 && t1 < s.dt) bp[nb++] = t1;
        if (t2 > 0 && t2 < s.dt) bp[nb++] = t2;
      }
    } else if (s.a != 0) {
      const double t1 = -s.v / s.a;
      if (t1 > 0 && t1 < s.dt) bp[nb++] = t1;
    }
    bp[nb++] = s.dt;
    double lo = 0.0;
    for (int k = 0; k < nb; ++k) {
      const double hi = bp[k];
      if (travel(s, hi) >= target) {
        double a = lo, b = hi;  // travel(a) < target <= travel(b), monotone on [a, b]
        if (travel(s, a) >= target) return s.t0 + a;
        // Newton on the monotone bracket, bisecting when a step leaves it:
        // a handful of iterations instead of 50+ halvings.
        const double tol = 1e-13 * std::max(1.0, target);
        double t = 0.5 * (a + b);
        for (int it = 0; it < 64; ++it) {
          const double f = travel(s, t) - target;
          if (std::fabs(f) <= tol) break;
          (f < 0 ? a : b) = t;
          const double d = sgn * (s.v + s.a * t + s.j * t * t / 2);  // d travel / d tau
          double tn = d != 0 ? t - f / d : a;
          if (!(tn > a && tn < b)) tn = 0.5 * (a + b);
          if (tn == t || b - a <= 1e-15 * std::max(1.0, b)) break;
          t = tn;
        }
        return s.t0 + t;
      }
      lo = hi;
    }
  }
  return prof.finite() ? prof.duration() : 0.0;
}

}  // namespace

namespace move {

Err check_event_distance(Ctx& x, const MamParams& p) noexcept {
  constexpr int kEd = op<Instr::MAM>("EventDistance"), kCd = op<Instr::MAM>("CalculatedData");
  const bool ed_given = p.event_distance != 0xFFFF, cd_given = p.calculated_data != 0xFFFF;
  if (ed_given && (p.event_distance >= kMaxRealArrays || array_from(x.c, p.event_distance, p.event_distance_start).empty()))
    return x.reject_operand(kEd);
  if (cd_given &&
      (p.calculated_data >= kMaxRealArrays || array_from(x.c, p.calculated_data, p.calculated_data_start).empty()))
    return x.reject_operand(kCd);
  if (!ed_given || !cd_given) return Err::None;  // 0 for either: no events
  const std::span<double> ed = array_from(x.c, p.event_distance, p.event_distance_start);
  for (double e : ed)
    if (!std::isfinite(e) || e < 0) return x.reject_operand(kEd);
  if (array_from(x.c, p.calculated_data, p.calculated_data_start).size() < ed.size()) return Err::CalculatedDataArraySize;
  return Err::None;
}

void write_calculated_data(Ctx& x, const MamParams& p, const ProfileGen& g) noexcept {
  const std::span<double> ed = array_from(x.c, p.event_distance, p.event_distance_start);
  const std::span<double> cd = array_from(x.c, p.calculated_data, p.calculated_data_start);
  if (ed.empty() || cd.size() < ed.size() || !(g.speed > 0) || !g.prof.finite()) return;
  // The profile's abscissa is time (s) for a time-driven move and master
  // travel (master units) for a master-driven one: exactly what
  // CalculatedData reports. Its ordinate is the move's own travel.
  const double total = std::fabs(g.total);
  const double sgn = g.total < 0 ? -1.0 : 1.0;
  for (std::size_t i = 0; i < ed.size(); ++i) {
    const double target = total - ed[i];  // travel at which EventDistance[i] remains
    // EventDistance 0 is the end of the move: its duration, exactly.
    cd[i] = target <= 0 ? 0.0 : (ed[i] == 0 ? g.prof.duration() : first_reach(g.prof, sgn, target));
  }
  x.tag.set(flag::CalculatedDataAvailable, true);
}

}  // namespace move
}  // namespace canmotion::motion
