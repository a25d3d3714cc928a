// The planner allocates nothing once constructed: count heap allocations made
// while update()/execute() run a representative workload (requests parsed
// beforehand, as the command thread does).
#include <gtest/gtest.h>

// GCC cannot see that the replaced operator new below uses malloc.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "motion/cam/cam_profile.hpp"
#include "rig.hpp"

namespace {
std::atomic<long> g_allocs{0};
std::atomic<bool> g_count{false};
}  // namespace

void* operator new(std::size_t n) {
  if (g_count.load(std::memory_order_relaxed)) g_allocs.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::maj;

TEST(NoAlloc, UpdateAndExecuteAllocateNothing) {
  test::Rig r;
  AxisConfig c;
  c.max_speed = 100;
  r.add_axis("X", c);
  AxisConfig d = c;
  d.type = AxisType::CipDrive;
  d.position_error_tolerance = 1e9;
  r.add_axis("D", d);
  r.fb[1].drive = DriveState::Enabled;
  AxisConfig e = c;
  r.add_axis("C", e);
  r.add_axis("P", e);  // position cam slave of X (MAPC, master offset moves)
  r.add_axis("S", e);  // master-driven MATC slave of X
  r.add_axis("Q", e);  // master-driven MATC with a position lock
  cam::CamProfile prof(8);  // allocated at configuration time
  const std::array<cam::CamPoint, 3> pts{{{0.0, 0.0, 1}, {0.5, 2.0, 1}, {1.0, 3.0, 1}}};
  ASSERT_TRUE(cam::mccp(cam::MccpRequest{pts, 0, 3, 0.0, 0.0}, prof).ok());
  r.p->attach_cam_profile(0, &prof);
  r.sym.cam_profiles["prof"] = 0;
  // parse everything first (the non-RT side)
  const std::vector<Request> script = {
      r.req("MSO(X, a);"), r.req("MSO(D, b);"),
      r.req(mam("X", "m", 0, 50, 40, 300, 300, "scurve", 60, 60)),
      r.req(maj("D", "j", 0, 20, 100, 100, "scurve")),
      r.req("MCD(D,c,jog,yes,30,no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);"),
      r.req(mam("X", "m2", 1, 5, 40, 300, 300, "trapezoidal", 0, 0, "%oftime", "enabled")),
      r.req("MAS(D, s, all, no, 0, unitspersec2, no, 0, unitspersec3);"),
      r.req("MRP(X, p, relative, command, 3);"),
      r.req("MAG(D, X, gear, same, 0.5, 1, 3, command, fraction_slave_master_counts, enabled, 100, unitspersec2);"),
      r.req("MDAC(X, D, link, move, command);"),
      r.req("MAM(X,mdm,incremental,5,0.5,unitspermasterunit,1,unitspermasterunit2,1,unitspermasterunit2,scurve,10,10,"
            "unitspermasterunit3,disabled,programmed,0,immediateforwardonly,0,0);"),
      r.req("MSO(C, on3);"),
      r.req("MATC(C, tc, same, prof[0], 1, 1, continuous, immediate, 0, none, timedrivenmode);"),
      r.req("MATC(C, tc2, same, prof[0], 2, 1, once, pending, 0, none, timedrivenmode);"),
      r.req("MSO(P, on4);"),
      r.req(maj("X", "jx", 0, 5)),
      r.req("MAPC(P, X, pc, same, prof[0], 1, 1, continuous, immediate, 0, 0, command, bidirectional);"),
      r.req(mam("P", "mo", 6, 0.3, 1, 10, 10, "scurve", 60, 60)),
      r.req("MDAC(P, X, link2, masteroffsetmove, command);"),
      r.req("MAM(P,mo2,5,-0.2,0.5,unitspermasterunit,1,unitspermasterunit2,1,unitspermasterunit2,trapezoidal,0,0,"
            "unitspermasterunit3,disabled,programmed,0,immediateforwardonly,0,0);"),
      r.req("MAS(P, s2, masteroffsetmove, no, 0, unitspersec2, no, 0, unitspersec3);"),
      r.req("MAPC(P, X, pc2, opposite, prof[0], 2, 1, once, pending, 0, 0.5, command, forwardonly);"),
      r.req("MAS(P, s3, positioncam, no, 0, unitspersec2, no, 0, unitspersec3);"),
      r.req("MAPC(P, X, pc3, same, prof[0], 1, 1, persistent, bidirectional, 5, 0, command, reverseonly);"),
      // master-driven MATC with lock directions, pending blend, reversal, stop
      r.req("MSO(S, on6);"), r.req("MSO(Q, on7);"),
      r.req("MDAC(S, X, lt, timecam, command);"), r.req("MDAC(Q, X, lp, all, command);"),
      r.req("MATC(S, mt, same, prof[0], 1, 1, continuous, immediate, 0, immediatereverseonly, masterdrivenmode);"),
      r.req("MATC(Q, mp, opposite, prof[0], 1, 2, continuous, immediate, 45, positionreverseonly, masterdrivenmode);"),
      r.req("MATC(S, mt2, same, prof[0], 2, 1, once, pending, 0, immediateforwardonly, masterdrivenmode);"),
      r.req(maj("X", "jr", 1, 20, 1000, 1000)),
      r.req(maj("X", "jf", 0, 20, 1000, 1000)),
      r.req("MAJ(Q,mj,forward,1,unitspermasterunit,10,unitspermasterunit2,10,unitspermasterunit2,trapezoidal,0,0,"
            "unitspermasterunit3,disabled,programmed,0,immediateforwardonly);"),
      r.req("MAS(S, st, timecam, no, 0, unitspersec2, no, 0, unitspersec3);"),
      r.req("MGS(g, gs, faststop);"),
  };
  r.queue.reserve(32);
  r.step();
  g_count = true;
  bool s_locked = false, p_locked = false, blended = false;  // the master-driven paths really ran
  for (std::size_t i = 0; i < script.size(); ++i) {
    r.queue.push_back(script[i]);  // capacity reserved below, before counting
    for (int k = 0; k < 200; ++k) {
      r.step();
      s_locked = s_locked || r.axis("S").motion(motion_status::TimeCamLockStatus);
      p_locked = p_locked || r.axis("Q").motion(motion_status::TimeCamLockStatus);
      blended = blended || r.tag("mt2").ac();
    }
  }
  g_count = false;
  EXPECT_EQ(g_allocs.load(), 0);
  // the position cam part of the workload really ran (no request refused)
  for (const char* t : {"pc", "pc2", "mo", "link2", "mo2", "s2", "s3", "pc3"}) EXPECT_FALSE(r.tag(t).er()) << t << " ERR " << r.tag(t).err;
  EXPECT_TRUE(r.tag("pc2").pc() || r.tag("pc2").ip());
  EXPECT_TRUE(s_locked && p_locked && blended);
  for (const char* t : {"mt", "mp", "mt2", "mj"}) EXPECT_FALSE(r.tag(t).er()) << t << " ERR " << r.tag(t).err;
}

// The counter itself works (so the test above can fail).
TEST(NoAlloc, CounterSeesAnAllocation) {
  const long before = g_allocs.load();
  g_count = true;
  int* volatile p = new int(3);
  g_count = false;
  delete p;
  EXPECT_EQ(g_allocs.load(), before + 1);
}

// MCCP as an instruction and MAM EventDistance / CalculatedData (issue #5):
// the calculation writes into storage attached at configuration.
TEST(NoAlloc, MccpAndCalculatedDataAllocateNothing) {
  test::Rig r;
  AxisConfig c;
  c.max_speed = 100;
  r.add_axis("X", c);
  std::vector<cam::CamPoint> pts(200);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i] = {0.01 * static_cast<double>(i), 0.1 * static_cast<double>(i % 7), 1};
  cam::CamProfile prof(200);
  std::vector<double> ed{0.0, 1.0, 5.0}, cd(3);
  r.p->attach_cam_array(0, pts);
  r.p->attach_cam_profile(0, &prof);
  r.p->attach_real_array(0, ed);
  r.p->attach_real_array(1, cd);
  r.sym.cams["pts"] = 0;
  r.sym.cam_profiles["prof"] = 0;
  r.sym.real_arrays["ed"] = 0;
  r.sym.real_arrays["cd"] = 1;
  const std::vector<Request> script = {
      r.req("MSO(X, on);"),
      r.req("MCCP(mc, pts[0], 200, 0, 0, prof[0]);"),
      r.req("MCCP(mc2, pts[0], 1, 0, 0, prof[0]);"),  // ERR 26
      r.req("MAM(X,m,1,20,10,unitspersec,50,unitspersec2,50,unitspersec2,scurve,50,50,%oftime,disabled,programmed,0,"
            "none,ed,cd);"),
      r.req("MATC(X, t, same, prof[0], 1, 1, once, immediate, 0, none, timedrivenmode);"),
  };
  r.queue.reserve(16);
  r.step();
  const long before = g_allocs.load();  // the counter is shared with the other tests
  g_count = true;
  for (const Request& q : script) {
    r.queue.push_back(q);
    r.step(100);
  }
  g_count = false;
  EXPECT_EQ(g_allocs.load() - before, 0);
  EXPECT_TRUE(r.tag("mc").dn());
  EXPECT_EQ(r.tag("mc2").err, 26);
  EXPECT_TRUE(r.tag("m").get(flag::CalculatedDataAvailable));
  EXPECT_GT(cd[0], cd[1]);
}
