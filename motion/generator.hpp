#pragma once
/// \file motion/generator.hpp
/// Generators: the running motion of an axis, one per slot, superposed, and
/// the generator interface through which the core (motion/core.hpp) steps
/// and ends them without knowing the instruction families that start them.
///
/// A generator type G (ProfileGen, GearGen, CamGen, PosCamGen, CoordGen)
/// derives from GenBase (its output `k`, an offset added to the axis command,
/// and its `owner`) and has:
///   AxisId master() const;            // the axis it follows, or kNoAxis (step order: masters first)
///   void step(Core&, AxisRt&, Slot);  // advance one cycle: set k; may fold itself or hand its slot over
///   void on_fold(Core&, AxisRt&);     // it ends: release what it holds (cam profile, MDAC AC, ...)
/// The planner reaches them only through one std::visit (with_generator(),
/// gen_base(), master_of()): a new generator type is one more alternative of
/// `Generator` and these four members. Their state is defined here, below
/// the core; `step` and `on_fold` are defined by the family that starts the
/// generator (motion/instr/<family>.cpp; ProfileGen::step inline in
/// motion/profile_step.hpp). A generator may take its output from state
/// shared by several axes (its step reads it through Core), e.g. a path of a
/// coordinate system stepped once per cycle.

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <variant>

#include "motion/cam/cam_motion.hpp"
#include "motion/control_tag.hpp"
#include "motion/coord_system.hpp"
#include "motion/master_follow.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

struct Core;    // motion/core.hpp: the planner's state
struct AxisRt;  // motion/core.hpp: one axis in the planner

/// Per-axis generator slots, in step order. Generators superpose: the command
/// position is base + the sum of the slot offsets. The master offset move
/// (master units, it shifts the position cam's master) steps before the
/// position cam and is not part of the sum. Bound: one slot per kind of
/// motion Logix can run at the same time on one axis (move, jog, gear, time
/// cam, master offset move, position cam) plus one for a stop of all motion,
/// and one for the member's share of a coordinate system's path (issue 14).
enum class Slot : std::uint8_t { Move = 0, Jog, Gear, TimeCam, MasterOffset, PositionCam, StopAll, Coord, Count };
inline constexpr std::size_t kSlots = static_cast<std::size_t>(Slot::Count);
constexpr std::size_t index(Slot s) noexcept { return static_cast<std::size_t>(s); }
/// Bit of a slot in AxisRt::live and in stop masks.
constexpr std::uint32_t slot_bit(Slot s) noexcept { return 1u << index(s); }
/// Every slot (MAS All, MGS, exception stops).
inline constexpr std::uint32_t kAllSlots = (1u << kSlots) - 1u;

/// The slots in the order of their numbers before the master offset move's
/// slot was put ahead of the position cam's (issue 13). The two loops whose
/// results depend on the slot order without stepping use it, so that the
/// results stay as they were: the speed an MAS stops from (a floating-point
/// sum) and the order in which the step-order walk visits masters.
inline constexpr std::array<Slot, kSlots> kLegacySlotOrder{Slot::Move, Slot::Jog, Slot::Gear, Slot::TimeCam,
                                                           Slot::PositionCam, Slot::MasterOffset, Slot::StopAll,
                                                           Slot::Coord};
static_assert([] {
  std::uint32_t seen = 0;
  for (const Slot s : kLegacySlotOrder) seen |= slot_bit(s);
  return seen == (1u << kSlots) - 1u;
}(), "kLegacySlotOrder lists every slot once (a new slot goes into it too)");

/// What every generator has: its output, an offset added to the axis
/// command, and the execution that owns it.
struct GenBase {
  Kin k{};           ///< position (offset), velocity, acceleration after the last step
  OwnerRef owner{};  ///< the control tag it writes (IP, PC, ACCEL, DECEL, ...)
};

/// What a profile generator is doing.
enum class GenRole : std::uint8_t { Move, Jog, Stop };

/// Generator of a profile-driven motion: MAM, MAJ, and the stop ramps of MAS,
/// MGS and exceptions. O(1) step: one Profile::sample, at time or (master
/// driven) at master travel.
struct ProfileGen : GenBase {
  GenRole role = GenRole::Move;
  Profile prof{};
  int hint = 0;
  std::uint64_t t0_cycle = 0;  ///< profile time = (cycle - t0_cycle) * period
  double total = 0.0;          ///< move: distance from the generator origin to the target
  double target_user = 0.0;    ///< move: programmed absolute target (user frame)
  bool exact_target = false;   ///< move: absolute linear target can be set exactly at the end
  MoveType move_type = MoveType::Absolute;
  Limits lim{};
  bool scurve = false;
  bool seconds = false;        ///< programmed in seconds (MCD not allowed: ERR 23)
  double speed = 0.0;          ///< programmed speed (0 = paused until MCD)
  double jog_velocity = 0.0;   ///< jog: signed programmed velocity
  std::uint8_t post_stop = 0;  ///< stop ramps of MGS: 0 none, 1 disable, 2 shutdown
  // master driven (MDSC): the profile's abscissa is master travel md.u, not
  // time; md as for a master-driven MATC (motion/master_follow.hpp)
  bool master_driven = false;
  MasterFollow md{};

  // generator interface; step inline in motion/profile_step.hpp, on_fold and finish in motion/instr/move.cpp
  AxisId master() const noexcept { return master_driven ? md.master : kNoAxis; }
  /// Defined in motion/profile_step.hpp: inline in the cycle.
  inline void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;
  /// The profile ended (step): PC, folded; a ramp of MGS FastDisable /
  /// FastShutdown then switches the servo off / shuts the axis down.
  void finish(Core& c, AxisRt& a, Slot s, ControlTag* t) noexcept;
};

/// Generator of an MAG: the slave offset follows the master position (drive
/// frame) at the ratio; O(1) step. No axis limits apply.
struct GearGen : GenBase {
  AxisId master_id = kNoAxis;
  bool use_actual = false;     ///< master reference actual (CIP masters only)
  bool fractional = false;     ///< RatioFormat fraction: exact integer counts
  double ratio = 1.0;          ///< signed real ratio, direction included
  std::int64_t slave_counts = 1, master_counts = 1;  ///< signed fraction, direction included
  double cc_master = 1.0, cc_slave = 1.0;            ///< conversion constants (counts/unit)
  bool locked = false;         ///< GearingLockStatus
  double clutch_accel = 0.0;   ///< units/s^2 while clutching
  double master_ref = 0.0;     ///< master position at lock (units, drive frame)
  std::int64_t master_ref_counts = 0;
  double offset_at_lock = 0.0;

  // generator interface (step: motion/instr/gear.cpp); gear ramps are trapezoidal
  AxisId master() const noexcept { return master_id; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core&, AxisRt&) noexcept {}
};

/// Generator of an MATC: the cam engineer's CamMotion evaluated at cam time,
/// or (master driven) at master travel in the lock direction. O(1) amortised
/// step.
struct CamGen : GenBase {
  cam::CamMotion cm{};
  cam::CamProfile* profile = nullptr;  ///< in use (acquired) while the cam runs
  std::uint64_t t0_cycle = 0;
  double x_offset = 0.0;       ///< cam time = (cycle - t0_cycle) * T - x_offset (pending takeovers)
  std::int64_t last_pass = 0;  ///< pass of the last step (a pending cam waits for its end)
  /// master-driven MATC (InstructionMode masterdrivenmode): cam coordinate =
  /// master travel in the lock direction (md.u - x_offset) instead of time
  bool master_driven = false;
  MasterFollow md{};
  double md_rate = 0.0;            ///< master travel per second in the lock direction, last step
  std::uint64_t md_cycle = ~0ull;  ///< cycle md was last advanced (a takeover steps twice per cycle)

  // generator interface (step, on_fold: motion/instr/time_cam.cpp)
  AxisId master() const noexcept { return master_driven ? md.master : kNoAxis; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;
};

/// Generator of an MAPC: the cam engineer's CamMotion evaluated at the master
/// coordinate = master travel since the lock (filtered by MasterDirection) +
/// the master offset (finished master offset moves + the running one in
/// Slot::MasterOffset). O(1) amortised step.
struct PosCamGen : GenBase {
  cam::CamMotion cm{};
  cam::CamProfile* profile = nullptr;  ///< in use (acquired) while the cam runs
  AxisId master_id = kNoAxis;
  bool use_actual = false;      ///< MasterReference actual (CIP masters only)
  std::uint8_t schedule = 0;    ///< ExecutionSchedule: schedule::Immediate, ForwardOnly, ReverseOnly, Bidirectional
  std::uint8_t master_dir = 0;  ///< master_direction::Bidirectional, ForwardOnly, ReverseOnly
  double master_lock = 0.0;     ///< MasterLockPosition (master user frame)
  bool locked = false;          ///< the master crossed MasterLockPosition (immediate: at once)
  bool inside = true;           ///< the cam coordinate is inside the profile (Persistent relocks)
  bool slipping = false;        ///< the master moved against MasterDirection this cycle
  double prev_mp = 0.0;         ///< master position (drive frame) last cycle
  double lock_mp = 0.0;         ///< master position (drive frame) at the lock
  double travel = 0.0;          ///< master travel since the lock as the cam follows it
  double offset_base = 0.0;     ///< sum of the finished master offset moves (master units)
  double x_shift = 0.0;         ///< cam coordinate of the takeover (pending cams)
  std::int64_t last_pass = 0;

  // generator interface (step, on_fold: motion/instr/position_cam.cpp)
  AxisId master() const noexcept { return master_id; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;  ///< release the profile, AC cleared, end the offset move
};

/// Generator of a member axis's coordinated slot: the axis's share of its
/// coordinate system's path (offset / ratio), stepped once per cycle by the
/// first member that steps.
struct CoordGen : GenBase {
  CoordSystemId cs = 0;
  std::uint8_t member = 0;
  AxisId link_master = kNoAxis;  ///< the MDCC master (steps before the members)

  // generator interface (step, on_fold: motion/instr/coord_system.cpp)
  AxisId master() const noexcept { return link_master; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;
};

/// The closed set of generator states.
using Generator = std::variant<std::monostate, ProfileGen, GearGen, CamGen, PosCamGen, CoordGen>;

/// Call f(generator) with the generator `g` holds (nothing for an empty slot).
template <class F>
inline void with_generator(Generator& g, F&& f) noexcept {
  std::visit(
      [&](auto& x) noexcept {
        if constexpr (!std::is_same_v<std::decay_t<decltype(x)>, std::monostate>) f(x);
      },
      g);
}

/// The output and owner of the generator `g` holds, or null for an empty slot.
inline GenBase* gen_base(Generator& g) noexcept {
  return std::visit(
      [](auto& x) noexcept -> GenBase* {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::monostate>) return nullptr;
        else return &x;
      },
      g);
}
inline const GenBase* gen_base(const Generator& g) noexcept { return gen_base(const_cast<Generator&>(g)); }

/// The axis the generator in `g` follows, or kNoAxis.
inline AxisId master_of(const Generator& g) noexcept {
  return std::visit(
      [](const auto& x) noexcept -> AxisId {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::monostate>) return kNoAxis;
        else return x.master();
      },
      g);
}

}  // namespace canmotion::motion
