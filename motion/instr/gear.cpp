// Gear family (motion/instr/gear.hpp): MAG and GearGen. Realtime-safe.
#include "motion/instr/gear.hpp"

#include <cmath>

#include "motion/cam/cam_motion.hpp"
#include "motion/instr/ctx.hpp"

namespace canmotion::motion {
namespace {

/// floor(a * b / c) in exact integer arithmetic (c > 0).
std::int64_t mul_div_floor(std::int64_t a, std::int64_t b, std::int64_t c) noexcept {
  __extension__ typedef __int128 i128;
  const i128 n = static_cast<i128>(a) * static_cast<i128>(b);
  i128 q = n / c;
  if ((n % c != 0) && ((n < 0) != (c < 0))) --q;
  return static_cast<std::int64_t>(q);
}

/// The ratio (signed, with the direction `dir`) of a real or fractional MAG.
Err gear_ratio(Ctx& x, const MagParams& p, int dir, GearGen& g) noexcept {
  if (g.fractional) {
    const double sc = p.slave_counts, mc = p.master_counts;
    // UINT32 operands [seed 003]: 1 .. 4294967295
    constexpr double kUint32Max = 4294967295.0;
    if (!(sc > 0) || sc > kUint32Max) return x.reject_operand(op<Instr::MAG>("SlaveCounts"));
    if (!(mc > 0) || mc > kUint32Max) return x.reject_operand(op<Instr::MAG>("MasterCounts"));
    g.slave_counts = dir * static_cast<std::int64_t>(sc);
    g.master_counts = static_cast<std::int64_t>(mc);
    return Err::None;
  }
  const double mag = std::fabs(p.ratio);
  // 0.00001 .. 9.99999 inclusive, sign-sensitive [seed 003]
  if (!(mag >= 0.00001 - 1e-12) || !(mag <= 9.99999 + 1e-12)) return x.reject_operand(op<Instr::MAG>("Ratio"));
  g.ratio = dir * p.ratio;
  return Err::None;
}

}  // namespace

MagParams MagParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  MagParams m;
  m.slave = q.ref(op<I>("SlaveAxis"));
  m.master = q.ref(op<I>("MasterAxis"));
  m.direction = q.enumeration<CamDirection>(op<I>("Direction"));
  m.ratio = q.real(op<I>("Ratio"));
  m.slave_counts = q.real(op<I>("SlaveCounts"));
  m.master_counts = q.real(op<I>("MasterCounts"));
  m.master_reference = q.enumeration<MasterReference>(op<I>("MasterReference"));
  m.fractional = q.yes(op<I>("RatioFormat"));
  m.clutch = q.number(op<I>("Clutch")) == 0;
  m.accel_rate = q.real(op<I>("AccelRate"));
  m.accel_units = q.enumeration<AccelUnits>(op<I>("AccelUnits"));
  return m;
}

Err start(Ctx& x, const MagParams& p) noexcept {
  AxisRt& a = x.axis(p.slave);
  if (Err e = x.c.common_checks(a, true); e != Err::None) return e;
  if (a.hs.homing) return Err::HomeInProcess;
  const AxisRt& m = x.axis(p.master);
  if (!m.cfg.configured) return Err::AxisNotConfigured;
  if (m.cfg.inhibited) return Err::AxisIsInhibited;
  // Only slave = master is refused. A reversed pair (the master geared to this
  // slave) is allowed: "if a Servo master axis and slave axis are reversed, the
  // axes become cross-coupled and unexpected motion may result" [seed 003]; the
  // step order then steps one of them with the other's command of last cycle.
  if (p.master == p.slave) return Err::MasterAxisConflict;
  // Direction: same/opposite, or reverse/unchanged relative to the last gearing
  // direction (first use: reverse = opposite, unchanged = same) [seed 003]:
  // the rule of the cams' Direction
  const int dir = cam::resolve_direction(static_cast<std::int32_t>(p.direction), a.gear_dir);
  GearGen g;
  g.master_id = p.master;
  g.fractional = p.fractional;
  g.cc_master = m.cfg.conversion_constant;
  g.cc_slave = a.cfg.conversion_constant;
  // a virtual master has no actual position: it always gives command [seed 000]
  g.use_actual = p.master_reference == MasterReference::Actual && m.cfg.type == AxisType::CipDrive;
  if (Err e = gear_ratio(x, p, dir, g); e != Err::None) return e;
  if (p.clutch) {
    constexpr int kAcc = op<Instr::MAG>("AccelRate");
    if (Err e = x.take(units::positive_rate(p.accel_rate, p.accel_units, a.cfg.max_accel, kAcc), g.clutch_accel);
        e != Err::None)
      return e;
    if (!(g.clutch_accel > 0)) return x.reject_operand(kAcc);
  }
  // commit: a new MAG supersedes the active one (ratio, direction or master change)
  Kin start{};
  if (const GenBase* old = gen_base(a.gen[index(Slot::Gear)])) start = Kin{0, old->k.v, 0};
  x.c.fold(a, Slot::Gear, true);
  g.k = start;
  g.owner = x.self;
  if (!p.clutch) {  // lock at once: the offset follows the master from here
    g.locked = true;
    g.master_ref = g.use_actual ? m.fb_pos : m.cmd.p;
    g.master_ref_counts = std::llround(g.master_ref * g.cc_master);
    g.offset_at_lock = 0.0;
    g.k = Kin{};
  }
  x.c.set_slot(a, Slot::Gear, g);
  a.gear_dir = dir;
  x.tag.set(flag::DN, true);
  x.tag.set(flag::IP, true);
  return Err::None;
}

void GearGen::step(Core& c, AxisRt&, Slot) noexcept {
  GearGen& g = *this;
  const AxisRt& m = c.axes[g.master_id];
  const double mp = g.use_actual ? m.fb_pos : m.cmd.p;
  const double mv = g.use_actual ? m.fb_vel : m.cmd.v;
  const double ma = g.use_actual ? 0.0 : m.cmd.a;
  const double kr = g.fractional ? static_cast<double>(g.slave_counts) / static_cast<double>(g.master_counts) *
                                       g.cc_master / g.cc_slave
                                 : g.ratio;
  const double target_v = kr * mv;
  if (!g.locked) {
    // clutch: trapezoidal ramp of the slave's gear velocity to the geared speed
    const double dv = target_v - g.k.v;
    const double max_dv = g.clutch_accel * c.T;
    if (std::fabs(dv) <= max_dv) {
      g.k.p += (g.k.v + target_v) / 2 * c.T;
      g.k.v = target_v;
      g.k.a = 0.0;
      g.locked = true;
      g.master_ref = mp;
      g.master_ref_counts = std::llround(mp * g.cc_master);
      g.offset_at_lock = g.k.p;
    } else {
      const double acc = dv > 0 ? g.clutch_accel : -g.clutch_accel;
      const double v1 = g.k.v + acc * c.T;
      g.k.p += (g.k.v + v1) / 2 * c.T;
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
  g.k.a = kr * ma;
}

}  // namespace canmotion::motion
