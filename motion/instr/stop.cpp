// Stop family (motion/instr/stop.hpp): MAS, MGS, MGSD, MGSR. The ramps are
// ProfileGens made by Core::stop_slots. Realtime-safe.
#include "motion/instr/stop.hpp"

#include <cmath>
#include <limits>

#include "motion/instr/coord.hpp"
#include "motion/instr/ctx.hpp"
#include "motion/instr/direct.hpp"
#include "motion/instr/home.hpp"
#include "motion/instr/mdac.hpp"
#include "motion/instr/position_cam.hpp"
#include "motion/instr/servo.hpp"
#include "motion/instr/time_cam.hpp"

namespace canmotion::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The slots an MAS StopType stops (none for home, tune, test and direct
/// control: no planner generator).
std::uint32_t stop_mask(StopType type) noexcept {
  switch (type) {
    case StopType::All: return kAllSlots;
    case StopType::Jog: return slot_bit(Slot::Jog);
    case StopType::Move: return slot_bit(Slot::Move);
    case StopType::Gear: return slot_bit(Slot::Gear);
    case StopType::TimeCam: return slot_bit(Slot::TimeCam);
    case StopType::PositionCam: return slot_bit(Slot::PositionCam);
    case StopType::MasterOffsetMove: return slot_bit(Slot::MasterOffset);
    default: return 0;
  }
}

/// MAS decel and decel jerk: the axis maxima or the operands (ChangeDecel /
/// ChangeDecelJerk yes); S-curve if any motion being stopped is S-curve.
Err mas_dynamics(Ctx& x, const MasParams& p, const AxisRt& a, std::uint32_t mask, double& d, double& jd) noexcept {
  d = a.cfg.max_decel;
  if (p.change_decel)
    if (Err e = x.take(units::positive_rate(p.decel_rate, p.decel_units, a.cfg.max_decel, op<Instr::MAS>("DecelRate")), d);
        e != Err::None)
      return e;
  if (!(d > 0)) return Err::ZeroMaxDecel;
  bool scurve = false;
  double speed = 0.0;
  for (const Slot s : kLegacySlotOrder) {  // the speed is a sum: in this order
    if (!(mask & slot_bit(s))) continue;
    if (auto* g = std::get_if<ProfileGen>(&a.gen[index(s)])) scurve = scurve || g->scurve;
    if (const GenBase* g = gen_base(a.gen[index(s)])) speed += g->k.v;
  }
  speed = std::fabs(speed);
  jd = a.cfg.max_decel_jerk;
  if (p.change_decel_jerk)
    if (Err e = x.take(units::jerk(p.decel_jerk, p.jerk_units, d, speed, a.cfg.max_decel_jerk, op<Instr::MAS>("DecelJerk")), jd);
        e != Err::None)
      return e;
  if (scurve && !(jd > 0)) return Err::ZeroMaxDecelJerk;
  if (!scurve) jd = kInf;
  return Err::None;
}

/// Each configured, not inhibited axis of a motion group.
template <class F>
void for_group(Core& c, std::uint16_t group, F&& f) noexcept {
  const auto grp = static_cast<std::uint8_t>(group);
  for (std::size_t i = 0; i < c.axis_count; ++i) {
    AxisRt& a = c.axes[i];
    if (!a.present || a.cfg.group != grp || !a.cfg.configured || a.cfg.inhibited) continue;
    f(a);
  }
}

}  // namespace

MasParams MasParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  return {q.ref(op<I>("Axis")),
          q.enumeration<StopType>(op<I>("StopType")),
          q.yes(op<I>("ChangeDecel")),
          q.real(op<I>("DecelRate")),
          q.enumeration<AccelUnits>(op<I>("DecelUnits")),
          q.yes(op<I>("ChangeDecelJerk")),
          q.real(op<I>("DecelJerk")),
          q.enumeration<JerkUnits>(op<I>("JerkUnits"))};
}
MgsParams MgsParams::decode(const Operands& q) noexcept {
  return {q.ref(op<kInstr>("Group")), q.enumeration<GroupStopMode>(op<kInstr>("StopMode"))};
}
MgsdParams MgsdParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Group"))}; }
MgsrParams MgsrParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Group"))}; }

// --------------------------------------------------------------------- MAS
Err start(Ctx& x, const MasParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  const StopType type = p.stop_type;
  // canmotion runs no tune or test process (CiA 402 drives tune and test with
  // their own tools): nothing MAS could stop; refused, ERR 13 at StopType
  // (motion/README.md, choices)
  if (type == StopType::Tune || type == StopType::Test) return x.reject_operand(op<Instr::MAS>("StopType"));
  const std::uint32_t mask = stop_mask(type);
  double d = 0.0, jd = 0.0;
  if (Err e = mas_dynamics(x, p, a, mask, d, jd); e != Err::None) return e;
  x.tag.set(flag::DN, true);
  if ((type == StopType::All || type == StopType::Home) && a.hs.homing) {
    home::cancel(x.c, a);
    if (a.cfg.type == AxisType::CipDrive) a.base = a.fb_pos;
  }
  const bool ramping = a.servo.on && mask != 0 && x.c.stop_slots(a, mask, d, jd, x.self.id, 0);
  if (type == StopType::All) {
    mdac::break_links(x.c, a);                    // MAS All on the slave breaks its MDAC links,
    coordsys::break_member_links(x.c, p.axis);    // and on a member its systems' MDCC links (seed 001)
  }
  if (type == StopType::All || type == StopType::TimeCam) time_cam::drop_pending(x.c, a);
  if (type == StopType::All || type == StopType::PositionCam) position_cam::drop_pending(x.c, a);
  if ((type == StopType::All || type == StopType::DirectControl) && a.direct.active) {
    direct::begin_stop(x.c, a, x.self);  // the drive ramps the direct command to zero; PC at standstill
    x.tag.set(flag::IP, true);
    return Err::None;
  }
  x.tag.set(ramping ? flag::IP : flag::PC, true);
  return Err::None;
}

// --------------------------------------------------------- MGS, MGSD, MGSR
Err start(Ctx& x, const MgsParams& p) noexcept {
  bool ramping = false;
  for_group(x.c, p.group, [&](AxisRt& a) noexcept {
    const ProgrammedStopMode m = p.mode == GroupStopMode::FastStop      ? ProgrammedStopMode::FastStop
                                 : p.mode == GroupStopMode::FastDisable ? ProgrammedStopMode::FastDisable
                                                                        : a.cfg.programmed_stop_mode;
    const bool r_ax = stop::programmed_stop(x.c, a, m, x.self.id);  // MGS breaks the MDAC links of its slaves
    ramping = ramping || r_ax;
  });
  x.tag.set(flag::DN, true);
  if (ramping) {
    x.tag.set(flag::IP, true);
    const auto grp = static_cast<std::uint8_t>(p.group);
    x.c.groups[grp] = GroupOp{x.self, grp, true};
  } else {
    x.tag.set(flag::PC, true);
  }
  return Err::None;
}

Err start(Ctx& x, const MgsdParams& p) noexcept {
  for_group(x.c, p.group, [&](AxisRt& a) noexcept { x.c.do_shutdown(a); });
  x.tag.set(flag::DN, true);
  return Err::None;
}

Err start(Ctx& x, const MgsrParams& p) noexcept {
  // DN when every CIP drive of the group has left Fault (servo::reset_feedback
  // sets it with the last one), at once if none has to.
  bool waiting = false;
  for_group(x.c, p.group, [&](AxisRt& a) noexcept {
    a.servo.shutdown = false;
    if (!servo::reset_faults(x.c, a, x.self, x.r.instr)) waiting = true;
  });
  if (!waiting) x.tag.set(flag::DN, true);
  return Err::None;
}

namespace stop {

void finish_group_stops(Core& c) noexcept {
  for (auto& g : c.groups) {
    if (!g.active) continue;
    bool any = false;
    for (std::size_t i = 0; i < c.axis_count && !any; ++i)
      for (const auto& s : c.axes[i].gen)
        if (auto* p = std::get_if<ProfileGen>(&s); p && p->owner == g.owner) any = true;
    any = any || coordsys::stop_owned_by(c, g.owner);  // a coordinate system still stops along its path
    if (!any) {
      if (ControlTag* t = c.tag(g.owner)) {
        t->set(flag::IP, false);
        t->set(flag::PC, true);
      }
      g.active = false;
    }
  }
}

bool programmed_stop(Core& c, AxisRt& a, ProgrammedStopMode m, ControlId owner) noexcept {
  if (a.hs.homing) home::cancel(c, a);
  mdac::break_links(c, a);
  coordsys::break_member_links(c, c.id_of(a));  // MGS on a member breaks the MDCC links (seed 001)
  if (m == ProgrammedStopMode::HardDisable) {
    c.servo_off(a);
    return false;
  }
  if (m == ProgrammedStopMode::HardShutdown) {
    c.do_shutdown(a);
    return false;
  }
  const std::uint8_t post = m == ProgrammedStopMode::FastDisable ? 1 : (m == ProgrammedStopMode::FastShutdown ? 2 : 0);
  const bool ramp = a.servo.on && c.stop_all(a, owner, post);
  if (!ramp) {
    if (post == 1) c.servo_off(a);
    if (post == 2) c.do_shutdown(a);
  }
  return ramp;
}

void change_mode(Core& c, bool program) noexcept {
  for (std::size_t i = 0; i < c.axis_count; ++i) {
    AxisRt& a = c.axes[i];
    if (!a.present) continue;
    mdac::break_links(c, a);  // a mode change breaks every link, on slaves and masters alike [seed 000]
    if (!program || !a.cfg.configured || a.cfg.inhibited) continue;
    time_cam::drop_pending(c, a);
    position_cam::drop_pending(c, a);
    (void)programmed_stop(c, a, a.cfg.programmed_stop_mode, kNoControl);
  }
}

}  // namespace stop
}  // namespace canmotion::motion
