// Byte-identity of the coordinated instructions through the planner (issue 27
// item 6, typed coordinated operands and the one rate decoder): seeded random
// sequences of MCLM, MCCM, MCS, MCSD, MCCD and MDCC on a 2-D and a 3-D
// coordinate system (valid and invalid operand values: every units value,
// mixed units, rates <= 0, %ofMaximum jerk on a system without max jerk,
// every termination type, circle type and direction, short arrays, lock
// directions), mixed with MAM/MAJ/MAS/MSF/MSO/MASR/MGS on the members
// and the master. One FNV-1a hash of every execute() result, every cycle's
// outputs, axis tags, coordinate system tags and control tags. Recorded on
// branch `motion` at 6b1f607 (main before the issue 27 items 5 and 6).
// CANMOTION_COORD_GOLDEN_PRINT=1 prints the hash and the counts.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "motion/planner.hpp"
#include "motion/st_parser.hpp"
#include "tests/motion/golden_util.hpp"

namespace canmotion::motion::test {
namespace {

constexpr std::uint64_t kExpected = 0x30aad3e14f622128ull;
constexpr std::uint64_t kSeed = 27;
constexpr int kRuns = 30;
constexpr int kOpsPerRun = 70;
constexpr int kControls = 24;

using golden::Hash;
using golden::num;
using golden::Rng;

constexpr std::array<const char*, 5> kAxes{"X", "Y", "Z", "M", "W"};  // cs {X, Y}, cs3 {X, Z, W}; M the master

/// The planner with two coordinate systems and REAL arrays whose values are
/// redrawn before each call.
struct World {
  std::unique_ptr<Planner> p = std::make_unique<Planner>(0.001);
  Symbols sym;
  std::array<std::vector<double>, 6> arrays{std::vector<double>(3), std::vector<double>(3), std::vector<double>(3),
                                            std::vector<double>(1), std::vector<double>(4), std::vector<double>(4)};
  std::array<AxisOutput, kAxes.size()> out{};
  std::uint64_t cycle = 0;

  World() {
    AxisConfig a;
    a.max_speed = 500;
    a.max_accel = a.max_decel = 5000;
    a.max_accel_jerk = a.max_decel_jerk = 1e5;
    for (std::size_t i = 0; i < kAxes.size(); ++i) {
      EXPECT_TRUE(p->configure_axis(static_cast<AxisId>(i), a));
      sym.axes[kAxes[i]] = static_cast<AxisId>(i);
    }
    for (int c = 0; c < kControls; ++c) sym.controls["c" + std::to_string(c)] = static_cast<ControlId>(c);
    sym.groups["g"] = 0;
    CoordSystemConfig c2;
    c2.dim = 2;
    c2.axes = {0, 1, kNoAxis};
    c2.ratio = {1.0, 2.0, 1.0};
    c2.max_speed = 200;
    c2.max_accel = 1000;
    c2.max_decel = 800;
    c2.max_accel_jerk = c2.max_decel_jerk = 1e5;
    c2.command_tolerance = 0.5;
    c2.actual_tolerance = 0.1;
    EXPECT_TRUE(p->configure_coordinate_system(0, c2));
    CoordSystemConfig c3;  // no max jerk: %ofMaximum jerk gives 0
    c3.dim = 3;
    c3.axes = {0, 2, 4};
    c3.max_speed = 150;
    c3.max_accel = 2000;
    c3.max_decel = 2000;
    c3.command_tolerance = 1.0;
    EXPECT_TRUE(p->configure_coordinate_system(1, c3));
    sym.coordinate_systems["cs"] = 0;
    sym.coordinate_systems["cs3"] = 1;
    static const std::array<const char*, 6> kArr{"p1", "p2", "p3", "r1", "ed", "cd"};
    for (std::size_t i = 0; i < arrays.size(); ++i) {
      EXPECT_TRUE(p->attach_real_array(static_cast<std::uint16_t>(i), std::span<double>(arrays[i])));
      sym.real_arrays[kArr[i]] = static_cast<std::uint16_t>(i);
    }
  }

  void redraw(Rng& g) {
    for (std::size_t i = 0; i < 3; ++i)
      for (double& v : arrays[i]) v = g.coin(0.1) ? 0.0 : g.uni(-100, 100);
    arrays[3][0] = g.coin(0.2) ? -g.uni(5, 60) : g.uni(5, 60);
    arrays[4] = {g.uni(0, 20), g.uni(0, 5), g.coin(0.1) ? -1.0 : 0.0, g.uni(0, 50)};
  }

  void step(Hash& h, const std::vector<Request>& reqs) {
    Input in{++cycle, {}, std::span<const Request>(reqs.data(), reqs.size())};
    Output o{std::span<AxisOutput>(out.data(), out.size())};
    h.i(static_cast<int>(p->update(in, o)));
    for (std::size_t i = 0; i < kAxes.size(); ++i) {
      const AxisOutput& x = out[i];
      h.f64(x.position); h.f64(x.velocity); h.f64(x.acceleration);
      const AxisTag& t = p->axis(static_cast<AxisId>(i));
      h.i(static_cast<int>(t.state)); h.u64(t.motion_status); h.u64(t.axis_status);
      h.f64(t.command_position); h.f64(t.command_velocity); h.f64(t.command_acceleration);
    }
    for (CoordSystemId s = 0; s < 2; ++s) {
      const CoordSystemTag& t = p->coordinate_system(s);
      h.u64(t.system_status); h.u64(t.motion_status); h.f64(t.speed);
      for (double v : t.command_position) h.f64(v);
    }
    for (int c = 0; c < kControls; ++c) {
      const ControlTag& t = p->control(static_cast<ControlId>(c));
      h.u64(t.flags); h.i(t.err); h.i(t.exerr); h.i(t.status); h.i(t.state); h.i(t.segment); h.u64(t.generation);
    }
    for (double v : arrays[5]) h.f64(v);
  }
};

/// Speed .. JerkUnits of a coordinated move (`md`: master-driven units), now
/// and then mixed or out of range.
std::string rates(Rng& g, bool md, bool with_profile) {
  static const std::array<const char*, 3> kSu{"unitspersec", "%ofmaximum", "unitspermasterunit"};
  static const std::array<const char*, 3> kAu{"unitspersec2", "%ofmaximum", "unitspermasterunit2"};
  static const std::array<const char*, 5> kJu{"unitspersec3", "%ofmaximum", "%oftime", "unitspermasterunit3",
                                              "%oftimemasterdriven"};
  const bool pct = !md && g.coin(0.3);
  std::string su = md ? "unitspermasterunit" : (pct ? "%ofmaximum" : "unitspersec");
  std::string au = md ? "unitspermasterunit2" : (pct ? "%ofmaximum" : "unitspersec2");
  std::string du = au;
  std::string ju = md ? (g.coin() ? "unitspermasterunit3" : "%oftimemasterdriven")
                      : (g.coin(0.4) ? "%oftime" : (pct ? "%ofmaximum" : "unitspersec3"));
  if (g.coin(0.06)) su = g.of(kSu);
  if (g.coin(0.06)) au = g.of(kAu);
  if (g.coin(0.06)) du = g.of(kAu);
  if (g.coin(0.06)) ju = g.of(kJu);
  const double sp = g.coin(0.06) ? 0.0 : (md ? g.uni(0.1, 3) : (pct ? g.uni(1, 120) : g.uni(1, 300)));
  const double ac = md ? g.uni(0.5, 50) : (pct ? g.uni(1, 120) : g.uni(10, 4000));
  const double dc = md ? g.uni(0.5, 50) : (pct ? g.uni(1, 120) : g.uni(10, 4000));
  const double aj = g.coin(0.05) ? -1.0 : g.uni(0, 110), dj = g.coin(0.05) ? 0.0 : g.uni(0, 110);
  std::string s = num(sp) + "," + su + "," + num(ac) + "," + au + "," + num(dc) + "," + du + ",";
  if (with_profile) s += std::string(g.coin(0.5) ? "scurve" : "trapezoidal") + ",";
  return s + num(md && g.coin(0.7) ? aj * 50 : aj) + "," + num(dj) + "," + ju;
}

std::string tail(Rng& g, bool md) {
  static const std::array<const char*, 9> kTt{"actualtolerance", "nosettle", "commandtolerance", "nodecel",
                                              "followcontourvelocityconstrained",
                                              "followcontourvelocityunconstrained", "commandtoleranceprogrammed",
                                              "2", "1"};
  static const std::array<const char*, 3> kMerge{"disabled", "coordinatedmotion", "allmotion"};
  static const std::array<const char*, 5> kLock{"none", "immediateforwardonly", "immediatereverseonly",
                                                "positionforwardonly", "positionreverseonly"};
  const char* lock = md ? kLock[static_cast<std::size_t>(1 + g.pick(4))] : "none";
  if (g.coin(0.05)) lock = g.of(kLock);
  return std::string(g.of(kTt)) + "," + (g.coin(0.1) ? g.of(kMerge) : "disabled") + "," +
         (g.coin(0.3) ? "current" : "programmed") + "," + num(g.coin(0.05) ? -1.0 : g.uni(0, 5)) + "," +
         num(g.uni(-20, 20)) + "," + lock + "," + (g.coin(0.15) ? "ed[0],cd[0]" : "0,0");
}

std::string random_call(Rng& g) {
  const std::string c = "c" + std::to_string(g.pick(kControls));
  const std::string cs = g.coin(0.75) ? "cs" : "cs3";
  static const std::array<const char*, 4> kPos{"p1[0]", "p2[0]", "p3[0]", "p1[1]"};
  static const std::array<const char*, 2> kType{"absolute", "incremental"};
  auto yn = [&](double p) { return g.coin(p) ? "yes" : "no"; };
  const bool md = g.coin(0.2);
  switch (g.pick(20)) {
    case 0: case 1: case 2: case 3: case 4:
      return "MCLM(" + cs + "," + c + "," + g.of(kType) + "," + g.of(kPos) + "," + rates(g, md, true) + "," +
             tail(g, md) + ");";
    case 5: case 6: case 7: {
      static const std::array<const char*, 4> kCt{"via", "center", "radius", "centerincremental"};
      static const std::array<const char*, 4> kDir{"clockwise", "counterclockwise", "clockwisefull",
                                                   "counterclockwisefull"};
      const int ct = g.pick(4);
      const std::string aux = ct == 2 ? (g.coin(0.9) ? "r1[0]" : "p1[0]") : g.of(kPos);
      return "MCCM(" + cs + "," + c + "," + g.of(kType) + "," + g.of(kPos) + "," + kCt[static_cast<std::size_t>(ct)] +
             "," + aux + "," + g.of(kDir) + "," + rates(g, md, true) + "," + tail(g, md) + ");";
    }
    case 8: case 9: {
      static const std::array<const char*, 3> kStop{"all", "coordinatedmove", "coordinatedtransform"};
      static const std::array<const char*, 3> kJu{"unitspersec3", "%ofmaximum", "%oftime"};
      return "MCS(" + cs + "," + c + "," + g.of(kStop) + "," + yn(0.5) + "," + num(g.coin(0.05) ? -1.0 : g.uni(1, 3000)) +
             "," + (g.coin() ? "%ofmaximum" : "unitspersec2") + "," + yn(0.4) + "," + num(g.uni(0, 110)) + "," +
             g.of(kJu) + ");";
    }
    case 10: case 11: case 12: {
      std::string r = rates(g, md, false);
      // MCCD: ChangeSpeed, Speed, SpeedUnits, ChangeAccel, Accel, ... in its own order
      std::vector<std::string> f;
      for (std::size_t b = 0, e; b <= r.size(); b = e + 1) {
        e = r.find(',', b);
        if (e == std::string::npos) e = r.size();
        f.push_back(r.substr(b, e - b));
      }
      if (g.coin(0.1)) f[2] = num(-g.uni(0, 10));  // accel <= 0
      if (g.coin(0.1)) f[4] = "0";                 // decel 0
      return "MCCD(" + cs + "," + c + ",coordinatedmove," + yn(0.6) + "," + f[0] + "," + f[1] + "," + yn(0.4) + "," +
             f[2] + "," + f[3] + "," + yn(0.4) + "," + f[4] + "," + f[5] + "," + yn(0.3) + "," + f[6] + "," +
             yn(0.3) + "," + f[7] + "," + f[8] + "," + (g.coin() ? "activemotion" : "activeandpendingmotion") + ");";
    }
    case 13:
      return "MDCC(" + cs + "," + (g.coin(0.9) ? "M" : "X") + "," + c + "," + (g.coin() ? "actual" : "command") + "," +
             num(g.uni(0, 100)) + ");";
    case 14:
      return g.coin(0.1) ? "MCSD(" + cs + "," + c + ");" : "MASR(" + std::string(g.of(kAxes)) + "," + c + ");";
    case 15:
      return "MAJ(M," + c + "," + (g.coin(0.8) ? "forward" : "reverse") + "," + num(g.uni(20, 300)) +
             ",unitspersec,3000,unitspersec2,3000,unitspersec2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none);";
    case 16: {
      static const std::array<const char*, 3> kStop{"all", "move", "jog"};
      const std::string ax = g.of(kAxes);
      if (g.coin(0.15)) return "MSF(" + ax + "," + c + ");";
      return "MAS(" + ax + "," + c + "," + g.of(kStop) + ",no,100,%ofmaximum,no,100,%oftime);";
    }
    case 17:
      return "MAM(" + std::string(g.coin() ? "X" : "Z") + "," + c + ",incremental," + num(g.uni(-20, 20)) +
             ",100,unitspersec,2000,unitspersec2,2000,unitspersec2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none,0,0);";
    case 18: return g.coin(0.2) ? "MGS(g," + c + ",programmed);" : "MSO(" + std::string(g.of(kAxes)) + "," + c + ");";
    default: return "MSO(" + std::string(g.of(kAxes)) + "," + c + ");";
  }
}

}  // namespace

TEST(CoordGolden, RandomCoordinatedSequencesHashAsRecorded) {
  Rng g{kSeed};
  Hash h;
  int accepted = 0, rejected = 0, unparsed = 0;
  std::array<int, 8> by_instr{};  // accepted MCLM, MCCM, MCS, MCSD, MCCD, MDCC
  for (int run = 0; run < kRuns; ++run) {
    World w;
    std::vector<Request> none;
    for (const char* ax : kAxes) {
      Request q;
      if (!parse_and_bind(std::string("MSO(") + ax + ",c0);", w.sym, q)) h.i(static_cast<int>(w.p->execute(q)));
    }
    for (int op = 0; op < kOpsPerRun; ++op) {
      std::vector<Request> reqs;
      w.redraw(g);
      if (g.coin(0.35)) golden::servo_on_again(g, h, *w.p, w.sym, kAxes, kControls);
      const int n = g.coin(0.3) ? 2 : 1;
      for (int k = 0; k < n; ++k) {
        const std::string text = random_call(g);
        Request q;
        if (auto err = parse_and_bind(text, w.sym, q)) {
          ++unparsed;
          if (std::getenv("CANMOTION_COORD_GOLDEN_PRINT")) std::printf("UNPARSED %s: %s\n", text.c_str(), err->c_str());
          continue;
        }
        if (g.coin(0.6)) {
          const Err e = w.p->execute(q);
          h.i(static_cast<int>(e));
          h.i(w.p->control(q.control).exerr);
          if (std::getenv("CANMOTION_COORD_GOLDEN_TRACE"))
            std::printf("EXEC %s %d %d\n", text.substr(0, text.find('(')).c_str(), static_cast<int>(e),
                        w.p->control(q.control).exerr);
          (e == Err::None ? accepted : rejected)++;
          const auto i = static_cast<int>(q.instr) - static_cast<int>(Instr::MCLM);
          if (e == Err::None && i >= 0 && i < 6) ++by_instr[static_cast<std::size_t>(i)];
        } else {
          reqs.push_back(q);
        }
      }
      const int cycles = 1 + g.pick(g.coin(0.2) ? 800 : 40);
      for (int k = 0; k < cycles; ++k) {
        w.step(h, reqs);
        reqs.clear();
      }
    }
  }
  if (std::getenv("CANMOTION_COORD_GOLDEN_PRINT"))
    std::printf("coord golden hash 0x%016llx (accepted %d, rejected %d, unparsed %d; MCLM %d MCCM %d MCS %d MCSD %d "
                "MCCD %d MDCC %d)\n",
                static_cast<unsigned long long>(h.h), accepted, rejected, unparsed, by_instr[0], by_instr[1],
                by_instr[2], by_instr[3], by_instr[4], by_instr[5]);
  EXPECT_EQ(unparsed, 0);
  for (int i = 0; i < 6; ++i) EXPECT_GT(by_instr[static_cast<std::size_t>(i)], 5) << "instruction " << i;
  EXPECT_GT(rejected, kRuns * 5);
  char got[32];
  std::snprintf(got, sizeof got, "0x%016llx", static_cast<unsigned long long>(h.h));
  EXPECT_EQ(h.h, kExpected) << "coordinated behaviour changed: hash " << got;
}

}  // namespace canmotion::motion::test
