// Realtime properties of the path generator: no heap allocation in submit,
// stop, change_dynamics, step and calculated_data; bit-identical outputs for
// identical inputs (determinism).
#include <gtest/gtest.h>

#include <cstring>

#include "coord_rig.hpp"
#include "tests/support/allocation_counter.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;
using namespace canmotion::motion::coord::test;

namespace {

/// A representative workload: lines and arcs, blends of every type, a merge,
/// a re-plan, a stop, master-driven motion. Returns a digest of every output.
void workload(Rig& rig, std::vector<double>* digest) {
  const Limits l = lim(10, 50, 50, 500, 500);
  auto run = [&](int cycles) {
    for (int i = 0; i < cycles; ++i) {
      rig.now.master_position += 0.01;
      rig.now.master_velocity = 10;
      const Output& o = rig.step();
      if (digest) {
        for (int k = 0; k < 3; ++k) digest->push_back(o.position[k]);
        for (int k = 0; k < 3; ++k) digest->push_back(o.velocity[k]);
        digest->push_back(static_cast<double>(o.motion_status));
      }
    }
  };
  rig.now.has_master = true;
  rig.submit(line(1, v3(10, 0), l, Termination::CommandTolerance));
  rig.submit(arc(2, v3(20, 10), CircleType::Center, v3(10, 10), CircleDirection::CounterClockwise, l,
                 Termination::NoDecel));
  run(800);
  rig.submit(arc(3, v3(10, 20), CircleType::Via, v3(15, 25), CircleDirection::Clockwise, l,
                 Termination::FollowContourVelocityConstrained));
  run(300);
  rig.submit(line(4, v3(0, 20), l, Termination::ActualTolerance));
  run(600);
  MoveRequest m = line(5, v3(0, 0), l);
  m.merge = CoordMerge::CoordinatedMotion;
  m.merge_speed = MergeSpeed::Current;
  rig.submit(m);
  run(200);
  DynamicsChange ch;
  ch.change_speed = true;
  ch.values.v = 4;
  Events ev;
  rig.g.change_dynamics(ch, ev);
  const double ed[2] = {0, 1};
  double cd[2];
  rig.g.calculated_data(ed, cd);
  run(200);
  rig.g.stop(6, 100, 1000, ev);
  run(300);
  MoveRequest md = line(7, v3(5, 5), lim(0.5, 1, 1));
  md.master_driven = true;
  md.lock_direction = LockDirection::ImmediateForwardOnly;
  rig.submit(md);
  run(3000);
  rig.g.clear(ev);
  run(10);
}

}  // namespace

TEST(CoordRt, NoAllocationInTheCycleOrThePlanning) {
  Rig rig(2);
  rig.record = false;
  canmotion::test::reset_allocation_count();
  {
    canmotion::test::CountAllocationsInScope count;
    workload(rig, nullptr);
  }
  EXPECT_EQ(canmotion::test::counted_allocations(), 0u);
  EXPECT_GT(rig.cycle, 5000u);
}

TEST(CoordRt, DeterministicOutputs) {
  std::vector<double> a, b;
  Rig r1(2), r2(2);
  r1.record = r2.record = false;
  workload(r1, &a);
  workload(r2, &b);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
}
