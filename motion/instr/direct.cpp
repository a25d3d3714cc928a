// Direct family (motion/instr/direct.hpp): MDS, direct velocity or torque
// control of an AXIS_CIP_DRIVE [seed 002]. The drive ramps the direct command
// with its own limits (configured at boot); the planner sends the command,
// enables the drive first if needed, and ends direct control on MAS, MSO,
// MSF, shutdown and faults. Realtime-safe.
#include "motion/instr/direct.hpp"

#include <algorithm>
#include <cmath>
#include <variant>

#include "motion/instr/coord.hpp"
#include "motion/instr/ctx.hpp"

namespace canmotion::motion {

MdsParams MdsParams::decode(const Operands& q) noexcept {
  return {q.ref(op<kInstr>("Axis")), q.real(op<kInstr>("Speed")), q.number(op<kInstr>("SpeedUnits")) == 0};
}

Err start(Ctx& x, const MdsParams& p) noexcept {
  AxisRt& a = x.axis(p.axis);
  if (Err e = x.c.common_checks(a, false); e != Err::None) return e;
  if (Err e = coordsys::check_no_coordinated_motion(x.c, a); e != Err::None) return e;  // ERR 52
  if (a.cfg.type != AxisType::CipDrive) return Err::WrongAxisType;  // AXIS_CIP_DRIVE only [seed 002]
  // "validated if the CIP drive device supports the ramp attributes" [seed 002]:
  // here, if the axis has direct_control: (ramps written at boot)
  if (!a.cfg.direct_control) return Err::OptionalAttributeNotSupported;
  if (a.hs.homing) return Err::HomeInProcess;
  for (const auto& g : a.gen)
    if (!std::holds_alternative<std::monostate>(g)) return Err::NotAllowedWhilePlannerActive;
  const bool torque = a.cfg.direct_mode == AxisConfig::DirectMode::Torque;
  // SLAT: Speed is the DirectVelocityControl command (a speed) [seed 002]
  const bool slat = torque && a.cfg.direct_slat;
  const double full = torque && !slat ? a.cfg.max_torque : a.cfg.max_speed;
  const double cmd = p.percent_of_maximum ? units::percent(p.speed, full) : p.speed;
  if (!std::isfinite(cmd)) return x.reject_operand(op<Instr::MDS>("Speed"));
  const bool first = !a.direct.mds.valid();
  if (!first && a.direct.mds != x.self)
    if (ControlTag* o = x.c.tag(a.direct.mds)) o->set(flag::IP, false);  // superseded by this MDS
  a.direct.status = true;
  a.direct.active = true;
  if (slat) {
    a.direct.vel_cmd = cmd;
    if (first) a.direct.cmd = 0.0;  // the torque command: set live (set_direct_command), kept by a superseding MDS
  } else {
    a.direct.cmd = cmd;
    if (first) a.direct.vel_cmd = a.cfg.direct_velocity_command;  // kept by a superseding MDS
  }
  a.direct.mds = x.self;
  a.direct.stop = {};
  x.tag.set(flag::IP, true);
  if (a.servo.on) {
    x.tag.set(flag::DN, true);
  } else {  // enable the drive first: STATE 0 request, 1 waiting [seed 002]
    a.servo.enable_req = true;
    a.direct.waiting = true;
    a.hs.since = x.c.cycle;
    a.hs.deadline = x.c.drive_deadline(a);
    x.tag.state = 0;
  }
  return Err::None;
}

namespace direct {

void end(Core& c, AxisRt& a, bool keep_status) noexcept {
  if (!a.direct.status) return;
  if (ControlTag* t = c.tag(a.direct.mds)) t->set(flag::IP, false);
  a.direct.active = false;
  a.direct.cmd = 0.0;
  a.direct.mds = {};
  a.direct.waiting = false;
  if (!keep_status) {
    a.direct.status = false;
    if (ControlTag* s = c.tag(a.direct.stop)) s->set(flag::IP, false);
    a.direct.stop = {};
  }
}

void begin_stop(Core& c, AxisRt& a, OwnerRef mas) noexcept {
  end(c, a, true);  // direct command to zero; the drive ramps down
  a.direct.stop = mas;
}

void feedback(Core& c, AxisRt& a) noexcept {
  if (a.direct.waiting) {  // MDS waiting for the drive enable
    ControlTag* t = c.tag(a.direct.mds);
    if (a.fb.drive == DriveState::Enabled) {
      a.servo.on = true;
      a.direct.waiting = false;
      if (t) { t->state = 1; t->set(flag::DN, true); }
    } else if (const auto cause = c.enable_failed(a, false); cause) {
      const OwnerRef mds = a.direct.mds;
      a.direct.waiting = false;
      end(c, a, false);
      a.servo.enable_req = false;
      c.end_drive_wait(a, t, mds.id, Instr::MDS, *cause, a.hs.since);
    } else if (t) {
      t->state = 1;
    }
  }
  if (a.direct.stop.valid()) {  // MAS: PC at standstill
    ControlTag* t = c.tag(a.direct.stop);
    if (!t || !a.direct.status) {
      a.direct.stop = {};
    } else if (std::fabs(a.fb_vel) <= std::max(1e-6, 1e-3 * a.cfg.max_speed)) {
      t->set(flag::IP, false);
      t->set(flag::PC, true);
      a.direct.stop = {};
    }
  }
}

void output(const AxisRt& a, AxisOutput& out) noexcept {
  const bool torque = a.cfg.direct_mode == AxisConfig::DirectMode::Torque;
  out.mode = torque ? DriveMode::CyclicTorque : DriveMode::CyclicVelocity;
  out.velocity = a.direct.active ? (torque ? a.direct.vel_cmd : a.direct.cmd) : 0.0;
  out.torque = torque && a.direct.active ? a.direct.cmd : 0.0;
  out.acceleration = 0.0;
}

bool set_command(Core& c, AxisId id, double value) noexcept {
  if (id >= kMaxAxes || !c.axes[id].direct.active || !std::isfinite(value)) return false;
  c.axes[id].direct.cmd = value;
  return true;
}

bool set_velocity_command(Core& c, AxisId id, double value) noexcept {
  if (id >= kMaxAxes || !c.axes[id].direct.active || !std::isfinite(value) ||
      c.axes[id].cfg.direct_mode != AxisConfig::DirectMode::Torque)
    return false;
  c.axes[id].direct.vel_cmd = value;
  return true;
}

}  // namespace direct
}  // namespace canmotion::motion
