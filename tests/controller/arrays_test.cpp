// Array tags of the `arrays:` section through the Controller (issue #5): CAM
// points written as tags from the non-RT side reach the RT thread in program
// order, MCCP calculates a CAM_PROFILE array from them at run time (the same
// numbers as the profile computed at configuration from the same points),
// REAL arrays carry MAM EventDistance / CalculatedData, and the cycle
// allocates nothing while all of it runs.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "rt/controller/host.hpp"
#include "rt/controller/script.hpp"
#include "tests/support/allocation_counter.hpp"

namespace canmotion::rt {
namespace {

// The same five points as the config cam "ref" below.
const std::vector<motion::cam::CamPoint> kPoints = {
    {0.0, 0.0, 1}, {0.25, 1.0, 1}, {0.5, 4.0, 0}, {0.75, 5.0, 1}, {1.0, 2.0, 0}};

struct ArrayRig {
  std::unique_ptr<Controller> ctl;
  std::unique_ptr<ControllerHost> host;
  std::int64_t now = 0;
  ArrayRig() {
    ControllerSpec spec;
    spec.period_ns = 1'000'000;
    for (const char* n : {"X", "Y"}) {
      AxisSpec a;
      a.name = n;
      a.config.type = motion::AxisType::Virtual;
      a.config.max_speed = 1000;
      a.config.max_accel = 10000;
      a.config.max_decel = 10000;
      spec.axes.push_back(a);
    }
    CamSpec ref;
    ref.name = "ref";
    ref.points = kPoints;
    ref.start_slope = 2.0;
    ref.end_slope = -1.0;
    spec.cams.push_back(ref);
    ArraySpec pts{"pts", ArraySpec::Type::kCam, 8, {}, {}};
    pts.cam_values = {{0.0, 0.0, 1}};  // the rest is written by the program
    spec.arrays.push_back(pts);
    spec.arrays.push_back({"prof", ArraySpec::Type::kCamProfile, 8, {}, {}});
    spec.arrays.push_back({"ed", ArraySpec::Type::kReal, 3, {}, {0.0, 5.0, 20.0}});
    spec.arrays.push_back({"cd", ArraySpec::Type::kReal, 3, {}, {}});
    ctl = std::make_unique<Controller>(spec);
    host = std::make_unique<ControllerHost>(*ctl);
  }
  void step(int n = 1) {
    for (int i = 0; i < n; ++i) {
      ctl->cycle(now);
      now += 1'000'000;
    }
  }
  double read(const std::string& tag) {
    std::string e;
    const auto v = host->read(tag, &e);
    EXPECT_TRUE(v) << tag << ": " << e;
    return v.value_or(-1e300);
  }
  void write(const std::string& tag, double v) {
    const auto e = host->write(tag, v);
    EXPECT_FALSE(e) << tag << ": " << *e;
  }
  void fill() {
    for (std::size_t i = 0; i < kPoints.size(); ++i) {
      const std::string p = "pts[" + std::to_string(i) + "].";
      write(p + "Master", kPoints[i].master);
      write(p + "Slave", kPoints[i].slave);
      write(p + "SegmentType", kPoints[i].segment_type);
    }
  }
  void exec(const std::string& call) {
    std::string c;
    const auto e = host->execute(call, &c);
    ASSERT_FALSE(e) << call << ": " << *e;
    for (int i = 0; i < 10 && !host->settled(); ++i) step();
    ASSERT_TRUE(host->settled());
  }
};

TEST(ArrayTags, CamPointsReadBackAndReachTheRtThreadInProgramOrder) {
  ArrayRig r;
  r.step();
  EXPECT_EQ(r.read("pts[0].SegmentType"), 1.0);  // initial value from the configuration
  r.fill();
  EXPECT_EQ(r.read("PTS[2].master"), 0.5);  // case-insensitive, read back at once
  EXPECT_EQ(r.read("pts[3].Slave"), 5.0);
  EXPECT_FALSE(r.host->settled());  // the writes are queued for the RT thread
  // MCCP queued behind the writes: it must see all of them.
  std::string c;
  ASSERT_FALSE(r.host->execute("MCCP(mc, pts[0], 5, 2.0, -1.0, prof[0])", &c));
  EXPECT_EQ(r.read("prof[0].Status"), 0.0);
  r.step(3);
  ASSERT_TRUE(r.host->settled());
  EXPECT_EQ(r.read("mc.DN"), 1.0);
  EXPECT_EQ(r.read("mc.ER"), 0.0);
  EXPECT_EQ(r.read("prof[0].Status"), 2.0);
}

TEST(ArrayTags, RunTimeProfileCamsLikeTheConfigProfile) {
  ArrayRig r;
  r.step();
  r.fill();
  r.exec("MCCP(mc, pts[0], 5, 2.0, -1.0, prof[0])");
  ASSERT_EQ(r.read("prof[0].Status"), 2.0);
  r.exec("MSO(X, on1)");
  r.exec("MSO(Y, on2)");
  std::string c;  // both cams start in the same cycle
  ASSERT_FALSE(r.host->execute("MATC(X, t1, same, prof[0], 3, 1, continuous, immediate, 0, none, timedrivenmode)", &c));
  r.exec("MATC(Y, t2, same, ref[0], 3, 1, continuous, immediate, 0, none, timedrivenmode)");
  EXPECT_EQ(r.read("prof[0].Status"), 3.0);  // in use by one cam
  const double x0 = r.read("X.CommandPosition"), y0 = r.read("Y.CommandPosition");
  for (int k = 0; k < 2500; ++k) {
    r.step();
    if (k % 50 == 0) {
      r.host->refresh();
      ASSERT_EQ(r.read("X.CommandPosition") - x0, r.read("Y.CommandPosition") - y0) << "cycle " << k;
      ASSERT_EQ(r.read("X.CommandVelocity"), r.read("Y.CommandVelocity")) << "cycle " << k;
    }
  }
  EXPECT_NE(r.read("X.CommandPosition"), x0);
  // recalculating a profile in use: ERR 31, the running cam keeps going
  r.exec("MCCP(mc, pts[0], 4, 0, 0, prof[0])");
  EXPECT_EQ(r.read("mc.ER"), 1.0);
  EXPECT_EQ(r.read("mc.ERR"), 31.0);
}

TEST(ArrayTags, EventDistanceAndCalculatedDataAsRealArrays) {
  ArrayRig r;
  r.step();
  EXPECT_EQ(r.read("ed[1]"), 5.0);
  r.write("ed[2]", 30.0);
  r.step();
  EXPECT_EQ(r.read("ed[2]"), 30.0);
  r.exec("MSO(X, on1)");
  r.exec("MAM(X, m, 1, 100, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 0, 0, "
         "unitspersec3, disabled, programmed, 0, none, ed, cd)");
  EXPECT_EQ(r.read("m.DN"), 1.0);
  // trapezoid: 0.1 s accel (2.5 units), 1.9 s cruise (95 units), 0.1 s decel (2.5 units): 2.1 s
  EXPECT_NEAR(r.read("cd[0]"), 2.1, 1e-9);
  EXPECT_NEAR(r.read("cd[1]"), 2.1 - 0.1 - 2.5 / 50, 1e-9);
  EXPECT_NEAR(r.read("cd[2]"), 2.1 - 0.1 - 27.5 / 50, 1e-9);
  // FLAGS.3 CalculatedDataAvailable: not a named member; read FLAGS through the planner tag
  Status s;
  ASSERT_TRUE(r.ctl->read_status(s));
  const auto id = r.ctl->find_control("m");
  ASSERT_TRUE(id);
  EXPECT_TRUE(s.controls[*id].get(motion::flag::CalculatedDataAvailable));
}

TEST(ArrayTags, RealElementsAreNumericOperands) {
  ArrayRig r;
  r.step();
  r.write("ed[2]", 12.5);
  r.step();
  r.exec("MSO(X, on1)");
  r.exec("MAM(X, m, 0, ed[2], 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 0, 0, "
         "unitspersec3, disabled, programmed, 0, none, 0, 0)");
  r.step(2000);
  EXPECT_EQ(r.read("m.PC"), 1.0);
  EXPECT_DOUBLE_EQ(r.read("X.CommandPosition"), 12.5);
  std::string c;
  const auto e = r.host->execute("MAM(X, m, 0, ed[3], 50, unitspersec, 500, unitspersec2, 500, unitspersec2, "
                                 "trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none, 0, 0)", &c);
  ASSERT_TRUE(e);
  EXPECT_NE(e->find("array 'ed' has 3 elements"), std::string::npos) << *e;
}

TEST(ArrayTags, ErrorsNameTheArrayAndWhatIsValid) {
  ArrayRig r;
  r.step();
  std::string e;
  EXPECT_FALSE(r.host->read("pts[8].Master", &e));
  EXPECT_NE(e.find("array 'pts' has 8 elements ([0] .. [7])"), std::string::npos) << e;
  EXPECT_FALSE(r.host->read("pts[1].Mastr", &e));
  EXPECT_NE(e.find("Master, Slave and SegmentType"), std::string::npos) << e;
  EXPECT_FALSE(r.host->read("ed[0].Value", &e));
  EXPECT_NE(e.find("REAL array"), std::string::npos) << e;
  const auto w = r.host->write("pts[1].SegmentType", 0.5);
  ASSERT_TRUE(w);
  EXPECT_NE(w->find("DINT"), std::string::npos) << *w;
  EXPECT_TRUE(r.host->check_tag("pts[9].Slave", true));
  EXPECT_FALSE(r.host->check_tag("pts[7].Slave", true));
  // An element out of range, or of an array that does not exist, is an error:
  // it never becomes a user numeric tag named "ed[99]".
  EXPECT_TRUE(r.host->check_tag("ed[99]", true));
  EXPECT_TRUE(r.host->check_tag("nosuch[2]", true));
  EXPECT_TRUE(r.host->write("ed[99]", 1.0));
  EXPECT_TRUE(r.host->write("nosuch[2]", 1.0));
  EXPECT_FALSE(r.host->read("ed[99]", &e));
  EXPECT_FALSE(r.host->check_tag("NewTag_2", true)) << "a plain name still creates a user tag";
  EXPECT_TRUE(r.host->write("prof[0].Status", 0));  // read-only (MCCP and the cams set it)
  // an illegal segment type written as a tag reaches MCCP: ERR 28
  r.fill();
  r.write("pts[1].SegmentType", 7);
  r.exec("MCCP(mc, pts[0], 5, 0, 0, prof[0])");
  EXPECT_EQ(r.read("mc.ERR"), 28.0);
  EXPECT_EQ(r.read("prof[0].Status"), 0.0);
}

TEST(ArrayTags, ScriptFillsPointsRunsMccpAndCams) {
  ArrayRig r;
  r.step();
  std::string text;
  for (std::size_t i = 0; i < kPoints.size(); ++i)
    text += "pts[" + std::to_string(i) + "].Master := " + script::format_value(kPoints[i].master) + "; pts[" +
            std::to_string(i) + "].Slave := " + script::format_value(kPoints[i].slave) + "; pts[" +
            std::to_string(i) + "].SegmentType := " + std::to_string(kPoints[i].segment_type) + ";\n";
  text +=
      "MCCP(mc, pts[0], 5, 2, -1, prof[0]);\nWAIT UNTIL mc.DN TIMEOUT 1;\nPRINT prof[0].Status;\n"
      "MSO(X, on);\nMATC(X, t, same, prof[0], 1, 1, once, immediate, 0, none, timedrivenmode);\n"
      "WAIT UNTIL t.PC TIMEOUT 2;\nPRINT X.CommandPosition, prof[0].Status;\n";
  script::Script sc = script::load(text, "fill.script", *r.host);
  std::vector<std::string> out;
  script::Runner run(sc, *r.host, [&](const std::string& l) { out.push_back(l); });
  for (int k = 0; k < 5000 && run.step(r.ctl->period_s() * static_cast<double>(r.ctl->cycles())) ==
                                  script::Runner::Status::kRunning;
       ++k)
    r.step();
  ASSERT_EQ(run.status(), script::Runner::Status::kDone) << run.error();
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NE(out[0].find("prof[0].Status=2"), std::string::npos) << out[0];
  // a Once cam ends at the profile's last slave value (2) and releases the profile
  EXPECT_NE(out[1].find("X.CommandPosition=2 prof[0].Status=2"), std::string::npos) << out[1];
}

TEST(ArrayTags, TheCycleAllocatesNothingForWritesMccpAndEvents) {
  ArrayRig r;
  r.step();
  r.exec("MSO(X, on1)");
  r.exec("MSO(Y, on2)");
  // Everything parsed and queued on the non-RT side; the cycles are counted.
  r.fill();
  std::string c;
  ASSERT_FALSE(r.host->execute("MCCP(mc, pts[0], 5, 2.0, -1.0, prof[0])", &c));
  ASSERT_FALSE(r.host->execute("MATC(X, t1, same, prof[0], 1, 1, once, immediate, 0, none, timedrivenmode)", &c));
  ASSERT_FALSE(r.host->execute("MAM(Y, m, 1, 100, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, "
                               "scurve, 50, 50, %oftime, disabled, programmed, 0, none, ed, cd)", &c));
  r.write("ed[0]", 1.0);
  test::reset_allocation_count();
  {
    test::CountAllocationsInScope count;
    r.step(1500);
  }
  EXPECT_EQ(test::counted_allocations(), 0u);
  ASSERT_TRUE(r.host->settled());
  EXPECT_EQ(r.read("mc.DN"), 1.0);
  EXPECT_EQ(r.read("t1.PC"), 1.0);
  EXPECT_EQ(r.read("m.DN"), 1.0);
  EXPECT_GT(r.read("cd[0]"), 2.0);  // CalculatedData written on the RT thread
}

}  // namespace
}  // namespace canmotion::rt
