// Home family (motion/instr/home.hpp): MAH and MRP. Realtime-safe.
#include "motion/instr/home.hpp"

#include "motion/instr/coord.hpp"
#include "motion/instr/ctx.hpp"

namespace canmotion::motion {

MahParams MahParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Axis"))}; }

MrpParams MrpParams::decode(const Operands& q) noexcept {
  return {q.ref(op<kInstr>("Axis")), q.yes(op<kInstr>("Type")), q.yes(op<kInstr>("PositionSelect")),
          q.real(op<kInstr>("Position"))};
}

Err start(Ctx& x, const MahParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, false); e != Err::None) return e;
  if (Err e = coordsys::check_no_coordinated_motion(x.c, a); e != Err::None) return e;  // ERR 52
  if (a.direct.status) return Err::NotAllowedWhileInDirectMotion;
  if (a.hs.homing) return Err::HomeInProcess;
  const HomingConfig& h = a.cfg.homing;
  if (a.cfg.rotary && (h.home_position < 0 || h.home_position >= a.cfg.unwind)) return Err::IllegalHomingConfig;
  if (h.mode == HomingConfig::Mode::Absolute && h.sequence != HomingConfig::Sequence::Immediate)
    return Err::IllegalHomingConfig;
  if (h.mode == HomingConfig::Mode::Absolute && a.servo.on) return Err::ServoOnState;
  if (h.mode == HomingConfig::Mode::Active && !a.servo.on) return Err::ServoOffState;
  const bool immediate = h.sequence == HomingConfig::Sequence::Immediate || a.cfg.type == AxisType::Virtual;
  if (!immediate && h.mode == HomingConfig::Mode::Passive) return Err::IllegalHomingConfig;
  if (h.mode == HomingConfig::Mode::Active) x.c.abort_all(a);  // active homing cancels other motion
  x.tag.set(flag::DN, true);
  if (immediate) {
    const double ref = h.mode == HomingConfig::Mode::Active ? x.c.user_command(a) : a.fb_pos + a.frame_offset;
    const double delta = h.home_position - (a.cfg.rotary ? unwind_position(ref, a.cfg.unwind) : ref);
    a.frame_offset += delta;
    a.hs.homed = true;
    x.tag.set(flag::PC, true);
    return Err::None;
  }
  // CIP drive homing, CiA 402 mode 6 with 0x6098/0x6099/0x609A from configuration
  a.hs.homing = true;
  a.hs.homing_started = false;
  a.hs.homing_clear = false;
  a.hs.homed = false;
  a.hs.mah = x.self;
  x.tag.set(flag::IP, true);
  return Err::None;
}

Err start(Ctx& x, const MrpParams& prm) noexcept {
  AxisRt& a = x.axis(prm.axis);
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  if (Err e = coordsys::check_no_coordinated_motion(x.c, a); e != Err::None) return e;  // ERR 52
  if (a.direct.status) return Err::NotAllowedWhileInDirectMotion;
  if (a.hs.homing) return Err::HomeInProcess;
  double delta = prm.position;
  if (!prm.relative) {
    double sel = prm.command ? x.c.user_command(a)
                             : (a.cfg.type == AxisType::Virtual ? x.c.user_command(a) : a.fb_pos + a.frame_offset);
    if (a.cfg.rotary) sel = unwind_position(sel, a.cfg.unwind);
    delta = prm.position - sel;
  }
  a.frame_offset += delta;  // both command and actual shift: the following error is kept
  x.tag.set(flag::DN, true);
  return Err::None;
}

namespace home {

void cancel(Core& c, AxisRt& a) noexcept {
  a.hs.homing = false;
  a.hs.resync = a.cfg.type == AxisType::CipDrive;  // the drive moved since the last feedback
  if (ControlTag* h = c.tag(a.hs.mah)) h->set(flag::IP, false);
}

void feedback(Core& c, AxisRt& a) noexcept {
  ControlTag* t = c.tag(a.hs.mah);
  // A "homing attained" left from an earlier homing is not this one's
  // completion: it counts only after the feedback showed it clear once
  // since this start went out.
  if (a.hs.homing_started && !a.fb.homing_attained) a.hs.homing_clear = true;
  if (a.fb.homing_attained && a.hs.homing_started && a.hs.homing_clear) {
    a.frame_offset = a.cfg.homing.home_position - a.fb_pos;
    a.hs.homed = true;
    a.hs.homing = false;
    a.base = a.fb_pos;
    a.cmd = Kin{a.fb_pos, 0, 0};
    if (t) { t->set(flag::IP, false); t->set(flag::PC, true); }
  } else if (a.fb.homing_error || link_failed(a.fb.link)) {
    a.hs.homing = false;
    a.base = a.fb_pos;
    const bool lf = link_failed(a.fb.link);
    if (t) { t->set(flag::IP, false); t->reject(Err::ServoMessageFailure, lf ? std::int8_t{16} : a.fb.homing_exerr); }
  }
}

void output(AxisRt& a, AxisOutput& out) noexcept {
  const HomingConfig& h = a.cfg.homing;
  out.homing = HomingRequest{h.cia_method, h.speed_search, h.speed_zero, h.accel, h.write_offset, h.offset};
  a.hs.homing_started = true;
}

}  // namespace home
}  // namespace canmotion::motion
