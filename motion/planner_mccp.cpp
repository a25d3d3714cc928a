// MCCP as a planner instruction, and the EventDistance / CalculatedData
// operands of MAM (issue #5). Kept apart from planner.cpp so the other
// instruction files stay untouched; see motion/cam/README.md ("MCCP as an
// instruction") for the design choice: the calculation runs in the cycle,
// into the CAM_PROFILE array's storage that was sized at configuration.
#include <algorithm>
#include <cmath>

#include "motion/instructions.hpp"
#include "motion/planner.hpp"

namespace canmotion::motion {
namespace {

// Operand positions from THE signature table (constant-initialised table:
// these are computed at load time, never on the cyclic path).
const int kMamEventDistance = operand_index(Instr::MAM, "EventDistance");
const int kMamCalculatedData = operand_index(Instr::MAM, "CalculatedData");

/// Elements of a REAL array operand from its start index to the array's end
/// (empty for the literal 0 = "none", or an index past the end).
std::span<double> array_from(const std::array<std::span<double>, kMaxRealArrays>& arrays, const Operand& op) noexcept {
  if (op.ref >= kMaxRealArrays) return {};
  const std::span<double> a = arrays[op.ref];
  if (!(op.value >= 0) || op.value >= static_cast<double>(a.size())) return {};
  return a.subspan(static_cast<std::size_t>(op.value));
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

bool Planner::attach_cam_array(std::uint16_t id, std::span<cam::CamPoint> points) noexcept {
  if (id >= kMaxCamArrays) return false;
  cam_arrays_[id] = points;
  return true;
}

bool Planner::attach_real_array(std::uint16_t id, std::span<double> values) noexcept {
  if (id >= kMaxRealArrays) return false;
  real_arrays_[id] = values;
  return true;
}

// --- MCCP (Motion Calculate Cam Profile), reference 2.13 and section 7.
// Synchronous: the profile is calculated in this scan (Status 1 during the
// calculation, 2 after), so DN is set in the same scan, like Logix' EN/DN/ER
// instruction without IP. The cost is O(Length) and Length is bounded by the
// CAM_PROFILE array's capacity, itself bounded at configuration
// (config `arrays:`, CAM_PROFILE size <= 4096; see motion/cam/README.md).
Err Planner::start_mccp(const Request& r, const MccpParams& p, std::int8_t& exerr) noexcept {
  using namespace cam::mccp_operand;
  if (p.cam >= kMaxCamArrays || cam_arrays_[p.cam].empty()) {
    exerr = static_cast<std::int8_t>(kCam);
    return Err::ParameterOutOfRange;
  }
  cam::CamProfile* prof = p.cam_profile < kMaxCamProfiles ? cam_profiles_[p.cam_profile] : nullptr;
  if (prof == nullptr) {
    exerr = static_cast<std::int8_t>(kCamProfile);
    return Err::ParameterOutOfRange;
  }
  cam::MccpRequest q;
  q.cam = cam_arrays_[p.cam];
  q.start_index = p.first_point;
  q.length = p.length;
  q.start_slope = p.start_slope;
  q.end_slope = p.end_slope;
  const cam::MccpResult res = cam::mccp(q, *prof);
  if (!res.ok()) {
    exerr = static_cast<std::int8_t>(res.exerr);
    return static_cast<Err>(cam::err_code(res.err));
  }
  controls_[r.control].set(flag::DN, true);
  return Err::None;
}

// --- MAM EventDistance / CalculatedData (reference 2.9 and section 5).
Err Planner::check_event_distance(const Request& r, std::int8_t& exerr) const noexcept {
  const Operand& ed_op = r.op[static_cast<std::size_t>(kMamEventDistance)];
  const Operand& cd_op = r.op[static_cast<std::size_t>(kMamCalculatedData)];
  const bool ed_given = ed_op.ref != 0xFFFF, cd_given = cd_op.ref != 0xFFFF;
  if (ed_given && (ed_op.ref >= kMaxRealArrays || array_from(real_arrays_, ed_op).empty())) {
    exerr = static_cast<std::int8_t>(kMamEventDistance);
    return Err::ParameterOutOfRange;
  }
  if (cd_given && (cd_op.ref >= kMaxRealArrays || array_from(real_arrays_, cd_op).empty())) {
    exerr = static_cast<std::int8_t>(kMamCalculatedData);
    return Err::ParameterOutOfRange;
  }
  if (!ed_given || !cd_given) return Err::None;  // 0 for either: no events
  const std::span<double> ed = array_from(real_arrays_, ed_op);
  for (double e : ed) {
    if (!std::isfinite(e) || e < 0) {
      exerr = static_cast<std::int8_t>(kMamEventDistance);
      return Err::ParameterOutOfRange;
    }
  }
  if (array_from(real_arrays_, cd_op).size() < ed.size()) return Err::CalculatedDataArraySize;
  return Err::None;
}

void Planner::write_calculated_data(const Request& r, const ProfileGen& g, ControlTag& c) noexcept {
  const Operand& ed_op = r.op[static_cast<std::size_t>(kMamEventDistance)];
  const Operand& cd_op = r.op[static_cast<std::size_t>(kMamCalculatedData)];
  const std::span<double> ed = array_from(real_arrays_, ed_op);
  const std::span<double> cd = array_from(real_arrays_, cd_op);
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
  c.set(flag::CalculatedDataAvailable, true);
}

}  // namespace canmotion::motion
