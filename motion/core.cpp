// The planner's shared operations (motion/core.hpp): what more than one
// instruction family, the exceptions and the cycle do to an axis.
#include "motion/core.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "motion/hooks.hpp"

namespace canmotion::motion {
Core::Core(double cycle_period) noexcept : T(cycle_period > 0 ? cycle_period : 0.001) {}

std::uint64_t Core::drive_deadline(const AxisRt& a) const noexcept {
  return cycle + static_cast<std::uint64_t>(a.cfg.drive_wait_limit / T);
}

std::optional<DriveWaitCause> Core::enable_failed(const AxisRt& a, bool fault_waits_for_reset) const noexcept {
  // A latched fault (Stop Drive) or Shutdown: the drive is not enabled again
  // before MAFR / MASR (ERR 20 / 7 had it come first).
  if (a.servo.faulted || a.servo.shutdown) return DriveWaitCause::AxisFaulted;
  if (a.fb.drive == DriveState::Fault && !(fault_waits_for_reset && a.servo.reset.valid())) return DriveWaitCause::DriveFault;
  if (link_failed(a.fb.link)) return DriveWaitCause::LinkFailed;
  if (a.fb.transition_timeout) return DriveWaitCause::TransitionTimeout;
  if (cycle >= a.hs.deadline) return DriveWaitCause::Limit;
  return std::nullopt;
}

void Core::end_drive_wait(AxisRt& a, ControlTag* t, ControlId id, Instr instr, DriveWaitCause cause, std::uint64_t since,
                          Err e, std::int8_t exerr) noexcept {
  if (t == nullptr) return;  // a newer execution owns the tag: not this wait's error
  t->reject(e, exerr);
  ++a.tag.drive_wait_errors;
  a.tag.last_drive_wait = DriveWaitEnd{instr, id, cause, static_cast<std::int16_t>(e), exerr, cycle - since};
}

bool Core::configure_axis(AxisId id, const AxisConfig& cfg) noexcept {
  if (id >= kMaxAxes) return false;
  if (!(cfg.conversion_constant > 0) || (cfg.rotary && !(cfg.unwind > 0)) || cfg.max_speed < 0 ||
      cfg.max_accel < 0 || cfg.max_decel < 0 || cfg.max_accel_jerk < 0 || cfg.max_decel_jerk < 0 ||
      cfg.position_error_tolerance < 0 || !(cfg.drive_wait_limit > 0) || cfg.group >= kMaxGroups)
    return false;
  AxisRt& a = axes[id];
  a = AxisRt{};
  a.cfg = cfg;
  a.present = true;
  axis_count = std::max<std::size_t>(axis_count, static_cast<std::size_t>(id) + 1);
  order_dirty = true;
  update_status(a);
  return true;
}

Kin Core::slot_kin(const AxisRt& a, Slot s) const noexcept {
  const GenBase* g = gen_base(a.gen[index(s)]);
  return g ? g->k : Kin{};
}

void Core::fold(AxisRt& a, Slot s, bool clear_owner_ip) noexcept {
  Generator& slot = a.gen[index(s)];
  with_generator(slot, [&](auto& g) noexcept {
    g.on_fold(*this, a);  // cam profile released, MDAC AC cleared, a cam's offset move ended
    if (s == Slot::MasterOffset) {  // a master offset move shifts the position cam's master for good, not the slave
      if (auto* pc = std::get_if<PosCamGen>(&a.gen[index(Slot::PositionCam)])) pc->offset_base += g.k.p;
    } else {
      a.base += g.k.p;
    }
    if (clear_owner_ip) {
      if (ControlTag* c = tag(g.owner)) {
        c->set(flag::IP, false);
        c->set(flag::ACCEL, false);
        c->set(flag::DECEL, false);
        c->set(flag::TrackingMaster, false);
        c->set(flag::AC, false);
      }
    }
  });
  if (a.live & slot_bit(s)) order_dirty = true;  // a master link may have gone
  a.live = static_cast<std::uint8_t>(a.live & ~slot_bit(s));
  slot = std::monostate{};
}

void Core::abort_all(AxisRt& a) noexcept {
  for (std::size_t s = 0; s < kSlots; ++s) fold(a, static_cast<Slot>(s), true);
  a.cmd.v = 0;
  a.cmd.a = 0;
  a.cmd.p = a.base;
}

void Core::servo_off(AxisRt& a) noexcept {
  abort_all(a);
  hooks::servo_off(*this, a);  // pending cams, direct control, drive homing
  a.servo.on = false;
  a.servo.enable_req = false;
}

void Core::do_shutdown(AxisRt& a) noexcept {
  servo_off(a);
  a.servo.shutdown = true;
  hooks::shutdown(*this, a);  // MDAC links as slave and master, MDCC links
}

bool Core::stop_slots(AxisRt& a, std::uint32_t mask, double d, double jd, ControlId owner,
                      std::uint8_t post_stop) noexcept {
  const OwnerRef own{owner, owner < kMaxControlTags ? controls[owner].generation : 0};
  ProfileGen st;
  st.role = GenRole::Stop;
  st.owner = own;
  st.post_stop = post_stop;
  st.scurve = !std::isinf(jd);
  st.t0_cycle = cycle;
  // A member's share of a coordinated path is stopped along the path (the
  // whole coordinate system at its max decel, reference "MAS All on a
  // member ... the path is kept"): its slot stays. Not when the servo goes
  // off after the ramp (FastDisable/FastShutdown): then the servo-off stops
  // the path for the other members (CoordGen::on_fold).
  bool path = false;
  if ((mask & slot_bit(Slot::Coord)) && post_stop == 0) path = hooks::stop_path(*this, a, own);
  if ((mask & kAllSlots) == kAllSlots) {
    // one ramp of the whole motion in Slot::StopAll; the master offset move
    // (master units) is not part of the axis' motion
    Kin tot{};
    bool any = false;
    for (std::size_t s = 0; s < kSlots; ++s) {
      if (path && s == index(Slot::Coord)) continue;
      if (const GenBase* g = gen_base(a.gen[s]); g && s != index(Slot::MasterOffset)) {
        tot.v += g->k.v;
        tot.a += g->k.a;
        any = true;
      }
      fold(a, static_cast<Slot>(s), true);
    }
    if (!any || (tot.v == 0 && tot.a == 0)) return path;
    if (!plan_stop(st.prof, Kin{0, tot.v, tot.a}, d, jd)) return path;
    st.k = Kin{0, tot.v, tot.a};
    set_slot(a, Slot::StopAll, st);
    return true;
  }
  if (path) mask &= ~slot_bit(Slot::Coord);
  bool any = false;
  for (std::size_t s = 0; s < kSlots; ++s) {
    if (!(mask & (1u << s))) continue;
    const GenBase* g = gen_base(a.gen[s]);
    if (!g) continue;
    const Kin k = g->k;
    fold(a, static_cast<Slot>(s), true);
    if (k.v == 0 && k.a == 0) continue;
    ProfileGen one = st;
    if (!plan_stop(one.prof, Kin{0, k.v, k.a}, d, jd)) continue;
    one.k = Kin{0, k.v, k.a};
    set_slot(a, static_cast<Slot>(s), one);
    any = true;
  }
  return any || path;
}

bool Core::stop_all(AxisRt& a, ControlId owner, std::uint8_t post_stop) noexcept {
  bool scurve = false;
  for (const auto& g : a.gen)
    if (auto* p = std::get_if<ProfileGen>(&g)) scurve = scurve || p->scurve;
  const double d = a.cfg.max_decel > 0 ? a.cfg.max_decel : 1e12;
  const double jd = scurve && a.cfg.max_decel_jerk > 0 ? a.cfg.max_decel_jerk : std::numeric_limits<double>::infinity();
  return stop_slots(a, kAllSlots, d, jd, owner, post_stop);
}

Err Core::common_checks(const AxisRt& a, bool need_servo) const noexcept {
  if (!a.present || !a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  // A CIP drive that refused its configuration or never answered: the axis
  // is not configured (Logix Axis Configuration State not "configured").
  if (a.cfg.type == AxisType::CipDrive && link_failed(a.fb.link)) return Err::AxisNotConfigured;
  if (a.servo.shutdown) return Err::ShutdownState;
  if (a.servo.faulted) return Err::AxisInFaultedState;
  if (need_servo && !a.servo.on) return Err::ServoOffState;
  if (need_servo && a.direct.status) return Err::NotAllowedWhileInDirectMotion;  // [RM002H p.578]
  return Err::None;
}

}  // namespace canmotion::motion
