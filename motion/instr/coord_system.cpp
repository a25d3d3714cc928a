// Coordinated family, the running side (motion/instr/coord.hpp): coordinate
// systems stepped once per cycle by their first member, CoordGen (a member's
// share of the path), the path's events written to the control tags, MDCC
// links, the CS tags. Everything here runs in the cycle: realtime-safe,
// allocation-free.
#include <algorithm>
#include <cmath>
#include <limits>

#include "motion/core.hpp"
#include "motion/instr/coord.hpp"

namespace canmotion::motion {
namespace {

CoordSystemRt::Owner* find_owner(CoordSystemRt& s, std::uint32_t id) noexcept {
  if (id == 0) return nullptr;
  for (auto& o : s.owners)
    if (o.id == id) return &o;
  return nullptr;
}

AxisRt& member(Core& c, const CoordSystemRt& s, int i) noexcept { return c.axes[s.cfg.axes[static_cast<std::size_t>(i)]]; }

/// The coordinated slot of `a` if it belongs to system `id`.
CoordGen* slot_of(AxisRt& a, CoordSystemId id) noexcept {
  auto* g = std::get_if<CoordGen>(&a.gen[index(Slot::Coord)]);
  return g && g->cs == id ? g : nullptr;
}

CoordSystemId id_of(const Core& c, const CoordSystemRt& s) noexcept {
  return static_cast<CoordSystemId>(&s - c.systems.data());
}

bool is_member(const CoordSystemRt& s, AxisId axis) noexcept {
  for (int i = 0; i < s.cfg.dim; ++i)
    if (s.cfg.axes[static_cast<std::size_t>(i)] == axis) return true;
  return false;
}

/// A single-axis stop ramp of `owner` still runs on a member (MAS All: the
/// member's other motion; its PC waits for both).
bool ramp_owned_by(Core& c, const CoordSystemRt& s, OwnerRef owner) noexcept {
  for (int i = 0; i < s.cfg.dim; ++i)
    for (const auto& g : member(c, s, i).gen)
      if (auto* p = std::get_if<ProfileGen>(&g); p && p->role == GenRole::Stop && p->owner == owner) return true;
  return false;
}

/// EventDistance / CalculatedData of the move that just went active.
void calculated_data(Core& c, CoordSystemRt& s, const CoordSystemRt::Owner& o, ControlTag* t) noexcept {
  if (o.ed >= kMaxRealArrays || o.cd >= kMaxRealArrays) return;
  const std::span<double> ed = c.real_arrays[o.ed], cd = c.real_arrays[o.cd];
  if (!(o.ed_start >= 0) || !(o.cd_start >= 0) || o.ed_start >= static_cast<double>(ed.size()) ||
      o.cd_start >= static_cast<double>(cd.size()))
    return;
  const auto e = ed.subspan(static_cast<std::size_t>(o.ed_start));
  const auto d = cd.subspan(static_cast<std::size_t>(o.cd_start));
  const std::size_t n = std::min(e.size(), d.size());
  if (s.path.calculated_data(e.first(n), d.first(n)) && t) t->set(flag::CalculatedDataAvailable, true);
}

}  // namespace

namespace coordsys {

bool configure(Core& c, CoordSystemId id, const CoordSystemConfig& cfg) noexcept {
  if (id >= kMaxCoordSystems || cfg.dim < 1 || cfg.dim > coord::kMaxDim) return false;
  if (!(cfg.max_speed > 0) || !(cfg.max_accel > 0) || !(cfg.max_decel > 0) || !(cfg.max_accel_jerk >= 0) ||
      !(cfg.max_decel_jerk >= 0) || !(cfg.actual_tolerance >= 0) || !(cfg.command_tolerance >= 0))
    return false;
  for (int i = 0; i < cfg.dim; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (cfg.axes[k] >= kMaxAxes || !c.axes[cfg.axes[k]].present) return false;
    if (!(cfg.ratio[k] > 0) || !std::isfinite(cfg.ratio[k])) return false;
    for (std::size_t j = 0; j < k; ++j)
      if (cfg.axes[j] == cfg.axes[k]) return false;
  }
  CoordSystemRt& s = c.systems[id];
  s = CoordSystemRt{};
  s.cfg = cfg;
  s.present = true;
  coord::SystemConfig sc;
  sc.dim = cfg.dim;
  sc.ratio = cfg.ratio;
  sc.period = c.T;
  sc.actual_tolerance = cfg.actual_tolerance;
  sc.command_tolerance = cfg.command_tolerance;
  s.path.configure(sc);
  return true;
}

void master_state(const Core& c, const MdccLink& l, coord::Present& now) noexcept {
  if (!l.valid()) return;
  const AxisRt& m = c.axes[l.master];
  now.has_master = true;
  now.master_position = l.use_actual ? m.fb_pos : m.cmd.p;
  now.master_velocity = l.use_actual ? m.fb_vel : m.cmd.v;
}

coord::Present present(const Core& c, const CoordSystemRt& s, const MdccLink& link) noexcept {
  coord::Present now;
  now.has_total = true;
  double fe2 = 0;
  for (int i = 0; i < s.cfg.dim; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const AxisRt& a = c.axes[s.cfg.axes[k]];
    now.total.c[k] = c.user_command(a) * s.cfg.ratio[k];
    if (a.cfg.type == AxisType::CipDrive) {
      const double e = (c.compared_command(a) - a.fb_pos) * s.cfg.ratio[k];
      fe2 += e * e;
    }
  }
  now.following_error = std::sqrt(fe2);
  master_state(c, link, now);
  return now;
}

void settle(Core& c, CoordSystemRt& s, const AxisRt* folding) noexcept {
  const CoordSystemId id = id_of(c, s);
  s.dropping = true;
  for (int i = 0; i < s.cfg.dim; ++i)
    if (AxisRt& a = member(c, s, i); &a != folding && slot_of(a, id)) c.fold(a, Slot::Coord, false);
  s.dropping = false;
  s.path.fold();
  s.fold_due = false;
}

void join_members(Core& c, CoordSystemRt& s) noexcept {
  const CoordSystemId id = id_of(c, s);
  for (int i = 0; i < s.cfg.dim; ++i) {
    AxisRt& a = member(c, s, i);
    if (slot_of(a, id)) continue;
    CoordGen g;
    g.cs = id;
    g.member = static_cast<std::uint8_t>(i);
    g.link_master = s.link.master;
    c.set_slot(a, Slot::Coord, g);
  }
}

void apply_events(Core& c, CoordSystemRt& s, const coord::Events& ev) noexcept {
  for (int i = 0; i < ev.n; ++i) {
    const coord::Event& e = ev.e[static_cast<std::size_t>(i)];
    CoordSystemRt::Owner* o = find_owner(s, e.id);
    if (!o) continue;
    ControlTag* t = c.tag(o->owner);
    // a stop of an MGS (its PC when the whole group stopped: stop::finish_group_stops),
    // or of an MAS All whose single-axis ramp still runs (that ramp ends it)
    if (t && o->stop && (c.group_owns(o->owner) || ramp_owned_by(c, s, o->owner))) t = nullptr;
    switch (e.kind) {
      case coord::EventKind::Activated:
        if (t) t->set(flag::AC, true);
        s.md_last = o->mdcc_ac;
        calculated_data(c, s, *o, t);
        continue;  // the owner stays
      case coord::EventKind::Completed:
      case coord::EventKind::StopDone:
        if (t) t->set(flag::PC, true);
        break;
      case coord::EventKind::Failed:
        if (t) t->reject(e.err);
        break;
      case coord::EventKind::Cancelled:
        break;
    }
    if (t) {
      t->set(flag::IP, false);
      t->set(flag::AC, false);
      t->set(flag::TrackingMaster, false);
    }
    *o = CoordSystemRt::Owner{};
  }
}

void step_system(Core& c, CoordSystemRt& s) noexcept {
  s.stepped = c.cycle;
  s.path.step(present(c, s, s.link), s.out);
  apply_events(c, s, s.out.events);
  if (!s.path.moving()) s.fold_due = true;  // the members fold their slots as they step
}

void drop(Core& c, CoordSystemRt& s, const AxisRt* folding) noexcept {
  if (s.dropping) return;
  coord::Events ev;
  s.path.clear(ev);
  apply_events(c, s, ev);
  settle(c, s, folding);
}

void start_stop(Core& c, CoordSystemRt& s, OwnerRef owner, double d, double jd) noexcept {
  if (s.fold_due && !s.path.moving()) settle(c, s);
  // a free owner entry always exists: the path holds an active, a pending
  // move and a stop (superseded by this one), 4 entries
  auto it = std::find_if(s.owners.begin(), s.owners.end(), [](const auto& o) { return o.id == 0; });
  const std::uint32_t id = s.next_id;
  s.next_id = s.next_id == 0xFFFFFFFFu ? 1 : s.next_id + 1;
  if (it != s.owners.end()) {
    *it = CoordSystemRt::Owner{id, owner};
    it->stop = true;
  }
  coord::Events ev;
  s.path.stop(id, d, jd, ev);
  apply_events(c, s, ev);
}

bool path_stop(Core& c, CoordSystemRt& s, OwnerRef owner) noexcept {
  if (!s.path.moving()) return false;
  if (const CoordSystemRt::Owner* o = find_owner(s, s.path.stop_id()); o && o->owner == owner) return true;
  start_stop(c, s, owner, s.cfg.max_decel, std::numeric_limits<double>::infinity());
  return true;
}

bool stop_member_path(Core& c, AxisRt& a, OwnerRef owner) noexcept {
  const auto* g = std::get_if<CoordGen>(&a.gen[index(Slot::Coord)]);
  return g && path_stop(c, c.systems[g->cs], owner);
}

bool stop_owned_by(const Core& c, OwnerRef owner) noexcept {
  for (const CoordSystemRt& s : c.systems) {
    if (!s.present || !s.path.stopping()) continue;
    for (const auto& o : s.owners)
      if (o.id != 0 && o.id == s.path.stop_id() && o.owner == owner) return true;
  }
  return false;
}

Err check_no_coordinated_motion(const Core& c, const AxisRt& a) noexcept {
  const auto* g = std::get_if<CoordGen>(&a.gen[index(Slot::Coord)]);
  return g && c.systems[g->cs].path.moving() ? Err::CoordinatedMotionInProcess : Err::None;
}

void break_member_links(Core& c, AxisId axis) noexcept {
  for (CoordSystemRt& s : c.systems)
    if (s.present && is_member(s, axis) && (s.link.valid() || s.pending.valid())) break_links(c, s);
}

void on_shutdown(Core& c, AxisId axis) noexcept {
  for (CoordSystemRt& s : c.systems) {
    if (!s.present) continue;
    const bool master = s.link.master == axis || s.pending.master == axis;
    if (master && s.path.master_driven()) path_stop(c, s, OwnerRef{});  // its master is gone
    if (master || is_member(s, axis)) {
      if (s.link.valid() || s.pending.valid()) break_links(c, s);
    }
  }
}

void take_pending_link(Core& c, CoordSystemRt& s) noexcept {
  if (ControlTag* old = c.tag(s.link.owner); old && !(s.link.owner == s.pending.owner)) {
    old->set(flag::IP, false);
    old->set(flag::AC, false);
  }
  s.link = s.pending;
  s.pending = MdccLink{};
  refresh_link_master(c, s);
}

void refresh_link_master(Core& c, CoordSystemRt& s) noexcept {
  const CoordSystemId id = id_of(c, s);
  for (int i = 0; i < s.cfg.dim; ++i)
    if (CoordGen* g = slot_of(member(c, s, i), id)) g->link_master = s.link.master;
  c.order_dirty = true;
}

void break_links(Core& c, CoordSystemRt& s) noexcept {
  for (MdccLink* l : {&s.link, &s.pending}) {
    if (ControlTag* t = c.tag(l->owner)) {
      t->set(flag::IP, false);
      t->set(flag::AC, false);
    }
    *l = MdccLink{};
  }
  refresh_link_master(c, s);
}

CoordSystemRt* system_of(Core& c, const AxisRt& a) noexcept {
  const auto* g = std::get_if<CoordGen>(&a.gen[index(Slot::Coord)]);
  return g ? &c.systems[g->cs] : nullptr;
}

void update_tags(Core& c) noexcept {
  using namespace coordinate_system_status;
  for (CoordSystemRt& s : c.systems) {
    if (!s.present) continue;
    CoordSystemTag& t = s.tag;
    bool shutdown = false, ready = true, inhibited = false;
    for (int i = 0; i < s.cfg.dim; ++i) {
      const AxisRt& a = member(c, s, i);
      const auto k = static_cast<std::size_t>(i);
      shutdown = shutdown || a.servo.shutdown;
      inhibited = inhibited || a.cfg.inhibited;
      ready = ready && a.servo.on && !a.servo.faulted && !a.servo.shutdown;
      const double act = a.cfg.type == AxisType::Virtual ? a.cmd.p : a.fb_pos;
      t.command_position[k] = c.user_command(a) * s.cfg.ratio[k];
      t.actual_position[k] = (act + a.frame_offset) * s.cfg.ratio[k];
    }
    const bool moving = s.path.moving();
    t.system_status = (shutdown ? 1u << ShutdownStatus : 0u) | (ready ? 1u << ReadyStatus : 0u) |
                      (moving ? 1u << MotionStatus : 0u) | (inhibited ? 1u << AxisInhibitStatus : 0u);
    const bool fresh = s.stepped == c.cycle;
    t.motion_status = fresh || moving ? s.out.motion_status : s.out.motion_status & ~(1u << coordinate_motion_status::MoveStatus);
    t.speed = moving && fresh ? s.out.speed : 0.0;
    // the active move: TrackingMaster; its MDCC: AC while a master-driven move is active
    const CoordSystemRt::Owner* act = find_owner(s, s.path.active_id());
    if (act) {
      if (ControlTag* m = c.tag(act->owner)) m->set(flag::TrackingMaster, act->mdcc_ac && s.out.tracking_master);
    }
    if (ControlTag* l = c.tag(s.link.owner)) l->set(flag::AC, act && act->mdcc_ac);
  }
}

}  // namespace coordsys

void CoordGen::step(Core& c, AxisRt& a, Slot s) noexcept {
  CoordSystemRt& sys = c.systems[cs];
  if (sys.stepped != c.cycle) coordsys::step_system(c, sys);
  const auto m = static_cast<std::size_t>(member);
  k = Kin{sys.out.axis_offset[m], sys.out.axis_velocity[m], sys.out.axis_acceleration[m]};
  if (!sys.path.moving()) c.fold(a, s, false);  // the path ended: the offset into the base (last statement: *this ends)
}

void CoordGen::on_fold(Core& c, AxisRt& a) noexcept {
  // A member's slot taken away while the path runs (servo off: MSF, a drive
  // that left Operation Enabled, a Stop Drive fault; shutdown: MASD, MGSD, a
  // Shutdown fault): the moves end and the path stops along itself at the
  // system's max decel, the other members following it (reference: "path-stop
  // the other members"). The last member that leaves drops the path.
  CoordSystemRt& sys = c.systems[cs];
  if (sys.dropping || !sys.path.moving()) return;
  bool others = false;
  for (int i = 0; i < sys.cfg.dim; ++i) {
    const AxisRt& m = c.axes[sys.cfg.axes[static_cast<std::size_t>(i)]];
    const auto* g = std::get_if<CoordGen>(&m.gen[index(Slot::Coord)]);
    others = others || (&m != &a && g && g->cs == cs);
  }
  if (others) coordsys::path_stop(c, sys, OwnerRef{});
  else coordsys::drop(c, sys, &a);  // `a` is folding already
}

}  // namespace canmotion::motion
