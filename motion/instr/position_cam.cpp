// Position cam family (motion/instr/position_cam.hpp): MAPC (Motion Axis Position Cam) and the MAM master offset moves (MoveType 5
// absolute / 6 incremental master offset) [reference 2.14, 2.9; seed 000 MDAC
// Motion Type 4; seed 004 for the cam rules MAPC shares with MATC].
//
// The position cam is a PosCamGen in Slot::PositionCam: the slave offset is
// the CamMotion (motion/cam) evaluated at the cam coordinate
//   x = master travel since the lock (filtered by MasterDirection)
//     + master offset (finished master offset moves + the one running in Slot::MasterOffset)
//     - x_shift (the coordinate at which a pending cam took over).
// A master offset move is an ordinary MAM ProfileGen (time or master driven)
// in Slot::MasterOffset whose position is master units: the cycle steps it
// before the cam and leaves it out of the slave's sum; Core::fold() moves
// its position into PosCamGen::offset_base. Everything here is realtime-safe:
// noexcept, no allocation.
#include "motion/instr/position_cam.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "motion/instr/ctx.hpp"

namespace canmotion::motion {
namespace {

/// Did the master, moving from p0 to p1 (user frame), cross the lock position
/// in a direction the schedule accepts? A rotary master crosses every
/// lock + k * unwind. Reaching the lock position counts, and so does leaving
/// it in the accepted direction. On true `at` is the crossed position.
bool crossed(double p0, double p1, double lock, std::uint8_t schedule, bool rotary, double unwind,
             double& at) noexcept {
  const bool fwd_ok = schedule != schedule::ReverseOnly;
  const bool rev_ok = schedule != schedule::ForwardOnly;
  if (p1 > p0 && fwd_ok) {
    const double l = rotary ? lock + unwind * std::ceil((p0 - lock) / unwind) : lock;  // smallest >= p0
    if (p0 <= l && l <= p1) { at = l; return true; }
  }
  if (p1 < p0 && rev_ok) {
    const double l = rotary ? lock + unwind * std::floor((p0 - lock) / unwind) : lock;  // largest <= p0
    if (p1 <= l && l <= p0) { at = l; return true; }
  }
  return false;
}

/// Does `master` follow `slave` (gear, master-driven motion or time cam,
/// position cam), directly or not?
bool follows(const Core& c, AxisId master, AxisId slave) noexcept {
  std::array<std::uint8_t, kMaxAxes> seen{};
  std::array<AxisId, kMaxAxes> stack{};  // each axis is pushed at most once
  std::size_t sp = 0;
  stack[sp++] = master;
  seen[master] = 1;
  while (sp > 0) {
    const AxisId i = stack[--sp];
    for (const auto& s : c.axes[i].gen) {
      const AxisId up = master_of(s);
      if (up == slave) return true;
      if (up < kMaxAxes && !seen[up]) {
        seen[up] = 1;
        stack[sp++] = up;
      }
    }
  }
  return false;
}

/// Follow the master one cycle: false while the cam waits for the master to
/// cross MasterLockPosition; then the travel since the lock, as a slip clutch
/// for forward / reverse only [RM002H p.171] (the master's velocity and
/// acceleration as the cam sees them in mv, ma).
bool track_master(const AxisRt& m, PosCamGen& g, double& mv, double& ma) noexcept {
  const double mp = g.use_actual ? m.fb_pos : m.cmd.p;
  mv = g.use_actual ? m.fb_vel : m.cmd.v;
  ma = g.use_actual ? 0.0 : m.cmd.a;
  if (!g.locked) {
    // forward / reverse / bidirectional: armed until the master crosses MasterLockPosition
    double at = 0.0;
    if (!crossed(g.prev_mp + m.frame_offset, mp + m.frame_offset, g.master_lock, g.schedule, m.cfg.rotary,
                 m.cfg.unwind, at)) {
      g.prev_mp = mp;
      g.k = Kin{};
      return false;
    }
    g.locked = true;
    g.lock_mp = at - m.frame_offset;  // the cam coordinate counts from the lock position exactly
    g.prev_mp = g.lock_mp;
  }
  const double dm = mp - g.prev_mp;
  g.prev_mp = mp;
  if (g.master_dir == master_direction::ForwardOnly) {
    g.travel += std::max(0.0, dm);
    g.slipping = dm < 0;
    if (!(dm > 0)) mv = ma = 0.0;
  } else if (g.master_dir == master_direction::ReverseOnly) {
    g.travel += std::min(0.0, dm);
    g.slipping = dm > 0;
    if (!(dm < 0)) mv = ma = 0.0;
  } else {
    g.travel = mp - g.lock_mp;  // exact, no accumulated rounding
    g.slipping = false;
  }
  return true;
}

/// Where the master leaves the current pass, if it did this cycle: a pending
/// cam takes over there (its end, or its start when the master runs
/// backwards) [RM002H p.180].
bool pass_left(const PosCamGen& g, const cam::CamMotionOutput& o, double& end) noexcept {
  const bool continuous = g.cm.config().mode == cam::ExecutionMode::Continuous;
  if (continuous && o.pass != g.last_pass) {
    end = o.pass > g.last_pass ? g.cm.pass_end(g.last_pass) : g.cm.pass_end(g.last_pass - 1);
    return true;
  }
  if (!continuous && o.range != cam::CamRange::Inside && g.inside) {
    // (a Persistent cam already outside its range hands over when the master next leaves it)
    end = o.range == cam::CamRange::PastEnd ? g.cm.pass_end(0) : g.cm.pass_end(0) - g.cm.pass_length();
    return true;
  }
  return false;
}

/// The pending cam takes over at cam coordinate `end` (`off`: the master
/// offset this cycle); g is replaced (or, when the pending profile became
/// invalid, folded).
void take_over(Core& c, AxisRt& a, PosCamGen& g, double end, double off) noexcept {
  const bool continuous = g.cm.config().mode == cam::ExecutionMode::Continuous;
  ControlTag* t = c.tag(g.owner);
  const cam::CamMotionOutput at_end = g.cm.step(end);
  PendingPosCam pc = a.cams.position;
  a.cams.position = PendingPosCam{};
  PosCamGen n;
  if (pc.profile->acquire() == cam::CamError::None) {
    if (n.cm.start(*pc.profile, pc.cfg) != cam::CamError::None) {
      pc.profile->release();
      pc.profile = nullptr;
    }
  } else {
    pc.profile = nullptr;
  }
  if (t) {
    t->set(flag::IP, false);
    if (!continuous) t->set(flag::PC, true);  // Once: PC; Continuous: IP cleared [seed 004]
  }
  if (!pc.profile) {  // the profile was invalidated while pending: the cam ends at the pass end
    if (ControlTag* pt = c.tag(pc.owner)) pt->reject(Err::CamProfileNotCalculated);
    g.k = Kin{at_end.position, 0, 0};
    c.fold(a, Slot::PositionCam, false);
    return;
  }
  a.base += at_end.position;  // the new cam starts where the old one ended: no jump
  if (g.profile) g.profile->release();
  if (t) t->set(flag::AC, false);
  n.profile = pc.profile;
  n.master_id = pc.master;
  n.use_actual = pc.use_actual;
  n.schedule = schedule::Immediate;
  n.master_dir = pc.master_dir;
  n.locked = true;
  n.offset_base = g.offset_base;
  const AxisRt& nm = c.axes[n.master_id];
  const double nmp = n.use_actual ? nm.fb_pos : nm.cmd.p;
  n.prev_mp = nmp;
  if (n.master_id == g.master_id && n.use_actual == g.use_actual) {
    n.travel = g.travel;  // the same master coordinate, shifted by the pass end
    n.lock_mp = nmp - g.travel;
    n.x_shift = g.x_shift + end;
  } else {  // a cam preloaded for another master: starts at its lock position now
    n.lock_mp = nmp;
    n.x_shift = off;
  }
  n.owner = pc.owner;
  if (ControlTag* nc = c.tag(n.owner)) nc->set(flag::AC, true);
  c.set_slot(a, Slot::PositionCam, n).step(c, a, Slot::PositionCam);  // g is gone from here on
}

}  // namespace

// ------------------------------------------------------------------ helpers
namespace position_cam {

const AxisConfig* master_config(const Core& c, const AxisRt& a) noexcept {
  const auto* pc = std::get_if<PosCamGen>(&a.gen[index(Slot::PositionCam)]);
  return pc ? &c.axes[pc->master_id].cfg : nullptr;
}

double master_offset(const AxisRt& a) noexcept {
  const auto* pc = std::get_if<PosCamGen>(&a.gen[index(Slot::PositionCam)]);
  if (!pc) return 0.0;
  const GenBase* o = gen_base(a.gen[index(Slot::MasterOffset)]);
  return pc->offset_base + (o ? o->k : Kin{}).p;
}

void drop_pending(Core& c, AxisRt& a) noexcept {
  if (!a.cams.position.valid()) return;
  if (ControlTag* t = c.tag(a.cams.position.owner)) t->set(flag::IP, false);
  a.cams.position = PendingPosCam{};
}

}  // namespace position_cam

// -------------------------------------------------------------------- MAPC
MapcParams MapcParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  MapcParams m;
  m.slave = q.ref(op<I>("SlaveAxis"));
  m.master = q.ref(op<I>("MasterAxis"));
  m.direction = q.enumeration<CamDirection>(op<I>("Direction"));
  m.cam_profile = q.ref(op<I>("CamProfile"));
  m.slave_scaling = q.real(op<I>("SlaveScaling"));
  m.master_scaling = q.real(op<I>("MasterScaling"));
  m.execution_mode = q.number(op<I>("ExecutionMode"));
  m.execution_schedule = q.number(op<I>("ExecutionSchedule"));
  m.master_lock_position = q.real(op<I>("MasterLockPosition"));
  m.cam_lock_position = q.real(op<I>("CamLockPosition"));
  m.master_reference = q.enumeration<MasterReference>(op<I>("MasterReference"));
  m.master_direction = q.number(op<I>("MasterDirection"));
  return m;
}

Err start(Ctx& x, const MapcParams& p) noexcept {
  constexpr Instr I = Instr::MAPC;
  AxisRt& a = x.axis(p.slave);
  if (Err e = x.c.common_checks(a, true); e != Err::None) return e;
  const AxisRt& m = x.axis(p.master);
  if (!m.cfg.configured) return Err::AxisNotConfigured;
  if (m.cfg.inhibited) return Err::AxisIsInhibited;
  // the master must not follow the slave, directly or not
  if (p.slave == p.master || follows(x.c, p.master, p.slave)) return Err::MasterAxisConflict;
  if (a.hs.homing || m.hs.homing) return Err::HomeInProcess;
  if (x.c.any_stopping(a)) return Err::NotAllowedWhileStopping;
  cam::CamProfile* prof = p.cam_profile < kMaxCamProfiles ? x.c.cam_profiles[p.cam_profile] : nullptr;
  if (!prof || !prof->calculated()) return Err::CamProfileNotCalculated;
  const cam::CamScaling sc{p.slave_scaling, p.master_scaling};
  bool bad_slave = false, bad_master = false;
  if (cam::check_scaling(sc, bad_slave, bad_master) != cam::CamError::None)
    return x.reject_operand(bad_slave ? op<I>("SlaveScaling") : op<I>("MasterScaling"));
  // CamLockPosition must lie inside the profile's master range [UM002F p.227]
  if (!(p.cam_lock_position >= prof->master_start() && p.cam_lock_position <= prof->master_end()))
    return x.reject_operand(op<I>("CamLockPosition"));
  const int dir = cam::resolve_direction(static_cast<std::int32_t>(p.direction), a.cams.position_dir);
  cam::CamMotionConfig cfg;
  cfg.mode = static_cast<cam::ExecutionMode>(p.execution_mode);
  cfg.scaling = sc;
  cfg.direction = dir;
  cfg.lock_position = p.cam_lock_position;
  cfg.use_lock_position = true;
  // a virtual master has no actual position: it always gives command [seed 000]
  const bool use_actual = p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive;
  const auto* active = std::get_if<PosCamGen>(&a.gen[index(Slot::PositionCam)]);
  if (p.execution_schedule == schedule::Pending) {
    // takes over when the master leaves the current pass; the pending cam
    // continues the active cam's master coordinate, so it needs the same master
    if (active && (active->master_id != p.master || active->use_actual != use_actual)) return Err::MasterAxisConflict;
    position_cam::drop_pending(x.c, a);  // a second pending MAPC overlays the first
    a.cams.position = PendingPosCam{prof, cfg, p.master, use_actual, p.master_direction, x.self};
    a.cams.position_dir = dir;
    x.tag.set(flag::DN, true);
    x.tag.set(flag::IP, true);
    return Err::None;
  }
  if (active) return Err::IllegalDynamicChange;  // as MATC: only a pending cam may follow an active one
  PosCamGen g;
  if (prof->acquire() != cam::CamError::None) return Err::CamProfileNotCalculated;
  if (g.cm.start(*prof, cfg) != cam::CamError::None) {  // checked above; defensive
    prof->release();
    return x.reject_operand(op<I>("CamLockPosition"));
  }
  x.c.fold(a, Slot::PositionCam, true);
  const double mp = use_actual ? m.fb_pos : m.cmd.p;
  g.profile = prof;
  g.master_id = p.master;
  g.use_actual = use_actual;
  g.schedule = p.execution_schedule;
  g.master_dir = p.master_direction;
  g.master_lock = p.master_lock_position;
  g.locked = p.execution_schedule == schedule::Immediate;
  g.prev_mp = mp;
  g.lock_mp = mp;
  g.owner = x.self;
  x.c.set_slot(a, Slot::PositionCam, g);
  a.cams.position_dir = dir;
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
  x.tag.set(flag::AC, true);  // the active (not pending) position cam of the axis
  return Err::None;
}

// --------------------------------------------------------------- PosCamGen
void PosCamGen::step(Core& c, AxisRt& a, Slot s) noexcept {
  double mv = 0.0, ma = 0.0;
  if (!track_master(c.axes[master_id], *this, mv, ma)) return;
  // the master offset move (only a ProfileGen runs there) stepped before this cam
  const GenBase* mo = gen_base(a.gen[index(Slot::MasterOffset)]);
  const Kin ko = mo ? mo->k : Kin{};
  const double off = offset_base + ko.p, off_v = ko.v, off_a = ko.a;
  const double x = travel + off - x_shift;
  const cam::CamMotionOutput o = cm.step(x);
  double end = 0.0;
  if (a.cams.position.valid() && pass_left(*this, o, end)) return take_over(c, a, *this, end, off);
  last_pass = o.pass;
  inside = o.range == cam::CamRange::Inside;
  const double xd = mv + off_v, xdd = ma + off_a;
  k = Kin{o.position, o.velocity * xd, o.acceleration * xd * xd + o.velocity * xdd};
  ControlTag* t = c.tag(owner);
  if (t) t->segment = static_cast<std::int32_t>(o.segment);
  if (o.complete) {  // Once: PC, the slave holds the end position, PositionCamStatus cleared
    k.v = 0.0;
    k.a = 0.0;
    if (t) t->set(flag::PC, true);
    c.fold(a, s, true);
  }
}

void PosCamGen::on_fold(Core& c, AxisRt& a) noexcept {
  if (profile) {
    profile->release();  // CAM_PROFILE[0].Status: one user less
    profile = nullptr;
  }
  if (ControlTag* t = c.tag(owner)) t->set(flag::AC, false);
  c.fold(a, Slot::MasterOffset, true);  // a master offset move needs the cam it offsets
}

}  // namespace canmotion::motion
