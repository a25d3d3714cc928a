#include "motion/planner.hpp"

#include <type_traits>

#include "motion/instructions.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace canmotion::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// MSO/MSF on a CIP drive: how long the planner waits for the drive (seconds)
/// before ERR 12 (Servo Message Failure, EXERR 16 device in wrong state).
constexpr double kDriveTimeout = 5.0;


// Operand indices, looked up once in THE signature table (motion/signatures.cpp).
struct Idx {
  int mam_type, mam_pos, mam_speed;
  int maj_dir, maj_speed;
  int mas_type, mas_chg_decel, mas_decel, mas_decel_units, mas_chg_jerk, mas_jerk, mas_jerk_units;
  int mcd_type, mcd_chg_speed, mcd_speed, mcd_chg_accel, mcd_accel, mcd_chg_decel, mcd_decel, mcd_chg_ajerk,
      mcd_ajerk, mcd_chg_djerk, mcd_djerk, mcd_speed_units, mcd_accel_units, mcd_decel_units, mcd_jerk_units;
  int mrp_type, mrp_select, mrp_pos;
  int mgs_mode;
  int mds_speed, matc_dir, matc_dscale, matc_tscale;
};
const Idx& idx() noexcept {
  static const Idx k{
      operand_index(Instr::MAM, "MoveType"), operand_index(Instr::MAM, "Position"), operand_index(Instr::MAM, "Speed"),
      operand_index(Instr::MAJ, "Direction"), operand_index(Instr::MAJ, "Speed"),
      operand_index(Instr::MAS, "StopType"), operand_index(Instr::MAS, "ChangeDecel"),
      operand_index(Instr::MAS, "DecelRate"), operand_index(Instr::MAS, "DecelUnits"),
      operand_index(Instr::MAS, "ChangeDecelJerk"), operand_index(Instr::MAS, "DecelJerk"),
      operand_index(Instr::MAS, "JerkUnits"),
      operand_index(Instr::MCD, "MotionType"), operand_index(Instr::MCD, "ChangeSpeed"),
      operand_index(Instr::MCD, "Speed"), operand_index(Instr::MCD, "ChangeAccel"),
      operand_index(Instr::MCD, "AccelRate"), operand_index(Instr::MCD, "ChangeDecel"),
      operand_index(Instr::MCD, "DecelRate"), operand_index(Instr::MCD, "ChangeAccelJerk"),
      operand_index(Instr::MCD, "AccelJerk"), operand_index(Instr::MCD, "ChangeDecelJerk"),
      operand_index(Instr::MCD, "DecelJerk"), operand_index(Instr::MCD, "SpeedUnits"),
      operand_index(Instr::MCD, "AccelUnits"), operand_index(Instr::MCD, "DecelUnits"),
      operand_index(Instr::MCD, "JerkUnits"),
      operand_index(Instr::MRP, "Type"), operand_index(Instr::MRP, "PositionSelect"),
      operand_index(Instr::MRP, "Position"),
      operand_index(Instr::MGS, "StopMode"),
      operand_index(Instr::MDS, "Speed"), operand_index(Instr::MATC, "Direction"),
      operand_index(Instr::MATC, "DistanceScaling"), operand_index(Instr::MATC, "TimeScaling"),
  };
  return k;
}

inline bool is_md_jerk(int u) noexcept { return u == 4 || u == 6 || u == 7; }

/// Generic access to any generator's state.
struct GenRef {
  Kin* k = nullptr;
  OwnerRef owner{};
};
GenRef gen_ref(Generator& g) noexcept {
  if (auto* p = std::get_if<ProfileGen>(&g)) return {&p->k, p->owner};
  if (auto* q = std::get_if<GearGen>(&g)) return {&q->k, q->owner};
  if (auto* c = std::get_if<CamGen>(&g)) return {&c->k, c->owner};
  if (auto* pc = std::get_if<PosCamGen>(&g)) return {&pc->k, pc->owner};
  return {};
}

/// floor(a * b / c) in exact integer arithmetic (c > 0).
std::int64_t mul_div_floor(std::int64_t a, std::int64_t b, std::int64_t c) noexcept {
  __extension__ typedef __int128 i128;
  const i128 n = static_cast<i128>(a) * static_cast<i128>(b);
  i128 q = n / c;
  if ((n % c != 0) && ((n < 0) != (c < 0))) --q;
  return static_cast<std::int64_t>(q);
}

/// Decoded dynamics of MAM/MAJ (operands Speed .. LockDirection are laid out
/// identically in both; `is` is the index of Speed).
struct Dyn {
  Limits lim{};
  double speed = 0.0;  ///< programmed speed, units/s (0 allowed: paused)
  bool scurve = false;
  bool seconds = false;
  bool merge = false;
  bool merge_current = false;
  double t_total = 0, t_acc = 0, t_dec = 0, tj_acc = 0, tj_dec = 0;  // seconds units
  int jerk_units = 0;
  double jerk_pct_a = 0, jerk_pct_d = 0;  // % of time (applied once the start speed is known)
  bool master_driven = false;  ///< units per master unit / master units: MDSC
  LockDirection lock = LockDirection::None;
  double lock_pos = 0.0;
};

Err decode_dynamics(const Dynamics& y, const AxisConfig& cfg, double last_speed, Dyn& d, std::int8_t& exerr) noexcept {
  const int is = y.first_operand;
  const int su = y.speed_units, au = y.accel_units, du = y.decel_units;
  const int ju = y.jerk_units;
  d.scurve = y.profile == ProfileType::SCurve;
  d.merge = y.merge == Merge::Enabled;
  d.merge_current = y.merge_speed == MergeSpeed::Current;
  const int lockdir = static_cast<int>(y.lock_direction);
  const bool md = is_master_driven(static_cast<std::uint8_t>(su));
  if (is_master_driven(static_cast<std::uint8_t>(au)) != md || is_master_driven(static_cast<std::uint8_t>(du)) != md ||
      (d.scurve && is_md_jerk(ju) != md))
    return Err::MdscUnitsConflict;
  // LockDirection: none in time-driven mode, not none in master-driven mode [RM002H p.512]
  if (md == (lockdir == 0)) return Err::MdscLockDirConflict;
  d.master_driven = md;
  d.lock = y.lock_direction;
  d.lock_pos = y.lock_position;
  const double speed = y.speed, accel = y.accel, decel = y.decel;
  const double ajerk = y.accel_jerk, djerk = y.decel_jerk;
  // seconds (3) or, master driven, master units (7): the distance over which
  // the move happens; all or nothing
  const int tu = md ? 7 : 3;
  if (su == tu || au == tu || du == tu || (d.scurve && ju == tu)) {
    if (su != tu) { exerr = static_cast<std::int8_t>(is + 1); return Err::ParameterOutOfRange; }
    if (au != tu) { exerr = static_cast<std::int8_t>(is + 3); return Err::ParameterOutOfRange; }
    if (du != tu) { exerr = static_cast<std::int8_t>(is + 5); return Err::ParameterOutOfRange; }
    if (d.scurve && ju != tu) { exerr = static_cast<std::int8_t>(is + 9); return Err::ParameterOutOfRange; }
    d.seconds = true;
    d.t_total = speed; d.t_acc = accel; d.t_dec = decel;
    if (!(speed > 0)) { exerr = static_cast<std::int8_t>(is); return Err::ParameterOutOfRange; }
    if (accel + decel > speed) { exerr = static_cast<std::int8_t>(is + 2); return Err::ParameterOutOfRange; }
    if (d.scurve) {
      if (!(ajerk >= 0) || ajerk > accel / 2) { exerr = static_cast<std::int8_t>(is + 7); return Err::ParameterOutOfRange; }
      if (!(djerk >= 0) || djerk > decel / 2) { exerr = static_cast<std::int8_t>(is + 8); return Err::ParameterOutOfRange; }
      d.tj_acc = ajerk; d.tj_dec = djerk;
    }
    return Err::None;
  }
  d.speed = su == 1 ? speed / 100.0 * cfg.max_speed : speed;
  d.lim.a = au == 1 ? accel / 100.0 * cfg.max_accel : accel;
  if (du == 1 && !(cfg.max_decel > 0)) return Err::ZeroMaxDecel;
  d.lim.d = du == 1 ? decel / 100.0 * cfg.max_decel : decel;
  if (!(d.lim.a > 0)) { exerr = static_cast<std::int8_t>(is + 2); return Err::ParameterOutOfRange; }
  if (!(d.lim.d > 0)) { exerr = static_cast<std::int8_t>(is + 4); return Err::ParameterOutOfRange; }
  d.lim.v = d.speed;
  d.lim.ja = d.lim.jd = kInf;
  d.jerk_units = ju;
  if (d.scurve) {
    switch (ju) {
      case 0:
      case 4:  // units per master unit^3
        if (!(ajerk > 0)) { exerr = static_cast<std::int8_t>(is + 7); return Err::ParameterOutOfRange; }
        if (!(djerk > 0)) { exerr = static_cast<std::int8_t>(is + 8); return Err::ParameterOutOfRange; }
        d.lim.ja = ajerk; d.lim.jd = djerk;
        break;
      case 1:
        if (!(ajerk > 0) || ajerk > 100) { exerr = static_cast<std::int8_t>(is + 7); return Err::ParameterOutOfRange; }
        if (!(djerk > 0) || djerk > 100) { exerr = static_cast<std::int8_t>(is + 8); return Err::ParameterOutOfRange; }
        if (!(cfg.max_decel_jerk > 0)) return Err::ZeroMaxDecelJerk;
        if (!(cfg.max_accel_jerk > 0)) { exerr = static_cast<std::int8_t>(is + 7); return Err::ParameterOutOfRange; }
        d.lim.ja = ajerk / 100.0 * cfg.max_accel_jerk;
        d.lim.jd = djerk / 100.0 * cfg.max_decel_jerk;
        break;
      case 2:
      case 6: {  // % of time (master driven: over master distance)
        if (!(ajerk >= 0) || ajerk > 100) { exerr = static_cast<std::int8_t>(is + 7); return Err::ParameterOutOfRange; }
        if (!(djerk >= 0) || djerk > 100) { exerr = static_cast<std::int8_t>(is + 8); return Err::ParameterOutOfRange; }
        d.jerk_pct_a = ajerk; d.jerk_pct_d = djerk;
        // [RM002H p.447]: a zero-speed S-curve uses the previous non-zero speed.
        const double v = d.speed > 0 ? d.speed : last_speed;
        d.lim.ja = jerk_from_percent_of_time(d.lim.a, v, ajerk);
        d.lim.jd = jerk_from_percent_of_time(d.lim.d, v, djerk);
        break;
      }
      default:
        exerr = static_cast<std::int8_t>(is + 9);
        return Err::ParameterOutOfRange;
    }
  }
  return Err::None;
}

}  // namespace

Planner::Planner(double cycle_period) noexcept : T_(cycle_period > 0 ? cycle_period : 0.001) {
  (void)idx();
  init_instruction_tables();  // operand positions, looked up once outside the cycle
}

bool Planner::begin_fault_reset(const Request& r, AxisRt& a) noexcept {
  a.servo.faulted = false;
  a.tag.exception_faults = 0;
  a.tag.motion_fault_status = 0;
  if (a.cfg.type != AxisType::CipDrive) return true;
  a.servo.fault_reset_pulse = true;
  const bool clear = a.fb.link == DriveLink::Up && a.fb.drive != DriveState::Fault && !a.fb.drive_fault && !a.fb.node_lost;
  if (clear) return true;
  // The drive acts on the reset this cycle (the pulse goes out with this
  // cycle's RPDO); DN when its feedback shows it left Fault.
  if (a.servo.reset.valid() && a.servo.reset.id != r.control)
    if (ControlTag* old = tag(a.servo.reset)) old->reject(Err::ServoMessageFailure, 16);
  a.servo.reset = OwnerRef{r.control, controls_[r.control].generation};
  a.servo.reset_deadline = cycle_ + static_cast<std::uint64_t>(kDriveTimeout / T_);
  return false;
}

void Planner::end_fault_reset(AxisRt& a, bool ok) noexcept {
  const OwnerRef owner = a.servo.reset;
  a.servo.reset = {};
  ControlTag* c = tag(owner);
  if (!c) return;
  if (!ok) {
    c->reject(Err::ServoMessageFailure, 16);  // device in wrong state
    for (std::size_t i = 0; i < axis_count_; ++i)  // MGSR: the other axes stop waiting
      if (axes_[i].servo.reset == owner) axes_[i].servo.reset = {};
    return;
  }
  for (std::size_t i = 0; i < axis_count_; ++i)  // MGSR: DN with the last axis
    if (axes_[i].servo.reset == owner) return;
  c->set(flag::DN, true);
}

bool Planner::configure_axis(AxisId id, const AxisConfig& cfg) noexcept {
  if (id >= kMaxAxes) return false;
  if (!(cfg.conversion_constant > 0) || (cfg.rotary && !(cfg.unwind > 0)) || cfg.max_speed < 0 ||
      cfg.max_accel < 0 || cfg.max_decel < 0 || cfg.max_accel_jerk < 0 || cfg.max_decel_jerk < 0 ||
      cfg.position_error_tolerance < 0 || cfg.group >= kMaxGroups)
    return false;
  AxisRt& a = axes_[id];
  a = AxisRt{};
  a.cfg = cfg;
  a.present = true;
  axis_count_ = std::max<std::size_t>(axis_count_, static_cast<std::size_t>(id) + 1);
  order_dirty_ = true;
  update_status(a);
  return true;
}

// ------------------------------------------------------------------ helpers
ControlTag* Planner::tag(OwnerRef o) noexcept {
  if (o.id >= kMaxControlTags) return nullptr;
  ControlTag& c = controls_[o.id];
  return c.generation == o.gen ? &c : nullptr;  // the tag was re-executed: not ours any more
}

Kin Planner::slot_kin(const AxisRt& a, Slot s) const noexcept {
  const GenRef r = gen_ref(const_cast<Generator&>(a.gen[static_cast<std::size_t>(s)]));
  return r.k ? *r.k : Kin{};
}

double Planner::user_command(const AxisRt& a) const noexcept { return a.cmd.p + a.frame_offset; }

bool Planner::any_scurve(const AxisRt& a) const noexcept {
  for (unsigned m = a.live; m != 0; m &= m - 1)  // live slots only
    if (auto* p = std::get_if<ProfileGen>(&a.gen[std::countr_zero(m)]); p && p->scurve) return true;
  return false;
}

bool Planner::any_stopping(const AxisRt& a) const noexcept {
  for (unsigned m = a.live; m != 0; m &= m - 1)  // live slots only
    if (auto* p = std::get_if<ProfileGen>(&a.gen[std::countr_zero(m)]); p && p->role == GenRole::Stop) return true;
  return false;
}

void Planner::fold(AxisRt& a, Slot s, bool clear_owner_ip) noexcept {
  auto& slot = a.gen[static_cast<std::size_t>(s)];
  if (auto* cg = std::get_if<CamGen>(&slot); cg && cg->profile) {
    cg->profile->release();  // CAM_PROFILE[0].Status: one user less
    cg->profile = nullptr;
  }
  if (auto* pc = std::get_if<PosCamGen>(&slot)) end_position_cam(a, *pc);  // MAPC (planner_mapc.cpp)
  if (const MasterFollow* f = follow_of(slot)) {  // master-driven move/jog/offset move or time cam
    if (ControlTag* m = tag(f->mdac)) m->set(flag::AC, false);
  }
  if (const GenRef g = gen_ref(slot); g.k) {
    if (s == Slot::MasterOffset) add_master_offset(a, g.k->p);  // shifts the cam's master, not the slave
    else a.base += g.k->p;
    if (clear_owner_ip) {
      if (ControlTag* c = tag(g.owner)) {
        c->set(flag::IP, false);
        c->set(flag::ACCEL, false);
        c->set(flag::DECEL, false);
        c->set(flag::TrackingMaster, false);
        c->set(flag::AC, false);
      }
    }
  }
  const unsigned bit = 1u << static_cast<unsigned>(s);
  if (a.live & bit) order_dirty_ = true;  // a master link may have gone
  a.live = static_cast<std::uint8_t>(a.live & ~bit);
  slot = std::monostate{};
}

void Planner::abort_all(AxisRt& a) noexcept {
  for (std::size_t s = 0; s < kSlots; ++s) fold(a, static_cast<Slot>(s), true);
  a.cmd.v = 0;
  a.cmd.a = 0;
  a.cmd.p = a.base;
}

void Planner::servo_off(AxisRt& a) noexcept {
  abort_all(a);
  drop_pending_cam(a);
  drop_pending_pcam(a);
  end_direct(a, false);
  a.servo.on = false;
  a.servo.enable_req = false;
  if (a.hs.homing) {
    a.hs.homing = false;
    if (ControlTag* c = tag(a.hs.mah)) c->set(flag::IP, false);
  }
}

void Planner::do_shutdown(AxisRt& a) noexcept {
  servo_off(a);
  a.servo.shutdown = true;
  break_links(a);  // MASD/MGSD on a slave ...
  break_links_of_master(static_cast<AxisId>(&a - axes_.data()));  // ... and on a master
}

void Planner::break_links(AxisRt& a) noexcept {
  for (auto* arr : {&a.links.active, &a.links.pending}) {
    for (auto& l : *arr) {
      if (!l.valid()) continue;
      if (ControlTag* c = tag(l.owner)) {
        c->set(flag::IP, false);
        c->set(flag::AC, false);
      }
      l = MdacLink{};
    }
  }
}

void Planner::break_links_of_master(AxisId master) noexcept {
  for (std::size_t i = 0; i < axis_count_; ++i) {
    bool uses = false;
    for (const auto& l : axes_[i].links.active) uses = uses || l.master == master;
    for (const auto& l : axes_[i].links.pending) uses = uses || l.master == master;
    if (uses) break_links(axes_[i]);
  }
}

void Planner::promote_pending(AxisRt& a, int ti) noexcept {
  MdacLink& p = a.links.pending[static_cast<std::size_t>(ti)];
  if (!p.valid()) return;
  MdacLink& l = a.links.active[static_cast<std::size_t>(ti)];
  if (l.valid() && (l.owner != p.owner)) {
    bool still_used = false;  // an "All" MDAC tag may still hold other motion types
    for (std::size_t k = 0; k < a.links.active.size(); ++k)
      if (static_cast<int>(k) != ti && a.links.active[k].owner == l.owner) still_used = true;
    if (!still_used)
      if (ControlTag* c = tag(l.owner)) { c->set(flag::IP, false); c->set(flag::AC, false); }
  }
  l = p;
  p = MdacLink{};
}

Err Planner::master_driven_setup(AxisRt& a, int ti, ProfileGen& g, Kin& start, bool& ok) noexcept {
  ok = false;
  const std::size_t k = static_cast<std::size_t>(ti);
  const MdacLink& l = a.links.pending[k].valid() ? a.links.pending[k] : a.links.active[k];
  if (!l.valid()) return Err::MdscNotActivated;
  const AxisRt& m = axes_[l.master];
  const double mp = l.use_actual ? m.fb_pos : m.cmd.p;
  const double mv = l.use_actual ? m.fb_vel : m.cmd.v;
  const bool immediate = lock_immediate(g.md.lock);
  const bool fwd = lock_forward(g.md.lock);
  const double udot = immediate ? std::max(0.0, fwd ? mv : -mv) : 0.0;
  if (start.v != 0 || start.a != 0) {
    // the slave's present motion, per unit of master travel
    if (!(udot > 1e-9)) return Err::MdscIdleMasterSlaveMoving;
    start = Kin{0, start.v / udot, 0};
  }
  g.master_driven = true;
  g.md.master = l.master;
  g.md.use_actual = l.use_actual;
  g.md.locked = immediate;
  g.md.following = immediate;  // Move/JogLockStatus set at once for immediate locks
  g.md.lock_pos -= m.frame_offset;  // LockPosition is a master position (user frame); mp is drive frame
  g.md.prev_mp = mp;
  g.md.u = 0;
  g.md.mdac = l.owner;
  ok = true;
  return Err::None;
}

// --- MDAC
Err Planner::start_mdac(const Request& r, const MdacParams& p, AxisRt& a, std::int8_t&) noexcept {
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  if (a.servo.shutdown) return Err::ShutdownState;
  const AxisRt& m = axes_[p.master];
  if (!m.cfg.configured) return Err::AxisNotConfigured;
  if (m.cfg.inhibited) return Err::AxisIsInhibited;
  if (p.slave == p.master) return Err::MasterAxisConflict;
  if (a.hs.homing || m.hs.homing) return Err::HomeInProcess;
  // a virtual master always gives command, a feedback-only/CIP master follows the operand [seed 000]
  const bool use_actual = p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive;
  const bool all = p.motion_type == 0;
  const bool moving = a.cmd.v != 0 || a.cmd.a != 0;
  bool any_all = false, any_single = false;
  for (const auto& l : a.links.active) {
    if (!l.valid()) continue;
    if (l.all) any_all = true; else any_single = true;
  }
  if ((all && any_single) || (!all && any_all)) return Err::MdscMdacAllConflict;  // [seed 000]
  const std::size_t first = all ? 0 : static_cast<std::size_t>(p.motion_type - 1);
  const std::size_t last = all ? a.links.active.size() : first + 1;
  for (std::size_t k = first; k < last; ++k) {
    const MdacLink& l = a.links.active[k];
    // changing the master reference of a moving slave errors; the original stays [seed 000]
    if (l.valid() && l.master == p.master && l.use_actual != use_actual && moving) return Err::MdscInvalidModeOrMasterChange;
  }
  ControlTag& c = controls_[r.control];
  const MdacLink nl{p.master, use_actual, all, OwnerRef{r.control, c.generation}};
  for (std::size_t k = first; k < last; ++k) {
    MdacLink& l = a.links.active[k];
    if (l.valid() && (l.master != p.master || l.use_actual != use_actual)) {
      // the new master is queued: it takes over when the next single-axis motion goes IP [seed 000]
      MdacLink& q = a.links.pending[k];
      if (q.valid() && (q.owner != OwnerRef{r.control, c.generation}))
        if (ControlTag* o = tag(q.owner)) o->set(flag::IP, false);  // a newer pending MDAC overrides
      q = nl;
    } else {
      if (l.valid() && (l.owner != OwnerRef{r.control, c.generation}))
        if (ControlTag* o = tag(l.owner)) { o->set(flag::IP, false); o->set(flag::AC, false); }
      l = nl;
    }
  }
  c.set(flag::DN, true);
  c.set(flag::IP, true);
  return Err::None;
}

bool Planner::stop_slots(AxisRt& a, std::uint32_t mask, double d, double jd, ControlId owner,
                         std::uint8_t post_stop) noexcept {
  const std::uint32_t all = (1u << kSlots) - 1u;
  const std::uint32_t gen_owner = owner < kMaxControlTags ? controls_[owner].generation : 0;
  if ((mask & all) == all) {
    Kin tot{};
    bool any = false;
    for (std::size_t s = 0; s < kSlots; ++s) {
      if (const GenRef g = gen_ref(a.gen[s]); g.k && s != static_cast<std::size_t>(Slot::MasterOffset)) {
        tot.v += g.k->v;
        tot.a += g.k->a;
        any = true;
      }
      fold(a, static_cast<Slot>(s), true);
    }
    if (!any || (tot.v == 0 && tot.a == 0)) return false;
    ProfileGen g;
    g.role = GenRole::Stop;
    if (!plan_stop(g.prof, Kin{0, tot.v, tot.a}, d, jd)) return false;
    g.t0_cycle = cycle_;
    g.k = Kin{0, tot.v, tot.a};
    g.owner = OwnerRef{owner, gen_owner};
    g.post_stop = post_stop;
    g.scurve = !std::isinf(jd);
    set_slot(a, Slot::StopAll, g);
    return true;
  }
  bool any = false;
  for (std::size_t s = 0; s < kSlots; ++s) {
    if (!(mask & (1u << s))) continue;
    const GenRef g = gen_ref(a.gen[s]);
    if (!g.k) continue;
    const Kin k = *g.k;
    fold(a, static_cast<Slot>(s), true);
    if (k.v == 0 && k.a == 0) continue;
    ProfileGen st;
    st.role = GenRole::Stop;
    if (!plan_stop(st.prof, Kin{0, k.v, k.a}, d, jd)) continue;
    st.t0_cycle = cycle_;
    st.k = Kin{0, k.v, k.a};
    st.owner = OwnerRef{owner, gen_owner};
    st.post_stop = post_stop;
    st.scurve = !std::isinf(jd);
    set_slot(a, static_cast<Slot>(s), st);
    any = true;
  }
  return any;
}

Err Planner::common_checks(const AxisRt& a, bool need_servo) const noexcept {
  if (!a.present || !a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  // A CIP drive that refused its configuration or never answered: the axis
  // is not configured (Logix Axis Configuration State not "configured").
  if (a.cfg.type == AxisType::CipDrive && (a.fb.link == DriveLink::ConfigFailed || a.fb.link == DriveLink::NoModule))
    return Err::AxisNotConfigured;
  if (a.servo.shutdown) return Err::ShutdownState;
  if (a.servo.faulted) return Err::AxisInFaultedState;
  if (need_servo && !a.servo.on) return Err::ServoOffState;
  if (need_servo && a.direct.status) return Err::NotAllowedWhileInDirectMotion;  // [RM002H p.578]
  return Err::None;
}

// ------------------------------------------------------------------ execute
Err Planner::execute(const Request& r) noexcept {
  if (r.control >= kMaxControlTags) return Err::ParameterOutOfRange;
  ControlTag& c = controls_[r.control];
  c.begin_execution();
  const InstrSig& sig = signature(r.instr);
  std::int8_t exerr = 0;
  Err e = Err::None;
  if (r.count != sig.operands.size()) {
    exerr = static_cast<std::int8_t>(std::min<std::size_t>(r.count, sig.operands.size()));
    e = Err::ParameterOutOfRange;
  } else if (!sig.executable) {
    e = Err::InstructionNotSupported;
  } else {
    // reference operands
    for (std::size_t i = 0; i < sig.operands.size() && e == Err::None; ++i) {
      const auto k = sig.operands[i].kind;
      const auto ref = r.op[i].ref;
      if (k == OperandKind::Axis && (ref >= kMaxAxes || !axes_[ref].present)) e = Err::AxisNotConfigured;
      if (k == OperandKind::Group && ref >= kMaxGroups) e = Err::AxisNotConfigured;
    }
    if (e == Err::None) {
      std::array<double, kMaxOperands> vals{};
      for (std::size_t i = 0; i < kMaxOperands; ++i) vals[i] = r.op[i].value;
      const OperandCheck oc = check_operands(r.instr, std::span<const double>(vals.data(), sig.operands.size()));
      if (!oc.ok) {
        e = Err::ParameterOutOfRange;
        exerr = static_cast<std::int8_t>(oc.index);
      }
    }
  }
  if (e == Err::None) {
    // params (typed, from the table-checked request) -> the instruction's start
    const Params prm = decode(r);
    e = std::visit(
        [&](const auto& p) noexcept -> Err {
          using P = std::decay_t<decltype(p)>;
          if constexpr (std::is_same_v<P, MsoParams>) return start_mso(r, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MsfParams>) return start_msf(r, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MasdParams>) return start_masd(r, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MasrParams>) return start_masr(r, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MafrParams>) return start_mafr(r, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MahParams>) return start_mah(r, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MasParams>) return start_mas(r, p, axes_[p.axis], exerr);
          else if constexpr (std::is_same_v<P, MajParams>) return start_maj(r, p, axes_[p.axis], exerr);
          else if constexpr (std::is_same_v<P, MamParams>) return start_mam(r, p, axes_[p.axis], exerr);
          else if constexpr (std::is_same_v<P, McdParams>) return start_mcd(r, p, axes_[p.axis], exerr);
          else if constexpr (std::is_same_v<P, MrpParams>) return start_mrp(r, p, axes_[p.axis]);
          else if constexpr (std::is_same_v<P, MagParams>) return start_mag(r, p, axes_[p.slave], exerr);
          else if constexpr (std::is_same_v<P, MdacParams>) return start_mdac(r, p, axes_[p.slave], exerr);
          else if constexpr (std::is_same_v<P, MdsParams>) return start_mds(r, p, axes_[p.axis], exerr);
          else if constexpr (std::is_same_v<P, MatcParams>) return start_matc(r, p, axes_[p.axis], exerr);
          else if constexpr (std::is_same_v<P, MapcParams>) return start_mapc(r, p, axes_[p.slave], exerr);
          else if constexpr (std::is_same_v<P, MccpParams>) return start_mccp(r, p, exerr);
          else if constexpr (std::is_same_v<P, MgsParams>) return start_group(r, p.group, p.mode, exerr);
          else if constexpr (std::is_same_v<P, MgsdParams> || std::is_same_v<P, MgsrParams>)
            return start_group(r, p.group, GroupStopMode::Programmed, exerr);
          else return Err::InstructionNotSupported;  // issue 5 / coordinated: parsed, not run yet
        },
        prm);
  }
  if (e != Err::None) {
    c.reject(e, exerr);
  }
  // refresh the tags of the axes this request named (all axes for group instructions)
  const auto ops = sig.operands;
  for (std::size_t i = 0; i < ops.size() && i < r.count; ++i) {
    if (ops[i].kind == OperandKind::Axis && r.op[i].ref < kMaxAxes && axes_[r.op[i].ref].present)
      update_status(axes_[r.op[i].ref]);
    if (ops[i].kind == OperandKind::Group)
      for (std::size_t k = 0; k < axis_count_; ++k) if (axes_[k].present) update_status(axes_[k]);
  }
  return e;
}

// --- MSO / MSF / MASD / MASR / MAFR
Err Planner::start_mso(const Request& r, AxisRt& a) noexcept {
  if (Err e = common_checks(a, false); e != Err::None) return e;
  ControlTag& c = controls_[r.control];
  if (a.direct.status) {  // MSO is the way out of direct control [RM002H p.578]
    end_direct(a, false);
    a.base = a.fb_pos;
    a.cmd = Kin{a.fb_pos, 0, 0};
  }
  if (a.servo.on) {
    c.set(flag::DN, true);
    return Err::None;
  }
  // [RM002H p.78] ERR 22 if the (servo-off) axis is moving: a drive coasting
  // faster than 0.1 % of max speed (at least 1e-6 units/s)
  if (a.cfg.type == AxisType::CipDrive && std::fabs(a.fb_vel) > std::max(1e-6, 1e-3 * a.cfg.max_speed))
    return Err::AxisInMotion;
  a.servo.enable_req = true;
  if (a.cfg.type == AxisType::Virtual) {
    a.servo.on = true;
    c.set(flag::DN, true);
    return Err::None;
  }
  // CIP: DN when the drive reports Operation Enabled (STATE 0 request, 1 waiting).
  a.hs.mso = OwnerRef{r.control, c.generation};
  a.hs.deadline = cycle_ + static_cast<std::uint64_t>(kDriveTimeout / T_);
  c.state = 0;
  return Err::None;
}

Err Planner::start_msf(const Request& r, AxisRt& a) noexcept {
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  if (a.servo.shutdown) return Err::ShutdownState;
  ControlTag& c = controls_[r.control];
  const bool was_enabled = a.cfg.type == AxisType::CipDrive && a.fb.drive == DriveState::Enabled;
  servo_off(a);
  if (a.hs.mso.valid()) {  // cancel a pending MSO
    if (ControlTag* m = tag(a.hs.mso)) m->reject(Err::ServoMessageFailure, 15);
    a.hs.mso = {};
  }
  if (!was_enabled) {
    c.set(flag::DN, true);
  } else {
    a.hs.msf = OwnerRef{r.control, c.generation};
    a.hs.deadline = cycle_ + static_cast<std::uint64_t>(kDriveTimeout / T_);
  }
  return Err::None;
}

Err Planner::start_masd(const Request& r, AxisRt& a) noexcept {
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  do_shutdown(a);
  controls_[r.control].set(flag::DN, true);
  return Err::None;
}

Err Planner::start_masr(const Request& r, AxisRt& a) noexcept {
  // MASR = MAFR (clear the faults, pulse a drive fault reset) + leave Shutdown.
  const Err e = start_mafr(r, a);
  if (e == Err::None) a.servo.shutdown = false;
  return e;
}

Err Planner::start_mafr(const Request& r, AxisRt& a) noexcept {
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  // CIP: the drive's fault reset goes out this cycle; DN once the drive has
  // left Fault (and is connected again after a lost node or a reboot).
  if (begin_fault_reset(r, a)) controls_[r.control].set(flag::DN, true);
  return Err::None;
}

// --- MAS
Err Planner::start_mas(const Request& r, const MasParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  const Idx& I = idx();
  const auto type = p.stop_type;
  std::uint32_t mask = 0;
  switch (type) {
    case StopType::All: mask = (1u << kSlots) - 1u; break;
    case StopType::Jog: mask = 1u << static_cast<unsigned>(Slot::Jog); break;
    case StopType::Move: mask = 1u << static_cast<unsigned>(Slot::Move); break;
    case StopType::Gear: mask = 1u << static_cast<unsigned>(Slot::Gear); break;
    case StopType::TimeCam: mask = 1u << static_cast<unsigned>(Slot::TimeCam); break;
    case StopType::PositionCam: mask = 1u << static_cast<unsigned>(Slot::PositionCam); break;
    case StopType::MasterOffsetMove: mask = 1u << static_cast<unsigned>(Slot::MasterOffset); break;
    default: mask = 0; break;  // home / tune / test / direct control: no planner generator
  }
  // decel
  double d = a.cfg.max_decel;
  if (p.change_decel) {
    const double rate = p.decel_rate;
    if (!(rate > 0)) { exerr = static_cast<std::int8_t>(I.mas_decel); return Err::ParameterOutOfRange; }
    d = p.decel_units == 1 ? rate / 100.0 * a.cfg.max_decel : rate;
  }
  if (!(d > 0)) return Err::ZeroMaxDecel;
  // S-curve stop if any motion being stopped is S-curve
  bool scurve = false;
  double speed = 0.0;
  for (std::size_t s = 0; s < kSlots; ++s) {
    if (!(mask & (1u << s))) continue;
    if (auto* g = std::get_if<ProfileGen>(&a.gen[s])) scurve = scurve || g->scurve;
    if (const GenRef g = gen_ref(a.gen[s]); g.k) speed += g.k->v;
  }
  speed = std::fabs(speed);
  double jd = a.cfg.max_decel_jerk;
  if (p.change_decel_jerk) {
    const double j = p.decel_jerk;
    const int ju = p.jerk_units;
    if (ju == 2) {
      if (!(j >= 0) || j > 100) { exerr = static_cast<std::int8_t>(I.mas_jerk); return Err::ParameterOutOfRange; }
      jd = jerk_from_percent_of_time(d, speed, j);
    } else {
      if (!(j > 0) || (ju == 1 && j > 100)) { exerr = static_cast<std::int8_t>(I.mas_jerk); return Err::ParameterOutOfRange; }
      jd = ju == 1 ? j / 100.0 * a.cfg.max_decel_jerk : j;
    }
  }
  if (scurve && !(jd > 0)) return Err::ZeroMaxDecelJerk;
  if (!scurve) jd = kInf;

  ControlTag& c = controls_[r.control];
  c.set(flag::DN, true);
  if (type == StopType::All || type == StopType::Home) {
    if (a.hs.homing) {
      a.hs.homing = false;
      if (ControlTag* h = tag(a.hs.mah)) h->set(flag::IP, false);
      if (a.cfg.type == AxisType::CipDrive) a.base = a.fb_pos;
    }
  }
  const bool ramping = a.servo.on && mask != 0 && stop_slots(a, mask, d, jd, r.control, 0);
  if (type == StopType::All) break_links(a);  // MAS All on the slave breaks its MDAC links
  if (type == StopType::All || type == StopType::TimeCam) drop_pending_cam(a);
  if (type == StopType::All || type == StopType::PositionCam) drop_pending_pcam(a);
  if ((type == StopType::All || type == StopType::DirectControl) && a.direct.active) {
    // direct command to zero; the drive ramps down; PC at standstill
    end_direct(a, true);
    a.direct.stop = OwnerRef{r.control, c.generation};
    c.set(flag::IP, true);
    return Err::None;
  }
  if (ramping) c.set(flag::IP, true);
  else c.set(flag::PC, true);
  return Err::None;
}

// --- MAH
Err Planner::start_mah(const Request& r, AxisRt& a) noexcept {
  if (Err e = common_checks(a, false); e != Err::None) return e;
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
  ControlTag& c = controls_[r.control];
  if (h.mode == HomingConfig::Mode::Active) abort_all(a);  // active homing cancels other motion
  c.set(flag::DN, true);
  if (immediate) {
    const double ref = h.mode == HomingConfig::Mode::Active ? user_command(a) : a.fb_pos + a.frame_offset;
    const double delta = h.home_position - (a.cfg.rotary ? unwind_position(ref, a.cfg.unwind) : ref);
    a.frame_offset += delta;
    a.hs.homed = true;
    c.set(flag::PC, true);
    return Err::None;
  }
  // CIP drive homing, CiA 402 mode 6 with 0x6098/0x6099/0x609A from configuration
  a.hs.homing = true;
  a.hs.homing_started = false;
  a.hs.homed = false;
  a.hs.mah = OwnerRef{r.control, c.generation};
  c.set(flag::IP, true);
  return Err::None;
}

// --- MAJ
Err Planner::start_maj(const Request& r, const MajParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  if (any_stopping(a)) return Err::NotAllowedWhileStopping;
  const Idx& I = idx();
  Dyn dy;
  if (Err e = decode_dynamics(p.dyn, a.cfg, a.last_speed, dy, exerr); e != Err::None) return e;
  if (dy.seconds) { exerr = static_cast<std::int8_t>(I.maj_speed + 1); return Err::ParameterOutOfRange; }
  const double dir = p.reverse ? -1.0 : 1.0;
  if (dir > 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitPositive & 1u)) return Err::OvertravelCondition;
  if (dir < 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitNegative & 1u)) return Err::OvertravelCondition;
  Kin start{};
  auto* old = std::get_if<ProfileGen>(&a.gen[static_cast<std::size_t>(Slot::Jog)]);
  if (dy.merge) start = Kin{0, a.cmd.v, any_scurve(a) ? a.cmd.a : 0.0};
  else if (old) start = Kin{0, old->k.v, old->scurve ? old->k.a : 0.0};
  double V = dy.speed;
  if (dy.merge && dy.merge_current && std::fabs(start.v) > 0) V = std::fabs(start.v);
  if (dy.scurve && (dy.jerk_units == 2 || dy.jerk_units == 6)) {
    // [UM003F p.258]: decel jerk uses max(Speed, |StartSpeed - Speed|)
    const double vref = V > 0 ? V : a.last_speed;
    dy.lim.ja = jerk_from_percent_of_time(dy.lim.a, vref, dy.jerk_pct_a);
    dy.lim.jd = jerk_from_percent_of_time(dy.lim.d, std::max(vref, std::fabs(std::fabs(start.v) - V)), dy.jerk_pct_d);
  }
  ProfileGen g;
  g.role = GenRole::Jog;
  if (dy.master_driven) {  // the profile runs over master travel
    g.md.lock = dy.lock;
    g.md.lock_pos = dy.lock_pos;
    bool ok_md = true;
    if (Err e = master_driven_setup(a, 1, g, start, ok_md); e != Err::None) return e;
  }
  g.lim = dy.lim;
  g.lim.v = V > 0 ? V : 1.0;
  if (!plan_velocity(g.prof, start, dir * V, g.lim)) {
    exerr = static_cast<std::int8_t>(I.maj_speed);
    return Err::ParameterOutOfRange;
  }
  // commit
  if (dy.merge) {
    for (std::size_t s = 0; s < kSlots; ++s) fold(a, static_cast<Slot>(s), true);
  } else {
    fold(a, Slot::Jog, true);
  }
  ControlTag& c = controls_[r.control];
  g.t0_cycle = cycle_;
  g.k = start;
  g.scurve = dy.scurve;
  g.speed = V;
  g.jog_velocity = dir * V;
  g.owner = OwnerRef{r.control, c.generation};
  promote_pending(a, 1);
  if (g.master_driven) {
    c.set(flag::AC, true);
    if (ControlTag* m = tag(g.md.mdac)) m->set(flag::AC, true);
  }
  set_slot(a, Slot::Jog, g);
  if (V > 0) a.last_speed = V;
  c.set(flag::DN, true);
  c.set(flag::IP, true);
  return Err::None;
}

// --- MAM
Err Planner::start_mam(const Request& r, const MamParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  if (any_stopping(a)) return Err::NotAllowedWhileStopping;
  const Idx& I = idx();
  const auto mt = p.move_type;
  // master offset moves (5/6) shift the master of the active position cam:
  // Slot::MasterOffset, master units, MDAC link 3 (planner_mapc.cpp)
  const bool offset = mt == MoveType::AbsoluteMasterOffset || mt == MoveType::IncrementalMasterOffset;
  const AxisConfig* ucfg = offset ? position_cam_master(a) : &a.cfg;
  if (!ucfg) return Err::PositionCamNotEnabled;
  const Slot slot = offset ? Slot::MasterOffset : Slot::Move;
  const int link = offset ? 3 : 0;
  Dyn dy;
  if (Err e = decode_dynamics(p.dyn, *ucfg, a.last_speed, dy, exerr); e != Err::None) return e;
  if (offset) dy.merge = false;  // a merge would end the cam it offsets: ignored (README)
  const double pos = p.position;
  const bool rot_type = mt == MoveType::RotaryShortest || mt == MoveType::RotaryPositive || mt == MoveType::RotaryNegative;
  if (rot_type) {
    if (!a.cfg.rotary) return Err::AxisModeNotRotary;
    if (pos < 0 || pos >= a.cfg.unwind) { exerr = static_cast<std::int8_t>(I.mam_pos); return Err::ParameterOutOfRange; }
  }
  auto* old = std::get_if<ProfileGen>(&a.gen[static_cast<std::size_t>(slot)]);
  if (old && old->role != GenRole::Move) old = nullptr;
  // The new profile continues the acceleration of S-curve motion; trapezoidal
  // motion steps its acceleration anyway, so it hands over with a = 0.
  Kin start{};
  if (dy.merge) start = Kin{0, a.cmd.v, any_scurve(a) ? a.cmd.a : 0.0};
  else if (old) start = Kin{0, old->k.v, old->scurve ? old->k.a : 0.0};
  const Kin rest = offset ? (old ? old->k : Kin{}) : a.cmd;
  if (dy.seconds && (rest.v != 0 || rest.a != 0)) return Err::AxisNotAtRest;
  if (Err e = check_event_distance(r, exerr); e != Err::None) return e;  // planner_mccp.cpp
  // distance
  const double cur = user_command(a);
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
    case MoveType::AbsoluteMasterOffset: L = pos - master_offset(a); break;
    case MoveType::IncrementalMasterOffset:
      L = pos;
      if (old && old->move_type == MoveType::IncrementalMasterOffset) L += old->total - old->k.p;
      break;
  }
  if (!offset && L > 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitPositive & 1u)) return Err::OvertravelCondition;
  if (!offset && L < 0 && (a.tag.motion_fault_status >> motion_fault::SoftTravelLimitNegative & 1u)) return Err::OvertravelCondition;
  ProfileGen g;
  g.role = GenRole::Move;
  if (dy.master_driven) {  // the profile runs over master travel
    g.md.lock = dy.lock;
    g.md.lock_pos = dy.lock_pos;
    bool ok_md = true;
    if (Err e = master_driven_setup(a, link, g, start, ok_md); e != Err::None) return e;
  }
  if (dy.seconds) {
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
  } else {
    double V = dy.speed;
    if (dy.merge && dy.merge_current && std::fabs(start.v) > 0) V = std::fabs(start.v);
    g.lim = dy.lim;
    g.lim.v = V;
    g.speed = V;
    if (dy.scurve && (dy.jerk_units == 2 || dy.jerk_units == 6) && V > 0) {
      g.lim.ja = jerk_from_percent_of_time(g.lim.a, V, dy.jerk_pct_a);
      g.lim.jd = jerk_from_percent_of_time(g.lim.d, V, dy.jerk_pct_d);
    }
  }
  bool ok;
  if (g.speed > 0) {
    ok = plan_move(g.prof, start, L, g.lim, Overshoot::Reverse);
  } else {  // zero speed: ramp to a halt and wait for MCD
    Limits l = g.lim;
    l.v = 1.0;
    ok = plan_velocity(g.prof, start, 0.0, l);
  }
  if (!ok) {
    exerr = static_cast<std::int8_t>(I.mam_speed);
    return Err::ParameterOutOfRange;
  }
  // commit: nothing above changed the axis
  if (dy.merge) {
    for (std::size_t s = 0; s < kSlots; ++s) fold(a, static_cast<Slot>(s), true);
  } else {
    fold(a, slot, true);
  }
  ControlTag& c = controls_[r.control];
  g.t0_cycle = cycle_;
  g.k = start;
  g.total = L;
  g.target_user = pos;
  g.exact_target = mt == MoveType::Absolute && !a.cfg.rotary;
  g.move_type = mt;
  g.scurve = dy.scurve;
  g.owner = OwnerRef{r.control, c.generation};
  promote_pending(a, link);
  if (g.master_driven) {
    c.set(flag::AC, true);
    if (ControlTag* m = tag(g.md.mdac)) m->set(flag::AC, true);
  }
  write_calculated_data(r, g, c);  // planner_mccp.cpp
  set_slot(a, slot, g);
  if (g.speed > 0) a.last_speed = g.speed;
  c.set(flag::DN, true);
  c.set(flag::IP, true);
  return Err::None;
}

// --- MCD
Err Planner::start_mcd(const Request& r, const McdParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, true); e != Err::None) return e;
  const Idx& I = idx();
  const bool jog = p.jog;
  const bool chs = p.change_speed, cha = p.change_accel, chd = p.change_decel, chja = p.change_accel_jerk,
             chjd = p.change_decel_jerk;
  const int su = p.speed_units, au = p.accel_units, du = p.decel_units, ju = p.jerk_units;
  const bool md = (chs && su == 4) || (cha && au == 4) || (chd && du == 4) || ((chja || chjd) && is_md_jerk(ju));
  const bool td = (chs && su != 4) || (cha && au != 4) || (chd && du != 4) || ((chja || chjd) && !is_md_jerk(ju));
  if (md && td) return Err::MdscUnitsConflict;
  if (md) return Err::MdscNotActivated;
  ControlTag& c = controls_[r.control];
  auto* g = std::get_if<ProfileGen>(&a.gen[static_cast<std::size_t>(jog ? Slot::Jog : Slot::Move)]);
  if (!g || g->role != (jog ? GenRole::Jog : GenRole::Move)) {
    c.set(flag::DN, true);  // nothing to change
    return Err::None;
  }
  if (g->seconds) return Err::IllegalDynamicChange;
  Limits lim = g->lim;
  double V = g->speed;
  if (chs) V = su == 1 ? p.speed / 100.0 * a.cfg.max_speed : p.speed;
  if (cha) {
    const double v = p.accel;
    if (!(v > 0)) { exerr = static_cast<std::int8_t>(I.mcd_accel); return Err::ParameterOutOfRange; }
    lim.a = au == 1 ? v / 100.0 * a.cfg.max_accel : v;
  }
  if (chd) {
    const double v = p.decel;
    if (!(v > 0)) { exerr = static_cast<std::int8_t>(I.mcd_decel); return Err::ParameterOutOfRange; }
    if (du == 1 && !(a.cfg.max_decel > 0)) return Err::ZeroMaxDecel;
    lim.d = du == 1 ? v / 100.0 * a.cfg.max_decel : v;
  }
  if (g->scurve && (chja || chjd)) {
    const double vref = V > 0 ? V : a.last_speed;
    auto conv = [&](double v, bool accel, int index, double& out) noexcept -> Err {
      if (ju == 2) {
        if (!(v >= 0) || v > 100) { exerr = static_cast<std::int8_t>(index); return Err::ParameterOutOfRange; }
        out = jerk_from_percent_of_time(accel ? lim.a : lim.d, vref, v);
      } else {
        if (!(v > 0) || (ju == 1 && v > 100)) { exerr = static_cast<std::int8_t>(index); return Err::ParameterOutOfRange; }
        out = ju == 1 ? v / 100.0 * (accel ? a.cfg.max_accel_jerk : a.cfg.max_decel_jerk) : v;
        if (!(out > 0)) return accel ? Err::ParameterOutOfRange : Err::ZeroMaxDecelJerk;
      }
      return Err::None;
    };
    if (chja) if (Err e = conv(p.accel_jerk, true, I.mcd_ajerk, lim.ja); e != Err::None) return e;
    if (chjd) if (Err e = conv(p.decel_jerk, false, I.mcd_djerk, lim.jd); e != Err::None) return e;
  }
  Profile prof;
  bool ok;
  Limits l = lim;
  l.v = V > 0 ? V : 1.0;
  Kin from = g->k;
  if (!g->scurve) from.a = 0.0;  // trapezoidal motion steps its acceleration
  if (jog) {
    ok = plan_velocity(prof, from, (g->jog_velocity < 0 ? -1.0 : 1.0) * V, l);
  } else if (V > 0) {
    // Limits dropped mid-move: stop exactly on target, never past it (README).
    // Unless the move was already going to pass the target with its old
    // limits (a merge from motion away from it): then it keeps reversing.
    Overshoot policy = Overshoot::StopAtTarget;
    Profile probe;
    if (plan_stop(probe, g->k, g->lim.d, g->lim.jd)) {
      const double rem = g->total - g->k.p;
      const double stop = probe.end_position() - g->k.p;
      if ((rem >= 0 && stop > rem) || (rem < 0 && stop < rem) || g->k.v * rem < 0) policy = Overshoot::Reverse;
    }
    ok = plan_move(prof, from, g->total - g->k.p, l, policy);
  } else {
    ok = plan_velocity(prof, from, 0.0, l);  // speed 0: pause
  }
  if (!ok) { exerr = static_cast<std::int8_t>(I.mcd_speed); return Err::ParameterOutOfRange; }
  g->prof = prof;
  g->hint = 0;
  g->t0_cycle = cycle_;
  g->lim = l;
  g->speed = V;
  if (jog) g->jog_velocity = (g->jog_velocity < 0 ? -1.0 : 1.0) * V;
  if (V > 0) a.last_speed = V;
  c.set(flag::DN, true);
  return Err::None;
}

// --- MRP
Err Planner::start_mrp(const Request& r, const MrpParams& prm, AxisRt& a) noexcept {
  if (!a.cfg.configured) return Err::AxisNotConfigured;
  if (a.cfg.inhibited) return Err::AxisIsInhibited;
  if (a.direct.status) return Err::NotAllowedWhileInDirectMotion;
  if (a.hs.homing) return Err::HomeInProcess;
  const bool relative = prm.relative;
  const bool command = prm.command;
  const double p = prm.position;
  double delta = p;
  if (!relative) {
    double sel = command ? user_command(a) : (a.cfg.type == AxisType::Virtual ? user_command(a) : a.fb_pos + a.frame_offset);
    if (a.cfg.rotary) sel = unwind_position(sel, a.cfg.unwind);
    delta = p - sel;
  }
  a.frame_offset += delta;  // both command and actual shift: the following error is kept
  controls_[r.control].set(flag::DN, true);
  return Err::None;
}

// --- MGS / MGSD / MGSR
Err Planner::start_group(const Request& r, std::uint16_t group, GroupStopMode mode, std::int8_t& exerr) noexcept {
  const std::uint8_t grp = static_cast<std::uint8_t>(group);
  ControlTag& c = controls_[r.control];
  (void)exerr;
  if (r.instr == Instr::MGSD || r.instr == Instr::MGSR) {
    for (std::size_t i = 0; i < axis_count_; ++i) {
      AxisRt& a = axes_[i];
      if (!a.present || a.cfg.group != grp || !a.cfg.configured || a.cfg.inhibited) continue;
      if (r.instr == Instr::MGSD) {
        do_shutdown(a);
      } else {
        a.servo.shutdown = false;
        (void)begin_fault_reset(r, a);
      }
    }
    // MGSR: DN when every CIP drive of the group has left Fault (the last
    // end_fault_reset sets it), at once if none has to.
    bool waiting = false;
    for (std::size_t i = 0; i < axis_count_; ++i)
      waiting = waiting || axes_[i].servo.reset == OwnerRef{r.control, c.generation};
    if (!waiting) c.set(flag::DN, true);
    return Err::None;
  }
  bool ramping = false;
  for (std::size_t i = 0; i < axis_count_; ++i) {
    AxisRt& a = axes_[i];
    if (!a.present || a.cfg.group != grp || !a.cfg.configured || a.cfg.inhibited) continue;
    ProgrammedStopMode m = mode == GroupStopMode::FastStop      ? ProgrammedStopMode::FastStop
                           : mode == GroupStopMode::FastDisable ? ProgrammedStopMode::FastDisable
                                                                : a.cfg.programmed_stop_mode;
    if (a.hs.homing) {
      a.hs.homing = false;
      if (ControlTag* h = tag(a.hs.mah)) h->set(flag::IP, false);
    }
    break_links(a);  // MGS breaks the MDAC links of its slaves
    if (m == ProgrammedStopMode::HardDisable) { servo_off(a); continue; }
    if (m == ProgrammedStopMode::HardShutdown) { do_shutdown(a); continue; }
    const std::uint8_t post = m == ProgrammedStopMode::FastDisable ? 1 : (m == ProgrammedStopMode::FastShutdown ? 2 : 0);
    bool scurve = false;
    for (const auto& g : a.gen)
      if (auto* p = std::get_if<ProfileGen>(&g)) scurve = scurve || p->scurve;
    const double d = a.cfg.max_decel > 0 ? a.cfg.max_decel : 1e12;
    const double jd = scurve && a.cfg.max_decel_jerk > 0 ? a.cfg.max_decel_jerk : kInf;
    const bool r_ax = a.servo.on && stop_slots(a, (1u << kSlots) - 1u, d, jd, r.control, post);
    ramping = ramping || r_ax;
    if (!r_ax) {
      if (post == 1) servo_off(a);
      if (post == 2) do_shutdown(a);
    }
  }
  c.set(flag::DN, true);
  if (ramping) {
    c.set(flag::IP, true);
    groups_[grp] = GroupOp{OwnerRef{r.control, c.generation}, grp, true};
  } else {
    c.set(flag::PC, true);
  }
  return Err::None;
}

// ------------------------------------------------------------------- cycle
void Planner::handle_feedback(AxisId, AxisRt& a, const AxisFeedback* fb) noexcept {
  if (a.cfg.type != AxisType::CipDrive) return;
  if (fb) {
    a.fb = *fb;
    a.fb_pos = fb->position;
    a.fb_vel = fb->velocity;
  }
  const bool link_failed = a.fb.link == DriveLink::ConfigFailed || a.fb.link == DriveLink::NoModule;
  // pending fault reset (MAFR, MASR, MGSR), judged on feedback given after
  // the pulse went out (the runtime acts on it: clears its failure, retries
  // a failed boot)
  if (a.servo.reset.valid() && !a.servo.fault_reset_pulse) {
    if (!tag(a.servo.reset)) {
      a.servo.reset = {};
    } else if (a.fb.link == DriveLink::Up && a.fb.drive != DriveState::Fault && !a.fb.drive_fault && !a.fb.node_lost) {
      end_fault_reset(a, true);
    } else if (link_failed || a.fb.transition_timeout || cycle_ >= a.servo.reset_deadline) {
      end_fault_reset(a, false);
    }
  }
  // pending MSO
  if (a.hs.mso.valid()) {
    ControlTag* c = tag(a.hs.mso);
    if (!c) {
      a.hs.mso = {};
    } else if (a.fb.drive == DriveState::Enabled) {
      a.servo.on = true;
      a.base = a.fb_pos;  // close the loop at the present position
      a.cmd = Kin{a.fb_pos, 0, 0};
      c->state = 1;
      c->set(flag::DN, true);
      a.hs.mso = {};
    } else if ((a.fb.drive == DriveState::Fault && !a.servo.reset.valid()) || link_failed || a.fb.transition_timeout ||
               cycle_ >= a.hs.deadline) {
      // (a drive still in Fault while a fault reset waits for it: wait too)
      c->reject(Err::ServoMessageFailure, 16);
      a.servo.enable_req = false;
      a.hs.mso = {};
    } else {
      c->state = 1;  // waiting for drive enable and servo action
    }
  }
  if (a.hs.msf.valid()) {
    ControlTag* c = tag(a.hs.msf);
    if (!c) {
      a.hs.msf = {};
    } else if (a.fb.drive != DriveState::Enabled) {
      c->set(flag::DN, true);
      a.hs.msf = {};
    } else if (cycle_ >= a.hs.deadline) {
      c->reject(Err::ServoMessageFailure, 16);
      a.hs.msf = {};
    }
  }
  // MDS waiting for the drive enable
  if (a.direct.waiting) {
    ControlTag* c = tag(a.direct.mds);
    if (a.fb.drive == DriveState::Enabled) {
      a.servo.on = true;
      a.direct.waiting = false;
      if (c) { c->state = 1; c->set(flag::DN, true); }
    } else if (a.fb.drive == DriveState::Fault || link_failed || a.fb.transition_timeout || cycle_ >= a.hs.deadline) {
      a.direct.waiting = false;
      end_direct(a, false);
      a.servo.enable_req = false;
      if (c) c->reject(Err::ServoMessageFailure, 16);
    } else if (c) {
      c->state = 1;
    }
  }
  if (a.direct.stop.valid()) {
    ControlTag* c = tag(a.direct.stop);
    if (!c || !a.direct.status) {
      a.direct.stop = {};
    } else if (std::fabs(a.fb_vel) <= std::max(1e-6, 1e-3 * a.cfg.max_speed)) {
      c->set(flag::IP, false);
      c->set(flag::PC, true);
      a.direct.stop = {};
    }
  }
  // drive homing
  if (a.hs.homing) {
    ControlTag* c = tag(a.hs.mah);
    if (a.fb.homing_attained && a.hs.homing_started) {
      a.frame_offset = a.cfg.homing.home_position - a.fb_pos;
      a.hs.homed = true;
      a.hs.homing = false;
      a.base = a.fb_pos;
      a.cmd = Kin{a.fb_pos, 0, 0};
      if (c) { c->set(flag::IP, false); c->set(flag::PC, true); }
    } else if (a.fb.homing_error || link_failed) {
      a.hs.homing = false;
      a.base = a.fb_pos;
      if (c) { c->set(flag::IP, false); c->reject(Err::ServoMessageFailure, 16); }
    }
  }
  // servo off or homing: the command follows the actual position
  if (!a.servo.on || a.hs.homing || a.direct.status) {
    a.base = a.fb_pos;
    a.cmd = Kin{a.fb_pos, a.direct.status ? a.fb_vel : 0.0, 0};
  }
  // a drive that dropped out of Operation Enabled switches the servo off
  if (a.servo.on && a.fb.drive != DriveState::Enabled && !a.direct.waiting) servo_off(a);
}

// Called once per axis per cycle from update() only: inlined there.
[[gnu::always_inline]] inline void Planner::handle_exceptions(AxisRt& a) noexcept {
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
    if (a.servo.on && a.cfg.position_error_tolerance > 0 &&
        std::fabs(a.cmd.p - a.fb_pos) > a.cfg.position_error_tolerance)
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
      if (a.servo.on) {
        bool scurve = false;
        for (const auto& g : a.gen)
          if (auto* p = std::get_if<ProfileGen>(&g)) scurve = scurve || p->scurve;
        const double d = a.cfg.max_decel > 0 ? a.cfg.max_decel : 1e12;
        const double jd = scurve && a.cfg.max_decel_jerk > 0 ? a.cfg.max_decel_jerk : kInf;
        stop_slots(a, (1u << kSlots) - 1u, d, jd, kNoControl, 0);
      }
      break;
    }
    case ExceptionAction::StopDrive:
      servo_off(a);
      a.servo.faulted = true;
      break_links(a);  // an axis fault breaks the MDAC link
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
  a.tag.axis_fault = af | link_fault;
}

// Called once per axis per cycle from update() only: inlined there.
[[gnu::always_inline]] inline void Planner::step_axis(AxisRt& a, AxisOutput* out) noexcept {
  double sum_p = 0, sum_v = 0, sum_a = 0;
  // the master offset move shifts the position cam's master: it steps first
  // and is not part of the slave's sum
  constexpr std::array<Slot, kSlots> kStepOrder{Slot::Move, Slot::Jog, Slot::Gear, Slot::TimeCam,
                                                Slot::MasterOffset, Slot::PositionCam, Slot::StopAll};
  // Visit the live slots (AxisRt::live) in step order: the next live one at
  // or after position `from`, looked up afresh after each step (a slot may
  // fold, or fold the others, while stepping). Step position = slot index
  // with PositionCam and MasterOffset swapped.
  static_assert(static_cast<unsigned>(Slot::PositionCam) == 4 && static_cast<unsigned>(Slot::MasterOffset) == 5);
  for (unsigned from = 0;;) {
    const unsigned x = a.live;
    const unsigned swap = ((x >> 4) ^ (x >> 5)) & 1u;
    const unsigned pending = (x ^ (swap << 4) ^ (swap << 5)) & (~0u << from);
    if (pending == 0) break;
    const auto pos = static_cast<unsigned>(std::countr_zero(pending));
    from = pos + 1;
    const Slot slot_id = kStepOrder[pos];
    const auto s = static_cast<std::size_t>(slot_id);
    // cams may end (fold) or hand over (pending) while stepping: add what the slot holds afterwards
    const auto add_slot = [&] {
      if (const GenRef r = gen_ref(a.gen[s]); r.k) {
        sum_p += r.k->p;
        sum_v += r.k->v;
        sum_a += r.k->a;
      }
    };
    if (auto* pc = std::get_if<PosCamGen>(&a.gen[s])) {
      step_position_cam(a, *pc);
      add_slot();
      continue;
    }
    if (auto* cg = std::get_if<CamGen>(&a.gen[s])) {
      step_cam(a, *cg);
      add_slot();
      continue;
    }
    if (auto* gg = std::get_if<GearGen>(&a.gen[s])) {
      step_gear(*gg);
      add_slot();
      continue;
    }
    auto* g = std::get_if<ProfileGen>(&a.gen[s]);
    if (!g) continue;
    bool done;
    bool tracking = false;
    if (g->master_driven) {
      // abscissa = master travel in the lock direction [RM002H p.512]
      const AxisRt& m = axes_[g->md.master];
      const double du = g->md.step(g->md.use_actual ? m.fb_pos : m.cmd.p);
      const Kin ku = g->prof.sample(g->md.u, g->hint);
      const double udot = du / T_;
      g->k = Kin{ku.p, ku.v * udot, ku.a * udot * udot};
      // TrackingMaster: locked, following, and the accel transition to the programmed ratio done
      tracking = g->md.locked && g->md.following && g->speed > 0 && std::fabs(ku.v) >= g->speed * (1 - 1e-9);
      done = g->role != GenRole::Jog && g->prof.finite() && g->md.u >= g->prof.duration();
    } else {
      const double t = static_cast<double>(cycle_ - g->t0_cycle) * T_;
      g->k = g->prof.sample(t, g->hint);
      done = g->role != GenRole::Jog && g->prof.finite() && t >= g->prof.duration();
    }
    ControlTag* c = tag(g->owner);
    if (done) {
      if (g->role == GenRole::Move) {
        const bool alone = (a.live & ~(1u << s)) == 0;  // no other live slot
        g->k = Kin{g->total, 0, 0};
        if (alone && g->exact_target) {
          a.base = g->target_user - a.frame_offset;  // ends exactly on the programmed target
          g->k.p = 0;
        }
      }
      const std::uint8_t post = g->post_stop;
      // ramps of an MGS: the MGS gets PC when every axis of its group stopped
      bool group_owned = false;
      for (const auto& go : groups_)
        if (go.active && go.owner == g->owner) group_owned = true;
      if (c && !group_owned) {
        c->set(flag::PC, true);
        c->set(flag::ACCEL, false);
        c->set(flag::DECEL, false);
      }
      fold(a, static_cast<Slot>(s), !group_owned);
      if (post == 1) servo_off(a);
      if (post == 2) do_shutdown(a);
      continue;
    }
    if (c) {
      c->set(flag::ACCEL, g->k.v * g->k.a > 0 || (g->k.v == 0 && g->k.a != 0));
      c->set(flag::DECEL, g->k.v * g->k.a < 0);
      if (g->master_driven) c->set(flag::TrackingMaster, tracking);
    }
    if (slot_id == Slot::MasterOffset) continue;
    sum_p += g->k.p;
    sum_v += g->k.v;
    sum_a += g->k.a;
  }
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
    if (a.direct.status) {  // MDS: CSV or CST following the axis configuration
      const bool torque = a.cfg.direct_mode == AxisConfig::DirectMode::Torque;
      out->mode = torque ? DriveMode::CyclicTorque : DriveMode::CyclicVelocity;
      out->velocity = a.direct.active ? (torque ? a.direct.vel_cmd : a.direct.cmd) : 0.0;
      out->torque = torque && a.direct.active ? a.direct.cmd : 0.0;
      out->acceleration = 0.0;
    }
    out->homing_start = a.hs.homing;
    if (a.hs.homing) {
      const HomingConfig& h = a.cfg.homing;
      out->homing = HomingRequest{h.cia_method, h.speed_search, h.speed_zero, h.accel};
      a.hs.homing_started = true;
    }
  }
  a.servo.fault_reset_pulse = false;
}

void Planner::update_status(AxisRt& a) noexcept {
  using namespace motion_status;
  AxisTag& t = a.tag;
  std::uint32_t ms = 0;
  auto setb = [&](unsigned b, bool on) { if (on) ms |= 1u << b; };
  const auto* mv = std::get_if<ProfileGen>(&a.gen[static_cast<std::size_t>(Slot::Move)]);
  const auto* jg = std::get_if<ProfileGen>(&a.gen[static_cast<std::size_t>(Slot::Jog)]);
  setb(MoveStatus, mv && mv->role == GenRole::Move);
  setb(JogStatus, jg && jg->role == GenRole::Jog);
  setb(MoveLockStatus, mv && mv->role == GenRole::Move && mv->master_driven && mv->md.locked && mv->md.following);
  setb(JogLockStatus, jg && jg->role == GenRole::Jog && jg->master_driven && jg->md.locked && jg->md.following);
  static_assert(std::tuple_size_v<decltype(a.links.active)> == 4);
  const bool linked = a.links.active[0].valid() || a.links.active[1].valid() || a.links.active[2].valid() || a.links.active[3].valid();
  setb(CoordinatedMotionStatus, linked);
  const auto* gr = std::get_if<GearGen>(&a.gen[static_cast<std::size_t>(Slot::Gear)]);
  setb(GearingStatus, gr != nullptr);
  setb(GearingLockStatus, gr && gr->locked);
  const bool stopping = any_stopping(a);
  setb(StoppingStatus, stopping);
  setb(HomingStatus, a.hs.homing);
  setb(AxisHomedStatus, a.hs.homed);
  setb(AccelStatus, a.cmd.v * a.cmd.a > 0 || (a.cmd.v == 0 && a.cmd.a != 0));
  setb(DecelStatus, a.cmd.v * a.cmd.a < 0);
  setb(TimeCamStatus, std::holds_alternative<CamGen>(a.gen[static_cast<std::size_t>(Slot::TimeCam)]));
  setb(TimeCamPendingStatus, a.cams.time.valid());
  position_cam_status(a, ms);
  const auto* tc = std::get_if<CamGen>(&a.gen[static_cast<std::size_t>(Slot::TimeCam)]);
  setb(TimeCamLockStatus, tc && tc->master_driven && tc->md.lock_status());
  const bool torque_mode = a.cfg.direct_mode == AxisConfig::DirectMode::Torque;
  setb(DirectVelocityControlStatus, a.direct.active && !torque_mode);
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
  t.position_error = a.cmd.p - act;
}

// --- MAG
Err Planner::start_mag(const Request& r, const MagParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  const AxisId slave_id = p.slave;
  const AxisId master_id = p.master;
  const AxisRt& m = axes_[master_id];
  if (!m.cfg.configured) return Err::AxisNotConfigured;
  if (m.cfg.inhibited) return Err::AxisIsInhibited;
  if (master_id == slave_id) return Err::MasterAxisConflict;
  // circular master chain: the master (transitively) geared to this slave
  AxisId c = master_id;
  for (std::size_t n = 0; n < kMaxAxes; ++n) {
    const auto* g = std::get_if<GearGen>(&axes_[c].gen[static_cast<std::size_t>(Slot::Gear)]);
    if (!g) break;
    if (g->master == slave_id) return Err::MasterAxisConflict;
    c = g->master;
  }
  static const int iRatio = operand_index(Instr::MAG, "Ratio"), iSc = operand_index(Instr::MAG, "SlaveCounts"),
                   iMc = operand_index(Instr::MAG, "MasterCounts"), iAcc = operand_index(Instr::MAG, "AccelRate");
  // Direction: same/opposite, or reverse/unchanged relative to the last gearing
  // direction (first use: reverse = opposite, unchanged = same) [seed 003].
  const int d = static_cast<int>(p.direction);
  const int dir = d == 0 ? 1 : d == 1 ? -1 : d == 2 ? (a.gear_dir == 0 ? -1 : -a.gear_dir) : (a.gear_dir == 0 ? 1 : a.gear_dir);
  GearGen g;
  g.master = master_id;
  g.fractional = p.fractional;
  g.cc_master = m.cfg.conversion_constant;
  g.cc_slave = a.cfg.conversion_constant;
  // a virtual master has no actual position: it always gives command [seed 000]
  g.use_actual = p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive;
  if (g.fractional) {
    const double sc = p.slave_counts, mc = p.master_counts;
    if (!(sc > 0) || sc > 2147483647.0) { exerr = static_cast<std::int8_t>(iSc); return Err::ParameterOutOfRange; }
    if (!(mc > 0) || mc > 2147483647.0) { exerr = static_cast<std::int8_t>(iMc); return Err::ParameterOutOfRange; }
    g.slave_counts = dir * static_cast<std::int64_t>(sc);
    g.master_counts = static_cast<std::int64_t>(mc);
  } else {
    const double ratio = p.ratio;
    const double mag = std::fabs(ratio);
    // 0.00001 .. 9.99999 inclusive, sign-sensitive [seed 003]
    if (!(mag >= 0.00001 - 1e-12) || !(mag <= 9.99999 + 1e-12)) { exerr = static_cast<std::int8_t>(iRatio); return Err::ParameterOutOfRange; }
    g.ratio = dir * ratio;
  }
  const bool clutch = p.clutch;
  if (clutch) {
    const double acc = p.accel_rate;
    if (!(acc > 0)) { exerr = static_cast<std::int8_t>(iAcc); return Err::ParameterOutOfRange; }
    g.clutch_accel = p.accel_units == 1 ? acc / 100.0 * a.cfg.max_accel : acc;
    if (!(g.clutch_accel > 0)) { exerr = static_cast<std::int8_t>(iAcc); return Err::ParameterOutOfRange; }
  }
  // commit: a new MAG supersedes the active one (ratio, direction or master change)
  Kin start{};
  if (const GenRef old = gen_ref(a.gen[static_cast<std::size_t>(Slot::Gear)]); old.k) start = Kin{0, old.k->v, 0};
  fold(a, Slot::Gear, true);
  ControlTag& ct = controls_[r.control];
  g.k = start;
  g.owner = OwnerRef{r.control, ct.generation};
  if (!clutch) {  // lock at once: the offset follows the master from here
    g.locked = true;
    g.master_ref = g.use_actual ? m.fb_pos : m.cmd.p;
    g.master_ref_counts = std::llround(g.master_ref * g.cc_master);
    g.offset_at_lock = 0.0;
    g.k = Kin{};
  }
  set_slot(a, Slot::Gear, g);
  a.gear_dir = dir;
  ct.set(flag::DN, true);
  ct.set(flag::IP, true);
  return Err::None;
}

void Planner::step_gear(GearGen& g) noexcept {
  const AxisRt& m = axes_[g.master];
  const double mp = g.use_actual ? m.fb_pos : m.cmd.p;
  const double mv = g.use_actual ? m.fb_vel : m.cmd.v;
  const double ma = g.use_actual ? 0.0 : m.cmd.a;
  const double k = g.fractional ? static_cast<double>(g.slave_counts) / static_cast<double>(g.master_counts) *
                                      g.cc_master / g.cc_slave
                                : g.ratio;
  const double target_v = k * mv;
  if (!g.locked) {
    // clutch: trapezoidal ramp of the slave's gear velocity to the geared speed
    const double dv = target_v - g.k.v;
    const double step = g.clutch_accel * T_;
    if (std::fabs(dv) <= step) {
      g.k.p += (g.k.v + target_v) / 2 * T_;
      g.k.v = target_v;
      g.k.a = 0.0;
      g.locked = true;
      g.master_ref = mp;
      g.master_ref_counts = std::llround(mp * g.cc_master);
      g.offset_at_lock = g.k.p;
    } else {
      const double acc = dv > 0 ? g.clutch_accel : -g.clutch_accel;
      const double v1 = g.k.v + acc * T_;
      g.k.p += (g.k.v + v1) / 2 * T_;
      g.k.v = v1;
      g.k.a = acc;
    }
    return;
  }
  if (g.fractional) {
    // exact: slave counts = floor(master counts moved * S / M); no accumulated error
    const std::int64_t dm = std::llround(mp * g.cc_master) - g.master_ref_counts;
    const std::int64_t sc = mul_div_floor(dm, g.slave_counts, g.master_counts);
    g.k.p = g.offset_at_lock + static_cast<double>(sc) / g.cc_slave;
  } else {
    g.k.p = g.offset_at_lock + g.ratio * (mp - g.master_ref);
  }
  g.k.v = target_v;
  g.k.a = k * ma;
}

// --- MDS
Err Planner::start_mds(const Request& r, const MdsParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, false); e != Err::None) return e;
  if (a.cfg.type != AxisType::CipDrive) return Err::WrongAxisType;  // AXIS_CIP_DRIVE only [seed 002]
  if (a.hs.homing) return Err::HomeInProcess;
  for (const auto& g : a.gen)
    if (!std::holds_alternative<std::monostate>(g)) return Err::NotAllowedWhilePlannerActive;
  const bool torque = a.cfg.direct_mode == AxisConfig::DirectMode::Torque;
  const double full = torque ? a.cfg.max_torque : a.cfg.max_speed;
  const double cmd = p.percent_of_maximum ? p.speed / 100.0 * full : p.speed;
  if (!std::isfinite(cmd)) {
    exerr = static_cast<std::int8_t>(idx().mds_speed);
    return Err::ParameterOutOfRange;
  }
  ControlTag& c = controls_[r.control];
  if (a.direct.mds.valid() && a.direct.mds != OwnerRef{r.control, c.generation})
    if (ControlTag* o = tag(a.direct.mds)) o->set(flag::IP, false);  // superseded by this MDS
  a.direct.status = true;
  a.direct.active = true;
  a.direct.cmd = cmd;
  if (!a.direct.mds.valid()) a.direct.vel_cmd = a.cfg.direct_velocity_command;  // kept by a superseding MDS
  a.direct.mds = OwnerRef{r.control, c.generation};
  a.direct.stop = {};
  c.set(flag::IP, true);
  if (a.servo.on) {
    c.set(flag::DN, true);
  } else {  // enable the drive first: STATE 0 request, 1 waiting [seed 002]
    a.servo.enable_req = true;
    a.direct.waiting = true;
    a.hs.deadline = cycle_ + static_cast<std::uint64_t>(kDriveTimeout / T_);
    c.state = 0;
  }
  return Err::None;
}

void Planner::end_direct(AxisRt& a, bool keep_direct_status) noexcept {
  if (!a.direct.status) return;
  if (ControlTag* c = tag(a.direct.mds)) c->set(flag::IP, false);
  a.direct.active = false;
  a.direct.cmd = 0.0;
  a.direct.mds = {};
  a.direct.waiting = false;
  if (!keep_direct_status) {
    a.direct.status = false;
    if (ControlTag* s = tag(a.direct.stop)) s->set(flag::IP, false);
    a.direct.stop = {};
  }
}

bool Planner::set_direct_command(AxisId id, double value) noexcept {
  if (id >= kMaxAxes || !axes_[id].direct.active || !std::isfinite(value)) return false;
  axes_[id].direct.cmd = value;
  return true;
}

bool Planner::set_direct_velocity_command(AxisId id, double value) noexcept {
  if (id >= kMaxAxes || !axes_[id].direct.active || !std::isfinite(value) ||
      axes_[id].cfg.direct_mode != AxisConfig::DirectMode::Torque)
    return false;
  axes_[id].direct.vel_cmd = value;
  return true;
}

// --- MATC (time driven)
bool Planner::attach_cam_profile(std::uint16_t id, cam::CamProfile* profile) noexcept {
  if (id >= kMaxCamProfiles) return false;
  cam_profiles_[id] = profile;
  return true;
}

void Planner::drop_pending_cam(AxisRt& a) noexcept {
  if (!a.cams.time.valid()) return;
  if (ControlTag* c = tag(a.cams.time.owner)) c->set(flag::IP, false);
  a.cams.time = PendingCam{};
}

Err Planner::start_matc(const Request& r, const MatcParams& p, AxisRt& a, std::int8_t& exerr) noexcept {
  if (Err e = common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  if (Err e = matc_mode_checks(a, p); e != Err::None) return e;  // lock direction, mode, MDAC (planner_md.cpp)
  cam::CamProfile* prof = p.cam_profile < kMaxCamProfiles ? cam_profiles_[p.cam_profile] : nullptr;
  if (!prof || !prof->calculated()) return Err::CamProfileNotCalculated;
  bool bad_slave = false, bad_master = false;
  const cam::CamScaling sc{p.distance_scaling, p.time_scaling};
  if (cam::check_scaling(sc, bad_slave, bad_master) != cam::CamError::None) {
    exerr = static_cast<std::int8_t>(bad_slave ? idx().matc_dscale : idx().matc_tscale);
    return Err::ParameterOutOfRange;
  }
  const int dir = cam::resolve_direction(static_cast<std::int32_t>(p.direction), a.cams.time_dir);
  cam::CamMotionConfig cfg;
  cfg.mode = p.execution_mode == 1 ? cam::ExecutionMode::Continuous : cam::ExecutionMode::Once;
  cfg.scaling = sc;
  cfg.direction = dir;
  ControlTag& c = controls_[r.control];
  const bool active = std::holds_alternative<CamGen>(a.gen[static_cast<std::size_t>(Slot::TimeCam)]);
  if (p.execution_schedule == 1) {  // pending: takes over at the end of the current pass [seed 004]
    drop_pending_cam(a);             // a second pending MATC overlays the first
    a.cams.time = PendingCam{prof, cfg, OwnerRef{r.control, c.generation}};
    a.cams.time_dir = dir;
    c.set(flag::DN, true);
    c.set(flag::IP, true);
    return Err::None;
  }
  if (active) return Err::IllegalDynamicChange;  // immediate on an axis already time camming [seed 004]
  CamGen g;
  int bad = 0;
  if (p.master_driven)
    if (Err e = matc_md_setup(a, p, g); e != Err::None) return e;
  if (prof->acquire() != cam::CamError::None) return Err::CamProfileNotCalculated;
  if (g.cm.start(*prof, cfg, &bad) != cam::CamError::None) {
    prof->release();
    exerr = static_cast<std::int8_t>(idx().matc_dir);
    return Err::ParameterOutOfRange;
  }
  fold(a, Slot::TimeCam, true);
  g.profile = prof;
  g.t0_cycle = cycle_;
  g.owner = OwnerRef{r.control, c.generation};
  promote_pending(a, 2);  // a queued MDAC master takes over as this MATC goes IP [seed 000]
  if (g.master_driven) {
    c.set(flag::AC, true);
    if (ControlTag* m = tag(g.md.mdac)) m->set(flag::AC, true);
  }
  set_slot(a, Slot::TimeCam, g);
  a.cams.time_dir = dir;
  c.set(flag::DN, true);
  c.set(flag::IP, true);
  return Err::None;
}

void Planner::step_cam(AxisRt& a, CamGen& g) noexcept {
  const double x = cam_coordinate(g);  // time, or master travel (master driven)
  cam::CamMotionOutput o = g.cm.step(x);
  // a pending cam takes over exactly at the end of the current pass [seed 004]
  const bool once = g.cm.config().mode == cam::ExecutionMode::Once;
  const std::int64_t pass_before = g.last_pass;
  g.last_pass = o.pass;
  if (a.cams.time.valid()) {
    const double end = once ? g.cm.pass_end(0) : g.cm.pass_end(pass_before);
    if (once ? x >= end : o.pass > pass_before) {
      const cam::CamMotionOutput at_end = g.cm.step(end);
      ControlTag* old = tag(g.owner);
      if (old) {
        old->set(flag::IP, false);
        old->set(flag::AC, false);
        old->set(flag::TrackingMaster, false);
        if (once) old->set(flag::PC, true);  // Once: PC; Continuous: IP cleared
      }
      const std::uint64_t t0 = g.t0_cycle;
      const double xo = g.x_offset + end;
      const CamGen md_from = g;  // the pending cam runs in this cam's mode, master and lock state [seed 000]
      g.k = Kin{at_end.position, 0, 0};
      fold(a, Slot::TimeCam, false);  // base += position at the pass end: no jump
      PendingCam pc = a.cams.time;
      a.cams.time = PendingCam{};
      CamGen n;
      if (pc.profile->acquire() == cam::CamError::None && n.cm.start(*pc.profile, pc.cfg) == cam::CamError::None) {
        n.profile = pc.profile;
        n.t0_cycle = t0;
        n.x_offset = xo;
        n.owner = pc.owner;
        n.master_driven = md_from.master_driven;
        n.md = md_from.md;
        n.md_rate = md_from.md_rate;
        n.md_cycle = md_from.md_cycle;
        if (n.master_driven) {
          if (ControlTag* nt = tag(n.owner)) nt->set(flag::AC, true);
          if (ControlTag* m = tag(n.md.mdac)) m->set(flag::AC, true);
        }
        CamGen& ng = set_slot(a, Slot::TimeCam, n);
        step_cam(a, ng);
      } else if (ControlTag* pt = tag(pc.owner)) {
        pt->reject(Err::CamProfileNotCalculated);
      }
      return;
    }
  }
  cam_output(g, o);  // velocity x master rate when master driven; SEGMENT; TrackingMaster
  if (o.complete) {  // Once: PC, the axis holds the end position, TimeCamStatus cleared
    if (ControlTag* c = tag(g.owner)) c->set(flag::PC, true);
    fold(a, Slot::TimeCam, true);
  }
}

void Planner::compute_order() noexcept {
  // depth-first: every axis after the masters it follows (gear, master-driven
  // motion). MAG refuses gear cycles (ERR 10); a cycle through master-driven
  // motion is broken arbitrarily (the stack below bounds the walk).
  // The order changes only with the slots (set_slot, fold) and the axes
  // (configure_axis): otherwise last cycle's order stands.
  if (!order_dirty_) return;
  order_dirty_ = false;
  std::array<std::uint8_t, kMaxAxes> mark{};  // 0 new, 1 on stack, 2 emitted
  order_n_ = 0;
  auto masters_of = [this](AxisId i, std::array<AxisId, kSlots>& out) noexcept {
    std::size_t n = 0;
    out.fill(kNoAxis);  // the first n are overwritten below
    for (unsigned live = axes_[i].live; live != 0; live &= live - 1) {  // empty slots have no master
      const AxisId m = master_of(axes_[i].gen[std::countr_zero(live)]);
      if (m < kMaxAxes && axes_[m].present && m != i) out[n++] = m;
    }
  };
  // The masters of every axis, once per recomputation (the walk below visits an axis
  // several times). Usually no axis follows another: then the order is the
  // axis order, which is what the walk would give.
  std::array<std::array<AxisId, kSlots>, kMaxAxes> masters;  // [i] set for present axes
  bool linked = false;
  for (std::size_t i = 0; i < axis_count_; ++i) {
    if (!axes_[i].present) continue;
    masters_of(static_cast<AxisId>(i), masters[i]);
    linked = linked || masters[i][0] != kNoAxis;
  }
  if (!linked) {
    for (std::size_t i = 0; i < axis_count_; ++i)
      if (axes_[i].present) order_[order_n_++] = static_cast<AxisId>(i);
    return;
  }
  struct Frame { AxisId axis; std::uint8_t next; };
  std::array<Frame, kMaxAxes> stack{};
  for (std::size_t i = 0; i < axis_count_; ++i) {
    if (!axes_[i].present || mark[i]) continue;
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
      order_[order_n_++] = f.axis;
      --sp;
    }
  }
}

bool Planner::check_incremental_state() noexcept {
  bool ok = true;
  for (std::size_t i = 0; i < axis_count_; ++i) {
    unsigned live = 0;
    for (std::size_t s = 0; s < kSlots; ++s)
      if (!std::holds_alternative<std::monostate>(axes_[i].gen[s])) live |= 1u << s;
    ok = ok && live == axes_[i].live;
  }
  // the cached order against a fresh one (an up-to-date cache is recomputed
  // to the same order; a stale one is reported and left as it was)
  const std::array<AxisId, kMaxAxes> cached = order_;
  const std::size_t cached_n = order_n_;
  const bool dirty = order_dirty_;
  order_dirty_ = true;
  compute_order();
  const bool same = order_n_ == cached_n && std::equal(cached.begin(), cached.begin() + static_cast<std::ptrdiff_t>(cached_n), order_.begin());
  if (!dirty && !same) {
    order_ = cached;
    order_n_ = cached_n;
    ok = false;
  }
  order_dirty_ = dirty;
  if (dirty) {  // leave a pending recomputation pending
    order_ = cached;
    order_n_ = cached_n;
  }
  return ok;
}

Result Planner::update(const Input& in, Output& out) noexcept {
  if (started_ && in.cycle <= cycle_) return Result::ErrorCycleNotIncreasing;
  // the first cycle index may be anything: time starts one period before it
  if (!started_) cycle_ = in.cycle > 0 ? in.cycle - 1 : 0;
  // 1. feedback and exceptions (against last cycle's command)
  for (std::size_t i = 0; i < axis_count_; ++i) {
    AxisRt& a = axes_[i];
    if (!a.present) continue;
    handle_feedback(static_cast<AxisId>(i), a, i < in.feedback.size() ? &in.feedback[i] : nullptr);
    handle_exceptions(a);
  }
  // 2. requests in program order; generators started now have their time
  //    origin at the last stepped cycle, so they continue from its state.
  for (const Request& r : in.requests) execute(r);
  // 3. step axes, masters before their gear slaves
  cycle_ = in.cycle;
  started_ = true;
  compute_order();
  for (std::size_t n = 0; n < order_n_; ++n) {
    const std::size_t i = order_[n];
    AxisRt& a = axes_[i];
    step_axis(a, i < out.axes.size() ? &out.axes[i] : nullptr);
    update_status(a);
  }
  // 4. group stops: PC when no ramp owned by the MGS is left
  for (auto& g : groups_) {
    if (!g.active) continue;
    bool any = false;
    for (std::size_t i = 0; i < axis_count_ && !any; ++i)
      for (const auto& s : axes_[i].gen)
        if (auto* p = std::get_if<ProfileGen>(&s); p && p->owner == g.owner) any = true;
    if (!any) {
      if (ControlTag* c = tag(g.owner)) { c->set(flag::IP, false); c->set(flag::PC, true); }
      g.active = false;
    }
  }
  return Result::Ok;
}

}  // namespace canmotion::motion
