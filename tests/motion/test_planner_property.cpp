// Seeded random instruction sequences through the Planner: merged moves,
// replacements, jogs, MCD and stops keep the sampled velocity continuous
// (bounded change per cycle) and within the speed limits, and a final stop
// ends at rest. CANMOTION_SEED / CANMOTION_PROP_COUNT override seed and count.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "prop_util.hpp"
#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::num;
using canmotion::motion::test::Rng;


TEST(PlannerProperty, RandomSequencesStayContinuousAndWithinLimits) {
  const std::uint64_t seed = canmotion::motion::test::prop_seed() + 10;
  const std::uint64_t runs = std::max<std::uint64_t>(1, canmotion::motion::test::prop_count(120000) / 600);
  Rng r(seed);
  for (std::uint64_t run = 0; run < runs; ++run) {
    const double A = r.logu(10, 5000), J = r.logu(100, 1e6), Vcap = r.logu(1, 500);
    AxisConfig c;
    c.max_speed = Vcap;
    c.max_accel = c.max_decel = A;
    c.max_accel_jerk = c.max_decel_jerk = J;
    test::Rig rig;
    rig.add_axis("X", c);
    ASSERT_EQ(rig.exec("MSO(X, on);"), Err::None);
    std::ostringstream log;
    double prev_v = 0;
    int id = 0;
    for (int op = 0; op < 25; ++op) {
      const std::string prof = r.coin() ? "scurve" : "trapezoidal";
      const std::string speed = num(r.uni(0.05, 1.0) * Vcap);
      const std::string rate = num(A);
      const std::string jerk = num(J);
      const std::string ctl = "c" + std::to_string(id++);
      std::string text;
      switch (r.pick(6)) {
        case 0:
        case 1:
          text = "MAM(X," + ctl + "," + (r.coin() ? "absolute" : "incremental") + "," + num(r.uni(-1, 1) * r.logu(0.01, 1000)) +
                 "," + speed + ",unitspersec," + rate + ",unitspersec2," + rate + ",unitspersec2," + prof + "," + jerk + "," +
                 jerk + ",unitspersec3,enabled,programmed,0,none,0,0);";
          break;
        case 2:
          text = "MAJ(X," + ctl + "," + (r.coin() ? "forward" : "reverse") + "," + speed + ",unitspersec," + rate +
                 ",unitspersec2," + rate + ",unitspersec2," + prof + "," + jerk + "," + jerk +
                 ",unitspersec3,enabled,programmed,0,none);";
          break;
        case 3:
          text = "MCD(X," + ctl + "," + (r.coin() ? "move" : "jog") + ",yes," + speed +
                 ",no,0,no,0,no,0,no,0,unitspersec,unitspersec2,unitspersec2,unitspersec3);";
          break;
        case 4:
          text = "MAS(X," + ctl + ",all,no,0,unitspersec2,no,0,unitspersec3);";
          break;
        default:
          text = "MAS(X," + ctl + "," + (r.coin() ? "move" : "jog") + ",no,0,unitspersec2,no,0,unitspersec3);";
          break;
      }
      log << "[" << rig.cycle << "] " << text << "\n";
      rig.exec(text);  // may be refused (e.g. 78 while stopping): that is fine
      const int cycles = 1 + r.pick(600);
      for (int k = 0; k < cycles; ++k) {
        rig.step();
        const double v = rig.axis("X").command_velocity;
        // accel bound: merge-enabled motion is a single generator; MCD and MAS
        // stay within A except the documented no-overshoot scaling (not hit here:
        // limits never drop).
        ASSERT_LE(std::fabs(v - prev_v), A * rig.p->period() * (1 + 1e-6) + 1e-9)
            << "seed=" << seed << " run=" << run << " cycle=" << rig.cycle << " v " << prev_v << " -> " << v << "\n" << log.str();
        ASSERT_LE(std::fabs(v), Vcap * (1 + 1e-9) + 1e-9)
            << "seed=" << seed << " run=" << run << " cycle=" << rig.cycle << " v=" << v << "\n" << log.str();
        ASSERT_TRUE(std::isfinite(rig.axis("X").command_position));
        prev_v = v;
      }
    }
    rig.exec("MAS(X, final, all, no, 0, unitspersec2, no, 0, unitspersec3);");
    rig.step_until([&] { return rig.tag("final").pc(); }, 10000000);
    EXPECT_EQ(rig.axis("X").command_velocity, 0.0) << "seed=" << seed << " run=" << run;
  }
}
