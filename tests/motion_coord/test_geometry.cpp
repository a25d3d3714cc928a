// Coordinated path geometry (motion/coord/geometry.hpp): MCCM arcs of every
// CircleType and Direction built from random circles, and every geometric
// .ERR case. Seeded (CANMOTION_SEED, CANMOTION_PROP_COUNT; seed printed on failure).
#include <gtest/gtest.h>

#include <sstream>

#include "coord_rig.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;
using namespace canmotion::motion::coord::test;

namespace {

/// A random circle and the MCCM operands that describe an arc of it.
struct ArcCase {
  int dim = 2;
  Vec3 start, center, end;
  double radius = 0, sweep = 0;
  bool full = false;
  PathSpec spec;
  std::string text;
};

// The orientation convention of geometry.cpp: counter-clockwise is positive
// about the normal whose first non-zero of (z, y, x) is positive.
bool positive_side(const Vec3& n) {
  if (std::fabs(n[2]) > 1e-12) return n[2] > 0;
  if (std::fabs(n[1]) > 1e-12) return n[1] > 0;
  return n[0] > 0;
}

ArcCase random_arc(Rng& r) {
  ArcCase c;
  const int type = r.pick(4);
  c.dim = type == 2 ? 2 : (r.coin() ? 2 : 3);  // Radius: 2-D only (3-D is ERR 47)
  c.full = r.coin(0.25);
  c.center = random_point(r, c.dim, 100);
  c.radius = r.logu(0.01, 100);
  Vec3 e1, e2, n;
  if (c.dim == 2) {
    const double phi = r.uni(0, kTwoPi);
    e1 = v3(std::cos(phi), std::sin(phi));
    n = v3(0, 0, r.coin() ? 1 : -1);  // turning sense
    e2 = cross(n, e1);
  } else {
    n = random_unit(r, 3);
    Vec3 t = random_unit(r, 3);
    e1 = t - dot(t, n) * n;
    e1 = (1.0 / norm(e1)) * e1;
    e2 = cross(n, e1);
  }
  auto at = [&](double th) { return c.center + c.radius * (std::cos(th) * e1 + std::sin(th) * e2); };
  c.start = at(0);
  // Sweeps away from 0 and 2 pi (a nearly closed arc is ill-conditioned) and,
  // for 3-D center arcs and radius arcs, away from pi (start, center and end
  // collinear: the plane or the side is undetermined).
  auto ok_angle = [&](double th) {
    if (th < 0.05 || th > kTwoPi - 0.05) return false;
    if ((type == 1 || type == 3) && c.dim == 3 && std::fabs(th - std::numbers::pi) < 0.05) return false;
    if (type == 2 && std::fabs(th - std::numbers::pi) < 1e-3) return false;
    return true;
  };
  double th;
  do th = r.uni(0, kTwoPi); while (!ok_angle(th));
  c.sweep = c.full ? kTwoPi : th;
  const Vec3 second = at(th);  // the end, or a second point of a full circle
  c.end = c.full ? c.start : second;  // (an incremental end is start + Position, below)
  c.spec.kind = PathKind::Circle;
  c.spec.incremental = r.coin(0.3);
  const bool ccw = positive_side(n);
  c.spec.direction = c.full ? (ccw ? CircleDirection::CounterClockwiseFull : CircleDirection::ClockwiseFull)
                            : (ccw ? CircleDirection::CounterClockwise : CircleDirection::Clockwise);
  c.spec.position = c.spec.incremental ? second - c.start : second;
  if (c.spec.incremental && !c.full) c.end = c.start + c.spec.position;  // what the operands say, exactly
  std::ostringstream os;
  switch (type) {
    case 0: {  // via: a point of the arc (full circle: a third point of the circle)
      c.spec.circle_type = CircleType::Via;
      double tv;
      if (c.full) {
        do tv = r.uni(0, kTwoPi); while (!ok_angle(tv) || std::fabs(tv - th) < 0.05);
      } else {
        tv = th * r.uni(0.1, 0.9);
        if (r.coin(0.5)) c.spec.direction = static_cast<CircleDirection>(r.pick(2));  // ignored for a via arc
      }
      const Vec3 via = at(tv);
      c.spec.aux = c.spec.incremental ? via - c.start : via;
      os << "via";
      break;
    }
    case 1:
    case 3: {
      c.spec.circle_type = type == 1 ? CircleType::Center : CircleType::CenterIncremental;
      c.spec.aux = (type == 3 || c.spec.incremental) ? c.center - c.start : c.center;
      os << (type == 1 ? "center" : "center incremental");
      break;
    }
    default: {  // radius: positive for at most half a turn (in the direction of motion)
      c.spec.circle_type = CircleType::Radius;
      c.spec.aux = v3(th <= std::numbers::pi ? c.radius : -c.radius);
      os << "radius";
      break;
    }
  }
  os << " dim=" << c.dim << " full=" << c.full << " incr=" << c.spec.incremental
     << " dir=" << static_cast<int>(c.spec.direction) << " R=" << c.radius << " sweep=" << c.sweep;
  c.text = os.str();
  return c;
}

}  // namespace

// Path::build on random circles: the center, radius, sweep and end point are
// the ones the operands describe, and every point of the arc is on the circle.
TEST(CoordGeometry, ArcsOfEveryTypeAndDirectionProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed();
  const std::uint64_t count = canmotion::motion::test::prop_count(100000);
  Rng r(seed);
  int per_type[4] = {0, 0, 0, 0};
  for (std::uint64_t n = 0; n < count; ++n) {
    const ArcCase c = random_arc(r);
    Path p;
    const Err e = Path::build(c.spec, c.start, c.dim, p);
    const std::string ctx = "seed=" + std::to_string(seed) + " n=" + std::to_string(n) + " " + c.text;
    ASSERT_EQ(e, Err::None) << ctx;
    ++per_type[static_cast<int>(c.spec.circle_type)];
    ASSERT_EQ(p.kind(), PathKind::Circle) << ctx;
    ASSERT_LE(norm(p.center() - c.center), 1e-7 * c.radius + 1e-11 * 100) << ctx;
    ASSERT_NEAR(p.radius(), c.radius, 1e-7 * c.radius) << ctx;
    if (c.full) {
      ASSERT_EQ(p.sweep(), kTwoPi) << ctx;
    } else {
      ASSERT_NEAR(p.sweep(), c.sweep, 1e-6) << ctx;
    }
    ASSERT_TRUE(p.end() == c.end) << ctx;  // exact: the operand itself (the start for a full circle)
    ASSERT_TRUE(p.point(p.length()) == c.end) << ctx;
    ASSERT_NEAR(p.length(), p.radius() * p.sweep(), 1e-12 * p.length()) << ctx;
    for (int i = 0; i <= 64; ++i) {
      const double s = p.length() * i / 64;
      ASSERT_LE(std::fabs(norm(p.point(s) - p.center()) - p.radius()), 1e-9 * p.radius()) << ctx << " s=" << s;
    }
  }
  for (int t = 0; t < 4; ++t) EXPECT_GT(per_type[t], 0) << "circle type " << t;
}

// The same arcs run through the generator: every cycle on the circle
// (1e-9 R), the exact end point, the swept angle (2 pi for full circles),
// speed and tangential acceleration within the programmed limits.
TEST(CoordGeometry, ArcsThroughTheGeneratorProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 1;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000) / 50 + 1;
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    const ArcCase c = random_arc(r);
    const bool scurve = r.coin();
    const Limits l = limits_for(r, c.radius * c.sweep, scurve);
    Rig rig(c.dim, r.uni(2.5e-4, 2e-3));
    rig.now.has_total = true;
    rig.now.total = c.start;
    const std::string ctx = "seed=" + std::to_string(seed) + " n=" + std::to_string(n) + " " + c.text;
    ASSERT_EQ(rig.submit(arc(7, c.spec.position, c.spec.circle_type, c.spec.aux, c.spec.direction, l,
                             Termination::NoSettle, c.spec.incremental)),
              Err::None)
        << ctx;
    rig.now.has_total = false;
    rig.record = false;
    // The circle the generator follows (the operands' circle to 1e-7 R, see above).
    Path ref;
    ASSERT_EQ(Path::build(c.spec, c.start, c.dim, ref), Err::None) << ctx;
    const Vec3 C = ref.center();
    const double R = ref.radius();
    double swept = 0.0;
    Vec3 prev = c.start;
    for (int i = 0; i < 4'000'000 && !rig.g.idle(); ++i) {
      const Output& o = rig.step();
      ASSERT_LE(std::fabs(norm(o.position - C) - R), 1e-9 * R) << ctx << " cycle " << i;
      ASSERT_LE(o.speed, l.v * (1 + 1e-9)) << ctx;
      if (o.speed > 1e-9 * l.v) {
        const double at = dot(o.acceleration, o.velocity) / o.speed;  // tangential
        ASSERT_LE(at, l.a * (1 + 1e-9) + 1e-9) << ctx;
        ASSERT_GE(at, -l.d * (1 + 1e-9) - 1e-9) << ctx;
      }
      // The motion never turns back: the unsigned angle steps add up to the sweep.
      const Vec3 a = prev - C, b = o.position - C;
      swept += std::atan2(norm(cross(a, b)), dot(a, b));
      prev = o.position;
    }
    ASSERT_TRUE(rig.g.idle()) << ctx;
    ASSERT_TRUE(rig.last.position == c.end) << ctx << " end exact";
    EXPECT_NEAR(swept, c.sweep, 1e-6) << ctx;
  }
}

namespace {

Err build(const PathSpec& s, const Vec3& start, int dim) {
  Path p;
  return Path::build(s, start, dim, p);
}

PathSpec circle(const Vec3& pos, CircleType t, const Vec3& aux, CircleDirection d, bool incremental = false) {
  PathSpec s;
  s.kind = PathKind::Circle;
  s.position = pos;
  s.circle_type = t;
  s.aux = aux;
  s.direction = d;
  s.incremental = incremental;
  return s;
}

constexpr auto CW = CircleDirection::Clockwise;
constexpr auto CCW = CircleDirection::CounterClockwise;
constexpr auto CWF = CircleDirection::ClockwiseFull;
constexpr auto CCWF = CircleDirection::CounterClockwiseFull;

}  // namespace

TEST(CoordGeometry, ErrorCasesByExample) {
  const Vec3 O = v3(0, 0);
  // 44 collinear via points (also a via point on the start or the end), and any circle in 1-D.
  EXPECT_EQ(build(circle(v3(2, 2), CircleType::Via, v3(1, 1), CW), O, 2), Err::CircularCollinearity);
  EXPECT_EQ(build(circle(v3(2, 2), CircleType::Via, v3(5, 5), CW), O, 2), Err::CircularCollinearity);
  EXPECT_EQ(build(circle(v3(2, 2), CircleType::Via, O, CW), O, 2), Err::CircularCollinearity);
  EXPECT_EQ(build(circle(v3(2, 2), CircleType::Via, v3(2, 2), CW), O, 2), Err::CircularCollinearity);
  EXPECT_EQ(build(circle(v3(2, 0, 0), CircleType::Via, v3(1, 0, 0), CCWF), O, 3), Err::CircularCollinearity);
  EXPECT_EQ(build(circle(v3(2), CircleType::Center, v3(1), CW), O, 1), Err::CircularCollinearity);
  // 45 start = end (not a full circle), every type; incremental 0.
  EXPECT_EQ(build(circle(O, CircleType::Via, v3(1, 1), CW), O, 2), Err::CircularStartEnd);
  EXPECT_EQ(build(circle(O, CircleType::Center, v3(1, 0), CCW), O, 2), Err::CircularStartEnd);
  EXPECT_EQ(build(circle(O, CircleType::CenterIncremental, v3(1, 0), CCW), O, 2), Err::CircularStartEnd);
  EXPECT_EQ(build(circle(O, CircleType::Radius, v3(1), CCW), O, 2), Err::CircularStartEnd);
  EXPECT_EQ(build(circle(v3(0, 0), CircleType::Center, v3(1, 0), CW, true), v3(3, 4), 2), Err::CircularStartEnd);
  // ... but a full circle through the start point is fine with a center (2-D).
  EXPECT_EQ(build(circle(O, CircleType::Center, v3(1, 0), CWF), O, 2), Err::None);
  // 46 center not equidistant (beyond 1e-6 relative); within it the arc ends exactly on the end point.
  EXPECT_EQ(build(circle(v3(2.0001, 0), CircleType::Center, v3(1, 0), CW), O, 2), Err::CircularR1R2Mismatch);
  EXPECT_EQ(build(circle(v3(1, 3), CircleType::Center, v3(1, 0), CCWF), O, 2), Err::CircularR1R2Mismatch);
  {
    Path p;
    ASSERT_EQ(Path::build(circle(v3(2 + 1e-7, 0), CircleType::Center, v3(1, 0), CW), O, 2, p), Err::None);
    EXPECT_TRUE(p.end() == v3(2 + 1e-7, 0));
    EXPECT_NEAR(norm(p.center() - v3(1 + 0.5e-7, 0)), 0.0, 1e-15);
  }
  // 47 the plane is not determined: 3-D radius arcs, 3-D half circles by center, full radius circle through one point.
  EXPECT_EQ(build(circle(v3(2, 0, 0), CircleType::Radius, v3(1), CW), O, 3), Err::CircularInfiniteSolutions);
  EXPECT_EQ(build(circle(v3(2, 0, 0), CircleType::Center, v3(1, 0, 0), CW), O, 3), Err::CircularInfiniteSolutions);
  EXPECT_EQ(build(circle(O, CircleType::Center, v3(1, 0, 0), CCWF), O, 3), Err::CircularInfiniteSolutions);
  EXPECT_EQ(build(circle(O, CircleType::Radius, v3(1), CCWF), O, 2), Err::CircularInfiniteSolutions);
  // ... while the same half circle in 2-D is fine (the direction picks the side).
  EXPECT_EQ(build(circle(v3(2, 0), CircleType::Center, v3(1, 0), CW), O, 2), Err::None);
  // 48 no circle: zero radius.
  EXPECT_EQ(build(circle(v3(2, 0), CircleType::Center, O, CW), O, 2), Err::CircularNoSolutions);
  EXPECT_EQ(build(circle(v3(2, 0), CircleType::Radius, v3(0), CW), O, 2), Err::CircularNoSolutions);
  // 49 |R| below half the chord; a radius short of it by <= 1e-9 relative is a half circle.
  EXPECT_EQ(build(circle(v3(2, 0), CircleType::Radius, v3(0.999), CW), O, 2), Err::CircularSmallR);
  EXPECT_EQ(build(circle(v3(2, 0), CircleType::Radius, v3(-0.5), CCW), O, 2), Err::CircularSmallR);
  {
    Path p;
    ASSERT_EQ(Path::build(circle(v3(2, 0), CircleType::Radius, v3(1 - 1e-12), CW), O, 2, p), Err::None);
    EXPECT_NEAR(p.sweep(), std::numbers::pi, 1e-9);
  }
}

TEST(CoordGeometry, RadiusSignAndDirection) {
  // From (0,0) to (2,0) with |R| = 2: counter-clockwise passes below the chord,
  // with a positive radius the short way (center above), with a negative one
  // the long way (center below); clockwise the mirror images.
  const Vec3 O = v3(0, 0);
  auto mid_y = [&](CircleDirection d, double r) {
    Path p;
    EXPECT_EQ(Path::build(circle(v3(2, 0), CircleType::Radius, v3(r), d), O, 2, p), Err::None);
    return std::make_pair(p.point(p.length() / 2)[1], p.sweep());
  };
  auto [y1, s1] = mid_y(CCW, 2);
  EXPECT_NEAR(y1, std::sqrt(3.0) - 2, 1e-12);  // center (1, +sqrt 3), the short way below
  EXPECT_LT(s1, std::numbers::pi);
  auto [y2, s2] = mid_y(CCW, -2);
  EXPECT_NEAR(y2, -std::sqrt(3.0) - 2, 1e-12);  // center (1, -sqrt 3), the long way round below
  EXPECT_GT(s2, std::numbers::pi);
  auto [y3, s3] = mid_y(CW, 2);
  EXPECT_NEAR(y3, 2 - std::sqrt(3.0), 1e-12);
  EXPECT_LT(s3, std::numbers::pi);
  auto [y4, s4] = mid_y(CW, -2);
  EXPECT_NEAR(y4, std::sqrt(3.0) + 2, 1e-12);
  EXPECT_GT(s4, std::numbers::pi);
  // Center arcs: CCW from (1,0) around the origin to (0,1) is a quarter turn, CW three quarters.
  Path p;
  ASSERT_EQ(Path::build(circle(v3(0, 1), CircleType::Center, O, CCW), v3(1, 0), 2, p), Err::None);
  EXPECT_NEAR(p.sweep(), std::numbers::pi / 2, 1e-15);
  ASSERT_EQ(Path::build(circle(v3(0, 1), CircleType::Center, O, CW), v3(1, 0), 2, p), Err::None);
  EXPECT_NEAR(p.sweep(), 1.5 * std::numbers::pi, 1e-15);
  // 3-D: the same arc lifted to z = 5 and seen from +z behaves as in 2-D; in the x-z plane from +y.
  ASSERT_EQ(Path::build(circle(v3(0, 1, 5), CircleType::Center, v3(0, 0, 5), CCW), v3(1, 0, 5), 3, p), Err::None);
  EXPECT_NEAR(p.sweep(), std::numbers::pi / 2, 1e-15);
  ASSERT_EQ(Path::build(circle(v3(0, 0, 1), CircleType::Center, O, CCW), v3(1, 0, 0), 3, p), Err::None);
  EXPECT_GT(p.normal()[1], 0.99);  // counter-clockwise about +y
  EXPECT_NEAR(p.sweep(), 1.5 * std::numbers::pi, 1e-15);
  // Components past the dimension are ignored.
  ASSERT_EQ(Path::build(circle(v3(0, 1, 7), CircleType::Center, v3(0, 0, 9), CCW), v3(1, 0), 2, p), Err::None);
  EXPECT_EQ(p.end()[2], 0.0);
}

// Each geometric error from random data, and a refused MCCM changes nothing
// (the running move and the queue are untouched).
TEST(CoordGeometry, ErrorCasesProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 2;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000) / 10 + 1;
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    const std::string ctx = "seed=" + std::to_string(seed) + " n=" + std::to_string(n);
    const int dim = r.coin() ? 2 : 3;
    const Vec3 S = random_point(r, dim, 50);
    Vec3 E = random_point(r, dim, 50);
    const int kind = r.pick(6);
    PathSpec s;
    Err want = Err::None;
    switch (kind) {
      case 0: {  // collinear via
        const double t = r.uni(-2, 3);
        s = circle(E, CircleType::Via, S + t * (E - S), CW);
        want = Err::CircularCollinearity;
        break;
      }
      case 1:  // start = end
        s = circle(S, static_cast<CircleType>(r.pick(dim == 2 ? 4 : 2)), random_point(r, dim, 50),
                   r.coin() ? CW : CCW);
        if (s.circle_type == CircleType::Radius) s.aux = v3(r.uni(1, 10));
        want = Err::CircularStartEnd;
        break;
      case 2: {  // center not equidistant by more than 1e-6
        Vec3 C = random_point(r, dim, 50);
        const double r1 = norm(S - C);
        const Vec3 dir = random_unit(r, dim);
        E = C + (r1 * (1 + (r.coin() ? 1 : -1) * r.logu(2e-6, 0.5))) * dir;
        s = circle(E, CircleType::Center, C, r.coin() ? CW : CCW);
        want = Err::CircularR1R2Mismatch;
        break;
      }
      case 3:  // 3-D radius
        s = circle(E, CircleType::Radius, v3(r.uni(100, 200)), CW);
        want = dim == 3 ? Err::CircularInfiniteSolutions : Err::None;
        break;
      case 4: {  // radius below half the chord
        const double half = norm(E - S) / 2;
        s = circle(E, CircleType::Radius, v3((r.coin() ? 1 : -1) * half * r.uni(0.01, 0.999)), CCW);
        want = dim == 3 ? Err::CircularInfiniteSolutions : Err::CircularSmallR;
        break;
      }
      default:  // center on the start point
        s = circle(E, CircleType::Center, S, CW);
        want = Err::CircularNoSolutions;
        break;
    }
    ASSERT_EQ(build(s, S, dim), want) << ctx << " kind " << kind;
    if (want == Err::None) continue;
    // Through the generator: a move runs, one waits; the refused MCCM leaves both.
    Rig rig(dim);
    rig.now.has_total = true;
    rig.now.total = S;
    ASSERT_EQ(rig.submit(line(1, S + v3(1, 1), lim(10, 100, 100))), Err::None) << ctx;
    rig.now.has_total = false;
    ASSERT_EQ(rig.submit(line(2, S, lim(10, 100, 100))), Err::None) << ctx;
    rig.step();
    MoveRequest bad = line(3, s.position, lim(10, 100, 100));
    bad.path = s;
    bad.merge = r.coin() ? CoordMerge::CoordinatedMotion : CoordMerge::Disabled;
    // a circle of this request starts at the end of move 1 or at the present point (merge): rebuild there
    const Vec3 from = bad.merge == CoordMerge::Disabled ? S : rig.g.position();  // behind move 2, or here
    const Err e2 = rig.submit(bad);
    const Err expect2 = build(s, from, dim);
    if (expect2 == Err::None && bad.merge == CoordMerge::Disabled) {
      ASSERT_EQ(e2, Err::CoordinateSystemQueueFull) << ctx;
    } else if (expect2 != Err::None) {
      ASSERT_EQ(e2, expect2) << ctx;
    } else {
      continue;  // a merge that is geometrically fine from here
    }
    EXPECT_EQ(rig.last_submit_events.n, 0) << ctx;
    EXPECT_EQ(rig.g.active_id(), 1u) << ctx;
    EXPECT_EQ(rig.g.pending_id(), 2u) << ctx;
  }
}
