// Time-driven MATC on the cam engineer's CamMotion (issue 5, seed 004): Once
// and Continuous, scaling, immediate on an active cam (ERR 23), pending
// takeover at the end of the pass without a position jump, pending without an
// active cam, uncalculated profile (ERR 32), MAS.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "motion/cam/cam_profile.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::Rig;

namespace {

struct CamRig {
  Rig r;
  cam::CamProfile fast{8}, slow{8}, uncalc{8};
  CamRig() {
    AxisConfig c;
    c.max_speed = 1000;
    r.add_axis("X", c);
    EXPECT_EQ(r.exec("MSO(X, on);"), Err::None);
    calc(fast, 10.0);
    calc(slow, 5.0);
    r.p->attach_cam_profile(0, &fast);
    r.p->attach_cam_profile(1, &slow);
    r.p->attach_cam_profile(2, &uncalc);
    r.sym.cam_profiles["fast"] = 0;
    r.sym.cam_profiles["slow"] = 1;
    r.sym.cam_profiles["uncalc"] = 2;
    r.step();
  }
  static void calc(cam::CamProfile& p, double rise) {  // linear: 0..1 s -> 0..rise
    const std::array<cam::CamPoint, 2> pts{{{0.0, 0.0, 0}, {1.0, rise, 0}}};
    ASSERT_TRUE(cam::mccp(cam::MccpRequest{pts, 0, 2, 0.0, 0.0}, p).ok());
  }
  static std::string matc(const std::string& ctl, const std::string& prof, double ds, double ts,
                          const std::string& mode, const std::string& sched, const std::string& dir = "same") {
    return "MATC(X, " + ctl + ", " + dir + ", " + prof + "[0], " + std::to_string(ds) + ", " + std::to_string(ts) +
           ", " + mode + ", " + sched + ", 0, none, timedrivenmode);";
  }
};

}  // namespace

TEST(Matc, OnceCompletesWithPcAndReleasesTheProfile) {
  CamRig c;
  ASSERT_EQ(c.r.exec(CamRig::matc("t", "fast", 1, 1, "once", "immediate")), Err::None);
  EXPECT_TRUE(c.r.tag("t").dn() && c.r.tag("t").ip());
  EXPECT_EQ(c.fast.status(), 3);  // in use by one cam
  c.r.step(500);
  EXPECT_TRUE(c.r.axis("X").motion(motion_status::TimeCamStatus));
  EXPECT_NEAR(c.r.axis("X").command_position, 5.0, 1e-9);
  EXPECT_NEAR(c.r.axis("X").command_velocity, 10.0, 1e-9);
  c.r.step(501);
  EXPECT_TRUE(c.r.tag("t").pc());
  EXPECT_FALSE(c.r.tag("t").ip());
  EXPECT_FALSE(c.r.axis("X").motion(motion_status::TimeCamStatus));
  EXPECT_NEAR(c.r.axis("X").command_position, 10.0, 1e-9);
  EXPECT_EQ(c.fast.status(), 2);
}

TEST(Matc, ContinuousRepeatsAndScalingScalesVelocity) {
  CamRig c;
  ASSERT_EQ(c.r.exec(CamRig::matc("t", "fast", 2, 4, "continuous", "immediate")), Err::None);
  c.r.step(10000);  // 10 s = 2.5 passes of 4 s
  EXPECT_NEAR(c.r.axis("X").command_position, 2 * 10 * 2.5, 1e-6);
  EXPECT_NEAR(c.r.axis("X").command_velocity, 10.0 * 2 / 4, 1e-9);  // distance x2, time x4
  EXPECT_TRUE(c.r.tag("t").ip());
  // immediate on an axis already time camming: Illegal Dynamic Change
  EXPECT_EQ(c.r.exec(CamRig::matc("t2", "slow", 1, 1, "once", "immediate")), Err::IllegalDynamicChange);
  EXPECT_EQ(c.r.tag("t2").err, 23);
  // opposite direction on a new axis state is checked by Reverse/Unchanged below
}

TEST(Matc, PendingTakesOverAtThePassEndWithoutAJump) {
  CamRig c;
  ASSERT_EQ(c.r.exec(CamRig::matc("a", "fast", 1, 1, "continuous", "immediate")), Err::None);
  c.r.step(300);
  ASSERT_EQ(c.r.exec(CamRig::matc("b", "slow", 1, 1, "once", "pending")), Err::None);
  EXPECT_TRUE(c.r.axis("X").motion(motion_status::TimeCamPendingStatus));
  EXPECT_TRUE(c.r.tag("b").ip());
  double prev = c.r.axis("X").command_position, worst = 0;
  for (int i = 0; i < 1200; ++i) {
    c.r.step();
    const double p = c.r.axis("X").command_position;
    worst = std::max(worst, std::fabs(p - prev));
    prev = p;
  }
  EXPECT_LE(worst, 10.0 * 0.001 + 1e-9);  // never faster than the faster cam: no jump
  EXPECT_FALSE(c.r.tag("a").ip());        // continuous cam superseded: IP cleared
  EXPECT_FALSE(c.r.tag("a").pc());
  EXPECT_FALSE(c.r.axis("X").motion(motion_status::TimeCamPendingStatus));
  c.r.step_until([&] { return c.r.tag("b").pc(); });
  EXPECT_NEAR(c.r.axis("X").command_position, 10.0 + 5.0, 1e-9);
  EXPECT_EQ(c.fast.status(), 2);
  EXPECT_EQ(c.slow.status(), 2);
}

TEST(Matc, PendingWithoutAnActiveCamWaitsForAnImmediateOne) {
  CamRig c;
  ASSERT_EQ(c.r.exec(CamRig::matc("p", "slow", 1, 1, "once", "pending")), Err::None);
  c.r.step(500);
  EXPECT_EQ(c.r.axis("X").command_position, 0.0);
  ASSERT_EQ(c.r.exec(CamRig::matc("i", "fast", 1, 1, "once", "immediate")), Err::None);
  c.r.step_until([&] { return c.r.tag("p").pc(); });
  EXPECT_TRUE(c.r.tag("i").pc());  // Once cam ended by the takeover: PC
  EXPECT_NEAR(c.r.axis("X").command_position, 15.0, 1e-9);
}

TEST(Matc, ErrorsAndDirection) {
  CamRig c;
  EXPECT_EQ(c.r.exec(CamRig::matc("e", "uncalc", 1, 1, "once", "immediate")), Err::CamProfileNotCalculated);
  EXPECT_EQ(c.r.tag("e").err, 32);
  EXPECT_EQ(c.r.exec(CamRig::matc("e", "fast", 1, 0, "once", "immediate")), Err::ParameterOutOfRange);
  EXPECT_EQ(c.r.tag("e").exerr, 5);  // the seed's example: EXERR 5 = Time Scaling
  // reverse on first use = opposite
  ASSERT_EQ(c.r.exec(CamRig::matc("r", "fast", 1, 1, "once", "immediate", "reverse")), Err::None);
  c.r.step_until([&] { return c.r.tag("r").pc(); });
  EXPECT_NEAR(c.r.axis("X").command_position, -10.0, 1e-9);
  // MAS timecam stops a running cam
  ASSERT_EQ(c.r.exec(CamRig::matc("t", "fast", 1, 1, "continuous", "immediate", "unchanged")), Err::None);
  c.r.step(200);
  EXPECT_LT(c.r.axis("X").command_velocity, 0);  // unchanged keeps opposite
  ASSERT_EQ(c.r.exec("MAS(X, s, timecam, yes, 1000, unitspersec2, no, 0, unitspersec3);"), Err::None);
  EXPECT_FALSE(c.r.tag("t").ip());
  c.r.step_until([&] { return c.r.tag("s").pc(); });
  EXPECT_EQ(c.r.axis("X").command_velocity, 0.0);
  EXPECT_EQ(c.fast.status(), 2);
}
