// Move family (motion/instr/move.hpp): MAM, MAJ, MCD and ProfileGen.
// Master offset moves (MAM MoveType 5/6) run here too, in Slot::MasterOffset,
// in the units of the position cam's master (motion/instr/position_cam.cpp).
// Realtime-safe.
#include "motion/instr/move.hpp"

#include <cmath>
#include <limits>

#include "motion/instr/coord.hpp"
#include "motion/instr/ctx.hpp"
#include "motion/instr/mdac.hpp"
#include "motion/instr/position_cam.hpp"

namespace canmotion::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Speed .. LockDirection of MAM or MAJ.
template <Instr I>
Dynamics read_dynamics(const Operands& q) noexcept {
  Dynamics y;
  static_cast<RateOperands&>(y) = read_rates<I>(q);
  y.merge = q.enumeration<Merge>(op<I>("Merge"));
  y.merge_speed = q.enumeration<MergeSpeed>(op<I>("MergeSpeed"));
  y.lock_position = q.real(op<I>("LockPosition"));
  y.lock_direction = q.enumeration<LockDirection>(op<I>("LockDirection"));
  return y;
}

/// Decoded dynamics of MAM/MAJ in axis (or master) units.
struct Dyn {
  Limits lim{};
  double speed = 0.0;  ///< programmed speed, units/s (0 allowed: paused)
  bool scurve = false;
  bool seconds = false;  ///< Seconds / MasterUnits: the times (master distances) of the move
  bool merge = false;
  bool merge_current = false;
  double t_total = 0, t_acc = 0, t_dec = 0, tj_acc = 0, tj_dec = 0;  // seconds units
  JerkUnits jerk_units = JerkUnits::UnitsPerSec3;
  double jerk_pct_a = 0, jerk_pct_d = 0;  // % of time (applied once the start speed is known)
  bool master_driven = false;  ///< units per master unit / master units: MDSC
  LockDirection lock = LockDirection::None;
  double lock_pos = 0.0;
};

/// Seconds (master units, master driven) for Speed, Accel, Decel and (S-curve)
/// Jerk: all or nothing [RM002H p.447].
Err decode_extent(Ctx& x, const Dynamics& y, bool md, Dyn& d) noexcept {
  if (!is_extent(y.speed_units, md)) return x.reject_operand(y.at.speed_units);
  if (!is_extent(y.accel_units, md)) return x.reject_operand(y.at.accel_units);
  if (!is_extent(y.decel_units, md)) return x.reject_operand(y.at.decel_units);
  if (d.scurve && !is_extent(y.jerk_units, md)) return x.reject_operand(y.at.jerk_units);
  d.seconds = true;
  d.t_total = y.speed;
  d.t_acc = y.accel;
  d.t_dec = y.decel;
  if (!(y.speed > 0)) return x.reject_operand(y.at.speed);
  if (y.accel + y.decel > y.speed) return x.reject_operand(y.at.accel);
  if (d.scurve) {
    if (!(y.accel_jerk >= 0) || y.accel_jerk > y.accel / 2) return x.reject_operand(y.at.accel_jerk);
    if (!(y.decel_jerk >= 0) || y.decel_jerk > y.decel / 2) return x.reject_operand(y.at.decel_jerk);
    d.tj_acc = y.accel_jerk;
    d.tj_dec = y.decel_jerk;
  }
  return Err::None;
}

Err decode_dynamics(Ctx& x, const Dynamics& y, const AxisConfig& cfg, double last_speed, Dyn& d) noexcept {
  d.scurve = y.profile == ProfileType::SCurve;
  d.merge = y.merge == Merge::Enabled;
  d.merge_current = y.merge_speed == MergeSpeed::Current;
  units::RateRule rule = units::rule_for(cfg, true);  // the axis' (or the cam master's) maxima
  rule.jerks = d.scurve;
  rule.idle_speed = last_speed;  // [RM002H p.447]: a zero-speed S-curve uses the previous non-zero speed (% of time)
  bool md = false;
  if (Err e = units::rates_mode(y, rule, md); e != Err::None) return e;
  // LockDirection: none in time-driven mode, not none in master-driven mode [RM002H p.512]
  if (md == (y.lock_direction == LockDirection::None)) return Err::MdscLockDirConflict;
  d.master_driven = md;
  d.lock = y.lock_direction;
  d.lock_pos = y.lock_position;
  if (is_extent(y.speed_units, md) || is_extent(y.accel_units, md) || is_extent(y.decel_units, md) ||
      (d.scurve && is_extent(y.jerk_units, md)))
    return decode_extent(x, y, md, d);
  if (Err e = x.check(units::convert_rates(y, rule, d.lim, md)); e != Err::None) return e;
  d.speed = d.lim.v;
  d.jerk_units = y.jerk_units;
  if (d.scurve && is_percent_of_time(y.jerk_units)) {  // applied again once the start speed is known
    d.jerk_pct_a = y.accel_jerk;
    d.jerk_pct_d = y.decel_jerk;
  }
  return Err::None;
}

/// The motion a new move or jog continues from: all motion when merging,
/// else the one it replaces. S-curve motion hands over its acceleration;
/// trapezoidal motion steps its acceleration anyway, so it hands over a = 0.
Kin start_state(const Core& c, const AxisRt& a, bool merge, const ProfileGen* old) noexcept {
  if (merge) return Kin{0, a.cmd.v, c.any_scurve(a) ? a.cmd.a : 0.0};
  if (old) return Kin{0, old->k.v, old->scurve ? old->k.a : 0.0};
  return Kin{};
}

/// Master-driven motion: the profile runs over master travel.
Err follow_master(Ctx& x, AxisRt& a, std::size_t lnk, const Dyn& dy, ProfileGen& g, Kin& start) noexcept {
  if (!dy.master_driven) return Err::None;
  g.md.lock = dy.lock;
  g.md.lock_pos = dy.lock_pos;
  return mdac::master_driven_setup(x.c, a, lnk, g, start);
}

/// Put a planned move or jog in place: the generator it replaces (merging:
/// every generator) folded, g in `slot` owned by this execution, DN and IP.
void commit(Ctx& x, AxisRt& a, Slot slot, std::size_t lnk, bool merge, ProfileGen& g) noexcept {
  if (merge) {
    for (std::size_t s = 0; s < kSlots; ++s) x.c.fold(a, static_cast<Slot>(s), true);
  } else {
    x.c.fold(a, slot, true);
  }
  g.t0_cycle = x.c.cycle;
  g.owner = x.self;
  mdac::promote_pending(x.c, a, lnk);
  if (g.master_driven) {
    x.tag.set(flag::AC, true);
    if (ControlTag* m = x.c.tag(g.md.mdac)) m->set(flag::AC, true);
  }
  x.c.set_slot(a, slot, g);
  if (g.speed > 0) a.last_speed = g.speed;
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
}

// ------------------------------------------------------------------- MAM
/// Distance of a MAM from the present command (or master offset).
double mam_distance(const Core& c, const AxisRt& a, MoveType mt, double pos, const ProfileGen* old) noexcept {
  const double cur = c.user_command(a);
  const double U = a.cfg.unwind;
  double L = 0;
  switch (mt) {
    case MoveType::Absolute: L = pos - (a.cfg.rotary ? unwind_position(cur, U) : cur); break;
    case MoveType::Incremental:
      L = pos;
      if (old && old->move_type == MoveType::Incremental) L += old->total - old->k.p;  // added to the previous target
      break;
    case MoveType::RotaryShortest: {
      L = pos - unwind_position(cur, U);
      L -= U * std::floor(L / U + 0.5);
      if (L >= U / 2) L -= U;
      break;
    }
    case MoveType::RotaryPositive:
      L = pos - unwind_position(cur, U);
      if (L < 0) L += U;
      break;
    case MoveType::RotaryNegative:
      L = pos - unwind_position(cur, U);
      if (L > 0) L -= U;
      break;
    case MoveType::AbsoluteMasterOffset: L = pos - position_cam::master_offset(a); break;
    case MoveType::IncrementalMasterOffset:
      L = pos;
      if (old && old->move_type == MoveType::IncrementalMasterOffset) L += old->total - old->k.p;
      break;
  }
  return L;
}

/// Limits of a move of distance L given in seconds: it takes exactly the
/// programmed time.
void seconds_limits(const Dyn& dy, double L, ProfileGen& g) noexcept {
  const double Ld = std::fabs(L);
  const double V = Ld / (dy.t_total - dy.t_acc / 2 - dy.t_dec / 2);
  if (Ld == 0 || !(V > 0) || !std::isfinite(V)) {
    g.lim = Limits{1, 1, 1, kInf, kInf};
  } else {
    g.lim.v = V;
    g.lim.a = V / (dy.t_acc - dy.tj_acc);
    g.lim.d = V / (dy.t_dec - dy.tj_dec);
    g.lim.ja = dy.scurve && dy.tj_acc > 0 ? g.lim.a / dy.tj_acc : kInf;
    g.lim.jd = dy.scurve && dy.tj_dec > 0 ? g.lim.d / dy.tj_dec : kInf;
    if (!std::isfinite(g.lim.a) || !std::isfinite(g.lim.d)) {  // zero accel/decel time: as fast as possible
      g.lim.a = std::isfinite(g.lim.a) ? g.lim.a : 1e12;
      g.lim.d = std::isfinite(g.lim.d) ? g.lim.d : 1e12;
    }
  }
  g.speed = g.lim.v;
  g.seconds = true;
}

/// Limits of a move given in rates (a merge at current speed keeps it).
void rate_limits(const Dyn& dy, const Kin& start, ProfileGen& g) noexcept {
  double V = dy.speed;
  if (dy.merge && dy.merge_current && std::fabs(start.v) > 0) V = std::fabs(start.v);
  g.lim = dy.lim;
  g.lim.v = V;
  g.speed = V;
  if (dy.scurve && is_percent_of_time(dy.jerk_units) && V > 0) {
    g.lim.ja = jerk_from_percent_of_time(g.lim.a, V, dy.jerk_pct_a);
    g.lim.jd = jerk_from_percent_of_time(g.lim.d, V, dy.jerk_pct_d);
  }
}

}  // namespace

// ------------------------------------------------------------------ decode
MajParams MajParams::decode(const Operands& q) noexcept {
  return {q.ref(op<kInstr>("Axis")), q.yes(op<kInstr>("Direction")), read_dynamics<kInstr>(q)};
}

MamParams MamParams::decode(const Operands& q) noexcept {
  MamParams m;
  m.axis = q.ref(op<kInstr>("Axis"));
  m.move_type = q.enumeration<MoveType>(op<kInstr>("MoveType"));
  m.position = q.real(op<kInstr>("Position"));
  m.dyn = read_dynamics<kInstr>(q);
  m.event_distance = q.ref(op<kInstr>("EventDistance"));
  m.calculated_data = q.ref(op<kInstr>("CalculatedData"));
  m.event_distance_start = q.real(op<kInstr>("EventDistance"));
  m.calculated_data_start = q.real(op<kInstr>("CalculatedData"));
  return m;
}

McdParams McdParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  McdParams m;
  m.axis = q.ref(op<I>("Axis"));
  m.jog = q.number(op<I>("MotionType")) == 0;
  m.change_speed = q.yes(op<I>("ChangeSpeed"));
  m.speed = q.real(op<I>("Speed"));
  m.change_accel = q.yes(op<I>("ChangeAccel"));
  m.accel = q.real(op<I>("AccelRate"));
  m.change_decel = q.yes(op<I>("ChangeDecel"));
  m.decel = q.real(op<I>("DecelRate"));
  m.change_accel_jerk = q.yes(op<I>("ChangeAccelJerk"));
  m.accel_jerk = q.real(op<I>("AccelJerk"));
  m.change_decel_jerk = q.yes(op<I>("ChangeDecelJerk"));
  m.decel_jerk = q.real(op<I>("DecelJerk"));
  m.speed_units = q.enumeration<SpeedUnits>(op<I>("SpeedUnits"));
  m.accel_units = q.enumeration<AccelUnits>(op<I>("AccelUnits"));
  m.decel_units = q.enumeration<AccelUnits>(op<I>("DecelUnits"));
  m.jerk_units = q.enumeration<JerkUnits>(op<I>("JerkUnits"));
  return m;
}

// --------------------------------------------------------------------- MAJ
Err start(Ctx& x, const MajParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  if (x.c.any_stopping(a)) return Err::NotAllowedWhileStopping;
  Dyn dy;
  if (Err e = decode_dynamics(x, p.dyn, a.cfg, a.last_speed, dy); e != Err::None) return e;
  if (dy.seconds) return x.reject_operand(op<Instr::MAJ>("SpeedUnits"));
  const double dir = p.reverse ? -1.0 : 1.0;
  if (dir > 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitPositive & 1u)) return Err::OvertravelCondition;
  if (dir < 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitNegative & 1u)) return Err::OvertravelCondition;
  Kin start = start_state(x.c, a, dy.merge, std::get_if<ProfileGen>(&a.gen[index(Slot::Jog)]));
  double V = dy.speed;
  if (dy.merge && dy.merge_current && std::fabs(start.v) > 0) V = std::fabs(start.v);
  if (dy.scurve && is_percent_of_time(dy.jerk_units)) {
    // [UM003F p.258]: decel jerk uses max(Speed, |StartSpeed - Speed|)
    const double vref = V > 0 ? V : a.last_speed;
    dy.lim.ja = jerk_from_percent_of_time(dy.lim.a, vref, dy.jerk_pct_a);
    dy.lim.jd = jerk_from_percent_of_time(dy.lim.d, std::max(vref, std::fabs(std::fabs(start.v) - V)), dy.jerk_pct_d);
  }
  ProfileGen g;
  g.role = GenRole::Jog;
  if (Err e = follow_master(x, a, link::Jog, dy, g, start); e != Err::None) return e;
  g.lim = dy.lim;
  g.lim.v = V > 0 ? V : 1.0;
  if (!plan_velocity(g.prof, start, dir * V, g.lim)) return x.reject_operand(op<Instr::MAJ>("Speed"));
  g.k = start;
  g.scurve = dy.scurve;
  g.speed = V;
  g.jog_velocity = dir * V;
  commit(x, a, Slot::Jog, link::Jog, dy.merge, g);
  return Err::None;
}

// --------------------------------------------------------------------- MAM
Err start(Ctx& x, const MamParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  if (x.c.any_stopping(a)) return Err::NotAllowedWhileStopping;
  const MoveType mt = p.move_type;
  // master offset moves (5/6) shift the master of the active position cam:
  // Slot::MasterOffset, master units, the MDAC link of master offset moves
  const bool offset = mt == MoveType::AbsoluteMasterOffset || mt == MoveType::IncrementalMasterOffset;
  const AxisConfig* ucfg = offset ? position_cam::master_config(x.c, a) : &a.cfg;
  if (!ucfg) return Err::PositionCamNotEnabled;
  const Slot slot = offset ? Slot::MasterOffset : Slot::Move;
  const std::size_t lnk = offset ? link::MasterOffsetMove : link::Move;
  Dyn dy;
  if (Err e = decode_dynamics(x, p.dyn, *ucfg, a.last_speed, dy); e != Err::None) return e;
  if (offset) dy.merge = false;  // a merge would end the cam it offsets: ignored (README)
  if (mt == MoveType::RotaryShortest || mt == MoveType::RotaryPositive || mt == MoveType::RotaryNegative) {
    if (!a.cfg.rotary) return Err::AxisModeNotRotary;
    if (p.position < 0 || p.position >= a.cfg.unwind) return x.reject_operand(op<Instr::MAM>("Position"));
  }
  auto* old = std::get_if<ProfileGen>(&a.gen[index(slot)]);
  if (old && old->role != GenRole::Move) old = nullptr;
  Kin start = start_state(x.c, a, dy.merge, old);
  const Kin rest = offset ? (old ? old->k : Kin{}) : a.cmd;
  if (dy.seconds && (rest.v != 0 || rest.a != 0)) return Err::AxisNotAtRest;
  if (Err e = move::check_event_distance(x, p); e != Err::None) return e;
  const double L = mam_distance(x.c, a, mt, p.position, old);
  if (!offset && L > 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitPositive & 1u)) return Err::OvertravelCondition;
  if (!offset && L < 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitNegative & 1u)) return Err::OvertravelCondition;
  ProfileGen g;
  g.role = GenRole::Move;
  if (Err e = follow_master(x, a, lnk, dy, g, start); e != Err::None) return e;
  if (dy.seconds) seconds_limits(dy, L, g);
  else rate_limits(dy, start, g);
  bool ok;
  if (g.speed > 0) {
    ok = plan_move(g.prof, start, L, g.lim, Overshoot::Reverse);
  } else {  // zero speed: ramp to a halt and wait for MCD
    Limits l = g.lim;
    l.v = 1.0;
    ok = plan_velocity(g.prof, start, 0.0, l);
  }
  if (!ok) return x.reject_operand(op<Instr::MAM>("Speed"));
  g.k = start;
  g.total = L;
  g.target_user = p.position;
  g.exact_target = mt == MoveType::Absolute && !a.cfg.rotary;
  g.move_type = mt;
  g.scurve = dy.scurve;
  move::write_calculated_data(x, p, g);  // move_events.cpp
  commit(x, a, slot, lnk, dy.merge, g);
  return Err::None;
}

// --------------------------------------------------------------------- MCD
namespace {

/// MCD's new limits from the old ones (each only if its Change operand says yes).
Err mcd_limits(Ctx& x, const McdParams& p, const AxisRt& a, const ProfileGen& g, Limits& lim, double& V) noexcept {
  constexpr Instr I = Instr::MCD;
  if (p.change_speed) V = units::rate(p.speed, p.speed_units, a.cfg.max_speed);
  if (p.change_accel)
    if (Err e = x.take(units::positive_rate(p.accel, p.accel_units, a.cfg.max_accel, op<I>("AccelRate")), lim.a);
        e != Err::None)
      return e;
  if (p.change_decel) {
    const units::Converted d = units::positive_rate(p.decel, p.decel_units, a.cfg.max_decel, op<I>("DecelRate"));
    if (!d.ok()) return x.take(d, lim.d);
    if (p.decel_units == AccelUnits::PercentOfMaximum && !(a.cfg.max_decel > 0)) return Err::ZeroMaxDecel;
    lim.d = d.value;
  }
  if (!g.scurve || !(p.change_accel_jerk || p.change_decel_jerk)) return Err::None;
  const double vref = V > 0 ? V : a.last_speed;
  const JerkUnits ju = p.jerk_units;
  if (p.change_accel_jerk) {
    if (Err e = x.take(units::jerk(p.accel_jerk, ju, lim.a, vref, a.cfg.max_accel_jerk, op<I>("AccelJerk")), lim.ja);
        e != Err::None)
      return e;
    if (!is_percent_of_time(ju) && !(lim.ja > 0)) return Err::ParameterOutOfRange;
  }
  if (p.change_decel_jerk) {
    if (Err e = x.take(units::jerk(p.decel_jerk, ju, lim.d, vref, a.cfg.max_decel_jerk, op<I>("DecelJerk")), lim.jd);
        e != Err::None)
      return e;
    if (!is_percent_of_time(ju) && !(lim.jd > 0)) return Err::ZeroMaxDecelJerk;
  }
  return Err::None;
}

/// The state of `g` on its profile's abscissa: time, or master travel for
/// master-driven motion (velocity per master unit, acceleration per master
/// unit squared: the profile's own sample at md.u).
Kin abscissa_state(const ProfileGen& g) noexcept {
  if (!g.master_driven) return g.k;
  int h = g.hint;
  const Kin ku = g.prof.sample(g.md.u, h);
  return Kin{g.k.p, ku.v, ku.a};
}

/// Re-plan the move or jog `g` from its present state with limits `l`
/// (per second, or per master unit when master driven).
bool mcd_replan(bool jog, const ProfileGen& g, double V, const Limits& l, Profile& prof) noexcept {
  const Kin now = abscissa_state(g);
  Kin from = now;
  if (!g.scurve) from.a = 0.0;  // trapezoidal motion steps its acceleration
  if (jog) return plan_velocity(prof, from, (g.jog_velocity < 0 ? -1.0 : 1.0) * V, l);
  if (!(V > 0)) return plan_velocity(prof, from, 0.0, l);  // speed 0: pause
  // Limits dropped mid-move: stop exactly on target, never past it (README).
  // Unless the move was already going to pass the target with its old
  // limits (a merge from motion away from it): then it keeps reversing.
  Overshoot policy = Overshoot::StopAtTarget;
  Profile probe;
  if (plan_stop(probe, now, g.lim.d, g.lim.jd)) {
    const double rem = g.total - now.p;
    const double stop = probe.end_position() - now.p;
    if ((rem >= 0 && stop > rem) || (rem < 0 && stop < rem) || now.v * rem < 0) policy = Overshoot::Reverse;
  }
  return plan_move(prof, from, g.total - g.k.p, l, policy);
}

}  // namespace

Err start(Ctx& x, const McdParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, true); e != Err::None) return e;
  const bool chj = p.change_accel_jerk || p.change_decel_jerk;
  bool md = false;
  if (Err e = units::changed_units_mode(p.change_speed, p.speed_units, p.change_accel, p.accel_units, p.change_decel,
                                        p.decel_units, chj, p.jerk_units, md);
      e != Err::None)
    return e;
  const bool td = !md && (p.change_speed || p.change_accel || p.change_decel || chj);  // time-driven units changed
  auto* g = std::get_if<ProfileGen>(&a.gen[index(p.jog ? Slot::Jog : Slot::Move)]);
  if (!g || g->role != (p.jog ? GenRole::Jog : GenRole::Move)) {
    // nothing to change; master-driven units still need an MDAC link of that motion type
    const std::size_t lnk = p.jog ? link::Jog : link::Move;
    if (md && !a.links.active[lnk].valid() && !a.links.pending[lnk].valid()) return Err::MdscNotActivated;
    x.tag.set(flag::DN, true);
    return Err::None;
  }
  if (g->seconds) return Err::IllegalDynamicChange;
  // the units must be in the mode of the running motion: MCD does not switch
  // between master- and time-driven (as MCCD: MDSC_INVALID_MODE_OR_MASTER_CHANGE [seed 001])
  if ((md && !g->master_driven) || (td && g->master_driven)) return Err::MdscInvalidModeOrMasterChange;
  Limits lim = g->lim;
  double V = g->speed;
  if (Err e = mcd_limits(x, p, a, *g, lim, V); e != Err::None) return e;
  Limits l = lim;
  l.v = V > 0 ? V : 1.0;
  Profile prof;
  if (!mcd_replan(p.jog, *g, V, l, prof)) return x.reject_operand(op<Instr::MCD>("Speed"));
  g->prof = prof;
  g->hint = 0;
  g->t0_cycle = x.c.cycle;
  g->md.u = 0.0;  // master driven: the new profile starts at the master travel of now (no jump)
  g->lim = l;
  g->speed = V;
  if (p.jog) g->jog_velocity = (g->jog_velocity < 0 ? -1.0 : 1.0) * V;
  if (V > 0) a.last_speed = V;
  x.tag.set(flag::DN, true);
  return Err::None;
}

// -------------------------------------------------------------- ProfileGen
void ProfileGen::finish(Core& c, AxisRt& a, Slot s, ControlTag* t) noexcept {
  if (role == GenRole::Move) {
    const bool alone = (a.live & ~slot_bit(s)) == 0;  // no other live slot
    k = Kin{total, 0, 0};
    if (alone && exact_target) {
      a.base = target_user - a.frame_offset;  // ends exactly on the programmed target
      k.p = 0;
    }
  }
  const std::uint8_t post = post_stop;
  // ramps of an MGS: the MGS gets PC when every axis of its group stopped;
  // an MAS All whose coordinate system still stops along its path: PC then
  const bool later = c.group_owns(owner) || (role == GenRole::Stop && coordsys::stop_owned_by(c, owner));
  if (t && !later) {
    t->set(flag::PC, true);
    t->set(flag::ACCEL, false);
    t->set(flag::DECEL, false);
  }
  c.fold(a, s, !later);  // *this is gone from here on
  if (post == 1) c.servo_off(a);
  if (post == 2) c.do_shutdown(a);
}

void ProfileGen::on_fold(Core& c, AxisRt&) noexcept {
  if (master_driven)  // a master-driven move/jog/offset move: its MDAC is no longer active
    if (ControlTag* m = c.tag(md.mdac)) m->set(flag::AC, false);
}

}  // namespace canmotion::motion
