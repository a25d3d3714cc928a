// Time cam family (motion/instr/time_cam.hpp): MATC and CamGen. Master-driven
// MATC (InstructionMode masterdrivenmode): the cam coordinate is the master
// travel through the slave's MDAC link for Time Cam (or All), in the lock
// direction [seed 000, seed 004, reference §2.15, §5]; the following rule
// itself (lock position, lock direction, pause, reversal) is
// master_follow_step() in motion/master_follow.hpp, shared with
// master-driven MAM/MAJ. Realtime-safe.
#include "motion/instr/time_cam.hpp"

#include <variant>

#include "motion/instr/ctx.hpp"
#include "motion/instr/mdac.hpp"

namespace canmotion::motion {
namespace {

constexpr bool position_lock(LockDirection d) noexcept {
  return d == LockDirection::PositionForwardOnly || d == LockDirection::PositionReverseOnly;
}

Err matc_mode_checks(const AxisRt& a, const MatcParams& p) noexcept {
  const bool pending = p.execution_schedule == schedule::Pending;
  // time driven: Lock Direction must be None [RM002H p.512, reference §5]
  if (!p.master_driven && p.lock_direction != LockDirection::None) return Err::MdscLockDirConflict;
  // "All pending CAMs must use the Immediate Forward or the Immediate Reverse
  // Lock Direction" [seed 004]: a position lock is LOCK_DIRECTION_CONFLICT (95),
  // and so is None on a master-driven pending cam (time driven: None, above)
  if (pending && position_lock(p.lock_direction)) return Err::MdscLockDirConflict;
  if (pending && p.master_driven && p.lock_direction == LockDirection::None) return Err::MdscLockDirConflict;
  const auto* cur = std::get_if<CamGen>(&a.gen[index(Slot::TimeCam)]);
  if (pending && cur != nullptr) {
    // the pending and the active cam must be in the same mode [seed 004]; it
    // then runs with the active cam's master and lock state [seed 000]
    if (cur->master_driven != p.master_driven) return Err::MdscInvalidModeOrMasterChange;
    return Err::None;
  }
  // master-driven mode needs an active MDAC link for Time Cam (or All) [seed 004 "Structure"]
  if (p.master_driven && !a.links.pending[link::TimeCam].valid() && !a.links.active[link::TimeCam].valid())
    return Err::MdscNotActivated;
  return Err::None;
}

Err matc_md_setup(const Core& c, const AxisRt& a, const MatcParams& p, CamGen& g) noexcept {
  // a queued master takes over when this MATC goes IP (start() promotes it) [seed 000]
  const MdacLink& l = a.links.pending[link::TimeCam].valid() ? a.links.pending[link::TimeCam] : a.links.active[link::TimeCam];
  if (!l.valid()) return Err::MdscNotActivated;
  const AxisRt& m = c.axes[l.master];
  g.master_driven = true;
  g.md = MasterFollow{};
  g.md.master = l.master;
  g.md.use_actual = l.use_actual;
  g.md.lock = p.lock_direction;
  g.md.lock_pos = p.lock_position - m.frame_offset;  // user frame (MRP, homing) -> drive frame
  // None and Immediate locks: locked from the start (TimeCamLockStatus set at once
  // for Immediate); Position locks wait for the master to cross LockPosition [seed 004]
  g.md.locked = p.lock_direction == LockDirection::None || lock_immediate(p.lock_direction);
  g.md.following = g.md.locked;
  g.md.prev_mp = l.use_actual ? m.fb_pos : m.cmd.p;
  g.md.mdac = l.owner;
  return Err::None;
}

/// The cam coordinate of this cycle: time, or master travel (master driven).
double cam_coordinate(const Core& c, CamGen& g) noexcept {
  if (!g.master_driven) return static_cast<double>(c.cycle - g.t0_cycle) * c.T - g.x_offset;
  if (g.md_cycle != c.cycle) {  // once per cycle (a pending takeover steps the new cam in the same cycle)
    const AxisRt& m = c.axes[g.md.master];
    const double du = g.md.step(g.md.use_actual ? m.fb_pos : m.cmd.p);
    g.md_rate = du / c.T;
    g.md_cycle = c.cycle;
  }
  return g.md.u - g.x_offset;
}

void cam_output(Core& c, CamGen& g, const cam::CamMotionOutput& o) noexcept {
  // d/dt = d/du * du/dt: slave velocity = cam slope x master velocity (lock direction)
  const double r = g.master_driven ? g.md_rate : 1.0;
  g.k = Kin{o.position, o.velocity * r, o.acceleration * r * r};
  if (ControlTag* t = c.tag(g.owner)) {
    t->segment = static_cast<std::int32_t>(o.segment);
    // a cam has no accel/decel transition: it tracks the master while locked and following
    if (g.master_driven) t->set(flag::TrackingMaster, g.md.locked && g.md.following);
  }
}

}  // namespace

MatcParams MatcParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  MatcParams m;
  m.axis = q.ref(op<I>("Axis"));
  m.direction = q.enumeration<CamDirection>(op<I>("Direction"));
  m.cam_profile = q.ref(op<I>("CamProfile"));
  m.distance_scaling = q.real(op<I>("DistanceScaling"));
  m.time_scaling = q.real(op<I>("TimeScaling"));
  m.execution_mode = q.number(op<I>("ExecutionMode"));
  m.execution_schedule = q.number(op<I>("ExecutionSchedule"));
  m.lock_position = q.real(op<I>("LockPosition"));
  m.lock_direction = q.enumeration<LockDirection>(op<I>("LockDirection"));
  m.master_driven = q.yes(op<I>("InstructionMode"));
  return m;
}

Err start(Ctx& x, const MatcParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  if (Err e = matc_mode_checks(a, p); e != Err::None) return e;  // lock direction, mode, MDAC
  cam::CamProfile* prof = p.cam_profile < kMaxCamProfiles ? x.c.cam_profiles[p.cam_profile] : nullptr;
  if (!prof || !prof->calculated()) return Err::CamProfileNotCalculated;
  bool bad_slave = false, bad_master = false;
  const cam::CamScaling sc{p.distance_scaling, p.time_scaling};
  if (cam::check_scaling(sc, bad_slave, bad_master) != cam::CamError::None)
    return x.reject_operand(bad_slave ? op<Instr::MATC>("DistanceScaling") : op<Instr::MATC>("TimeScaling"));
  const int dir = cam::resolve_direction(static_cast<std::int32_t>(p.direction), a.cams.time_dir);
  cam::CamMotionConfig cfg;
  cfg.mode = static_cast<cam::ExecutionMode>(p.execution_mode);  // once or continuous (the table checked it)
  cfg.scaling = sc;
  cfg.direction = dir;
  const bool active = std::holds_alternative<CamGen>(a.gen[index(Slot::TimeCam)]);
  if (p.execution_schedule == schedule::Pending) {  // takes over at the end of the current pass [seed 004]
    time_cam::drop_pending(x.c, a);                   // a second pending MATC overlays the first
    a.cams.time = PendingCam{prof, cfg, x.self, p.master_driven};
    a.cams.time_dir = dir;
    x.tag.set(flag::DN, true);
    x.tag.set(flag::IP, true);
    return Err::None;
  }
  if (active) return Err::IllegalDynamicChange;  // immediate on an axis already time camming [seed 004]
  CamGen g;
  int bad = 0;
  if (p.master_driven)
    if (Err e = matc_md_setup(x.c, a, p, g); e != Err::None) return e;
  if (prof->acquire() != cam::CamError::None) return Err::CamProfileNotCalculated;
  if (g.cm.start(*prof, cfg, &bad) != cam::CamError::None) {
    prof->release();
    return x.reject_operand(op<Instr::MATC>("Direction"));
  }
  x.c.fold(a, Slot::TimeCam, true);
  // a preloaded pending cam in the other mode cannot follow this one: "An
  // instruction that pends a CAM to an active CAM in a different mode (than
  // the active CAM) will cause an error" [seed 004]; it errs now (ERR 105, as
  // when pended onto an active cam) and is dropped
  if (a.cams.time.valid() && a.cams.time.master_driven != p.master_driven) {
    if (ControlTag* pt = x.c.tag(a.cams.time.owner)) pt->reject(Err::MdscInvalidModeOrMasterChange);
    time_cam::drop_pending(x.c, a);
  }
  g.profile = prof;
  g.t0_cycle = x.c.cycle;
  g.owner = x.self;
  mdac::promote_pending(x.c, a, link::TimeCam);  // a queued MDAC master takes over as this MATC goes IP [seed 000]
  if (g.master_driven) {
    x.tag.set(flag::AC, true);
    if (ControlTag* m = x.c.tag(g.md.mdac)) m->set(flag::AC, true);
  }
  x.c.set_slot(a, Slot::TimeCam, g);
  a.cams.time_dir = dir;
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
  return Err::None;
}

void CamGen::step(Core& c, AxisRt& a, Slot s) noexcept {
  const double x = cam_coordinate(c, *this);  // time, or master travel (master driven)
  cam::CamMotionOutput o = cm.step(x);
  // a pending cam takes over exactly at the end of the current pass [seed 004]
  const bool once = cm.config().mode == cam::ExecutionMode::Once;
  const std::int64_t pass_before = last_pass;
  last_pass = o.pass;
  if (a.cams.time.valid()) {
    const double end = once ? cm.pass_end(0) : cm.pass_end(pass_before);
    if (once ? x >= end : o.pass > pass_before) {
      const cam::CamMotionOutput at_end = cm.step(end);
      if (ControlTag* old = c.tag(owner)) {
        old->set(flag::IP, false);
        old->set(flag::AC, false);
        old->set(flag::TrackingMaster, false);
        if (once) old->set(flag::PC, true);  // Once: PC; Continuous: IP cleared
      }
      const CamGen md_from = *this;  // the pending cam runs in this cam's mode, master and lock state [seed 000]
      k = Kin{at_end.position, 0, 0};
      c.fold(a, s, false);  // base += position at the pass end: no jump; *this is gone from here on
      const PendingCam pc = a.cams.time;
      a.cams.time = PendingCam{};
      CamGen n;
      if (pc.profile->acquire() == cam::CamError::None && n.cm.start(*pc.profile, pc.cfg) == cam::CamError::None) {
        n.profile = pc.profile;
        n.t0_cycle = md_from.t0_cycle;
        n.x_offset = md_from.x_offset + end;
        n.owner = pc.owner;
        n.master_driven = md_from.master_driven;
        n.md = md_from.md;
        n.md_rate = md_from.md_rate;
        n.md_cycle = md_from.md_cycle;
        if (n.master_driven) {
          if (ControlTag* nt = c.tag(n.owner)) nt->set(flag::AC, true);
          if (ControlTag* m = c.tag(n.md.mdac)) m->set(flag::AC, true);
        }
        c.set_slot(a, s, n).step(c, a, s);
      } else if (ControlTag* pt = c.tag(pc.owner)) {
        pt->reject(Err::CamProfileNotCalculated);
      }
      return;
    }
  }
  cam_output(c, *this, o);  // velocity x master rate when master driven; SEGMENT; TrackingMaster
  if (o.complete) {  // Once: PC, the axis holds the end position, TimeCamStatus cleared
    if (ControlTag* t = c.tag(owner)) t->set(flag::PC, true);
    c.fold(a, s, true);
  }
}

void CamGen::on_fold(Core& c, AxisRt&) noexcept {
  if (profile) {
    profile->release();  // CAM_PROFILE[0].Status: one user less
    profile = nullptr;
  }
  if (master_driven)  // a master-driven cam: its MDAC is no longer active
    if (ControlTag* m = c.tag(md.mdac)) m->set(flag::AC, false);
}

namespace time_cam {

void drop_pending(Core& c, AxisRt& a) noexcept {
  if (!a.cams.time.valid()) return;
  if (ControlTag* t = c.tag(a.cams.time.owner)) t->set(flag::IP, false);
  a.cams.time = PendingCam{};
}

}  // namespace time_cam
}  // namespace canmotion::motion
