#pragma once
/// \file motion/profile_step.hpp
/// ProfileGen::step (motion/generator.hpp), inline: the cycle
/// (motion/cycle.cpp) steps every moving axis through it, and so builds
/// without link-time optimisation (the tests and motion_bench) inline it as
/// the product does. Its end (finish) is in motion/instr/move.cpp, the move
/// family that starts it. Realtime-safe.

#include <cmath>

#include "motion/core.hpp"
#include "motion/generator.hpp"

namespace canmotion::motion {

inline void ProfileGen::step(Core& c, AxisRt& a, Slot s) noexcept {
  bool done;
  bool tracking = false;
  if (master_driven) {
    // abscissa = master travel in the lock direction [RM002H p.512]
    const AxisRt& m = c.axes[md.master];
    const double du = md.step(md.use_actual ? m.fb_pos : m.cmd.p);
    const Kin ku = prof.sample(md.u, hint);
    const double udot = du / c.T;
    k = Kin{ku.p, ku.v * udot, ku.a * udot * udot};
    // TrackingMaster: locked, following, and the accel transition to the programmed ratio done
    tracking = md.locked && md.following && speed > 0 && std::fabs(ku.v) >= speed * (1 - 1e-9);
    done = role != GenRole::Jog && prof.finite() && md.u >= prof.duration();
  } else {
    const double t = static_cast<double>(c.cycle - t0_cycle) * c.T;
    k = prof.sample(t, hint);
    done = role != GenRole::Jog && prof.finite() && t >= prof.duration();
  }
  ControlTag* t = c.tag(owner);
  if (done) return finish(c, a, s, t);
  if (t) {
    t->set(flag::ACCEL, k.v * k.a > 0 || (k.v == 0 && k.a != 0));
    t->set(flag::DECEL, k.v * k.a < 0);
    if (master_driven) t->set(flag::TrackingMaster, tracking);
  }
}

}  // namespace canmotion::motion
