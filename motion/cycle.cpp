// One cycle of the planner (motion/core.hpp): feedback and exceptions, then
// (after the requests) every axis stepped in order, its output and its tag.
// Everything here runs every cycle: realtime-safe, allocation-free.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "motion/core.hpp"
#include "motion/hooks.hpp"
#include "motion/profile_step.hpp"

namespace canmotion::motion {

// ---------------------------------------------------------------- feedback
void Core::handle_feedback(AxisRt& a, const AxisFeedback* fb) noexcept {
  if (a.cfg.type != AxisType::CipDrive) return;
  const double cmd_before = a.cmd.p;
  if (fb) {
    a.fb = *fb;
    a.fb_pos = fb->position;
    a.fb_vel = fb->velocity;
  }
  hooks::drive_feedback(*this, a);  // the instructions waiting for the drive
  // servo off or homing (or a homing just cancelled): the command follows the actual position
  if (!a.servo.on || a.hs.homing || a.direct.status || a.hs.resync) {
    a.hs.resync = false;
    a.base = a.fb_pos;
    a.cmd = Kin{a.fb_pos, a.direct.status ? a.fb_vel : 0.0, 0};
  }
  // a drive that dropped out of Operation Enabled switches the servo off
  if (a.servo.on && a.fb.drive != DriveState::Enabled && !a.direct.waiting) servo_off(a);
  // A command taken from the actual here (servo off, homing, MSO closing the
  // loop) has no older one: the drive is taken to be at it.
  if (a.cmd.p != cmd_before) a.prev_cmd_p = a.cmd.p;
}

// -------------------------------------------------------------- exceptions
// Called once per axis per cycle from read_feedback() only: inlined there.
[[gnu::always_inline]] inline void Core::handle_exceptions(AxisRt& a) noexcept {
  std::uint32_t active = 0;
  auto bit = [](ExceptionKind k) { return 1u << static_cast<unsigned>(k); };
  if (a.cfg.type == AxisType::CipDrive) {
    const bool drive_fault = a.fb.drive_fault || a.fb.drive == DriveState::Fault;
    // while a fault reset waits for the drive to leave Fault (or to come
    // back), its conditions are not latched again; they are if it fails
    const bool resetting = a.servo.reset.valid();
    if (drive_fault && !resetting) active |= bit(ExceptionKind::DriveFault);
    if (a.fb.node_lost && !resetting) active |= bit(ExceptionKind::NodeLost);
    if (a.fb.bus_off) active |= bit(ExceptionKind::BusOff);
    if (a.fb.limit_positive) active |= bit(ExceptionKind::HardOvertravelPos);
    if (a.fb.limit_negative) active |= bit(ExceptionKind::HardOvertravelNeg);
    if (a.servo.on && a.cfg.position_error_tolerance > 0 &&
        std::fabs(compared_command(a) - a.fb_pos) > a.cfg.position_error_tolerance)
      active |= bit(ExceptionKind::PositionError);
  }
  if (a.cfg.soft_limits_enabled && !a.cfg.rotary) {
    const double p = user_command(a);
    if (p > a.cfg.soft_limit_pos) active |= bit(ExceptionKind::SoftOvertravelPos);
    if (p < a.cfg.soft_limit_neg) active |= bit(ExceptionKind::SoftOvertravelNeg);
  }
  // A drive that refused its configuration or never answered (not latched:
  // it shows while the condition lasts; MAFR retries the drive's boot).
  std::uint32_t link_fault = 0;
  if (a.cfg.type == AxisType::CipDrive) {
    if (a.fb.link == DriveLink::ConfigFailed) link_fault = 1u << axis_fault::ConfigFault;
    if (a.fb.link == DriveLink::NoModule) link_fault = 1u << axis_fault::ModuleFault;
  }
  if (active == 0 && a.tag.exception_faults == 0) {  // the usual case: what the code below gives then
    a.tag.exception_alarms = 0;
    a.tag.motion_alarm_status = 0;
    a.tag.axis_fault = link_fault;
    return;
  }
  std::uint32_t alarms = 0, faults = 0;
  for (unsigned k = 0; active != 0 && k < static_cast<unsigned>(ExceptionKind::Count); ++k) {  // usually none active
    if (!(active & (1u << k))) continue;
    const ExceptionAction act = a.cfg.action(static_cast<ExceptionKind>(k));
    if (act == ExceptionAction::Alarm) alarms |= 1u << k;
    if (act >= ExceptionAction::FaultStatusOnly) faults |= 1u << k;
  }
  a.tag.exception_alarms = alarms;
  const std::uint32_t fresh = faults & ~a.tag.exception_faults;
  a.tag.exception_faults |= faults;
  // the values that latched them, before the action below moves the command
  if (fresh & bit(ExceptionKind::PositionError))
    a.tag.exception_fault_values[static_cast<std::size_t>(ExceptionKind::PositionError)] =
        std::fabs(compared_command(a) - a.fb_pos);
  for (ExceptionKind k : {ExceptionKind::SoftOvertravelPos, ExceptionKind::SoftOvertravelNeg})
    if (fresh & bit(k)) a.tag.exception_fault_values[static_cast<std::size_t>(k)] = user_command(a);
  // the most severe action of the new faults wins
  ExceptionAction worst = ExceptionAction::Ignore;
  for (unsigned k = 0; fresh != 0 && k < static_cast<unsigned>(ExceptionKind::Count); ++k)
    if (fresh & (1u << k)) worst = most_severe(worst, a.cfg.action(static_cast<ExceptionKind>(k)));
  if (fresh & bit(ExceptionKind::SoftOvertravelPos)) a.tag.motion_fault_status |= 1u << motion_fault::SoftTravelLimitPositive;
  if (fresh & bit(ExceptionKind::SoftOvertravelNeg)) a.tag.motion_fault_status |= 1u << motion_fault::SoftTravelLimitNegative;
  a.tag.motion_alarm_status = 0;
  if (alarms & bit(ExceptionKind::SoftOvertravelPos)) a.tag.motion_alarm_status |= 1u << motion_fault::SoftTravelLimitPositive;
  if (alarms & bit(ExceptionKind::SoftOvertravelNeg)) a.tag.motion_alarm_status |= 1u << motion_fault::SoftTravelLimitNegative;
  switch (worst) {
    case ExceptionAction::StopPlanner: {
      if (a.servo.on) stop_all(a, kNoControl, 0);
      // "an axis fault also breaks the MDAC link" [seed 000]: the slave's (a
      // stop of all its planned motion, as MAS All); not the slaves' of a
      // master (MAS on a master keeps them)
      hooks::break_links(*this, a, false);
      break;
    }
    case ExceptionAction::StopDrive:
      servo_off(a);
      a.servo.faulted = true;
      hooks::break_links(*this, a, true);  // an axis fault breaks the MDAC link [seed 000]: on the slave and on the master (faulted, as MASD)
      break;
    case ExceptionAction::Shutdown:
      do_shutdown(a);
      a.servo.faulted = true;
      break;
    default:
      break;
  }
  // AxisFault summary bits
  std::uint32_t af = 0;
  const std::uint32_t f = a.tag.exception_faults;
  if (f & (bit(ExceptionKind::DriveFault) | bit(ExceptionKind::PositionError))) af |= 1u << axis_fault::PhysicalAxisFault;
  if (f & (bit(ExceptionKind::NodeLost) | bit(ExceptionKind::BusOff))) af |= 1u << axis_fault::ModuleFault;
  if (f & (bit(ExceptionKind::SoftOvertravelPos) | bit(ExceptionKind::SoftOvertravelNeg))) af |= 1u << axis_fault::MotionFault;
  if (f & (bit(ExceptionKind::HardOvertravelPos) | bit(ExceptionKind::HardOvertravelNeg))) af |= 1u << axis_fault::PhysicalAxisFault;
  a.tag.axis_fault = af | link_fault;
}

void Core::read_feedback(const Input& in) noexcept {
  // the first cycle index may be anything: time starts one period before it
  if (!started) cycle = in.cycle > 0 ? in.cycle - 1 : 0;
  // feedback and exceptions, against last cycle's command
  for (std::size_t i = 0; i < axis_count; ++i) {
    AxisRt& a = axes[i];
    if (!a.present) continue;
    handle_feedback(a, i < in.feedback.size() ? &in.feedback[i] : nullptr);
    handle_exceptions(a);
  }
}

// -------------------------------------------------------------------- step
// Called once per axis per cycle from step() only: inlined there.
[[gnu::always_inline]] inline void Core::step_axis(AxisRt& a, AxisOutput* out) noexcept {
  double sum_p = 0, sum_v = 0, sum_a = 0;
  // The live slots (AxisRt::live) in slot order, which is the step order:
  // the next live one after the last stepped, looked up afresh after each
  // step (a generator may fold, fold the others, or hand its slot over).
  for (unsigned from = 0;;) {
    const unsigned pending = a.live & (~0u << from);
    if (pending == 0) break;
    const auto s = static_cast<unsigned>(std::countr_zero(pending));
    from = s + 1;
    const Slot slot = static_cast<Slot>(s);
    with_generator(a.gen[s], [&](auto& g) noexcept { g.step(*this, a, slot); });
    // the master offset move is in master units: it shifts the position
    // cam's master and is not part of the sum
    if (slot == Slot::MasterOffset) continue;
    // what the slot holds now (a generator that ended is in the base)
    if (const GenBase* g = gen_base(a.gen[s])) {
      sum_p += g->k.p;
      sum_v += g->k.v;
      sum_a += g->k.a;
    }
  }
  a.prev_cmd_p = a.cmd.p;
  a.cmd = Kin{a.base + sum_p, sum_v, sum_a};
  if (out) {
    out->position = a.cmd.p;
    out->velocity = a.cmd.v;
    out->acceleration = a.cmd.a;
    out->torque = 0;
    out->enable = a.servo.enable_req && !a.servo.shutdown;
    out->shutdown = a.servo.shutdown;
    out->fault_reset = a.servo.fault_reset_pulse;
    out->mode = a.hs.homing ? DriveMode::Homing : DriveMode::CyclicPosition;
    out->homing_start = a.hs.homing;
    if (a.direct.status || a.hs.homing) hooks::drive_output(a, *out);  // MDS: CSV or CST; MAH: the homing objects
  }
  a.servo.fault_reset_pulse = false;
}

void Core::step(std::uint64_t new_cycle, Output& out) noexcept {
  // generators started by this cycle's requests have their time origin at
  // the last stepped cycle, so they continue from its state
  cycle = new_cycle;
  started = true;
  compute_order();
  for (std::size_t n = 0; n < order_n; ++n) {
    const std::size_t i = order[n];
    AxisRt& a = axes[i];
    step_axis(a, i < out.axes.size() ? &out.axes[i] : nullptr);
    update_status(a);
  }
  hooks::cycle_end(*this);  // the coordinate systems' tags
}

// ------------------------------------------------------------------ status
void Core::update_status(AxisRt& a) noexcept {
  using namespace motion_status;
  AxisTag& t = a.tag;
  std::uint32_t ms = 0;
  auto setb = [&](unsigned b, bool on) { if (on) ms |= 1u << b; };
  const auto* mv = std::get_if<ProfileGen>(&a.gen[index(Slot::Move)]);
  const auto* jg = std::get_if<ProfileGen>(&a.gen[index(Slot::Jog)]);
  setb(MoveStatus, mv && mv->role == GenRole::Move);
  setb(JogStatus, jg && jg->role == GenRole::Jog);
  setb(MoveLockStatus, mv && mv->role == GenRole::Move && mv->master_driven && mv->md.locked && mv->md.following);
  setb(JogLockStatus, jg && jg->role == GenRole::Jog && jg->master_driven && jg->md.locked && jg->md.following);
  static_assert(link::Count == 4);
  const bool linked = a.links.active[0].valid() || a.links.active[1].valid() || a.links.active[2].valid() || a.links.active[3].valid();
  setb(CoordinatedMotionStatus, linked || (a.live & slot_bit(Slot::Coord)));  // MDAC link or a coordinated move
  const auto* gr = std::get_if<GearGen>(&a.gen[index(Slot::Gear)]);
  setb(GearingStatus, gr != nullptr);
  setb(GearingLockStatus, gr && gr->locked);
  const bool stopping = any_stopping(a);
  setb(StoppingStatus, stopping);
  setb(HomingStatus, a.hs.homing);
  setb(AxisHomedStatus, a.hs.homed);
  setb(AccelStatus, a.cmd.v * a.cmd.a > 0 || (a.cmd.v == 0 && a.cmd.a != 0));
  setb(DecelStatus, a.cmd.v * a.cmd.a < 0);
  setb(TimeCamStatus, std::holds_alternative<CamGen>(a.gen[index(Slot::TimeCam)]));
  setb(TimeCamPendingStatus, a.cams.time.valid());
  const auto* pc = std::get_if<PosCamGen>(&a.gen[index(Slot::PositionCam)]);
  setb(PositionCamStatus, pc != nullptr);
  setb(PositionCamLockStatus, pc && pc->locked && pc->inside && !pc->slipping);
  setb(PositionCamPendingStatus, a.cams.position.valid());
  const auto* mo = std::get_if<ProfileGen>(&a.gen[index(Slot::MasterOffset)]);
  setb(MasterOffsetMoveStatus, mo != nullptr);
  setb(MasterOffsetMoveLockStatus, mo && mo->master_driven && mo->md.locked && mo->md.following);
  const auto* tc = std::get_if<CamGen>(&a.gen[index(Slot::TimeCam)]);
  setb(TimeCamLockStatus, tc && tc->master_driven && tc->md.lock_status());
  const bool torque_mode = a.cfg.direct_mode == AxisConfig::DirectMode::Torque;
  setb(DirectVelocityControlStatus, a.direct.active && (!torque_mode || a.cfg.direct_slat));  // SLAT: both [seed 002]
  setb(DirectTorqueControlStatus, a.direct.active && torque_mode);
  setb(MaximumSpeedExceeded, a.cfg.max_speed > 0 && std::fabs(a.cmd.v) > a.cfg.max_speed * (1 + 1e-9));
  t.motion_status = ms;
  std::uint32_t as = 0;
  if (a.servo.on) as |= (1u << axis_status::ServoActionStatus) | (1u << axis_status::DriveEnableStatus);
  if (a.servo.shutdown) as |= 1u << axis_status::ShutdownStatus;
  if (a.cfg.inhibited) as |= 1u << axis_status::InhibitStatus;
  if (a.direct.status) as |= 1u << axis_status::DirectControlStatus;
  as |= 1u << axis_status::AxisUpdateStatus;
  t.axis_status = as;
  if (!a.cfg.configured) t.state = AxisState::Ungrouped;
  else if (a.cfg.inhibited) t.state = AxisState::Inhibited;
  else if (a.servo.shutdown) t.state = AxisState::Shutdown;
  else if (a.servo.faulted) t.state = AxisState::Faulted;
  else if (a.servo.on) t.state = AxisState::ServoControl;
  else t.state = AxisState::Ready;
  if (a.cfg.inhibited) t.cip_state = CipAxisState::AxisInhibited;
  else if (a.servo.shutdown) t.cip_state = CipAxisState::Shutdown;
  else if (a.servo.faulted) t.cip_state = CipAxisState::MajorFaulted;
  else if (a.servo.on) t.cip_state = stopping ? CipAxisState::Stopping : CipAxisState::Running;
  else if (a.servo.enable_req) t.cip_state = CipAxisState::Starting;
  else t.cip_state = CipAxisState::Stopped;
  // tags in the user frame
  const double act = a.cfg.type == AxisType::Virtual ? a.cmd.p : a.fb_pos;
  const double actv = a.cfg.type == AxisType::Virtual ? a.cmd.v : a.fb_vel;
  t.command_position = a.cmd.p + a.frame_offset;
  t.actual_position = act + a.frame_offset;
  if (a.cfg.rotary) {
    t.command_position = unwind_position(t.command_position, a.cfg.unwind);
    t.actual_position = unwind_position(t.actual_position, a.cfg.unwind);
  }
  t.command_velocity = a.cmd.v;
  t.command_acceleration = a.cmd.a;
  t.actual_velocity = actv;
  t.position_error = (a.cfg.type == AxisType::Virtual ? a.cmd.p : compared_command(a)) - act;
}

// -------------------------------------------------------------- step order
void Core::compute_order() noexcept {
  // depth-first: every axis after the masters it follows (gear, master-driven
  // motion). MAG refuses gear cycles (ERR 10); a cycle through master-driven
  // motion is broken arbitrarily (the stack below bounds the walk).
  // The order changes only with the slots (set_slot, fold) and the axes
  // (configure_axis): otherwise last cycle's order stands.
  if (!order_dirty) return;
  order_dirty = false;
  std::array<std::uint8_t, kMaxAxes> mark{};  // 0 new, 1 on stack, 2 emitted
  order_n = 0;
  // The masters of an axis in the order the walk visits them
  // (kLegacySlotOrder: it decides only the order of two unrelated masters of
  // one slave).
  auto masters_of = [this](AxisId i, std::array<AxisId, kSlots>& out) noexcept {
    std::size_t n = 0;
    out.fill(kNoAxis);  // the first n are overwritten below
    const AxisRt& a = axes[i];
    for (const Slot s : kLegacySlotOrder) {
      if (!(a.live & slot_bit(s))) continue;  // empty slots have no master
      const AxisId m = master_of(a.gen[index(s)]);
      if (m < kMaxAxes && axes[m].present && m != i) out[n++] = m;
    }
  };
  // The masters of every axis, once per recomputation (the walk below visits an axis
  // several times). Usually no axis follows another: then the order is the
  // axis order, which is what the walk would give.
  std::array<std::array<AxisId, kSlots>, kMaxAxes> masters;  // [i] set for present axes
  bool linked = false;
  for (std::size_t i = 0; i < axis_count; ++i) {
    if (!axes[i].present) continue;
    masters_of(static_cast<AxisId>(i), masters[i]);
    linked = linked || masters[i][0] != kNoAxis;
  }
  if (!linked) {
    for (std::size_t i = 0; i < axis_count; ++i)
      if (axes[i].present) order[order_n++] = static_cast<AxisId>(i);
    return;
  }
  struct Frame { AxisId axis; std::uint8_t next; };
  std::array<Frame, kMaxAxes> stack{};
  for (std::size_t i = 0; i < axis_count; ++i) {
    if (!axes[i].present || mark[i]) continue;
    std::size_t sp = 0;
    stack[sp++] = Frame{static_cast<AxisId>(i), 0};
    mark[i] = 1;
    while (sp > 0) {
      Frame& f = stack[sp - 1];
      const std::array<AxisId, kSlots>& ms = masters[f.axis];
      bool pushed = false;
      while (f.next < kSlots) {
        const AxisId m = ms[f.next++];
        if (m != kNoAxis && mark[m] == 0 && sp < kMaxAxes) {
          mark[m] = 1;
          stack[sp++] = Frame{m, 0};
          pushed = true;
          break;
        }
      }
      if (pushed) continue;
      mark[f.axis] = 2;
      order[order_n++] = f.axis;
      --sp;
    }
  }
}

bool Core::check_incremental_state() noexcept {
  bool ok = true;
  for (std::size_t i = 0; i < axis_count; ++i) {
    unsigned live = 0;
    for (std::size_t s = 0; s < kSlots; ++s)
      if (!std::holds_alternative<std::monostate>(axes[i].gen[s])) live |= 1u << s;
    ok = ok && live == axes[i].live;
  }
  // the cached order against a fresh one (an up-to-date cache is recomputed
  // to the same order; a stale one is reported and left as it was)
  const std::array<AxisId, kMaxAxes> cached = order;
  const std::size_t cached_n = order_n;
  const bool dirty = order_dirty;
  order_dirty = true;
  compute_order();
  const bool same = order_n == cached_n && std::equal(cached.begin(), cached.begin() + static_cast<std::ptrdiff_t>(cached_n), order.begin());
  if (!dirty && !same) {
    order = cached;
    order_n = cached_n;
    ok = false;
  }
  order_dirty = dirty;
  if (dirty) {  // leave a pending recomputation pending
    order = cached;
    order_n = cached_n;
  }
  return ok;
}


}  // namespace canmotion::motion
