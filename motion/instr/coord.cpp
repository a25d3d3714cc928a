// Coordinated family (motion/instr/coord.hpp): MCLM, MCCM, MCS, MCSD, MCCD
// and MDCC on a coordinate system (seed 001, reference coordinated-motion.md).
// The path is motion/coord/PathGenerator; this file turns operands into its
// requests and its answers into control tag bits. Realtime-safe.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string_view>

#include "motion/instr/coord.hpp"
#include "motion/instr/ctx.hpp"

namespace canmotion::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Seed 001: a master change that leaves the slave system less than 10 % of
/// its speed is refused (ERR 103).
constexpr double kMinSpeedRatioOnMasterChange = 0.10;

/// True when the signature table numbers `keyword` of operand `operand` of
/// `I` as `value`: the typed operands below keep the Logix numbers.
template <Instr I, class E>
consteval bool numbered(std::string_view operand, std::string_view keyword, E value) {
  // operand_index, not op<I>: clang 14 refuses a consteval call on a
  // parameter of this consteval function (gcc accepts it).
  const int k = operand_index(I, operand);
  if (k < 0) return false;
  for (const EnumEntry& e : signature(I).operands[static_cast<std::size_t>(k)].enums)
    if (e.keyword == keyword) return e.value == static_cast<int>(value);
  return false;
}
// MCCM's MoveType, TerminationType and Merge are the same enumerations as MCLM's.
static_assert(numbered<Instr::MCLM>("MoveType", "absolute", MoveType::Absolute) &&
              numbered<Instr::MCLM>("MoveType", "incremental", MoveType::Incremental));
static_assert(numbered<Instr::MCLM>("TerminationType", "actualtolerance", coord::Termination::ActualTolerance) &&
              numbered<Instr::MCLM>("TerminationType", "nosettle", coord::Termination::NoSettle) &&
              numbered<Instr::MCLM>("TerminationType", "commandtolerance", coord::Termination::CommandTolerance) &&
              numbered<Instr::MCLM>("TerminationType", "nodecel", coord::Termination::NoDecel) &&
              numbered<Instr::MCLM>("TerminationType", "followcontourvelocityconstrained",
                                    coord::Termination::FollowContourVelocityConstrained) &&
              numbered<Instr::MCLM>("TerminationType", "followcontourvelocityunconstrained",
                                    coord::Termination::FollowContourVelocityUnconstrained) &&
              numbered<Instr::MCLM>("TerminationType", "commandtoleranceprogrammed",
                                    coord::Termination::CommandToleranceProgrammed));
static_assert(numbered<Instr::MCLM>("Merge", "disabled", coord::CoordMerge::Disabled) &&
              numbered<Instr::MCLM>("Merge", "coordinatedmotion", coord::CoordMerge::CoordinatedMotion) &&
              numbered<Instr::MCLM>("Merge", "allmotion", coord::CoordMerge::AllMotion));
static_assert(numbered<Instr::MCCM>("CircleType", "via", coord::CircleType::Via) &&
              numbered<Instr::MCCM>("CircleType", "center", coord::CircleType::Center) &&
              numbered<Instr::MCCM>("CircleType", "radius", coord::CircleType::Radius) &&
              numbered<Instr::MCCM>("CircleType", "centerincremental", coord::CircleType::CenterIncremental));
static_assert(numbered<Instr::MCCM>("Direction", "clockwise", coord::CircleDirection::Clockwise) &&
              numbered<Instr::MCCM>("Direction", "counterclockwise", coord::CircleDirection::CounterClockwise) &&
              numbered<Instr::MCCM>("Direction", "clockwisefull", coord::CircleDirection::ClockwiseFull) &&
              numbered<Instr::MCCM>("Direction", "counterclockwisefull", coord::CircleDirection::CounterClockwiseFull));
static_assert(numbered<Instr::MCS>("StopType", "all", CoordStopType::All) &&
              numbered<Instr::MCS>("StopType", "coordinatedmove", CoordStopType::CoordinatedMove) &&
              numbered<Instr::MCS>("StopType", "coordinatedtransform", CoordStopType::CoordinatedTransform));
static_assert(numbered<Instr::MCCD>("Scope", "activemotion", coord::ChangeScope::ActiveMotion) &&
              numbered<Instr::MCCD>("Scope", "activeandpendingmotion", coord::ChangeScope::ActiveAndPendingMotion));

/// Elements of a REAL array operand from its start index to the array's end
/// (empty for "none" or an index past the end).
std::span<const double> array_from(const Core& c, std::uint16_t ref, double start) noexcept {
  if (ref >= kMaxRealArrays) return {};
  const std::span<const double> a = c.real_arrays[ref];
  if (!(start >= 0) || start >= static_cast<double>(a.size())) return {};
  return a.subspan(static_cast<std::size_t>(start));
}

template <Instr I, class P>
P decode_move(const Operands& q) noexcept {
  P p;
  p.cs = q.ref(op<I>("CoordinateSystem"));
  p.move_type = q.enumeration<MoveType>(op<I>("MoveType"));
  p.position = q.ref(op<I>("Position"));
  p.position_start = q.real(op<I>("Position"));
  p.dyn = read_rates<I>(q);
  p.termination = q.enumeration<coord::Termination>(op<I>("TerminationType"));
  p.merge = q.enumeration<coord::CoordMerge>(op<I>("Merge"));
  p.merge_speed = q.enumeration<MergeSpeed>(op<I>("MergeSpeed"));
  p.command_tolerance = q.real(op<I>("CommandTolerance"));
  p.lock_position = q.real(op<I>("LockPosition"));
  p.lock_direction = q.enumeration<LockDirection>(op<I>("LockDirection"));
  p.event_distance = q.ref(op<I>("EventDistance"));
  p.event_distance_start = q.real(op<I>("EventDistance"));
  p.calculated_data = q.ref(op<I>("CalculatedData"));
  p.calculated_data_start = q.real(op<I>("CalculatedData"));
  return p;
}

/// The checks of a move on every member: ERR 11, 53, 7, 20, 5, 87; 39 when
/// a member runs a move of another coordinate system (an axis may belong to
/// several systems, moved by one at a time).
Err member_checks(const Core& c, const CoordSystemRt& s) noexcept {
  for (int i = 0; i < s.cfg.dim; ++i) {
    const AxisRt& a = c.axes[s.cfg.axes[static_cast<std::size_t>(i)]];
    if (Err e = c.common_checks(a, true); e != Err::None) return e;
    const auto* g = std::get_if<CoordGen>(&a.gen[index(Slot::Coord)]);
    if (g && &c.systems[g->cs] != &s) return Err::ProcessConflict;
  }
  return Err::None;
}

/// Seed 001, master change: the pending MDCC's master takes over when this
/// move goes IP. ERR 97 when the system moves and the new master is idle,
/// 103 when the new effective speed is below 10 % of the present one.
Err check_master_change(const Core& c, const CoordSystemRt& s, bool md, double speed) noexcept {
  if (!s.pending.valid() || !md || !s.path.moving()) return Err::None;
  coord::Present m;
  coordsys::master_state(c, s.pending, m);
  const double mv = std::fabs(m.master_velocity);
  if (!(mv > 0)) return Err::MdscIdleMasterSlaveMoving;
  if (mv * speed < kMinSpeedRatioOnMasterChange * s.path.speed()) return Err::MdscInvalidSlaveSpeedReduction;
  return Err::None;
}

/// The path request of an MCLM/MCCM, its REAL array operands read.
Err build_request(Ctx& x, const CoordMoveParams& p, const CoordSystemRt& s, coord::MoveRequest& rq) noexcept {
  const Instr in = p.circle ? Instr::MCCM : Instr::MCLM;
  const auto dim = static_cast<std::size_t>(s.cfg.dim);
  const std::span<const double> pos = array_from(x.c, p.position, p.position_start);
  if (pos.size() < dim) return x.reject_operand(operand_index(in, "Position"));
  rq.path.kind = p.circle ? coord::PathKind::Circle : coord::PathKind::Line;
  rq.path.incremental = p.move_type == MoveType::Incremental;
  for (std::size_t i = 0; i < dim; ++i) rq.path.position.c[i] = pos[i];
  if (p.circle) {
    const std::span<const double> aux = array_from(x.c, p.aux, p.aux_start);
    const std::size_t need = p.circle_type == coord::CircleType::Radius ? 1 : dim;
    if (aux.size() < need) return x.reject_operand(operand_index(in, "Via/Center/Radius"));
    for (std::size_t i = 0; i < need; ++i) rq.path.aux.c[i] = aux[i];
    rq.path.circle_type = p.circle_type;
    rq.path.direction = p.direction;
  }
  // Speed .. JerkUnits in coordination units (the jerks with an S-curve; a
  // %ofTime jerk of a zero-speed move refers to the system's max speed)
  units::RateRule rates = units::rule_for(s.cfg, false);  // the system's maxima
  rates.jerks = p.dyn.profile == ProfileType::SCurve;
  rates.idle_speed = s.cfg.max_speed;
  bool md = false;
  if (Err e = x.check(units::convert_rates(p.dyn, rates, rq.limits, md)); e != Err::None) return e;
  if (md == (p.lock_direction == LockDirection::None)) return Err::MdscLockDirConflict;
  if (md && !s.link.valid() && !s.pending.valid()) return Err::MdscNotActivated;
  if (p.termination == coord::Termination::CommandToleranceProgrammed && !(p.command_tolerance >= 0))
    return x.reject_operand(operand_index(in, "CommandTolerance"));
  rq.termination = p.termination;
  rq.command_tolerance = p.command_tolerance;
  rq.merge = p.merge;
  rq.merge_speed = p.merge_speed;
  rq.master_driven = md;
  rq.lock_direction = p.lock_direction;
  rq.lock_position = p.lock_position;
  return Err::None;
}

/// MCLM, MCCM.
Err run(Ctx& x, CoordSystemRt& s, const CoordMoveParams& p) noexcept {
  if (Err e = member_checks(x.c, s); e != Err::None) return e;
  coord::MoveRequest rq;
  if (Err e = build_request(x, p, s, rq); e != Err::None) return e;
  if (Err e = check_master_change(x.c, s, rq.master_driven, rq.limits.v); e != Err::None) return e;
  if (s.fold_due && !s.path.moving()) coordsys::settle(x.c, s);
  const MdccLink& link = s.pending.valid() ? s.pending : s.link;
  // an owner entry for the move (a free one always exists: the path holds at most 3 ids)
  auto it = std::find_if(s.owners.begin(), s.owners.end(), [](const auto& o) { return o.id == 0; });
  if (it == s.owners.end()) return Err::CoordinateSystemQueueFull;
  rq.id = s.next_id;
  coord::Events ev;
  if (Err e = s.path.submit(rq, coordsys::present(x.c, s, link), ev); e != Err::None) return e;
  if (s.pending.valid()) s.path.master_changed();  // the next step references the new master
  s.next_id = s.next_id == 0xFFFFFFFFu ? 1 : s.next_id + 1;
  *it = CoordSystemRt::Owner{rq.id, x.self, rq.master_driven, p.calculated_data, p.event_distance,
                             p.calculated_data_start, p.event_distance_start};
  if (s.pending.valid()) coordsys::take_pending_link(x.c, s);  // seed 001: the switch happens as this move goes IP
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
  coordsys::join_members(x.c, s);
  coordsys::apply_events(x.c, s, ev);
  return Err::None;
}

}  // namespace

MclmParams MclmParams::decode(const Operands& q) noexcept {
  MclmParams p;
  static_cast<CoordMoveParams&>(p) = decode_move<kInstr, CoordMoveParams>(q);
  return p;
}

MccmParams MccmParams::decode(const Operands& q) noexcept {
  MccmParams p;
  static_cast<CoordMoveParams&>(p) = decode_move<kInstr, CoordMoveParams>(q);
  p.circle = true;
  p.circle_type = q.enumeration<coord::CircleType>(op<kInstr>("CircleType"));
  p.aux = q.ref(op<kInstr>("Via/Center/Radius"));
  p.aux_start = q.real(op<kInstr>("Via/Center/Radius"));
  p.direction = q.enumeration<coord::CircleDirection>(op<kInstr>("Direction"));
  return p;
}


McsParams McsParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  McsParams p;
  p.cs = q.ref(op<I>("CoordinateSystem"));
  p.stop_type = q.enumeration<CoordStopType>(op<I>("StopType"));
  p.change_decel = q.yes(op<I>("ChangeDecel"));
  p.decel = q.real(op<I>("DecelRate"));
  p.decel_units = q.enumeration<AccelUnits>(op<I>("DecelUnits"));
  p.change_decel_jerk = q.yes(op<I>("ChangeDecelJerk"));
  p.decel_jerk = q.real(op<I>("DecelJerk"));
  p.jerk_units = q.enumeration<JerkUnits>(op<I>("JerkUnits"));
  return p;
}

static Err run(Ctx& x, CoordSystemRt& s, const McsParams& p) noexcept {
  constexpr Instr I = Instr::MCS;
  // the system's max decel; trapezoidal unless ChangeDecelJerk gives a jerk (README choices)
  double d = s.cfg.max_decel, jd = kInf;
  if (p.change_decel &&
      x.take(units::positive_rate(p.decel, p.decel_units, s.cfg.max_decel, op<I>("DecelRate")), d) != Err::None)
    return Err::ParameterOutOfRange;
  if (p.change_decel_jerk &&
      x.take(units::jerk(p.decel_jerk, p.jerk_units, d, std::max(s.path.speed(), 1e-9), s.cfg.max_decel_jerk,
                         op<I>("DecelJerk")), jd) != Err::None)
    return Err::ParameterOutOfRange;
  x.tag.set(flag::DN, true);
  if (p.stop_type == CoordStopType::CoordinatedTransform) {  // this project has no transforms
    x.tag.set(flag::PC, true);
    return Err::None;
  }
  if (p.stop_type == CoordStopType::All) {  // the members' single-axis motion too, and the MDCC links
    coordsys::break_links(x.c, s);
    for (int i = 0; i < s.cfg.dim; ++i) {
      AxisRt& a = x.c.axes[s.cfg.axes[static_cast<std::size_t>(i)]];
      const std::uint32_t others = kAllSlots & ~slot_bit(Slot::Coord);
      if (a.servo.on) x.c.stop_slots(a, others, a.cfg.max_decel > 0 ? a.cfg.max_decel : 1e12, kInf, kNoControl, 0);
    }
  }
  x.tag.set(flag::IP, true);
  coordsys::start_stop(x.c, s, x.self, d, jd);
  return Err::None;
}

McsdParams McsdParams::decode(const Operands& q) noexcept {
  McsdParams p;
  p.cs = q.ref(op<kInstr>("CoordinateSystem"));
  return p;
}

static Err run(Ctx& x, CoordSystemRt& s, const McsdParams&) noexcept {
  coordsys::drop(x.c, s);          // queue cleared, the moves' IP cleared
  coordsys::break_links(x.c, s);   // MDCC links broken
  for (int i = 0; i < s.cfg.dim; ++i) {
    AxisRt& a = x.c.axes[s.cfg.axes[static_cast<std::size_t>(i)]];
    x.c.do_shutdown(a);  // MASD on every member (MDS cancelled, MDAC links broken)
  }
  x.tag.set(flag::DN, true);
  return Err::None;
}

MccdParams MccdParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  MccdParams p;
  p.cs = q.ref(op<I>("CoordinateSystem"));
  p.change_speed = q.yes(op<I>("ChangeSpeed"));
  p.change_accel = q.yes(op<I>("ChangeAccel"));
  p.change_decel = q.yes(op<I>("ChangeDecel"));
  p.change_accel_jerk = q.yes(op<I>("ChangeAccelJerk"));
  p.change_decel_jerk = q.yes(op<I>("ChangeDecelJerk"));
  p.dyn = read_rates<I>(q);
  p.scope = q.enumeration<coord::ChangeScope>(op<I>("Scope"));
  return p;
}

static Err run(Ctx& x, CoordSystemRt& s, const MccdParams& p) noexcept {
  // the changed values in coordination units: all of one mode (94; the other
  // mode than the move's: 105, seed 001); a %ofTime jerk refers to the
  // system's max accel / decel to the larger of the path's and its max speed
  const CoordSystemConfig& cfg = s.cfg;
  units::RateRule rates = units::rule_for(cfg, false);
  rates.speed = p.change_speed;
  rates.accel = p.change_accel;
  rates.decel = p.change_decel;
  rates.jerks = p.change_accel_jerk || p.change_decel_jerk;
  rates.accel_jerk = p.change_accel_jerk;
  rates.decel_jerk = p.change_decel_jerk;
  rates.ramp = units::JerkRamp{cfg.max_accel, cfg.max_decel, std::max(s.path.speed(), cfg.max_speed)};
  coord::DynamicsChange ch;
  if (Err e = x.check(units::convert_rates(p.dyn, rates, ch.values, ch.master_driven)); e != Err::None) return e;
  ch.change_speed = p.change_speed;
  ch.change_accel = p.change_accel;
  ch.change_decel = p.change_decel;
  ch.change_accel_jerk = p.change_accel_jerk;
  ch.change_decel_jerk = p.change_decel_jerk;
  ch.scope = p.scope;
  coord::Events ev;
  if (Err e = s.path.change_dynamics(ch, ev); e != Err::None) return e;
  x.tag.set(flag::DN, true);
  coordsys::apply_events(x.c, s, ev);
  return Err::None;
}

MdccParams MdccParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  MdccParams p;
  p.cs = q.ref(op<I>("SlaveSystem"));
  p.master = q.ref(op<I>("MasterAxis"));
  p.master_reference = q.enumeration<MasterReference>(op<I>("MasterReference"));
  p.nominal_master_velocity = q.real(op<I>("NominalMasterVelocity"));
  return p;
}

static Err run(Ctx& x, CoordSystemRt& s, const MdccParams& p) noexcept {
  for (int i = 0; i < s.cfg.dim; ++i)
    if (s.cfg.axes[static_cast<std::size_t>(i)] == p.master) return Err::MasterAxisConflict;  // master in the slave system
  const AxisRt& m = x.c.axes[p.master];
  if (Err e = x.c.common_checks(m, false); e != Err::None && e != Err::AxisInFaultedState) return e;
  if (m.hs.homing) return Err::HomeInProcess;
  // a virtual master always gives its command position
  const MdccLink l{p.master, p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive,
                   x.self};
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
  if (s.link.valid() && s.link.master != p.master && s.path.moving()) {
    // seed 001: another master while the system runs a move: pending until the next MCLM/MCCM goes IP
    if (ControlTag* old = x.c.tag(s.pending.owner); old && !(s.pending.owner == x.self)) old->set(flag::IP, false);
    s.pending = l;
    return Err::None;
  }
  if (ControlTag* old = x.c.tag(s.link.owner); old && !(s.link.owner == x.self)) {
    old->set(flag::IP, false);
    old->set(flag::AC, false);
  }
  if (s.link.valid() && s.link.master != p.master) s.path.master_changed();
  s.link = l;
  coordsys::refresh_link_master(x.c, s);
  return Err::None;
}

namespace {
/// The coordinate system an execution names, handed to the instruction's
/// `run`; ERR 11 when it is not configured.
template <class P>
Err on_system(Ctx& x, const P& p) noexcept {
  if (p.cs >= kMaxCoordSystems || !x.c.systems[p.cs].present) return Err::AxisNotConfigured;
  return run(x, x.c.systems[p.cs], p);
}
}  // namespace

Err start(Ctx& x, const MclmParams& p) noexcept { return on_system(x, p); }
Err start(Ctx& x, const MccmParams& p) noexcept { return on_system(x, p); }
Err start(Ctx& x, const McsParams& p) noexcept { return on_system(x, p); }
Err start(Ctx& x, const McsdParams& p) noexcept { return on_system(x, p); }
Err start(Ctx& x, const MccdParams& p) noexcept { return on_system(x, p); }
Err start(Ctx& x, const MdccParams& p) noexcept { return on_system(x, p); }

}  // namespace canmotion::motion
