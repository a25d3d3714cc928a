// Stop along the path (MCS), re-plan (MCCD), merges, EventDistance /
// CalculatedData and clear (MCSD): seeded properties (CANMOTION_SEED,
// CANMOTION_PROP_COUNT).
#include <gtest/gtest.h>

#include <sstream>

#include "coord_rig.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;
using namespace canmotion::motion::coord::test;
namespace cms = canmotion::motion::coordinate_motion_status;

namespace {

/// A random line or arc (a center arc: 2-D or 3-D) starting at S.
struct Seg {
  MoveRequest rq;
  Vec3 start;
  Path path;
};

Seg random_segment(Rng& r, int dim, std::uint32_t id, const Limits& l) {
  Seg s;
  s.start = random_point(r, dim, 50);
  if (dim >= 2 && r.coin()) {
    const double R = r.logu(0.05, 20);
    const Vec3 c = s.start + R * random_unit(r, dim);
    Vec3 n = dim == 2 ? v3(0, 0, 1) : random_unit(r, 3);
    const Vec3 e1 = (1.0 / R) * (s.start - c);
    n = n - dot(n, e1) * e1;
    n = (1.0 / norm(n)) * n;
    const double th = r.uni(0.2, 3.0);
    const Vec3 e = c + R * (std::cos(th) * e1 + std::sin(th) * cross(n, e1));
    const bool ccw = n[2] > 1e-12 || (std::fabs(n[2]) <= 1e-12 && (n[1] > 1e-12 || (std::fabs(n[1]) <= 1e-12 && n[0] > 0)));
    s.rq = arc(id, e, CircleType::Center, c, ccw ? CircleDirection::CounterClockwise : CircleDirection::Clockwise, l);
  } else {
    s.rq = line(id, s.start + r.logu(0.01, 50) * random_unit(r, dim), l);
  }
  EXPECT_EQ(Path::build(s.rq.path, s.start, dim, s.path), Err::None);
  return s;
}

/// Distance of p from the segment's path (line segment or circle).
double off_path(const Path& p, const Vec3& x) {
  if (p.kind() == PathKind::Line) return dist_to_segment(x, p.start(), p.end());
  return std::fabs(norm(x - p.center()) - p.radius());
}

/// A random segment started from rest in a fresh rig and stepped for 1 ..
/// window/period cycles. False if it has already finished.
struct Running {
  Seg s;
  Limits l;
  bool scurve = false;
  Rig rig;
  int before = 0;
};
bool start_random_move(Rng& r, double window, Running& m) {
  const int dim = 1 + r.pick(3);
  m.scurve = r.coin();
  m.s = random_segment(r, dim, 5, lim(1, 1, 1));
  m.l = limits_for(r, m.s.path.length(), m.scurve);
  m.s.rq.limits = m.l;
  m.rig = Rig(dim, r.uni(2.5e-4, 2e-3));
  m.rig.record = false;
  m.rig.now.has_total = true;
  m.rig.now.total = m.s.start;
  EXPECT_EQ(m.rig.submit(m.s.rq), Err::None);
  m.rig.now.has_total = false;
  m.before = 1 + r.pick(static_cast<int>(window / m.rig.cfg.period) + 1);
  for (int i = 0; i < m.before && !m.rig.g.idle(); ++i) m.rig.step();
  return !m.rig.g.idle();
}

}  // namespace

// MCS: the move ends (Cancelled) and the system stops on the path (1e-9)
// within the stop's decel, never past the end of the move; StoppingStatus
// until StopDone at standstill.
TEST(CoordStop, StopsOnThePathProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 20;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000) / 50 + 1;
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    Running m;
    const bool running = start_random_move(r, 0.2, m);
    const std::string ctx = "seed=" + std::to_string(seed) + " n=" + std::to_string(n);
    if (!running) continue;
    Rig& rig = m.rig;
    const Seg& s = m.s;
    const Limits& l = m.l;
    const bool scurve = m.scurve;
    // A stop at least as strong as the move's own decel.
    const double d = l.d * r.uni(1, 3), jd = scurve ? l.jd * r.uni(1, 3) : kInf;
    Events ev;
    rig.g.stop(77, d, jd, ev);
    ASSERT_TRUE(has_event(ev, 5, EventKind::Cancelled)) << ctx;
    const double a0 = dot(rig.last.acceleration, rig.last.velocity) / std::max(rig.last.speed, 1e-300);
    const double a_ramp = std::fabs(a0);
    // A braking acceleration the stop's jerk cannot ramp out before the speed
    // is 0: the stop ends there with the jerk scaled up (it never backs up).
    const bool scaled = std::isfinite(jd) && a0 < 0 && rig.last.speed - a0 * a0 / (2 * jd) < 0;
    bool done = false;
    double max_decel = 0.0;
    for (int i = 0; i < 2'000'000 && !done; ++i) {
      const Output& o = rig.step();
      ASSERT_LE(off_path(s.path, o.position), 1e-9 * std::max(s.path.length(), s.path.radius())) << ctx;
      if (o.speed > 0) {
        const double at = dot(o.acceleration, o.velocity) / o.speed;
        max_decel = std::max(max_decel, -at);
        ASSERT_LE(at, a_ramp * (1 + 1e-9) + 1e-12) << ctx;  // only the ramp-out of a present acceleration
      }
      done = has_event(o.events, 77, EventKind::StopDone);
      if (!done) {
        ASSERT_TRUE(bit(o.motion_status, cms::StoppingStatus)) << ctx;
      }
      ASSERT_FALSE(has_event(o.events, 5, EventKind::Completed)) << ctx;
    }
    ASSERT_TRUE(done) << ctx;
    // Within the stop's decel, unless that would have passed the end of the
    // move: then it stops exactly there (harder).
    if (!(rig.last.position == s.path.end()) && !scaled) {
      EXPECT_LE(max_decel, d * (1 + 1e-9)) << ctx;
    }
    EXPECT_EQ(rig.last.speed, 0.0) << ctx;
    EXPECT_FALSE(bit(rig.last.motion_status, cms::StoppingStatus)) << ctx;
    EXPECT_TRUE(rig.g.idle()) << ctx;
  }
}

TEST(CoordStop, ClearsThePendingMoveAndRefusesNewMovesWhileStopping) {
  Rig rig(2);
  ASSERT_EQ(rig.submit(line(1, v3(100, 0), lim(10, 10, 10))), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(100, 100), lim(10, 10, 10))), Err::None);
  for (int i = 0; i < 500; ++i) rig.step();
  Events ev;
  rig.g.stop(9, 20, kInf, ev);
  EXPECT_TRUE(has_event(ev, 1, EventKind::Cancelled));
  EXPECT_TRUE(has_event(ev, 2, EventKind::Cancelled));
  EXPECT_EQ(rig.submit(line(3, v3(0, 0), lim(10, 10, 10))), Err::NotAllowedWhileStopping);
  rig.g.stop(10, 40, kInf, ev);  // a newer stop supersedes
  EXPECT_TRUE(has_event(ev, 9, EventKind::Cancelled));
  rig.run();
  EXPECT_GE(rig.find(10, EventKind::StopDone), 0);
  EXPECT_LT(rig.find(9, EventKind::StopDone), 0);
  EXPECT_EQ(rig.last.position[1], 0.0);
  // Nothing moving: PC at once.
  rig.g.stop(11, 20, kInf, ev);
  EXPECT_TRUE(has_event(ev, 11, EventKind::StopDone));
  EXPECT_FALSE(rig.g.stopping());
}

// MCCD re-plans from the present state: no position step, the move still
// ends exactly on its target and never passes it.
TEST(CoordChangeDynamics, ReplanWithoutPositionStepProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 30;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000) / 50 + 1;
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    Running m;
    const bool running = start_random_move(r, 0.3, m);
    std::string ctx = "seed=" + std::to_string(seed) + " n=" + std::to_string(n);
    if (!running) continue;
    Rig& rig = m.rig;
    const Seg& s = m.s;
    const Limits& l = m.l;
    const bool scurve = m.scurve;
    const int before = m.before;
    DynamicsChange ch;
    ch.change_speed = r.coin(0.7);
    ch.change_accel = r.coin(0.5);
    ch.change_decel = r.coin(0.5);
    ch.change_accel_jerk = scurve && r.coin(0.5);
    ch.change_decel_jerk = scurve && r.coin(0.5);
    ch.values = Limits{l.v * r.logu(0.1, 3), l.a * r.logu(0.2, 5), l.d * r.logu(0.2, 5), l.ja * r.logu(0.2, 5),
                       l.jd * r.logu(0.2, 5)};
    const bool pause = r.coin(0.1);
    if (pause) {
      ch.change_speed = true;
      ch.values.v = 0;
    }
    std::ostringstream os;
    os << ctx << " kind=" << static_cast<int>(s.path.kind()) << " L=" << s.path.length() << " before=" << before
       << " pause=" << pause << " change={" << ch.change_speed << ch.change_accel << ch.change_decel
       << ch.change_accel_jerk << ch.change_decel_jerk << "} values={" << ch.values.v << "," << ch.values.a << ","
       << ch.values.d << "," << ch.values.ja << "," << ch.values.jd << "} lim={" << l.v << "," << l.a << "," << l.d
       << "," << l.ja << "," << l.jd << "}";
    ctx = os.str();
    Events ev;
    ASSERT_EQ(rig.g.change_dynamics(ch, ev), Err::None) << ctx;
    Output prev = rig.last;
    double max_speed = prev.speed, max_acc = norm(prev.acceleration);
    for (int i = 0; i < 4'000'000 && !rig.g.idle(); ++i) {
      const Output& o = rig.step();
      max_speed = std::max(max_speed, o.speed);
      max_acc = std::max(max_acc, norm(o.acceleration));
      const double step = norm(o.position - prev.position);
      ASSERT_LE(step, std::max(prev.speed, o.speed) * rig.cfg.period * (1 + 1e-6) + max_acc * rig.cfg.period * rig.cfg.period + 1e-12)
          << ctx << " position step at cycle " << i;
      ASSERT_LE(off_path(s.path, o.position), 1e-9 * std::max(s.path.length(), s.path.radius())) << ctx;
      prev = o;
      if (pause && i == 200) {  // resume after a while at rest
        DynamicsChange go;
        go.change_speed = true;
        go.values.v = l.v;
        ASSERT_EQ(rig.g.change_dynamics(go, ev), Err::None);
      }
    }
    ASSERT_TRUE(rig.g.idle()) << ctx;
    ASSERT_TRUE(rig.last.position == s.path.end()) << ctx;
  }
}

TEST(CoordChangeDynamics, ScopeModeAndErrors) {
  Rig rig(2);
  ASSERT_EQ(rig.submit(line(1, v3(100, 0), lim(10, 10, 10))), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(100, 100), lim(10, 10, 10))), Err::None);
  for (int i = 0; i < 1500; ++i) rig.step();
  DynamicsChange ch;
  ch.change_speed = true;
  ch.values.v = 5;
  Events ev;
  ch.master_driven = true;
  EXPECT_EQ(rig.g.change_dynamics(ch, ev), Err::MdscInvalidModeOrMasterChange);
  ch.master_driven = false;
  ch.values.v = -1;
  EXPECT_EQ(rig.g.change_dynamics(ch, ev), Err::ParameterOutOfRange);
  ch.values.v = 5;
  ASSERT_EQ(rig.g.change_dynamics(ch, ev), Err::None);  // Scope 0: the pending move keeps 10
  rig.run();
  double max1 = 0, max2 = 0;
  const long a2 = rig.find(2, EventKind::Activated);
  for (std::size_t i = 2100; i < rig.log.size(); ++i)  // after the 0.5 s ramp from 10 to 5
    (static_cast<long>(i) < a2 ? max1 : max2) = std::max(static_cast<long>(i) < a2 ? max1 : max2, rig.log[i].o.speed);
  EXPECT_NEAR(max1, 5.0, 1e-9);
  EXPECT_NEAR(max2, 10.0, 1e-9);
}

// MCCD lowers the decel jerk while the move brakes hard (for a lower
// speed): the braking cannot be ramped out before the speed is 0, so the
// move stops there without backing up, then goes on from rest to its target.
TEST(CoordChangeDynamics, LowerDecelJerkWhileBrakingNeverJumps) {
  Rig rig(2);
  ASSERT_EQ(rig.submit(line(1, v3(100, 0), lim(10, 100, 100, 1000, 1000))), Err::None);
  for (int i = 0; i < 2000; ++i) rig.step();
  DynamicsChange slower;
  slower.change_speed = true;
  slower.values.v = 2;
  Events ev;
  ASSERT_EQ(rig.g.change_dynamics(slower, ev), Err::None);
  for (int i = 0; i < 1000 && rig.last.acceleration[0] > -80; ++i) rig.step();  // braking, peak ~ -89
  ASSERT_LE(rig.last.acceleration[0], -80);
  DynamicsChange soft;
  soft.change_decel_jerk = true;
  soft.values.jd = 10;  // 0.01 s of ramp would need 10 s now
  ASSERT_EQ(rig.g.change_dynamics(soft, ev), Err::None);
  Output prev = rig.last;
  double min_v = 1e9;
  for (int i = 0; i < 1'000'000 && !rig.g.idle(); ++i) {
    const Output& o = rig.step();
    EXPECT_LE(std::fabs(o.position[0] - prev.position[0]), std::max(prev.speed, o.speed) * 0.001 + 1e-9);
    min_v = std::min(min_v, o.velocity[0]);
    prev = o;
  }
  EXPECT_GE(min_v, -1e-12);  // never backs up
  EXPECT_TRUE(rig.g.idle());
  EXPECT_TRUE(rig.last.position == v3(100, 0));
}

// A TT2 move paused (MCCD speed 0) inside its tolerance: PC is given, and
// it resumes and finishes exactly when a speed comes.
TEST(CoordChangeDynamics, PausedInsideTheToleranceResumes) {
  Rig rig(2, 0.001, 2.0);
  ASSERT_EQ(rig.submit(line(1, v3(10, 0), lim(10, 100, 100), Termination::CommandTolerance)), Err::None);
  while (norm(v3(10, 0) - rig.last.position) > 2.4) rig.step();  // halts within the tolerance (2)
  DynamicsChange ch;
  ch.change_speed = true;
  ch.values.v = 0;
  Events ev;
  ASSERT_EQ(rig.g.change_dynamics(ch, ev), Err::None);
  for (int i = 0; i < 2000; ++i) rig.step();
  EXPECT_GE(rig.find(1, EventKind::Completed), 0);  // within 2 of the end
  EXPECT_EQ(rig.last.speed, 0.0);
  EXPECT_LT(rig.last.position[0], 10.0);
  EXPECT_TRUE(rig.g.moving());
  ch.values.v = 10;
  ASSERT_EQ(rig.g.change_dynamics(ch, ev), Err::None);
  rig.run();
  EXPECT_TRUE(rig.last.position == v3(10, 0));
}

// Merge coordinated: the active and pending moves end (Cancelled), the new
// one starts at once from the present velocity; MergeSpeed Current keeps the
// present speed.
TEST(CoordMerge, CollinearMergeKeepsTheSpeed) {
  for (const bool current : {true, false}) {
    Rig rig(2);
    const Limits l = lim(10, 50, 50, 500, 500);
    ASSERT_EQ(rig.submit(line(1, v3(100, 0), l)), Err::None);
    ASSERT_EQ(rig.submit(line(2, v3(100, 100), l)), Err::None);
    for (int i = 0; i < 1000; ++i) rig.step();
    ASSERT_NEAR(rig.last.speed, 10.0, 1e-12);
    MoveRequest m = line(3, v3(200, 0), lim(20, 50, 50, 500, 500));
    m.merge = CoordMerge::CoordinatedMotion;
    m.merge_speed = current ? MergeSpeed::Current : MergeSpeed::Programmed;
    Events ev;
    ASSERT_EQ(rig.submit(m, &ev), Err::None);
    EXPECT_TRUE(has_event(ev, 1, EventKind::Cancelled));
    EXPECT_TRUE(has_event(ev, 2, EventKind::Cancelled));
    EXPECT_TRUE(has_event(ev, 3, EventKind::Activated));
    Output prev = rig.last;
    rig.run();
    double vmax = 0;
    for (std::size_t i = 1000; i < rig.log.size(); ++i) {
      const Output& o = rig.log[i].o;
      EXPECT_LE(norm(o.velocity - prev.velocity), 50 * 0.001 * (1 + 1e-9)) << i;  // no velocity step
      prev = o;
      vmax = std::max(vmax, o.speed);
    }
    EXPECT_NEAR(vmax, current ? 10.0 : 20.0, 1e-9);
    EXPECT_LT(rig.find(1, EventKind::Completed), 0);
    EXPECT_GE(rig.find(3, EventKind::Completed), 0);
    EXPECT_TRUE(rig.last.position == v3(200, 0));
  }
}

// A merge backwards along the line brakes and comes back (single-axis
// merge behaviour); a merge across keeps the along-component of the velocity.
TEST(CoordMerge, ReverseAndCrossMerges) {
  Rig rig(2);
  const Limits l = lim(10, 50, 50);
  ASSERT_EQ(rig.submit(line(1, v3(100, 0), l)), Err::None);
  for (int i = 0; i < 1000; ++i) rig.step();
  const double x = rig.last.position[0];
  MoveRequest back = line(2, v3(0, 0), l);
  back.merge = CoordMerge::AllMotion;
  ASSERT_EQ(rig.submit(back), Err::None);
  Output prev = rig.last;
  double xmax = x;
  rig.run();
  for (std::size_t i = 1000; i < rig.log.size(); ++i) {
    EXPECT_LE(norm(rig.log[i].o.velocity - prev.velocity), 50 * 0.001 * (1 + 1e-9));
    EXPECT_LE(std::fabs(rig.log[i].o.position[1]), 0.0);
    prev = rig.log[i].o;
    xmax = std::max(xmax, rig.log[i].o.position[0]);
  }
  EXPECT_NEAR(xmax - x, 1.0, 0.02);  // brakes over v^2 / 2d = 1 unit, then comes back
  EXPECT_TRUE(rig.last.position == v3(0, 0));
  // Across: the new move starts with the velocity component along it (0 here).
  ASSERT_EQ(rig.submit(line(3, v3(100, 0), l)), Err::None);
  for (int i = 0; i < 1000; ++i) rig.step();
  MoveRequest across = line(4, v3(rig.last.position[0], 50), l);
  across.merge = CoordMerge::CoordinatedMotion;
  Events ev;
  ASSERT_EQ(rig.submit(across, &ev), Err::None);
  const Output& o = rig.step();
  EXPECT_NEAR(o.velocity[0], 0.0, 1e-12);
  rig.run();
  EXPECT_NEAR(rig.last.position[1], 50.0, 0);
}

// EventDistance / CalculatedData: the abscissa from the move's start to
// where the distance to its completion point falls to each event distance.
TEST(CoordCalculatedData, TimeToEventDistances) {
  Rig rig(2, 0.001, 2.0);
  const Limits l = lim(10, 20, 20, 400, 400);
  ASSERT_EQ(rig.submit(line(1, v3(30, 40), l)), Err::None);  // L = 50
  const double ed[] = {0.0, 25.0, 50.0, 80.0, 10.0};
  double cd[5];
  ASSERT_TRUE(rig.g.calculated_data(ed, cd));
  Profile p;
  ASSERT_TRUE(plan_move(p, Kin{}, 50.0, l));
  int h = 0;
  EXPECT_EQ(cd[0], p.duration());
  EXPECT_NEAR(p.sample(cd[1], h).p, 25.0, 1e-9);
  EXPECT_EQ(cd[2], 0.0);
  EXPECT_EQ(cd[3], 0.0);
  EXPECT_NEAR(p.sample(cd[4], h).p, 40.0, 1e-9);
  double small[2];
  EXPECT_FALSE(rig.g.calculated_data(ed, std::span<double>(small, 2)));  // CalculatedData shorter
  // TT2: measured to the completion point (distance to go = CT).
  Rig r2(2, 0.001, 2.0);
  ASSERT_EQ(r2.submit(line(1, v3(30, 40), l, Termination::CommandTolerance)), Err::None);
  ASSERT_TRUE(r2.g.calculated_data(std::span<const double>(ed, 2), std::span<double>(cd, 2)));
  EXPECT_NEAR(p.sample(cd[0], h).p, 48.0, 1e-9);
  EXPECT_NEAR(p.sample(cd[1], h).p, 23.0, 1e-9);
}

// MCSD: everything ends at once, the position holds.
TEST(CoordClear, DropsEverythingAndHolds) {
  Rig rig(2);
  ASSERT_EQ(rig.submit(line(1, v3(100, 0), lim(10, 10, 10))), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(100, 100), lim(10, 10, 10))), Err::None);
  for (int i = 0; i < 500; ++i) rig.step();
  const Vec3 here = rig.last.position;
  Events ev;
  rig.g.clear(ev);
  EXPECT_TRUE(has_event(ev, 1, EventKind::Cancelled));
  EXPECT_TRUE(has_event(ev, 2, EventKind::Cancelled));
  rig.step();
  EXPECT_TRUE(rig.last.position == here);
  EXPECT_EQ(rig.last.speed, 0.0);
  EXPECT_TRUE(rig.g.idle());
}
