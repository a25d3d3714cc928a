#pragma once
// Test rig for position cams (MAPC) and master offset moves: a slave S and a
// master M (virtual by default, or another axis type / rotary), servo on,
// and four CAM_PROFILEs: lin (0..10 -> 0..20, slope 2), cub (a cubic spline
// over 0..10 -> 0..10), uncalc (never calculated), step (0..4 -> 0..4).
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "motion/cam/cam_profile.hpp"
#include "rig.hpp"

namespace canmotion::motion::test {

struct PcRig {
  Rig r;
  cam::CamProfile lin{4}, cub{8}, uncalc{4}, step{4};
  explicit PcRig(AxisType master_type = AxisType::Virtual, bool master_rotary = false) {
    AxisConfig c;
    c.max_speed = 1000;
    r.add_axis("S", c);
    AxisConfig m = c;
    m.type = master_type;
    m.rotary = master_rotary;
    m.unwind = 360;
    r.add_axis("M", m);
    EXPECT_EQ(r.exec("MSO(S, on);"), Err::None);
    if (master_type == AxisType::Virtual) {
      EXPECT_EQ(r.exec("MSO(M, on2);"), Err::None);
    }
    // lin: master 0..10 -> slave 0..20 (slope 2)
    const std::array<cam::CamPoint, 2> l{{{0.0, 0.0, 0}, {10.0, 20.0, 0}}};
    EXPECT_TRUE(cam::mccp(cam::MccpRequest{l, 0, 2, 0.0, 0.0}, lin).ok());
    // cub: a cubic spline over 0..10 -> 0..10
    const std::array<cam::CamPoint, 5> q{{{0.0, 0.0, 1}, {2.0, 1.0, 1}, {5.0, 6.0, 1}, {8.0, 7.0, 1}, {10.0, 10.0, 1}}};
    EXPECT_TRUE(cam::mccp(cam::MccpRequest{q, 0, 5, 0.0, 0.0}, cub).ok());
    // step: master 0..4 -> slave 0..4 (slope 1), for pending takeovers
    const std::array<cam::CamPoint, 2> s{{{0.0, 0.0, 0}, {4.0, 4.0, 0}}};
    EXPECT_TRUE(cam::mccp(cam::MccpRequest{s, 0, 2, 0.0, 0.0}, step).ok());
    r.p->attach_cam_profile(0, &lin);
    r.p->attach_cam_profile(1, &cub);
    r.p->attach_cam_profile(2, &uncalc);
    r.p->attach_cam_profile(3, &step);
    r.sym.cam_profiles["lin"] = 0;
    r.sym.cam_profiles["cub"] = 1;
    r.sym.cam_profiles["uncalc"] = 2;
    r.sym.cam_profiles["step"] = 3;
    r.step();
  }
  static std::string mapc(const std::string& ctl, const std::string& prof, double ss, double ms,
                          const std::string& mode, const std::string& sched, double mlp = 0, double clp = 0,
                          const std::string& ref = "command", const std::string& mdir = "bidirectional",
                          const std::string& dir = "same", const std::string& slave = "S",
                          const std::string& master = "M") {
    return "MAPC(" + slave + ", " + master + ", " + ctl + ", " + dir + ", " + prof + "[0], " + std::to_string(ss) +
           ", " + std::to_string(ms) + ", " + mode + ", " + sched + ", " + std::to_string(mlp) + ", " +
           std::to_string(clp) + ", " + ref + ", " + mdir + ");";
  }
  double m() { return r.axis("M").command_position; }
  double s() { return r.axis("S").command_position; }
  bool bit(unsigned b) { return r.axis("S").motion(b); }
  /// Move the virtual master to `target` at `speed` and wait for the end.
  void move_master(double target, double speed = 10) {
    ASSERT_EQ(r.exec(mam("M", "mm", 0, target, speed, 1e5, 1e5)), Err::None);
    r.step_until([&] { return r.tag("mm").pc(); });
  }
};

}  // namespace canmotion::motion::test
