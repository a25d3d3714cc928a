// MCCP as a planner instruction (issue #5) and the EventDistance /
// CalculatedData operands of MAM: Logix bits and errors, the profile equal to
// the one cam::mccp() computes directly, a MATC running on the calculated
// profile, recalculation refused while in use, and CalculatedData against the
// sampled profile (time driven and master driven).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "motion/cam/cam_profile.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::Rig;

namespace {

struct MccpRig {
  Rig r;
  std::vector<cam::CamPoint> pts = std::vector<cam::CamPoint>(10);
  cam::CamProfile prof{8}, small{3};
  std::vector<double> ed = std::vector<double>(4, 0.0), cd = std::vector<double>(4, -1.0), cd2 = std::vector<double>(2, 0.0);
  MccpRig() {
    AxisConfig c;
    c.max_speed = 1000;
    r.add_axis("X", c);
    r.add_axis("M", c);
    EXPECT_EQ(r.exec("MSO(X, on);"), Err::None);
    EXPECT_EQ(r.exec("MSO(M, on2);"), Err::None);
    r.p->attach_cam_array(0, pts);
    r.p->attach_cam_profile(0, &prof);
    r.p->attach_cam_profile(1, &small);
    r.p->attach_real_array(0, ed);
    r.p->attach_real_array(1, cd);
    r.p->attach_real_array(2, cd2);
    r.sym.cams["pts"] = 0;
    r.sym.cams["unattached"] = 5;
    r.sym.cam_profiles["prof"] = 0;
    r.sym.cam_profiles["small"] = 1;
    r.sym.cam_profiles["nothere"] = 7;
    r.sym.real_arrays["ed"] = 0;
    r.sym.real_arrays["cd"] = 1;
    r.sym.real_arrays["cd2"] = 2;
    // 0 -> 0 cubic, 1 -> 2 cubic, 2 -> 3 linear, 3 -> 5 linear, 4 -> 5
    const double m[] = {0, 1, 2, 3, 4}, s[] = {0, 2, 3, 5, 5};
    const int t[] = {1, 1, 0, 0, 0};
    for (int i = 0; i < 5; ++i) pts[static_cast<std::size_t>(i)] = {m[i], s[i], t[i]};
    r.step();
  }
};

std::string mam_ed(const std::string& c, double pos, double speed, const std::string& ed, const std::string& cd,
                   const std::string& profile = "trapezoidal") {
  return "MAM(X," + c + ",1," + std::to_string(pos) + "," + std::to_string(speed) + ",unitspersec,400,unitspersec2,200,"
         "unitspersec2," + profile + ",50,50,%oftime,disabled,programmed,0,none," + ed + "," + cd + ");";
}

}  // namespace

TEST(MccpInstr, CalculatesTheSameProfileAsTheDirectCall) {
  MccpRig c;
  ASSERT_EQ(c.r.exec("MCCP(mc, pts[0], 5, 0.5, -0.25, prof[0]);"), Err::None);
  const ControlTag& t = c.r.tag("mc");
  EXPECT_TRUE(t.en());
  EXPECT_TRUE(t.dn());  // synchronous: done in the same scan
  EXPECT_FALSE(t.er());
  EXPECT_FALSE(t.ip());
  EXPECT_FALSE(t.pc());
  EXPECT_EQ(c.prof.status(), cam::profile_status::kCalculated);
  cam::CamProfile ref(8);
  ASSERT_TRUE(cam::mccp(cam::MccpRequest{c.pts, 0, 5, 0.5, -0.25}, ref).ok());
  ASSERT_EQ(c.prof.point_count(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    const auto& a = c.prof.elements()[i];
    const auto& b = ref.elements()[i];
    EXPECT_EQ(a.master, b.master);
    EXPECT_EQ(a.a0, b.a0);
    EXPECT_EQ(a.a1, b.a1);
    EXPECT_EQ(a.a2, b.a2);
    EXPECT_EQ(a.a3, b.a3);
  }
  EXPECT_EQ(c.prof.elements()[0].a1, 0.5);  // StartSlope used: the first segment is cubic
}

TEST(MccpInstr, StartIndexSelectsTheFirstPoint) {
  MccpRig c;
  ASSERT_EQ(c.r.exec("MCCP(mc, pts[2], 3, 0, 0, prof[0]);"), Err::None);
  EXPECT_EQ(c.prof.point_count(), 3u);
  EXPECT_EQ(c.prof.master_start(), 2.0);
  EXPECT_EQ(c.prof.slave_end(), 5.0);
  // no index = element [0] (seed 004: "If you do not include the index ...")
  ASSERT_EQ(c.r.exec("MCCP(mc, pts, 2, 0, 0, prof[0]);"), Err::None);
  EXPECT_EQ(c.prof.master_start(), 0.0);
}

TEST(MccpInstr, ErrorsCarryTheLogixCodes) {
  MccpRig c;
  struct Case {
    const char* call;
    Err err;
    int exerr;
  };
  const Case cases[] = {
      {"MCCP(e, pts[0], 1, 0, 0, prof[0]);", Err::IllegalCamLength, 0},        // Length < 2
      {"MCCP(e, pts[8], 3, 0, 0, prof[0]);", Err::IllegalCamLength, 0},        // past the CAM array
      {"MCCP(e, pts[0], 5, 0, 0, small[0]);", Err::IllegalCamProfileLength, 0},  // profile of 3 elements
      {"MCCP(e, pts[10], 2, 0, 0, prof[0]);", Err::ParameterOutOfRange, 1},    // Cam index outside the array
      {"MCCP(e, unattached[0], 2, 0, 0, prof[0]);", Err::ParameterOutOfRange, 1},
      {"MCCP(e, pts[0], 2, 0, 0, nothere[0]);", Err::ParameterOutOfRange, 5},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.call);
    const auto before = c.prof.status();
    EXPECT_EQ(c.r.exec(k.call), k.err);
    const ControlTag& t = c.r.tag("e");
    EXPECT_TRUE(t.er());
    EXPECT_FALSE(t.dn());
    EXPECT_EQ(t.err, static_cast<int>(k.err));
    EXPECT_EQ(t.exerr, k.exerr);
    EXPECT_EQ(c.prof.status(), before);  // nothing half-applied
  }
  // Length not an integer: ERR 13, EXERR 2 (table check on the numeric tag)
  c.r.sym.numeric_tags["len"] = 2.5;
  EXPECT_EQ(c.r.exec("MCCP(e, pts[0], len, 0, 0, prof[0]);"), Err::ParameterOutOfRange);
  EXPECT_EQ(c.r.tag("e").exerr, 2);
  // SegmentType 7: ERR 28; masters not increasing: ERR 29
  c.pts[1].segment_type = 7;
  EXPECT_EQ(c.r.exec("MCCP(e, pts[0], 5, 0, 0, prof[0]);"), Err::IllegalCamType);
  c.pts[1].segment_type = 0;
  c.pts[3].master = 1.5;
  EXPECT_EQ(c.r.exec("MCCP(e, pts[0], 5, 0, 0, prof[0]);"), Err::IllegalCamOrder);
  EXPECT_EQ(c.r.tag("e").err, 29);
  EXPECT_EQ(c.prof.status(), cam::profile_status::kNotCalculated);
}

TEST(MccpInstr, RecalculationIsRefusedWhileACamUsesTheProfileAndMatcRunsOnIt) {
  MccpRig c;
  ASSERT_EQ(c.r.exec("MCCP(mc, pts[0], 5, 0, 0, prof[0]);"), Err::None);
  ASSERT_EQ(c.r.exec("MATC(X, t, same, prof[0], 1, 1, once, immediate, 0, none, timedrivenmode);"), Err::None);
  EXPECT_EQ(c.prof.status(), 3);
  EXPECT_EQ(c.r.exec("MCCP(mc2, pts[0], 4, 0, 0, prof[0]);"), Err::CamProfileBeingUsed);
  EXPECT_EQ(c.r.tag("mc2").err, 31);
  const double x0 = c.r.axis("X").command_position;
  c.r.step(2000);  // cam time 0 .. 4 s (master values are seconds)
  EXPECT_NEAR(c.r.axis("X").command_position - x0, c.prof.evaluate(2.0).position, 1e-9);
  c.r.step(2100);
  EXPECT_TRUE(c.r.tag("t").pc());
  EXPECT_NEAR(c.r.axis("X").command_position - x0, 5.0, 1e-9);
  EXPECT_EQ(c.prof.status(), 2);  // released: recalculation allowed again
  EXPECT_EQ(c.r.exec("MCCP(mc2, pts[0], 4, 0, 0, prof[0]);"), Err::None);
  EXPECT_EQ(c.prof.point_count(), 4u);
}

TEST(MccpInstr, WritingStatusOneGivesBeingCalculated) {
  MccpRig c;
  c.prof.write_status(cam::profile_status::kCalculating);
  EXPECT_EQ(c.r.exec("MCCP(mc, pts[0], 5, 0, 0, prof[0]);"), Err::CamProfileBeingCalculated);
  EXPECT_EQ(c.r.tag("mc").err, 30);
}

TEST(MamEvents, CalculatedDataIsTheTimeToEachEventPoint) {
  MccpRig c;
  c.ed[0] = 0.0;   // the end of the move
  c.ed[1] = 10.0;  // 10 units before the end
  c.ed[2] = 50.0;
  c.ed[3] = 500.0;  // before the start: 0
  ASSERT_EQ(c.r.exec(mam_ed("m", 100, 50, "ed", "cd", "scurve")), Err::None);
  const ControlTag& t = c.r.tag("m");
  EXPECT_TRUE(t.dn());
  EXPECT_TRUE(t.get(flag::CalculatedDataAvailable));
  // Check against the executed move: the time at which the remaining distance
  // first reaches EventDistance[i] (cycle resolution: 1 ms).
  const double x0 = c.r.axis("X").command_position;
  std::array<double, 3> seen{-1, -1, -1};
  for (int k = 1; k < 10000 && !t.pc(); ++k) {
    c.r.step();
    const double remaining = 100.0 - (c.r.axis("X").command_position - x0);
    for (std::size_t i = 0; i < 3; ++i)
      if (seen[i] < 0 && remaining <= c.ed[i] + 1e-9) seen[i] = k * 0.001;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_GT(c.cd[i], 0.0);
    EXPECT_LE(c.cd[i], seen[i] + 1e-9);
    EXPECT_GT(c.cd[i], seen[i] - 0.001 - 1e-9);
  }
  EXPECT_EQ(c.cd[3], 0.0);
  EXPECT_LT(c.cd[2], c.cd[1]);
  EXPECT_LT(c.cd[1], c.cd[0]);
}

TEST(MamEvents, StartIndexAndNoneAndErrors) {
  MccpRig c;
  c.ed = {1, 2, 3, 4};
  // none (0) for either operand: no calculation, no CalculatedDataAvailable
  ASSERT_EQ(c.r.exec(mam_ed("m", 10, 50, "0", "cd")), Err::None);
  EXPECT_FALSE(c.r.tag("m").get(flag::CalculatedDataAvailable));
  EXPECT_EQ(c.cd[0], -1.0);
  // ed[2..3] into cd2[0..1]
  ASSERT_EQ(c.r.exec(mam_ed("m", 10, 50, "ed[2]", "cd2")), Err::None);
  EXPECT_TRUE(c.r.tag("m").get(flag::CalculatedDataAvailable));
  EXPECT_GT(c.cd2[0], c.cd2[1]);  // 3 units before the end is reached after 4 units before it
  // CalculatedData shorter than EventDistance: ERR 101
  EXPECT_EQ(c.r.exec(mam_ed("m2", 10, 50, "ed", "cd2")), Err::CalculatedDataArraySize);
  EXPECT_EQ(c.r.tag("m2").err, 101);
  // negative distance: ERR 13 on EventDistance (operand 18)
  c.ed[1] = -1;
  EXPECT_EQ(c.r.exec(mam_ed("m3", 10, 50, "ed", "cd")), Err::ParameterOutOfRange);
  EXPECT_EQ(c.r.tag("m3").exerr, 18);
  // index past the array: ERR 13 on the operand
  EXPECT_EQ(c.r.exec(mam_ed("m4", 10, 50, "ed[9]", "cd")), Err::ParameterOutOfRange);
  EXPECT_EQ(c.r.tag("m4").exerr, 18);
  c.ed[1] = 1;
  EXPECT_EQ(c.r.exec(mam_ed("m5", 10, 50, "ed", "cd[3]")), Err::CalculatedDataArraySize);
}

TEST(MamEvents, MasterDrivenReportsMasterDistance) {
  MccpRig c;
  ASSERT_EQ(c.r.exec("MDAC(X, M, link, move, command);"), Err::None);
  c.ed[2] = 0.0;
  c.ed[3] = 5.0;
  // 20 units at 0.5 units per master unit, accel/decel over 4 master units each
  ASSERT_EQ(c.r.exec("MAM(X,m,1,20,0.5,unitspermasterunit,0.125,unitspermasterunit2,0.125,unitspermasterunit2,"
                     "trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0,immediateforwardonly,ed[2],cd[2]);"),
            Err::None);
  EXPECT_TRUE(c.r.tag("m").get(flag::CalculatedDataAvailable));
  // trapezoid: accel 4 mu covers 1 unit, cruise 18 units = 36 mu, decel 4 mu: end at 44 mu
  EXPECT_NEAR(c.cd[2], 44.0, 1e-9);
  // 5 units before the end: 1 unit of decel (4 mu) + 4 units of cruise (8 mu) = 12 mu before the end
  EXPECT_NEAR(c.cd[3], 32.0, 1e-9);
}
