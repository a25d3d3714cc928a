// MAPC (Motion Axis Position Cam) and the MAM master offset moves (MoveType 5
// absolute / 6 incremental master offset) [reference 2.14, 2.9; seed 000 MDAC
// Motion Type 4; seed 004 for the cam rules MAPC shares with MATC].
//
// The position cam is a PosCamGen in Slot::PositionCam: the slave offset is
// the CamMotion (motion/cam) evaluated at the cam coordinate
//   x = master travel since the lock (filtered by MasterDirection)
//     + master offset (finished master offset moves + the one running in Slot::MasterOffset)
//     - x_shift (the coordinate at which a pending cam took over).
// A master offset move is an ordinary MAM ProfileGen (time or master driven)
// in Slot::MasterOffset whose position is master units: step_axis steps it
// before the cam and leaves it out of the slave's sum; fold() moves its
// position into PosCamGen::offset_base. Everything here is realtime-safe:
// noexcept, no allocation.
#include <algorithm>
#include <cmath>

#include "motion/instructions.hpp"
#include "motion/planner.hpp"

namespace canmotion::motion {
namespace {

constexpr std::size_t kPosCam = static_cast<std::size_t>(Slot::PositionCam);
constexpr std::size_t kOffset = static_cast<std::size_t>(Slot::MasterOffset);

/// MAPC operand indices (EXERR for ERR 13), from THE signature table. A
/// namespace-scope constant: initialised at load time (the table is constant
/// data), so the cyclic path never runs a guarded static initialisation.
struct MapcIdx {
  int scaling_slave, scaling_master, cam_lock;
};
const MapcIdx kIdx{operand_index(Instr::MAPC, "SlaveScaling"), operand_index(Instr::MAPC, "MasterScaling"),
                   operand_index(Instr::MAPC, "CamLockPosition")};

/// ExecutionSchedule numbers [RM002H p.171].
constexpr std::uint8_t kImmediate = 0, kPending = 1, kForwardOnly = 2, kReverseOnly = 3;
/// MasterDirection numbers [RM002H p.171].
constexpr std::uint8_t kMasterForward = 1, kMasterReverse = 2;

/// Did the master, moving from p0 to p1 (user frame), cross the lock position
/// in a direction the schedule accepts? A rotary master crosses every
/// lock + k * unwind. Reaching the lock position counts, and so does leaving
/// it in the accepted direction. On true `at` is the crossed position.
bool crossed(double p0, double p1, double lock, std::uint8_t schedule, bool rotary, double unwind,
             double& at) noexcept {
  const bool fwd_ok = schedule != kReverseOnly;
  const bool rev_ok = schedule != kForwardOnly;
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

}  // namespace

// ------------------------------------------------------------------ helpers
const AxisConfig* Planner::position_cam_master(const AxisRt& a) const noexcept {
  const auto* pc = std::get_if<PosCamGen>(&a.gen[kPosCam]);
  return pc ? &axes_[pc->master].cfg : nullptr;
}

double Planner::master_offset(const AxisRt& a) const noexcept {
  const auto* pc = std::get_if<PosCamGen>(&a.gen[kPosCam]);
  if (!pc) return 0.0;
  return pc->offset_base + slot_kin(a, Slot::MasterOffset).p;
}

void Planner::add_master_offset(AxisRt& a, double d) noexcept {
  if (auto* pc = std::get_if<PosCamGen>(&a.gen[kPosCam])) pc->offset_base += d;
}

void Planner::end_position_cam(AxisRt& a, PosCamGen& g) noexcept {
  if (g.profile) {
    g.profile->release();  // CAM_PROFILE[0].Status: one user less
    g.profile = nullptr;
  }
  if (ControlTag* c = tag(g.owner)) c->set(flag::AC, false);
  fold(a, Slot::MasterOffset, true);  // a master offset move needs the cam it offsets
}

void Planner::drop_pending_pcam(AxisRt& a) noexcept {
  if (!a.cams.position.valid()) return;
  if (ControlTag* c = tag(a.cams.position.owner)) c->set(flag::IP, false);
  a.cams.position = PendingPosCam{};
}

void Planner::position_cam_status(const AxisRt& a, std::uint32_t& ms) const noexcept {
  using namespace motion_status;
  auto setb = [&](unsigned b, bool on) { if (on) ms |= 1u << b; };
  const auto* pc = std::get_if<PosCamGen>(&a.gen[kPosCam]);
  setb(PositionCamStatus, pc != nullptr);
  setb(PositionCamLockStatus, pc && pc->locked && pc->inside && !pc->slipping);
  setb(PositionCamPendingStatus, a.cams.position.valid());
  const auto* o = std::get_if<ProfileGen>(&a.gen[kOffset]);
  setb(MasterOffsetMoveStatus, o != nullptr);
  setb(MasterOffsetMoveLockStatus, o && o->master_driven && o->md.locked && o->md.following);
}

// -------------------------------------------------------------------- MAPC
Err Planner::start_mapc(const Request& r, const MapcParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, true); e != Err::None) return e;
  const AxisRt& m = axes_[p.master];
  if (!m.cfg.configured) return Err::AxisNotConfigured;
  if (m.cfg.inhibited) return Err::AxisIsInhibited;
  if (p.slave == p.master) return Err::MasterAxisConflict;
  {
    // the master must not follow the slave (gear, master-driven motion or time cam, position cam), directly or not
    std::array<std::uint8_t, kMaxAxes> seen{};
    std::array<AxisId, kMaxAxes> stack{};  // each axis is pushed at most once
    std::size_t sp = 0;
    stack[sp++] = p.master;
    seen[p.master] = 1;
    while (sp > 0) {
      const AxisId i = stack[--sp];
      for (const auto& s : axes_[i].gen) {
        const AxisId up = master_of(s);  // gear, master-driven motion or cam, position cam
        if (up == p.slave) return Err::MasterAxisConflict;
        if (up < kMaxAxes && !seen[up]) {
          seen[up] = 1;
          stack[sp++] = up;
        }
      }
    }
  }
  if (a.hs.homing || m.hs.homing) return Err::HomeInProcess;
  if (any_stopping(a)) return Err::NotAllowedWhileStopping;
  cam::CamProfile* prof = p.cam_profile < kMaxCamProfiles ? cam_profiles_[p.cam_profile] : nullptr;
  if (!prof || !prof->calculated()) return Err::CamProfileNotCalculated;
  const cam::CamScaling sc{p.slave_scaling, p.master_scaling};
  bool bad_slave = false, bad_master = false;
  if (cam::check_scaling(sc, bad_slave, bad_master) != cam::CamError::None) {
    exerr = static_cast<std::int8_t>(bad_slave ? kIdx.scaling_slave : kIdx.scaling_master);
    return Err::ParameterOutOfRange;
  }
  // CamLockPosition must lie inside the profile's master range [UM002F p.227]
  if (!(p.cam_lock_position >= prof->master_start() && p.cam_lock_position <= prof->master_end())) {
    exerr = static_cast<std::int8_t>(kIdx.cam_lock);
    return Err::ParameterOutOfRange;
  }
  const int dir = cam::resolve_direction(static_cast<std::int32_t>(p.direction), a.cams.position_dir);
  cam::CamMotionConfig cfg;
  cfg.mode = static_cast<cam::ExecutionMode>(p.execution_mode);
  cfg.scaling = sc;
  cfg.direction = dir;
  cfg.lock_position = p.cam_lock_position;
  cfg.use_lock_position = true;
  // a virtual master has no actual position: it always gives command [seed 000]
  const bool use_actual = p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive;
  ControlTag& c = controls_[r.control];
  const auto* active = std::get_if<PosCamGen>(&a.gen[kPosCam]);
  if (p.execution_schedule == kPending) {
    // takes over when the master leaves the current pass; the pending cam
    // continues the active cam's master coordinate, so it needs the same master
    if (active && (active->master != p.master || active->use_actual != use_actual)) return Err::MasterAxisConflict;
    drop_pending_pcam(a);  // a second pending MAPC overlays the first
    a.cams.position = PendingPosCam{prof, cfg, p.master, use_actual, p.master_direction, OwnerRef{r.control, c.generation}};
    a.cams.position_dir = dir;
    c.set(flag::DN, true);
    c.set(flag::IP, true);
    return Err::None;
  }
  if (active) return Err::IllegalDynamicChange;  // as MATC: only a pending cam may follow an active one
  PosCamGen g;
  if (prof->acquire() != cam::CamError::None) return Err::CamProfileNotCalculated;
  if (g.cm.start(*prof, cfg) != cam::CamError::None) {  // checked above; defensive
    prof->release();
    exerr = static_cast<std::int8_t>(kIdx.cam_lock);
    return Err::ParameterOutOfRange;
  }
  fold(a, Slot::PositionCam, true);
  const double mp = use_actual ? m.fb_pos : m.cmd.p;
  g.profile = prof;
  g.master = p.master;
  g.use_actual = use_actual;
  g.schedule = p.execution_schedule;
  g.master_dir = p.master_direction;
  g.master_lock = p.master_lock_position;
  g.locked = p.execution_schedule == kImmediate;
  g.prev_mp = mp;
  g.lock_mp = mp;
  g.owner = OwnerRef{r.control, c.generation};
  set_slot(a, Slot::PositionCam, g);
  a.cams.position_dir = dir;
  c.set(flag::DN, true);
  c.set(flag::IP, true);
  c.set(flag::AC, true);  // the active (not pending) position cam of the axis
  return Err::None;
}

void Planner::step_position_cam(AxisRt& a, PosCamGen& g) noexcept {
  const AxisRt& m = axes_[g.master];
  const double mp = g.use_actual ? m.fb_pos : m.cmd.p;
  double mv = g.use_actual ? m.fb_vel : m.cmd.v;
  double ma = g.use_actual ? 0.0 : m.cmd.a;
  if (!g.locked) {
    // forward / reverse / bidirectional: armed until the master crosses MasterLockPosition
    double at = 0.0;
    if (!crossed(g.prev_mp + m.frame_offset, mp + m.frame_offset, g.master_lock, g.schedule, m.cfg.rotary,
                 m.cfg.unwind, at)) {
      g.prev_mp = mp;
      g.k = Kin{};
      return;
    }
    g.locked = true;
    g.lock_mp = at - m.frame_offset;  // the cam coordinate counts from the lock position exactly
    g.prev_mp = g.lock_mp;
  }
  // master travel, as a slip clutch for forward / reverse only [RM002H p.171]
  const double dm = mp - g.prev_mp;
  g.prev_mp = mp;
  if (g.master_dir == kMasterForward) {
    g.travel += std::max(0.0, dm);
    g.slipping = dm < 0;
    if (!(dm > 0)) mv = ma = 0.0;
  } else if (g.master_dir == kMasterReverse) {
    g.travel += std::min(0.0, dm);
    g.slipping = dm > 0;
    if (!(dm < 0)) mv = ma = 0.0;
  } else {
    g.travel = mp - g.lock_mp;  // exact, no accumulated rounding
    g.slipping = false;
  }
  const Kin ko = slot_kin(a, Slot::MasterOffset);  // the master offset move (only a ProfileGen runs there)
  const double off = g.offset_base + ko.p, off_v = ko.v, off_a = ko.a;
  const double x = g.travel + off - g.x_shift;
  const cam::CamMotionOutput o = g.cm.step(x);
  const bool continuous = g.cm.config().mode == cam::ExecutionMode::Continuous;
  ControlTag* c = tag(g.owner);
  if (a.cams.position.valid()) {
    // the pending cam takes over where the master leaves the current pass
    // (its end, or its start when the master runs backwards) [RM002H p.180]
    bool take = false;
    double end = 0.0;
    if (continuous && o.pass != g.last_pass) {
      take = true;
      end = o.pass > g.last_pass ? g.cm.pass_end(g.last_pass) : g.cm.pass_end(g.last_pass - 1);
    } else if (!continuous && o.range != cam::CamRange::Inside && g.inside) {
      // (a Persistent cam already outside its range hands over when the master next leaves it)
      take = true;
      end = o.range == cam::CamRange::PastEnd ? g.cm.pass_end(0) : g.cm.pass_end(0) - g.cm.pass_length();
    }
    if (take) {
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
      if (c) {
        c->set(flag::IP, false);
        if (!continuous) c->set(flag::PC, true);  // Once: PC; Continuous: IP cleared [seed 004]
      }
      if (!pc.profile) {  // the profile was invalidated while pending: the cam ends at the pass end
        if (ControlTag* pt = tag(pc.owner)) pt->reject(Err::CamProfileNotCalculated);
        g.k = Kin{at_end.position, 0, 0};
        fold(a, Slot::PositionCam, false);
        return;
      }
      a.base += at_end.position;  // the new cam starts where the old one ended: no jump
      if (g.profile) g.profile->release();
      if (c) c->set(flag::AC, false);
      n.profile = pc.profile;
      n.master = pc.master;
      n.use_actual = pc.use_actual;
      n.schedule = kImmediate;
      n.master_dir = pc.master_dir;
      n.locked = true;
      n.offset_base = g.offset_base;
      const AxisRt& nm = axes_[n.master];
      const double nmp = n.use_actual ? nm.fb_pos : nm.cmd.p;
      n.prev_mp = nmp;
      if (n.master == g.master && n.use_actual == g.use_actual) {
        n.travel = g.travel;  // the same master coordinate, shifted by the pass end
        n.lock_mp = nmp - g.travel;
        n.x_shift = g.x_shift + end;
      } else {  // a cam preloaded for another master: starts at its lock position now
        n.lock_mp = nmp;
        n.x_shift = off;
      }
      n.owner = pc.owner;
      if (ControlTag* nc = tag(n.owner)) nc->set(flag::AC, true);
      PosCamGen& ng = set_slot(a, Slot::PositionCam, n);  // g is gone from here on
      step_position_cam(a, ng);
      return;
    }
  }
  g.last_pass = o.pass;
  g.inside = o.range == cam::CamRange::Inside;
  const double xd = mv + off_v, xdd = ma + off_a;
  g.k = Kin{o.position, o.velocity * xd, o.acceleration * xd * xd + o.velocity * xdd};
  if (c) c->segment = static_cast<std::int32_t>(o.segment);
  if (o.complete) {  // Once: PC, the slave holds the end position, PositionCamStatus cleared
    g.k.v = 0.0;
    g.k.a = 0.0;
    if (c) c->set(flag::PC, true);
    fold(a, Slot::PositionCam, true);
  }
}

}  // namespace canmotion::motion
