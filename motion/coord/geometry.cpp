#include "motion/coord/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace canmotion::motion::coord {
namespace {

using Tol = GeometryTolerances;
constexpr double kTwoPi = 2 * std::numbers::pi;

Vec3 masked(const Vec3& v, int dim) noexcept {
  Vec3 r;
  for (int i = 0; i < dim; ++i) r[i] = v[i];
  return r;
}

bool coincide(const Vec3& a, const Vec3& b, double scale) noexcept {
  return norm(a - b) <= Tol::kCoincident * scale;
}

/// The unit normal seen from the positive side: first non-zero of z, y, x
/// positive. Clockwise / counter-clockwise in 3-D are as seen from there (in a
/// 2-D system the normal is +z, the usual x-y orientation).
Vec3 oriented(Vec3 n) noexcept {
  constexpr double eps = 1e-12;  // n is a unit vector
  const bool flip = n[2] < -eps || (std::fabs(n[2]) <= eps && (n[1] < -eps || (std::fabs(n[1]) <= eps && n[0] < 0)));
  return flip ? -1.0 * n : n;
}

}  // namespace

/// Arc around `c` from `s` turning positively about unit normal `n` when
/// dir > 0 (negatively when dir < 0), to `e`, or a full turn back to `s`.
void Path::set_arc(const Vec3& c, const Vec3& s, const Vec3& e, const Vec3& n, double dir, bool full) noexcept {
  center_ = c;
  radius_ = norm(s - c);
  e1_ = (1.0 / radius_) * (s - c);
  e2_ = dir * cross(n, e1_);
  if (full) {
    sweep_ = kTwoPi;
    end_ = s;
    return;
  }
  const Vec3 r = e - c;
  double th = std::atan2(dot(r, e2_), dot(r, e1_));
  if (th <= 0) th += kTwoPi;
  sweep_ = th;
  end_ = e;
}

Err Path::build(const PathSpec& spec, const Vec3& start_in, int dim, Path& out) noexcept {
  dim = std::clamp(dim, 1, kMaxDim);
  const Vec3 S = masked(start_in, dim);
  const Vec3 pos = masked(spec.position, dim);
  // End point (non-full) or the second point on a full circle.
  const Vec3 Q = spec.incremental ? S + pos : pos;
  Path p;
  p.start_ = S;
  if (spec.kind == PathKind::Line) {
    p.kind_ = PathKind::Line;
    p.end_ = Q;
    p.length_ = norm(Q - S);
    if (p.length_ > 0) p.u_ = (1.0 / p.length_) * (Q - S);
    out = p;
    return Err::None;
  }
  p.kind_ = PathKind::Circle;
  if (dim == 1) return Err::CircularCollinearity;  // every point of a 1-D system is on one line
  const bool full = is_full(spec.direction);
  const double dir = (spec.direction == CircleDirection::CounterClockwise ||
                      spec.direction == CircleDirection::CounterClockwiseFull) ? 1.0 : -1.0;
  const Vec3 aux = masked(spec.aux, dim);
  const Vec3 z{{0, 0, 1}};
  if (spec.circle_type == CircleType::Via) {
    const Vec3 V = spec.incremental ? S + aux : aux;
    const double scale = std::max({max_abs(S), max_abs(Q), max_abs(V)});
    if (!full && coincide(S, Q, scale)) return Err::CircularStartEnd;
    if (coincide(S, V, scale) || coincide(S, Q, scale) || coincide(V, Q, scale)) return Err::CircularCollinearity;
    const Vec3 u = V - S, w = Q - S;
    const Vec3 nn = cross(u, w);
    const double nl = norm(nn);
    if (nl <= Tol::kCollinearSine * norm(u) * norm(w)) return Err::CircularCollinearity;
    // Circumcenter of S, V, Q.
    const Vec3 C = S + (1.0 / (2 * nl * nl)) * cross(dot(u, u) * w - dot(w, w) * u, nn);
    const Vec3 n = (1.0 / nl) * nn;  // S -> V -> Q turns positively about n
    if (full) {
      p.set_arc(C, S, S, oriented(n), dir, true);
    } else {
      p.set_arc(C, S, Q, n, 1.0, false);
    }
  } else if (spec.circle_type == CircleType::Center || spec.circle_type == CircleType::CenterIncremental) {
    const bool rel = spec.incremental || spec.circle_type == CircleType::CenterIncremental;
    Vec3 C = rel ? S + aux : aux;
    const double scale = std::max({max_abs(S), max_abs(Q), max_abs(C)});
    if (!full && coincide(S, Q, scale)) return Err::CircularStartEnd;
    const double r1 = norm(S - C), r2 = norm(Q - C);
    if (r1 <= Tol::kCoincident * scale) return Err::CircularNoSolutions;  // zero radius
    if (std::fabs(r1 - r2) > Tol::kRadiusMismatch * std::max(r1, r2)) return Err::CircularR1R2Mismatch;
    Vec3 n = z;
    if (dim == 3) {
      const Vec3 nn = cross(S - C, Q - C);
      const double nl = norm(nn);
      if (nl <= Tol::kCollinearSine * r1 * r2) return Err::CircularInfiniteSolutions;  // plane not determined
      n = oriented((1.0 / nl) * nn);
    }
    if (!full) {  // exact equidistance: the center on the chord's bisector in the plane
      const Vec3 M = 0.5 * (S + Q);
      const Vec3 d = Q - S;
      const Vec3 w = (1.0 / norm(d)) * cross(n, d);
      C = M + dot(C - M, w) * w;
    }
    p.set_arc(C, S, Q, n, dir, full);
  } else {  // Radius
    if (dim == 3) return Err::CircularInfiniteSolutions;  // two points and a radius leave the plane open
    const double r = spec.aux[0];
    const double scale = std::max(max_abs(S), max_abs(Q));
    if (coincide(S, Q, scale)) return full ? Err::CircularInfiniteSolutions : Err::CircularStartEnd;
    if (r == 0) return Err::CircularNoSolutions;
    const Vec3 d = Q - S;
    const double c = norm(d);
    const double half = c / 2;
    double h = 0.0;
    if (std::fabs(r) < half) {
      if (half - std::fabs(r) > Tol::kHalfChord * half) return Err::CircularSmallR;
    } else {
      h = std::sqrt((std::fabs(r) - half) * (std::fabs(r) + half));
    }
    // Positive radius: the arc of at most half a turn; negative: the longer one.
    // Counter-clockwise with the center left of start->end gives the short arc.
    const Vec3 w = (1.0 / c) * cross(z, d);
    const double side = (dir > 0) == (r > 0) ? 1.0 : -1.0;
    const Vec3 C = 0.5 * (S + Q) + (side * h) * w;
    p.set_arc(C, S, Q, z, dir, full);
  }
  p.length_ = p.radius_ * p.sweep_;
  out = p;
  return Err::None;
}

Vec3 Path::point(double s) const noexcept {
  if (at_end(s)) return end_;
  if (kind_ == PathKind::Line) return start_ + s * u_;
  const double th = s / radius_;
  return center_ + radius_ * (std::cos(th) * e1_ + std::sin(th) * e2_);
}

Vec3 Path::tangent(double s) const noexcept {
  if (kind_ == PathKind::Line) return u_;
  const double th = s / radius_;
  return std::cos(th) * e2_ - std::sin(th) * e1_;
}

void Path::eval(double s, double v, double a, Vec3& p, Vec3& vel, Vec3& acc) const noexcept {
  if (kind_ == PathKind::Line) {
    p = at_end(s) ? end_ : start_ + s * u_;
    vel = v * u_;
    acc = a * u_;
    return;
  }
  const double th = s / radius_;
  const double cs = std::cos(th), sn = std::sin(th);
  const Vec3 rad = cs * e1_ + sn * e2_;  // unit, from the center
  const Vec3 tan = cs * e2_ - sn * e1_;
  p = at_end(s) ? end_ : center_ + radius_ * rad;
  vel = v * tan;
  acc = a * tan - (v * v / radius_) * rad;
}

}  // namespace canmotion::motion::coord
