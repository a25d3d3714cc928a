// Master-driven coordinated motion in the path generator (seed 001): the
// abscissa is master travel in the lock direction, the system holds on the
// path while the master reverses, lock position, mode errors, and the stop
// that runs time-driven.
#include <gtest/gtest.h>

#include "coord_rig.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;
using namespace canmotion::motion::coord::test;
namespace cms = canmotion::motion::coordinate_motion_status;

namespace {

MoveRequest md_line(std::uint32_t id, const Vec3& target, const Limits& l, LockDirection lock, double lock_pos = 0) {
  MoveRequest m = line(id, target, l);
  m.master_driven = true;
  m.lock_direction = lock;
  m.lock_position = lock_pos;
  return m;
}

struct MasterRig : Rig {
  double mp = 0;
  MasterRig() : Rig(2) {
    now.has_master = true;
    now.master_position = 0;
  }
  const Output& move_master(double dm) {
    mp += dm;
    now.master_position = mp;
    now.master_velocity = dm / cfg.period;
    return step();
  }
};

}  // namespace

TEST(CoordMasterDriven, PathFollowsMasterTravelAndHoldsWhenTheMasterReverses) {
  MasterRig rig;
  const Limits l = lim(0.5, 0.1, 0.1, 1.0, 1.0);  // per master unit
  ASSERT_EQ(rig.submit(md_line(1, v3(6, 8), l, LockDirection::ImmediateForwardOnly)), Err::None);
  Profile ref;
  ASSERT_TRUE(plan_move(ref, Kin{}, 10.0, l));
  int h = 0;
  bool tracking = false;
  double travel = 0;
  for (int i = 0; i < 30; ++i) {  // 15 master units forward
    const Output& o = rig.move_master(0.5);
    travel += 0.5;
    EXPECT_NEAR(norm(o.position), ref.sample(travel, h).p, 1e-9);
    EXPECT_NEAR(o.speed, ref.sample(travel, h).v * 500, 1e-6);
    EXPECT_TRUE(bit(o.motion_status, cms::CoordinateSystemLockStatus));
    tracking |= o.tracking_master;
  }
  EXPECT_TRUE(tracking);  // cruising at the programmed ratio
  const Vec3 held = rig.last.position;
  for (int i = 0; i < 20; ++i) {  // the master backs up: the system holds on the path
    const Output& o = rig.move_master(-0.3);
    EXPECT_TRUE(o.position == held);
    EXPECT_EQ(o.speed, 0.0);
    EXPECT_FALSE(bit(o.motion_status, cms::CoordinateSystemLockStatus));
    EXPECT_FALSE(o.tracking_master);
  }
  for (int i = 0; i < 20; ++i) {  // and resumes when it comes forward again
    const Output& o = rig.move_master(0.5);
    travel += 0.5;
    EXPECT_NEAR(norm(o.position), ref.sample(travel, h).p, 1e-9);
  }
  while (!rig.g.idle()) rig.move_master(0.5);
  EXPECT_TRUE(rig.last.position == v3(6, 8));
}

TEST(CoordMasterDriven, PositionLockWaitsForTheMasterToCrossIt) {
  MasterRig rig;
  const Limits l = lim(0.5, 0.1, 0.1);
  ASSERT_EQ(rig.submit(md_line(1, v3(10, 0), l, LockDirection::PositionForwardOnly, 20.0)), Err::None);
  for (int i = 0; i < 39; ++i) {
    const Output& o = rig.move_master(0.5);  // up to 19.5
    EXPECT_EQ(o.position[0], 0.0);
  }
  rig.move_master(0.7);  // crosses 20 by 0.2
  Profile ref;
  ASSERT_TRUE(plan_move(ref, Kin{}, 10.0, l));
  int h = 0;
  EXPECT_NEAR(rig.last.position[0], ref.sample(0.2, h).p, 1e-12);
  while (!rig.g.idle()) rig.move_master(0.5);
  EXPECT_TRUE(rig.last.position == v3(10, 0));
}

TEST(CoordMasterDriven, ModeErrors) {
  MasterRig rig;
  const Limits l = lim(0.5, 0.1, 0.1);
  // Lock direction None in master-driven mode, or a lock direction in time-driven mode: 95.
  EXPECT_EQ(rig.submit(md_line(1, v3(10, 0), l, LockDirection::None)), Err::MdscLockDirConflict);
  MoveRequest t = line(2, v3(10, 0), lim(10, 10, 10));
  t.lock_direction = LockDirection::ImmediateForwardOnly;
  EXPECT_EQ(rig.submit(t), Err::MdscLockDirConflict);
  // Follow Contour types are not master-driven blending types.
  MoveRequest fc = md_line(3, v3(10, 0), l, LockDirection::ImmediateForwardOnly);
  fc.termination = Termination::FollowContourVelocityConstrained;
  EXPECT_EQ(rig.submit(fc), Err::ParameterOutOfRange);
  // A master-driven start while the system moves and the master is idle: 97.
  ASSERT_EQ(rig.submit(line(4, v3(100, 0), lim(10, 10, 10))), Err::None);
  for (int i = 0; i < 500; ++i) rig.move_master(0.0);
  MoveRequest merge = md_line(5, v3(0, 50), l, LockDirection::ImmediateForwardOnly);
  merge.merge = CoordMerge::CoordinatedMotion;
  EXPECT_EQ(rig.submit(merge), Err::MdscIdleMasterSlaveMoving);
  // ... but queued behind the time-driven move it is accepted (the queue decides later).
  EXPECT_EQ(rig.submit(md_line(6, v3(0, 50), l, LockDirection::ImmediateForwardOnly)), Err::None);
  // MCCD in the other mode: 105.
  DynamicsChange ch;
  ch.change_speed = true;
  ch.values.v = 1;
  ch.master_driven = true;
  Events ev;
  EXPECT_EQ(rig.g.change_dynamics(ch, ev), Err::MdscInvalidModeOrMasterChange);
}

// Time-driven then master-driven in the queue: the mode follows each move;
// a master-driven move that becomes active from a time-driven one takes its
// own lock.
TEST(CoordMasterDriven, ModeChangesWithTheNextMove) {
  MasterRig rig;
  ASSERT_EQ(rig.submit(line(1, v3(1, 0), lim(10, 100, 100))), Err::None);
  ASSERT_EQ(rig.submit(md_line(2, v3(1, 1), lim(0.5, 1, 1), LockDirection::ImmediateForwardOnly)), Err::None);
  for (int i = 0; i < 2000; ++i) rig.move_master(0.0);  // the master stands still
  EXPECT_GE(rig.find(2, EventKind::Activated), 0);
  EXPECT_TRUE(rig.last.position == v3(1, 0));  // waits for master travel
  while (!rig.g.idle()) rig.move_master(0.25);
  EXPECT_TRUE(rig.last.position == v3(1, 1));
}

// MCS of master-driven motion runs time-driven at the given decel, on the path.
TEST(CoordMasterDriven, StopRunsTimeDriven) {
  MasterRig rig;
  ASSERT_EQ(rig.submit(md_line(1, v3(100, 0), lim(0.5, 0.1, 0.1), LockDirection::ImmediateForwardOnly)), Err::None);
  for (int i = 0; i < 40; ++i) rig.move_master(0.5);  // 20 master units: cruising at 250 u/s
  const double v0 = rig.last.speed;
  ASSERT_NEAR(v0, 250.0, 1e-9);
  Events ev;
  rig.g.stop(9, 5000.0, kInf, ev);
  int cycles = 0;
  while (rig.g.stopping()) {
    rig.move_master(0.0);  // the master stops too: the time-driven ramp still runs
    ++cycles;
    EXPECT_EQ(rig.last.position[1], 0.0);
  }
  EXPECT_NEAR(cycles, 50, 1);  // 250 / 5000 s
  EXPECT_EQ(rig.last.speed, 0.0);
  EXPECT_GE(rig.find(9, EventKind::StopDone), 0);
}
