// The queue (one active, one pending) and the termination types between
// two moves: seeded properties (CANMOTION_SEED, CANMOTION_PROP_COUNT).
#include <gtest/gtest.h>

#include <sstream>

#include "coord_rig.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;
using namespace canmotion::motion::coord::test;
namespace cms = canmotion::motion::coordinate_motion_status;

TEST(CoordQueue, SecondWaitsThirdIsRefused) {
  Rig rig(2);
  Events ev;
  ASSERT_EQ(rig.submit(line(1, v3(10, 0), lim(10, 100, 100)), &ev), Err::None);
  EXPECT_TRUE(has_event(ev, 1, EventKind::Activated));
  ASSERT_EQ(rig.submit(line(2, v3(10, 10), lim(10, 100, 100)), &ev), Err::None);
  EXPECT_EQ(ev.n, 0);  // queued: IP without AC
  EXPECT_EQ(rig.g.active_id(), 1u);
  EXPECT_EQ(rig.g.pending_id(), 2u);
  const Output& o = rig.step();
  EXPECT_TRUE(bit(o.motion_status, cms::MovePendingStatus));
  EXPECT_TRUE(bit(o.motion_status, cms::MovePendingQueueFullStatus));
  EXPECT_EQ(rig.submit(line(3, v3(0, 0), lim(10, 100, 100)), &ev), Err::CoordinateSystemQueueFull);
  EXPECT_EQ(ev.n, 0);
  EXPECT_EQ(rig.g.pending_id(), 2u);
  rig.run();
  const long c1 = rig.find(1, EventKind::Completed), a2 = rig.find(2, EventKind::Activated);
  ASSERT_GE(c1, 0);
  EXPECT_EQ(c1, a2);  // the pending move starts in the cycle the active one completes
  EXPECT_FALSE(bit(rig.log[static_cast<std::size_t>(a2)].o.motion_status, cms::MovePendingStatus));
  EXPECT_TRUE(rig.last.position == v3(10, 10));
}

// TT0: PC waits until the vector following error is within the actual
// tolerance; the next move waits for that PC.
TEST(CoordTermination, ActualToleranceWaitsForTheFollowingError) {
  Rig rig(2, 0.001, 0.0, 0.01);
  rig.now.following_error = 0.5;
  ASSERT_EQ(rig.submit(line(1, v3(1, 0), lim(10, 100, 100), Termination::ActualTolerance)), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(1, 1), lim(10, 100, 100))), Err::None);
  for (int i = 0; i < 2000; ++i) rig.step();  // the profile ended long ago
  EXPECT_LT(rig.find(1, EventKind::Completed), 0);
  EXPECT_EQ(rig.g.pending_id(), 2u);
  EXPECT_TRUE(rig.last.position == v3(1, 0));
  EXPECT_FALSE(bit(rig.last.motion_status, cms::ActualPosToleranceStatus));
  rig.now.following_error = 0.009;
  rig.step();
  EXPECT_EQ(rig.find(1, EventKind::Completed), static_cast<long>(rig.log.size()) - 1);
  EXPECT_EQ(rig.find(2, EventKind::Activated), static_cast<long>(rig.log.size()) - 1);
}

// TT1: the move stops on its target (the corner is exact) before the next starts.
TEST(CoordTermination, NoSettleStopsAtTheTarget) {
  Rig rig(2);
  const Limits l = lim(10, 100, 100, 1e4, 1e4);
  ASSERT_EQ(rig.submit(line(1, v3(1, 0), l, Termination::NoSettle)), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(1, 1), l)), Err::None);
  rig.run();
  const long c1 = rig.find(1, EventKind::Completed);
  ASSERT_GT(c1, 0);
  for (const Sample& s : rig.log) {
    const double dev = std::min(dist_to_segment(s.o.position, v3(0, 0), v3(1, 0)),
                                dist_to_segment(s.o.position, v3(1, 0), v3(1, 1)));
    EXPECT_LE(dev, 1e-12);
  }
  // One cycle before PC the move was still on its way in; at PC speed is a
  // fraction of a cycle of acceleration from rest.
  EXPECT_LE(rig.log[static_cast<std::size_t>(c1)].o.speed, l.a * rig.cfg.period);
}

namespace {

struct Corner {
  Vec3 s, p1, p2;
  double la = 0, lb = 0;
};

Corner random_corner(Rng& r, int dim, double max_angle_deg) {
  Corner c;
  c.s = random_point(r, dim, 50);
  const Vec3 u = random_unit(r, dim);
  Vec3 w = u;
  if (dim > 1) {  // a direction at a random angle in [0, max] from u
    const double ang = r.uni(0, max_angle_deg) * std::numbers::pi / 180;
    Vec3 t = random_unit(r, dim);
    t = t - dot(t, u) * u;
    if (norm(t) < 1e-3) t = dim == 2 ? v3(-u[1], u[0]) : cross(u, v3(0, 0, 1));
    t = (1.0 / norm(t)) * t;
    w = std::cos(ang) * u + std::sin(ang) * t;
  }
  c.la = r.logu(0.01, 50);
  c.lb = r.logu(0.01, 50);
  c.p1 = c.s + c.la * u;
  c.p2 = c.p1 + c.lb * w;
  return c;
}

}  // namespace

// TT2 / TT6: the next move starts where the distance to go is within the
// command tolerance (min(CT, L) for the first move): the path never leaves
// the corner by more than that, the speed is never 0 at the corner and never
// above the larger programmed speed; PC at the tolerance; exact end.
TEST(CoordTermination, CommandToleranceCornerProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 10;
  const std::uint64_t count = canmotion::motion::test::prop_count(100000) / 50 + 1;
  Rng r(seed);
  int mirrored = 0;
  for (std::uint64_t n = 0; n < count; ++n) {
    const int dim = 2 + r.pick(2);
    const Corner c = random_corner(r, dim, 170);
    const bool scurve = r.coin();
    const Limits la = limits_for(r, c.la, scurve);
    Limits lb = limits_for(r, c.lb, scurve);
    if (r.coin(0.3) && c.lb < 10 * c.la) lb = la;  // equal limits (k = 1), on moves of similar length
    const bool programmed = r.coin();
    const double ct = r.logu(1e-3, 2) * std::min(c.la, c.lb);
    Rig rig(dim, r.uni(2.5e-4, 2e-3), programmed ? 0.0 : ct);
    rig.record = false;
    std::ostringstream os;
    os << "seed=" << seed << " n=" << n << " dim=" << dim << " la=" << c.la << " lb=" << c.lb << " ct=" << ct
       << " tt=" << (programmed ? 6 : 2) << " scurve=" << scurve;
    const std::string ctx = os.str();
    MoveRequest a = line(1, c.p1, la, programmed ? Termination::CommandToleranceProgrammed : Termination::CommandTolerance);
    a.command_tolerance = ct;
    rig.now.has_total = true;
    rig.now.total = c.s;
    ASSERT_EQ(rig.submit(a), Err::None) << ctx;
    rig.now.has_total = false;
    ASSERT_EQ(rig.submit(line(2, c.p2, lb)), Err::None) << ctx;
    const double ct_rule = std::min(ct, c.la);  // first move of the sequence: 100 % of L
    const double vmax = std::max(la.v, lb.v);
    bool started = false, completed_a = false, transition = false;
    double prev_to_go = c.la;
    for (int i = 0; i < 4'000'000 && !rig.g.idle(); ++i) {
      const Output& o = rig.step();
      const double dev = std::min(dist_to_segment(o.position, c.s, c.p1), dist_to_segment(o.position, c.p1, c.p2));
      ASSERT_LE(dev, ct_rule * (1 + 1e-9) + 1e-12 * 100) << ctx << " cycle " << i;
      ASSERT_LE(o.speed, vmax * (1 + 1e-9)) << ctx << " cycle " << i;
      started |= o.speed > 0;
      const bool in_transition = bit(o.motion_status, cms::MoveTransitionStatus);
      transition |= in_transition;
      if (in_transition) {
        ASSERT_GT(o.speed, 0.0) << ctx << " speed 0 at the corner, cycle " << i;
      }
      if (has_event(o.events, 1, EventKind::Completed)) {
        completed_a = true;
        ASSERT_TRUE(has_event(o.events, 2, EventKind::Activated)) << ctx;
        // The overlap runs as if it started exactly where the distance to go
        // met the tolerance inside this cycle: the head has moved a little.
        const double to_go = norm(c.p1 - o.position);
        ASSERT_LE(to_go, ct_rule * (1 + 1e-9) + vmax * rig.cfg.period) << ctx;
        ASSERT_GT(prev_to_go, ct_rule * (1 - 1e-9) - 1e-12 * 100) << ctx;
      }
      if (!completed_a) prev_to_go = norm(c.p1 - o.position);
    }
    ASSERT_TRUE(completed_a) << ctx;
    ASSERT_TRUE(rig.g.idle()) << ctx;
    ASSERT_TRUE(rig.last.position == c.p2) << ctx << " end exact";
    ASSERT_EQ(rig.last.speed, 0.0) << ctx;
    mirrored += transition;
  }
  EXPECT_GT(mirrored, static_cast<int>(count / 4));  // most of them really overlapped
}

// TT3: the next move starts at the point where the first would start to
// decelerate (PC there); with equal limits on a straight continuation the
// speed stays at the programmed speed through the blend (no dip).
TEST(CoordTermination, NoDecelBlendsAtTheDecelPoint) {
  for (const bool scurve : {false, true}) {
    const Limits l = scurve ? lim(10, 50, 50, 500, 500) : lim(10, 50, 50);
    const double period = 0.001;
    Rig rig(2, period);
    ASSERT_EQ(rig.submit(line(1, v3(20, 0), l, Termination::NoDecel)), Err::None);
    ASSERT_EQ(rig.submit(line(2, v3(40, 0), l)), Err::None);
    rig.run();
    // Where move 1 alone would start to decelerate (after the cruise), and the
    // cycle whose abscissa (accumulated as the generator does) first reaches it.
    Profile p;
    ASSERT_TRUE(plan_move(p, Kin{}, 20.0, l));
    double td = p.duration();
    for (int i = 0; i < p.size(); ++i)
      if (p.segment(i).a < 0 || (p.segment(i).a == 0 && p.segment(i).j < 0)) {
        td = p.segment(i).t0;
        break;
      }
    std::uint64_t expect_cycle = 0;
    for (double u = 0; u < td; u += period) ++expect_cycle;
    const long c1 = rig.find(1, EventKind::Completed);
    ASSERT_GE(c1, 0);
    EXPECT_EQ(rig.log[static_cast<std::size_t>(c1)].cycle, expect_cycle) << "scurve=" << scurve;
    // Cruise speed from the end of the first ramp to the start of the last one.
    const double ramp = scurve ? 10.0 / 50 + 50.0 / 500 : 10.0 / 50;
    for (const Sample& s : rig.log) {
      const double t = static_cast<double>(s.cycle) * period;
      if (t > ramp + period && t < 4.0 - ramp - 2 * period) {
        EXPECT_NEAR(s.o.speed, 10.0, 1e-9) << "t=" << t;
      }
    }
    EXPECT_TRUE(rig.last.position == v3(40, 0));
  }
}

// TT3 at a corner: overlapped, the speed never 0 and never above the programmed speed.
TEST(CoordTermination, NoDecelCorner) {
  Rig rig(2);
  const Limits l = lim(10, 50, 50, 500, 500);
  ASSERT_EQ(rig.submit(line(1, v3(20, 0), l, Termination::NoDecel)), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(20, 20), l)), Err::None);
  rig.run();
  const long c1 = rig.find(1, EventKind::Completed);
  ASSERT_GT(c1, 0);
  bool overlapped = false;
  for (std::size_t i = 0; i < rig.log.size(); ++i) {
    const Output& o = rig.log[i].o;
    if (bit(o.motion_status, cms::MoveTransitionStatus)) {
      overlapped = true;
      EXPECT_GT(o.speed, 0.0) << i;
    }
    EXPECT_LE(o.speed, 10 * (1 + 1e-9)) << i;
  }
  EXPECT_TRUE(overlapped);
  EXPECT_TRUE(rig.last.position == v3(20, 20));
}

// TT4: a line into a tangent arc at the programmed speed: no dip at the junction.
TEST(CoordTermination, FollowContourLineToTangentArcWithoutDip) {
  for (const bool scurve : {false, true}) {
    const Limits l = scurve ? lim(10, 50, 50, 500, 500) : lim(10, 50, 50);
    Rig rig(2);
    ASSERT_EQ(rig.submit(line(1, v3(20, 0), l, Termination::FollowContourVelocityConstrained)), Err::None);
    // Quarter circle of radius 10 around (20, 10), counter-clockwise: tangent +x at the start.
    ASSERT_EQ(rig.submit(arc(2, v3(30, 10), CircleType::Center, v3(20, 10), CircleDirection::CounterClockwise, l)),
              Err::None);
    rig.run();
    const long c1 = rig.find(1, EventKind::Completed);
    ASSERT_GT(c1, 0);
    EXPECT_EQ(rig.find(2, EventKind::Activated), c1);
    const double t_up = scurve ? 0.3 : 0.2;  // the ramp to speed
    const double L = 20 + 10 * std::numbers::pi / 2;
    for (const Sample& s : rig.log) {
      const double t = static_cast<double>(s.cycle) * 0.001;
      if (t > t_up + 0.002 && t < L / 10 - 0.002) {
        EXPECT_NEAR(s.o.speed, 10.0, 1e-9) << "t=" << t << " scurve=" << scurve;
      }
    }
    EXPECT_TRUE(rig.last.position == v3(30, 10));
  }
}

// TT4, velocity constrained: the junction speed lets the next (short) move
// stop by its end with its own decel; TT5 does not look ahead, so the short
// move stops harder, but exactly on its end and never past it.
TEST(CoordTermination, FollowContourLookAhead) {
  const Limits la = lim(10, 50, 50);
  const Limits lb = lim(10, 50, 20);
  for (const auto tt : {Termination::FollowContourVelocityConstrained, Termination::FollowContourVelocityUnconstrained}) {
    Rig rig(2);
    ASSERT_EQ(rig.submit(line(1, v3(20, 0), la, tt)), Err::None);
    ASSERT_EQ(rig.submit(line(2, v3(21, 0), lb)), Err::None);
    rig.run();
    const long c1 = rig.find(1, EventKind::Completed);
    ASSERT_GT(c1, 0);
    const double vj = rig.log[static_cast<std::size_t>(c1) - 1].o.speed;
    const double vstop = std::sqrt(2 * lb.d * 1.0);  // 6.32: stop in 1 unit at 20 u/s^2
    double max_decel = 0, max_x = 0;
    for (std::size_t i = static_cast<std::size_t>(c1); i < rig.log.size(); ++i) {
      max_decel = std::max(max_decel, -rig.log[i].o.acceleration[0]);
      max_x = std::max(max_x, rig.log[i].o.position[0]);
    }
    if (tt == Termination::FollowContourVelocityConstrained) {
      EXPECT_LE(vj, vstop + la.d * 0.001) << "junction speed";
      EXPECT_GT(vj, vstop - la.d * 0.002);
      EXPECT_LE(max_decel, lb.d * (1 + 1e-9));
    } else {
      EXPECT_NEAR(vj, 10.0, 1e-9);
      EXPECT_GT(max_decel, lb.d);
    }
    EXPECT_LE(max_x, 21.0);
    EXPECT_TRUE(rig.last.position == v3(21, 0));
  }
}

// TT4 at a real corner: the junction speed is cut so that the direction
// change costs at most one cycle of acceleration.
TEST(CoordTermination, FollowContourCornerSpeed) {
  const Limits l = lim(10, 50, 50);
  Rig rig(2);
  ASSERT_EQ(rig.submit(line(1, v3(20, 0), l, Termination::FollowContourVelocityConstrained)), Err::None);
  ASSERT_EQ(rig.submit(line(2, v3(20, 20), l)), Err::None);
  rig.run();
  const long c1 = rig.find(1, EventKind::Completed);
  ASSERT_GT(c1, 0);
  const double vj = rig.log[static_cast<std::size_t>(c1) - 1].o.speed;
  const double bound = 50 * 0.001 / (2 * std::sin(std::numbers::pi / 4));
  EXPECT_LE(vj, bound + 50 * 0.001);
  EXPECT_GT(vj, 0.0);
  EXPECT_TRUE(rig.last.position == v3(20, 20));
}

// Rockwell's advice to end a sequence with TT0/TT1 aside, every type stops
// exactly on the target when nothing is queued (also covered by LinesProperty).
TEST(CoordTermination, NothingQueuedStopsExactlyForEveryType) {
  for (int tt = 0; tt <= 6; ++tt) {
    Rig rig(2, 0.001, 0.5);
    MoveRequest m = arc(1, v3(10, 0), CircleType::Radius, v3(5), CircleDirection::Clockwise, lim(10, 50, 50, 500, 500),
                        static_cast<Termination>(tt));
    m.command_tolerance = 0.5;
    ASSERT_EQ(rig.submit(m), Err::None);
    rig.run();
    EXPECT_GE(rig.find(1, EventKind::Completed), 0) << tt;
    EXPECT_TRUE(rig.last.position == v3(10, 0)) << tt;
    EXPECT_EQ(rig.last.speed, 0.0) << tt;
  }
}

// A move submitted while the previous (TT2) one finishes after its PC blends
// in at once; a move in the other mode waits for the finish instead.
TEST(CoordTermination, LateSubmitBlendsIntoTheFinishingMove) {
  Rig rig(2, 0.001, 1.0);
  ASSERT_EQ(rig.submit(line(1, v3(10, 0), lim(10, 50, 50), Termination::CommandTolerance)), Err::None);
  while (rig.find(1, EventKind::Completed) < 0) rig.step();
  rig.step();
  EXPECT_TRUE(bit(rig.last.motion_status, cms::MoveStatus));
  EXPECT_EQ(rig.g.active_id(), 0u);
  Events ev;
  ASSERT_EQ(rig.submit(line(2, v3(10, 10), lim(10, 50, 50)), &ev), Err::None);
  EXPECT_TRUE(has_event(ev, 2, EventKind::Activated));
  const Output& o = rig.step();
  EXPECT_TRUE(bit(o.motion_status, cms::MoveTransitionStatus));
  rig.run();
  EXPECT_TRUE(rig.last.position == v3(10, 10));
}
