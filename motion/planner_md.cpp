// Master-driven MATC (InstructionMode masterdrivenmode): the cam coordinate is
// the master travel through the slave's MDAC link for Time Cam (or All), in
// the lock direction [seed 000, seed 004, reference §2.15, §5]. The
// following rule itself (lock position, lock direction, pause, reversal) is
// master_follow_step() in motion/master_follow.hpp, shared with master-driven
// MAM/MAJ.
#include <variant>

#include "motion/instructions.hpp"
#include "motion/planner.hpp"

namespace canmotion::motion {
namespace {
/// Index of the Time Cam link in AxisRt::mdac (0 move, 1 jog, 2 time cam, 3 master offset move).
constexpr std::size_t kTimeCamLink = 2;

constexpr bool position_lock(LockDirection d) noexcept {
  return d == LockDirection::PositionForwardOnly || d == LockDirection::PositionReverseOnly;
}
}  // namespace

Err Planner::matc_mode_checks(const AxisRt& a, const MatcParams& p) const noexcept {
  const bool pending = p.execution_schedule == 1;
  // time driven: Lock Direction must be None [RM002H p.512, reference §5]
  if (!p.master_driven && p.lock_direction != LockDirection::None) return Err::MdscLockDirConflict;
  // pending cams use an immediate lock; a position lock is LOCK_DIRECTION_CONFLICT (95) [seed 004]
  if (pending && position_lock(p.lock_direction)) return Err::MdscLockDirConflict;
  const auto* cur = std::get_if<CamGen>(&a.gen[static_cast<std::size_t>(Slot::TimeCam)]);
  if (pending && cur != nullptr) {
    // the pending and the active cam must be in the same mode [seed 004]; it
    // then runs with the active cam's master and lock state [seed 000]
    if (cur->master_driven != p.master_driven) return Err::MdscInvalidModeOrMasterChange;
    return Err::None;
  }
  // master-driven mode needs an active MDAC link for Time Cam (or All) [seed 004 "Structure"]
  if (p.master_driven && !a.links.pending[kTimeCamLink].valid() && !a.links.active[kTimeCamLink].valid())
    return Err::MdscNotActivated;
  return Err::None;
}

Err Planner::matc_md_setup(const AxisRt& a, const MatcParams& p, CamGen& g) const noexcept {
  // a queued master takes over when this MATC goes IP (start_matc promotes it) [seed 000]
  const MdacLink& l = a.links.pending[kTimeCamLink].valid() ? a.links.pending[kTimeCamLink] : a.links.active[kTimeCamLink];
  if (!l.valid()) return Err::MdscNotActivated;
  const AxisRt& m = axes_[l.master];
  g.master_driven = true;
  g.md = MasterFollow{};
  g.md.master = l.master;
  g.md.use_actual = l.use_actual;
  g.md.lock = p.lock_direction;
  g.md.lock_pos = p.lock_position - m.frame_offset;  // user frame (MRP, homing) -> drive frame
  // None and Immediate locks: locked from the start (TimeCamLockStatus set at once
  // for Immediate); Position locks wait for the master to cross LockPosition [seed 004]
  g.md.locked = p.lock_direction == LockDirection::None || lock_immediate(p.lock_direction);
  g.md.following = g.md.locked;
  g.md.prev_mp = l.use_actual ? m.fb_pos : m.cmd.p;
  g.md.mdac = l.owner;
  return Err::None;
}

double Planner::cam_coordinate(CamGen& g) noexcept {
  if (!g.master_driven) return static_cast<double>(cycle_ - g.t0_cycle) * T_ - g.x_offset;
  if (g.md_cycle != cycle_) {  // once per cycle (a pending takeover steps the new cam in the same cycle)
    const AxisRt& m = axes_[g.md.master];
    const double du = g.md.step(g.md.use_actual ? m.fb_pos : m.cmd.p);
    g.md_rate = du / T_;
    g.md_cycle = cycle_;
  }
  return g.md.u - g.x_offset;
}

void Planner::cam_output(CamGen& g, const cam::CamMotionOutput& o) noexcept {
  // d/dt = d/du * du/dt: slave velocity = cam slope x master velocity (lock direction)
  const double r = g.master_driven ? g.md_rate : 1.0;
  g.k = Kin{o.position, o.velocity * r, o.acceleration * r * r};
  if (ControlTag* c = tag(g.owner)) {
    c->segment = static_cast<std::int32_t>(o.segment);
    // a cam has no accel/decel transition: it tracks the master while locked and following
    if (g.master_driven) c->set(flag::TrackingMaster, g.md.locked && g.md.following);
  }
}

}  // namespace canmotion::motion
