// Servo family (motion/instr/servo.hpp): MSO, MSF, MASD, MASR, MAFR and the
// enable handshakes with an AXIS_CIP_DRIVE. Realtime-safe.
#include "motion/instr/servo.hpp"

#include <algorithm>
#include <cmath>

#include "motion/instr/ctx.hpp"
#include "motion/instr/direct.hpp"

namespace canmotion::motion {

MsoParams MsoParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Axis"))}; }
MsfParams MsfParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Axis"))}; }
MasdParams MasdParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Axis"))}; }
MasrParams MasrParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Axis"))}; }
MafrParams MafrParams::decode(const Operands& q) noexcept { return {q.ref(op<kInstr>("Axis"))}; }

Err start(Ctx& x, const MsoParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, false); e != Err::None) return e;
  if (a.direct.status) {  // MSO is the way out of direct control [RM002H p.578]
    direct::end(x.c, a, false);
    a.base = a.fb_pos;
    a.cmd = Kin{a.fb_pos, 0, 0};
  }
  if (a.servo.on) {
    x.tag.set(flag::DN, true);
    return Err::None;
  }
  // [RM002H p.78] ERR 22 if the (servo-off) axis is moving: a drive coasting
  // faster than 0.1 % of max speed (at least 1e-6 units/s)
  if (a.cfg.type == AxisType::CipDrive && std::fabs(a.fb_vel) > std::max(1e-6, 1e-3 * a.cfg.max_speed))
    return Err::AxisInMotion;
  a.servo.enable_req = true;
  if (a.cfg.type == AxisType::Virtual) {
    a.servo.on = true;
    x.tag.set(flag::DN, true);
    return Err::None;
  }
  // CIP: DN when the drive reports Operation Enabled (STATE 0 request, 1 waiting).
  a.hs.mso = x.self;
  a.hs.since = x.c.cycle;
  a.hs.deadline = x.c.drive_deadline(a);
  x.tag.state = 0;
  return Err::None;
}

Err start(Ctx& x, const MsfParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  if (a.servo.shutdown) return Err::ShutdownState;
  const bool was_enabled = a.cfg.type == AxisType::CipDrive && a.fb.drive == DriveState::Enabled;
  x.c.servo_off(a);
  if (a.hs.mso.valid()) {  // cancel a pending MSO
    if (ControlTag* m = x.c.tag(a.hs.mso)) m->reject(Err::ServoMessageFailure, 15);
    a.hs.mso = {};
  }
  if (!was_enabled) {
    x.tag.set(flag::DN, true);
  } else {
    a.hs.msf = x.self;
    a.hs.since = x.c.cycle;
    a.hs.deadline = x.c.drive_deadline(a);
  }
  return Err::None;
}

Err start(Ctx& x, const MasdParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  x.c.do_shutdown(a);
  x.tag.set(flag::DN, true);
  return Err::None;
}

Err start(Ctx& x, const MasrParams& p) noexcept {
  // MASR = MAFR (clear the faults, pulse a drive fault reset) + leave Shutdown.
  const Err e = start(x, MafrParams{p.axis});
  if (e == Err::None) x.axis(p.axis).servo.shutdown = false;
  return e;
}

Err start(Ctx& x, const MafrParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  // CIP: the drive's fault reset goes out this cycle; DN once the drive has
  // left Fault (and is connected again after a lost node or a reboot).
  if (servo::reset_faults(x.c, a, x.self, x.r.instr)) x.tag.set(flag::DN, true);
  return Err::None;
}

namespace servo {

namespace {
bool drive_clear(const AxisFeedback& f) noexcept {
  return f.link == DriveLink::Up && f.drive != DriveState::Fault && !f.drive_fault && !f.node_lost;
}

void end_reset(Core& c, AxisRt& a, bool ok, DriveWaitCause cause = DriveWaitCause::Limit) noexcept {
  const OwnerRef owner = a.servo.reset;
  a.servo.reset = {};
  ControlTag* t = c.tag(owner);
  if (!t) return;
  if (!ok) {
    c.end_drive_wait(a, t, owner.id, a.servo.reset_instr, cause, a.servo.reset_since);  // ERR 12, device in wrong state
    for (std::size_t i = 0; i < c.axis_count; ++i)  // MGSR: the other axes stop waiting
      if (c.axes[i].servo.reset == owner) c.axes[i].servo.reset = {};
    return;
  }
  for (std::size_t i = 0; i < c.axis_count; ++i)  // MGSR: DN with the last axis
    if (c.axes[i].servo.reset == owner) return;
  t->set(flag::DN, true);
}
}  // namespace

bool reset_faults(Core& c, AxisRt& a, OwnerRef owner, Instr instr) noexcept {
  a.servo.faulted = false;
  a.tag.exception_faults = 0;
  a.tag.motion_fault_status = 0;
  if (a.cfg.type != AxisType::CipDrive) return true;
  a.servo.fault_reset_pulse = true;
  if (drive_clear(a.fb)) return true;
  // The drive acts on the reset this cycle (the pulse goes out with this
  // cycle's RPDO); DN when its feedback shows it left Fault.
  if (a.servo.reset.valid() && a.servo.reset.id != owner.id)
    if (ControlTag* old = c.tag(a.servo.reset)) old->reject(Err::ServoMessageFailure, 16);
  a.servo.reset = owner;
  a.servo.reset_instr = instr;
  a.servo.reset_since = c.cycle;
  a.servo.reset_deadline = c.drive_deadline(a);
  return false;
}

void reset_feedback(Core& c, AxisRt& a) noexcept {
  // judged on feedback given after the pulse went out (the runtime acts on
  // it: clears its failure, retries a failed boot)
  if (!c.tag(a.servo.reset)) {
    a.servo.reset = {};
  } else if (drive_clear(a.fb)) {
    end_reset(c, a, true);
  } else if (link_failed(a.fb.link)) {
    end_reset(c, a, false, DriveWaitCause::LinkFailed);
  } else if (a.fb.transition_timeout) {
    end_reset(c, a, false, DriveWaitCause::TransitionTimeout);
  } else if (c.cycle >= a.servo.reset_deadline) {
    end_reset(c, a, false, DriveWaitCause::Limit);
  }
}

void feedback(Core& c, AxisRt& a) noexcept {
  if (a.hs.mso.valid()) {
    ControlTag* t = c.tag(a.hs.mso);
    if (!t) {
      a.hs.mso = {};
    } else if (a.fb.drive == DriveState::Enabled) {
      a.servo.on = true;
      a.base = a.fb_pos;  // close the loop at the present position
      a.cmd = Kin{a.fb_pos, 0, 0};
      t->state = 1;
      t->set(flag::DN, true);
      a.hs.mso = {};
    } else if (const auto cause = c.enable_failed(a, true); cause) {
      // (a drive still in Fault while a fault reset waits for it: wait too)
      c.end_drive_wait(a, t, a.hs.mso.id, Instr::MSO, *cause, a.hs.since);
      a.servo.enable_req = false;
      a.hs.mso = {};
    } else {
      t->state = 1;  // waiting for drive enable and servo action
    }
  }
  if (a.hs.msf.valid()) {
    ControlTag* t = c.tag(a.hs.msf);
    if (!t) {
      a.hs.msf = {};
    } else if (a.fb.drive != DriveState::Enabled) {
      t->set(flag::DN, true);
      a.hs.msf = {};
    } else if (c.cycle >= a.hs.deadline) {
      c.end_drive_wait(a, t, a.hs.msf.id, Instr::MSF, DriveWaitCause::Limit, a.hs.since);
      a.hs.msf = {};
    }
  }
}

}  // namespace servo
}  // namespace canmotion::motion
