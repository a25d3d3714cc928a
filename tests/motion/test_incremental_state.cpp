// The planner keeps some state incrementally for speed: each axis's live-slot
// mask (which generator slots are in use) and the step order (masters before
// slaves), recomputed only when a slot or an axis changes. Seeded random
// instruction sequences over several axes (moves, jogs, gears, time and
// position cams, master offset moves, master-driven motion, stops, servo and
// shutdown changes, group stops) check Planner::check_incremental_state()
// after every instruction and every cycle. CANMOTION_SEED /
// CANMOTION_PROP_COUNT override seed and count (printed on failure).
#include <gtest/gtest.h>

#include <array>
#include <sstream>
#include <string>

#include "motion/cam/cam_profile.hpp"
#include "prop_util.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::Rig;
using canmotion::motion::test::num;
using canmotion::motion::test::Rng;

namespace {


struct StateRig {
  Rig r;
  cam::CamProfile lin{4}, cub{8};
  static constexpr std::array<const char*, 4> kAxes{"A", "B", "C", "D"};
  StateRig() {
    for (const char* ax : kAxes) {
      AxisConfig c;
      c.max_speed = 1000;
      c.max_accel = c.max_decel = 10000;
      r.add_axis(ax, c);
    }
    const std::array<cam::CamPoint, 2> l{{{0.0, 0.0, 0}, {10.0, 20.0, 0}}};
    EXPECT_TRUE(cam::mccp(cam::MccpRequest{l, 0, 2, 0.0, 0.0}, lin).ok());
    const std::array<cam::CamPoint, 4> q{{{0.0, 0.0, 1}, {2.0, 1.0, 1}, {5.0, 6.0, 1}, {8.0, 2.0, 1}}};
    EXPECT_TRUE(cam::mccp(cam::MccpRequest{q, 0, 4, 0.0, 0.0}, cub).ok());
    r.p->attach_cam_profile(0, &lin);
    r.p->attach_cam_profile(1, &cub);
    r.sym.cam_profiles["lin"] = 0;
    r.sym.cam_profiles["cub"] = 1;
  }
};

std::string random_call(Rng& g, int id) {
  const std::string ax = StateRig::kAxes[static_cast<std::size_t>(g.pick(4))];
  const std::string m = StateRig::kAxes[static_cast<std::size_t>(g.pick(4))];  // may equal ax: refused
  const std::string c = "c" + std::to_string(id);
  const std::string sp = num(g.uni(1, 200));
  const std::string prof = g.coin() ? "lin" : "cub";
  const std::string dir = g.coin() ? "forward" : "reverse";
  switch (g.pick(18)) {
    case 0: return "MSO(" + ax + "," + c + ");";
    case 1: return "MSF(" + ax + "," + c + ");";
    case 2:
      return "MAM(" + ax + "," + c + "," + (g.coin() ? "absolute" : "incremental") + "," + num(g.uni(-50, 50)) + "," + sp +
             ",unitspersec,1000,unitspersec2,1000,unitspersec2," + (g.coin() ? "scurve" : "trapezoidal") +
             ",100,100,%oftime," + (g.coin() ? "enabled" : "disabled") + ",programmed,0,none,0,0);";
    case 3:
      return "MAJ(" + ax + "," + c + "," + dir + "," + sp + ",unitspersec,1000,unitspersec2,1000,unitspersec2," +
             (g.coin() ? "scurve" : "trapezoidal") + ",100,100,%oftime," + (g.coin() ? "enabled" : "disabled") +
             ",programmed,0,none);";
    case 4:
      return "MAG(" + ax + "," + m + "," + c + "," + (g.coin() ? "same" : "opposite") + "," + num(g.uni(0.2, 3)) +
             ",1,1,command,real," + (g.coin() ? "enabled" : "disabled") + ",1000,unitspersec2);";
    case 5:
      return "MATC(" + ax + "," + c + ",same," + prof + "[0],1,1," + (g.coin() ? "once" : "continuous") + "," +
             (g.coin() ? "immediate" : "pending") + ",0,none,timedrivenmode);";
    case 6: return "MDAC(" + ax + "," + m + "," + c + "," + (g.coin() ? "all" : (g.coin() ? "jog" : "timecam")) + ",command);";
    case 7:
      return "MAJ(" + ax + "," + c + "," + dir + ",1,unitspermasterunit,2,unitspermasterunit2,2,unitspermasterunit2,"
             "trapezoidal,0,0,unitspermasterunit3,disabled,programmed,0," + (g.coin() ? "immediateforwardonly" : "none") + ");";
    case 8:
      return "MATC(" + ax + "," + c + ",same," + prof + "[0],1,1,continuous," + (g.coin() ? "immediate" : "pending") +
             ",0,immediateforwardonly,masterdrivenmode);";
    case 9:
      return "MAPC(" + ax + "," + m + "," + c + ",same," + prof + "[0],1,1," + (g.coin() ? "once" : "continuous") + "," +
             (g.coin() ? "immediate" : "pending") + "," + num(g.uni(-5, 5)) + ",0,command,bidirectional);";
    case 10:
      return "MAM(" + ax + "," + c + ",incrementalmasteroffset," + num(g.uni(-5, 5)) + ",10,unitspersec,100,unitspersec2,100,"
             "unitspersec2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none,0,0);";
    case 11:
      return "MAS(" + ax + "," + c + "," + (g.coin() ? "all" : (g.coin() ? "jog" : (g.coin() ? "move" : "gear"))) +
             ",no,100,%ofmaximum,no,100,%oftime);";
    case 12: return "MAS(" + ax + "," + c + ",all,no,100,%ofmaximum,no,100,%oftime);";
    case 13: return "MASD(" + ax + "," + c + ");";
    case 14: return "MASR(" + ax + "," + c + ");";
    case 15: return std::string("MGS(g,") + c + "," + (g.coin() ? "faststop" : "programmed") + ");";
    case 16: return "MCD(" + ax + "," + c + "," + (g.coin() ? "move" : "jog") + ",yes," + sp +
                    ",no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);";
    default: return "MAFR(" + ax + "," + c + ");";
  }
}

}  // namespace

TEST(PlannerIncrementalState, LiveSlotsAndStepOrderMatchTheSlotsAfterRandomInstructions) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 40;
  const std::uint64_t runs = std::max<std::uint64_t>(1, canmotion::motion::test::prop_count(120000) / 2000);
  Rng g(seed);
  int accepted = 0, linked_cycles = 0;
  for (std::uint64_t run = 0; run < runs; ++run) {
    StateRig s;
    Rig& r = s.r;
    std::ostringstream log;
    for (const char* ax : StateRig::kAxes) ASSERT_EQ(r.exec(std::string("MSO(") + ax + ", on" + ax + ");"), Err::None);
    ASSERT_TRUE(r.p->check_incremental_state()) << "seed=" << seed;
    int id = 0;
    for (int op = 0; op < 60; ++op) {
      const std::string text = random_call(g, id++);
      log << "[" << r.cycle << "] " << text << "\n";
      if (g.coin(0.7)) {
        if (r.exec(text) == Err::None) ++accepted;  // refusals are fine: nothing may be half-applied
        ASSERT_TRUE(r.p->check_incremental_state())
            << "seed=" << seed << " run=" << run << " after exec\n" << log.str();
      } else {
        r.submit(text);  // executed inside update(), before the order is used
      }
      const int cycles = 1 + g.pick(g.coin(0.2) ? 3000 : 40);
      for (int k = 0; k < cycles; ++k) {
        r.step();
        ASSERT_TRUE(r.p->check_incremental_state())
            << "seed=" << seed << " run=" << run << " cycle=" << r.cycle << "\n" << log.str();
        if (r.axis("A").motion(motion_status::GearingStatus) || r.axis("B").motion(motion_status::PositionCamStatus)) ++linked_cycles;
      }
    }
  }
  // the sequences did exercise the instructions and the master links
  EXPECT_GT(accepted, static_cast<int>(runs) * 10) << "seed=" << seed;
  EXPECT_GT(linked_cycles, 0) << "seed=" << seed;
}
