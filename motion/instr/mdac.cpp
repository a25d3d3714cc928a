// MDAC family (motion/instr/mdac.hpp): Motion Drive Axis Coordination, the
// links of a slave's motion types to a master, and what master-driven motion
// (MAM, MAJ, MATC with master-driven units or mode) takes from them
// [seed 000]. Realtime-safe.
#include "motion/instr/mdac.hpp"

#include <algorithm>

#include "motion/instr/ctx.hpp"

namespace canmotion::motion {

MdacParams MdacParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  return {q.ref(op<I>("SlaveAxis")), q.ref(op<I>("MasterAxis")), q.number(op<I>("MotionType")),
          q.enumeration<MasterReference>(op<I>("MasterReference"))};
}

Err start(Ctx& x, const MdacParams& p) noexcept {
  AxisRt& a = x.axis(p.slave);
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  if (a.servo.shutdown) return Err::ShutdownState;
  const AxisRt& m = x.axis(p.master);
  if (!m.cfg.configured) return Err::AxisNotConfigured;
  if (m.cfg.inhibited) return Err::AxisIsInhibited;
  if (p.slave == p.master) return Err::MasterAxisConflict;
  if (a.hs.homing || m.hs.homing) return Err::HomeInProcess;
  // a virtual master always gives command, a feedback-only/CIP master follows the operand [seed 000]
  const bool use_actual = p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive;
  const bool all = p.motion_type == 0;
  const bool moving = a.cmd.v != 0 || a.cmd.a != 0;
  bool any_all = false, any_single = false;
  for (const auto& l : a.links.active) {
    if (!l.valid()) continue;
    if (l.all) any_all = true; else any_single = true;
  }
  if ((all && any_single) || (!all && any_all)) return Err::MdscMdacAllConflict;  // [seed 000]
  const std::size_t first = all ? 0 : static_cast<std::size_t>(p.motion_type - 1);
  const std::size_t last = all ? a.links.active.size() : first + 1;
  for (std::size_t k = first; k < last; ++k) {
    const MdacLink& l = a.links.active[k];
    // changing the master reference of a moving slave errors; the original stays
    // [seed 000], whether the MDAC names the same master or another one
    if (l.valid() && l.use_actual != use_actual && moving) return Err::MdscInvalidModeOrMasterChange;
  }
  const MdacLink nl{p.master, use_actual, all, x.self};
  for (std::size_t k = first; k < last; ++k) {
    MdacLink& l = a.links.active[k];
    if (l.valid() && (l.master != p.master || l.use_actual != use_actual)) {
      // the new master is queued: it takes over when the next single-axis motion goes IP [seed 000]
      MdacLink& q = a.links.pending[k];
      if (q.valid() && (q.owner != x.self))
        if (ControlTag* o = x.c.tag(q.owner)) o->set(flag::IP, false);  // a newer pending MDAC overrides
      q = nl;
    } else {
      if (l.valid() && (l.owner != x.self))
        if (ControlTag* o = x.c.tag(l.owner)) { o->set(flag::IP, false); o->set(flag::AC, false); }
      l = nl;
    }
  }
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
  return Err::None;
}

namespace mdac {

void break_links(Core& c, AxisRt& a) noexcept {
  for (auto* arr : {&a.links.active, &a.links.pending}) {
    for (auto& l : *arr) {
      if (!l.valid()) continue;
      if (ControlTag* t = c.tag(l.owner)) {
        t->set(flag::IP, false);
        t->set(flag::AC, false);
      }
      l = MdacLink{};
    }
  }
}

void break_links_of_master(Core& c, AxisId master) noexcept {
  for (std::size_t i = 0; i < c.axis_count; ++i) {
    bool uses = false;
    for (const auto& l : c.axes[i].links.active) uses = uses || l.master == master;
    for (const auto& l : c.axes[i].links.pending) uses = uses || l.master == master;
    if (uses) break_links(c, c.axes[i]);
  }
}

void promote_pending(Core& c, AxisRt& a, std::size_t ti) noexcept {
  MdacLink& p = a.links.pending[ti];
  if (!p.valid()) return;
  MdacLink& l = a.links.active[ti];
  if (l.valid() && (l.owner != p.owner)) {
    bool still_used = false;  // an "All" MDAC tag may still hold other motion types
    for (std::size_t k = 0; k < a.links.active.size(); ++k)
      if (k != ti && a.links.active[k].owner == l.owner) still_used = true;
    if (!still_used)
      if (ControlTag* t = c.tag(l.owner)) { t->set(flag::IP, false); t->set(flag::AC, false); }
  }
  l = p;
  p = MdacLink{};
}

Err master_driven_setup(Core& c, AxisRt& a, std::size_t k, ProfileGen& g, Kin& start) noexcept {
  const MdacLink& l = a.links.pending[k].valid() ? a.links.pending[k] : a.links.active[k];
  if (!l.valid()) return Err::MdscNotActivated;
  const AxisRt& m = c.axes[l.master];
  const double mp = l.use_actual ? m.fb_pos : m.cmd.p;
  const double mv = l.use_actual ? m.fb_vel : m.cmd.v;
  const bool immediate = lock_immediate(g.md.lock);
  const bool fwd = lock_forward(g.md.lock);
  const double udot = immediate ? std::max(0.0, fwd ? mv : -mv) : 0.0;
  if (start.v != 0 || start.a != 0) {
    // the slave's present motion, per unit of master travel
    if (!(udot > 1e-9)) return Err::MdscIdleMasterSlaveMoving;
    start = Kin{0, start.v / udot, 0};
  }
  g.master_driven = true;
  g.md.master = l.master;
  g.md.use_actual = l.use_actual;
  g.md.locked = immediate;
  g.md.following = immediate;  // Move/JogLockStatus set at once for immediate locks
  g.md.lock_pos -= m.frame_offset;  // LockPosition is a master position (user frame); mp is drive frame
  g.md.prev_mp = mp;
  g.md.u = 0;
  g.md.mdac = l.owner;
  return Err::None;
}

}  // namespace mdac
}  // namespace canmotion::motion
