#pragma once
/// \file motion/coord/geometry.hpp
/// Geometry of one coordinated segment (MCLM line, MCCM arc): built once at
/// plan time from the instruction's operands, with the Logix .ERR of every
/// degenerate case; evaluated per cycle in closed form (a line is a
/// multiply-add, an arc one sin/cos pair). Rules and tolerances:
/// motion/coord/README.md, "Geometry". Pure and realtime-safe.

#include <cstdint>

#include "motion/coord/vec3.hpp"
#include "motion/types.hpp"

namespace canmotion::motion::coord {

/// Largest coordinate-system dimension (Logix: 1..3 Cartesian axes).
inline constexpr int kMaxDim = 3;

enum class PathKind : std::uint8_t { Line = 0, Circle = 1 };
/// MCCM CircleType (reference 2.20; numbers ⚠ from memory).
enum class CircleType : std::uint8_t { Via = 0, Center = 1, Radius = 2, CenterIncremental = 3 };
/// MCCM Direction (reference 2.20; numbers ⚠ from memory).
enum class CircleDirection : std::uint8_t { Clockwise = 0, CounterClockwise = 1, ClockwiseFull = 2, CounterClockwiseFull = 3 };

constexpr bool is_full(CircleDirection d) noexcept {
  return d == CircleDirection::ClockwiseFull || d == CircleDirection::CounterClockwiseFull;
}

/// The geometric operands of one MCLM or MCCM, as the instruction gives them.
struct PathSpec {
  PathKind kind = PathKind::Line;
  bool incremental = false;  ///< MoveType 1: Position (and Via/Center) relative to the start point
  Vec3 position;             ///< Position[0..dim-1]; for a full circle: a second point on the circle
  CircleType circle_type = CircleType::Via;
  Vec3 aux;                  ///< Via or Center point; for CircleType Radius the radius is aux[0]
  CircleDirection direction = CircleDirection::Clockwise;
};

/// Tolerances of the geometric checks (README "Geometry").
struct GeometryTolerances {
  /// Two points coincide when |a - b| <= this x the largest |coordinate| involved.
  static constexpr double kCoincident = 1e-12;
  /// Three points are collinear when |u x w| <= this x |u| |w| (the sine of their angle).
  static constexpr double kCollinearSine = 1e-9;
  /// Center type: |R1 - R2| <= this x max(R1, R2) is accepted (ERR 46 beyond);
  /// the center is then moved onto the bisector of the chord so the arc runs
  /// exactly from start to end. 1e-6 covers REAL (24-bit) operands.
  static constexpr double kRadiusMismatch = 1e-6;
  /// Radius type: |R| short of half the chord by at most this (relative) is a half circle.
  static constexpr double kHalfChord = 1e-9;
};

/// One segment: p(s) for s in [0, length()], exact start and end points.
class Path {
 public:
  /// Build from operands and the start point. `dim` (1..3) masks unused
  /// components. Returns Err::None, or 44..49 for a degenerate circle (and
  /// nothing is written to `out`). Not realtime-critical (O(1), no allocation).
  static Err build(const PathSpec& spec, const Vec3& start, int dim, Path& out) noexcept;

  PathKind kind() const noexcept { return kind_; }
  double length() const noexcept { return length_; }
  const Vec3& start() const noexcept { return start_; }
  const Vec3& end() const noexcept { return end_; }
  /// Arc data (meaningless for a line): center, radius, swept angle (rad, > 0,
  /// 2 pi for a full circle) and the unit normal about which the arc turns
  /// positively (e1 x e2).
  const Vec3& center() const noexcept { return center_; }
  double radius() const noexcept { return radius_; }
  double sweep() const noexcept { return sweep_; }
  Vec3 normal() const noexcept { return cross(e1_, e2_); }

  /// Point at arc length s (s within a few ulps of length() gives end()
  /// exactly: a profile re-planned from s0 ends at s0 + (L - s0), which may
  /// differ from L in the last bit; s outside [0, length()] extends the line
  /// / continues on the circle). Realtime-safe.
  Vec3 point(double s) const noexcept;
  /// Unit tangent at s (direction of motion). Realtime-safe.
  Vec3 tangent(double s) const noexcept;
  /// Point, velocity and acceleration for path speed v and tangential
  /// acceleration a at s (the arc adds the centripetal v^2/R). Realtime-safe.
  void eval(double s, double v, double a, Vec3& p, Vec3& vel, Vec3& acc) const noexcept;
  /// Translate the whole segment (a re-based start point). Realtime-safe.
  void translate(const Vec3& d) noexcept {
    start_ += d;
    end_ += d;
    center_ += d;
  }

 private:
  bool at_end(double s) const noexcept { return std::fabs(s - length_) <= 4e-16 * length_; }
  void set_arc(const Vec3& c, const Vec3& s, const Vec3& e, const Vec3& n, double dir, bool full) noexcept;

  PathKind kind_ = PathKind::Line;
  double length_ = 0.0;
  Vec3 start_, end_;
  Vec3 u_;        ///< line: unit direction (0 for a zero-length line)
  Vec3 center_;   ///< arc
  Vec3 e1_, e2_;  ///< arc: p(theta) = center + R (cos theta e1 + sin theta e2)
  double radius_ = 0.0;
  double sweep_ = 0.0;
};

}  // namespace canmotion::motion::coord
