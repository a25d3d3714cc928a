// Coordinated lines through the path generator, every termination type with
// nothing queued: seeded property (CANMOTION_SEED, CANMOTION_PROP_COUNT).
#include <gtest/gtest.h>

#include <sstream>

#include "coord_rig.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;
using namespace canmotion::motion::coord::test;

// Exact end point; every cycle within 1e-9 L of the line and between its
// ends; vector speed, tangential accel/decel and jerk never above the
// programmed values (1e-9 relative); PC once, at the termination condition;
// speed 0 at the end whatever the termination type (nothing is queued).
TEST(CoordLines, LinesProperty) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed();
  const std::uint64_t count = canmotion::motion::test::prop_count(100000) / 20 + 1;
  Rng r(seed);
  for (std::uint64_t n = 0; n < count; ++n) {
    const int dim = 1 + r.pick(3);
    const Vec3 S = random_point(r, dim, 100);
    const Vec3 delta = r.logu(1e-3, 100) * random_unit(r, dim);
    const bool incremental = r.coin(0.3);
    const Vec3 E = S + delta;
    const double L = norm(E - S);
    const bool scurve = r.coin();
    const Limits l = limits_for(r, L, scurve);
    const double period = r.uni(2.5e-4, 2e-3);
    const auto tt = static_cast<Termination>(r.pick(7));
    const double ct = r.coin() ? r.logu(1e-4, 2) * L : 0.0;
    Rig rig(dim, period, ct, 1e-6);
    rig.record = false;
    std::ostringstream os;
    os << "seed=" << seed << " n=" << n << " dim=" << dim << " L=" << L << " tt=" << static_cast<int>(tt)
       << " ct=" << ct << " scurve=" << scurve << " period=" << period << " lim={" << l.v << "," << l.a << ","
       << l.d << "," << l.ja << "," << l.jd << "}";
    const std::string ctx = os.str();
    MoveRequest m = line(11, incremental ? delta : E, l, tt, incremental);
    m.command_tolerance = ct * r.uni(0.5, 1.5);
    rig.now.has_total = true;
    rig.now.total = S;
    Events ev;
    ASSERT_EQ(rig.submit(m, &ev), Err::None) << ctx;
    ASSERT_TRUE(has_event(ev, 11, EventKind::Activated)) << ctx;
    rig.now.has_total = false;
    const double ct_rule = std::min(tt == Termination::CommandTolerance ? ct : m.command_tolerance, L);
    const Vec3 u = (1.0 / L) * (E - S);
    const double J = std::max(l.ja, l.jd);
    double prev_a = 0.0;
    double prev_to_go = L;
    int completed = 0;
    for (int i = 0; i < 2'000'000 && !rig.g.idle(); ++i) {
      const Output& o = rig.step();
      const Vec3 d = o.position - S;
      const double along = dot(d, u);
      ASSERT_LE(norm(d - along * u), 1e-9 * L) << ctx << " cycle " << i;
      ASSERT_GE(along, -1e-9 * L) << ctx;
      ASSERT_LE(along, L * (1 + 1e-9)) << ctx;
      ASSERT_LE(o.speed, l.v * (1 + 1e-9)) << ctx;
      const double vt = dot(o.velocity, u), at = dot(o.acceleration, u);
      ASSERT_GE(vt, -1e-9 * l.v) << ctx;
      ASSERT_LE(at, l.a * (1 + 1e-9)) << ctx;
      ASSERT_GE(at, -l.d * (1 + 1e-9)) << ctx;
      if (scurve) {
        ASSERT_LE(std::fabs(at - prev_a), J * period * (1 + 1e-9)) << ctx << " jerk, cycle " << i;
      }
      prev_a = at;
      const double to_go = L - along;
      for (int j = 0; j < o.events.n; ++j) {
        const Event& e = o.events.e[static_cast<std::size_t>(j)];
        ASSERT_EQ(e.id, 11u) << ctx;
        ASSERT_EQ(e.kind, EventKind::Completed) << ctx;
        ++completed;
        if (tt == Termination::CommandTolerance || tt == Termination::CommandToleranceProgrammed) {
          ASSERT_LE(to_go, ct_rule * (1 + 1e-9) + 1e-12 * L) << ctx;  // PC at the tolerance ...
          ASSERT_GT(prev_to_go, ct_rule * (1 - 1e-9) - 1e-12 * L) << ctx;  // ... and not a cycle before
        } else if (tt != Termination::NoDecel) {  // TT3: PC where the deceleration starts
          ASSERT_TRUE(o.position == E) << ctx;
        }
      }
      prev_to_go = to_go;
    }
    ASSERT_TRUE(rig.g.idle()) << ctx;
    ASSERT_EQ(completed, 1) << ctx;
    ASSERT_TRUE(rig.last.position == E) << ctx << " end exact";
    ASSERT_EQ(rig.last.speed, 0.0) << ctx;
  }
}

// Member axis outputs: the offset divided by the conversion ratio; all
// members move in the same cycle and reach PC in the same cycle (one generator).
TEST(CoordLines, MemberAxisUnitsAndStatusBits) {
  Rig rig(3);
  rig.cfg.ratio = {2.0, 0.5, 4.0};
  rig.g.configure(rig.cfg);
  ASSERT_EQ(rig.submit(line(1, v3(3, 4, 12), lim(13, 100, 50))), Err::None);
  bool accel = false, decel = false;
  while (!rig.g.idle()) {
    const Output& o = rig.step();
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(o.axis_offset[static_cast<std::size_t>(i)], o.offset[i] / rig.cfg.ratio[static_cast<std::size_t>(i)]);
      EXPECT_EQ(o.axis_velocity[static_cast<std::size_t>(i)], o.velocity[i] / rig.cfg.ratio[static_cast<std::size_t>(i)]);
    }
    EXPECT_TRUE(bit(o.motion_status, coordinate_motion_status::MoveStatus) || rig.g.idle());
    accel |= bit(o.motion_status, coordinate_motion_status::AccelStatus);
    decel |= bit(o.motion_status, coordinate_motion_status::DecelStatus);
    EXPECT_FALSE(bit(o.motion_status, coordinate_motion_status::AccelStatus) &&
                 bit(o.motion_status, coordinate_motion_status::DecelStatus));
  }
  EXPECT_TRUE(accel);
  EXPECT_TRUE(decel);
  EXPECT_TRUE(rig.last.position == v3(3, 4, 12));
  EXPECT_EQ(rig.last.axis_offset[0], 1.5);
  EXPECT_EQ(rig.last.axis_offset[1], 8.0);
  EXPECT_EQ(rig.last.axis_offset[2], 3.0);
  EXPECT_FALSE(bit(rig.last.motion_status, coordinate_motion_status::MoveStatus));
  EXPECT_TRUE(bit(rig.last.motion_status, coordinate_motion_status::ActualPosToleranceStatus));
  // fold(): the slot's offset is handed to the axes; the next move continues from here.
  rig.g.fold();
  ASSERT_EQ(rig.submit(line(2, v3(1, 0, 0), lim(13, 100, 50), Termination::NoSettle, true)), Err::None);
  rig.run();
  EXPECT_TRUE(rig.last.position == v3(4, 4, 12));
  EXPECT_EQ(rig.last.offset[0], 1.0);
  EXPECT_EQ(rig.last.offset[1], 0.0);
}

// A zero-length line completes at once; speed 0 waits (paused) for MCCD.
TEST(CoordLines, ZeroLengthAndZeroSpeed) {
  Rig rig(2);
  ASSERT_EQ(rig.submit(line(1, v3(0, 0), lim(10, 100, 100))), Err::None);
  rig.step();
  EXPECT_EQ(rig.find(1, EventKind::Completed), 0);
  EXPECT_TRUE(rig.g.idle());
  ASSERT_EQ(rig.submit(line(2, v3(5, 0), lim(0, 100, 100))), Err::None);
  for (int i = 0; i < 100; ++i) rig.step();
  EXPECT_EQ(rig.g.active_id(), 2u);
  EXPECT_EQ(rig.last.speed, 0.0);
  DynamicsChange ch;
  ch.change_speed = true;
  ch.values.v = 10;
  Events ev;
  ASSERT_EQ(rig.g.change_dynamics(ch, ev), Err::None);
  rig.run();
  EXPECT_GE(rig.find(2, EventKind::Completed), 0);
  EXPECT_TRUE(rig.last.position == v3(5, 0));
}
