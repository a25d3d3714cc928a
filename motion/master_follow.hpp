#pragma once
/// \file motion/master_follow.hpp
/// Master-driven following (MDSC): how far the master moved in the lock
/// direction this cycle. One definition shared by master-driven MAM/MAJ
/// (ProfileGen) and master-driven MATC (CamGen) [RM002H p.512, p.534; seed 004
/// TimeCamLockStatus]. Pure, realtime-safe.

#include "motion/control_tag.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// True for the Lock Directions that follow forward master motion.
constexpr bool lock_forward(LockDirection d) noexcept {
  return d == LockDirection::ImmediateForwardOnly || d == LockDirection::PositionForwardOnly;
}
/// True for Immediate Forward/Reverse Only: locked from the start.
constexpr bool lock_immediate(LockDirection d) noexcept {
  return d == LockDirection::ImmediateForwardOnly || d == LockDirection::ImmediateReverseOnly;
}

/// One cycle of following. `mp` is the master position now (actual or command
/// per the MDAC link), `prev_mp` the position last cycle (updated here).
/// Returns the increment of the driving coordinate (master travel counted in
/// the lock direction):
///  * None: the signed master travel (the slave follows both directions; only
///    a master-driven MATC may run with None, MAM/MAJ refuse it with ERR 95);
///  * Immediate/Position Forward (Reverse) Only: the forward (reverse) master
///    travel, >= 0. A position lock waits until the master crosses `lock_pos`
///    in that direction (`locked` is set then; only the travel past it counts);
///    a master that starts exactly on `lock_pos` never crosses it.
/// `following` (Move/Jog/TimeCamLockStatus together with `locked`) is set
/// when the master moves in the lock direction, cleared when it moves the
/// other way (the slave stops without backing up), and kept while the master
/// stands still (a master paused at speed 0 keeps the lock status [seed 004]).
constexpr double master_follow_step(LockDirection lock, double lock_pos, double mp, double& prev_mp, bool& locked,
                                    bool& following) noexcept {
  double dm = mp - prev_mp;
  if (lock == LockDirection::None) {
    prev_mp = mp;
    locked = true;
    following = true;
    return dm;
  }
  const bool fwd = lock_forward(lock);
  if (!locked) {
    const bool crossed = fwd ? (prev_mp < lock_pos && mp >= lock_pos) : (prev_mp > lock_pos && mp <= lock_pos);
    if (crossed) {
      locked = true;
      following = true;
      dm = mp - lock_pos;
    } else {
      dm = 0;
    }
  }
  prev_mp = mp;
  if (!locked) return 0.0;
  const double d = fwd ? dm : -dm;
  if (d > 0) following = true;
  else if (d < 0) following = false;
  return d > 0 ? d : 0.0;
}

/// Following state of a master-driven generator: MATC (CamGen::md) and
/// MAM/MAJ (ProfileGen::md).
struct MasterFollow {
  AxisId master = kNoAxis;
  bool use_actual = false;     ///< master reference actual (CIP masters only)
  LockDirection lock = LockDirection::None;
  double lock_pos = 0.0;
  bool locked = false;         ///< lock condition met
  bool following = false;      ///< the master last moved in the lock direction
  double u = 0.0;              ///< driving coordinate: master travel counted so far
  double prev_mp = 0.0;        ///< master position last cycle
  OwnerRef mdac{};             ///< the MDAC control whose AC bit this motion sets
  /// Advance by one cycle with master position `mp`; returns du. Realtime-safe.
  constexpr double step(double mp) noexcept {
    const double du = master_follow_step(lock, lock_pos, mp, prev_mp, locked, following);
    u += du;
    return du;
  }
  /// Lock status bit (TimeCamLockStatus): lock condition met and following;
  /// not used (false) for Lock Direction None [seed 004].
  constexpr bool lock_status() const noexcept { return lock != LockDirection::None && locked && following; }
};

}  // namespace canmotion::motion
