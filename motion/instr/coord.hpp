#pragma once
/// \file motion/instr/coord.hpp
/// Coordinated family (issue 14, seed 001): the instructions MCLM, MCCM,
/// MCS, MCSD, MCCD, MDCC on a COORDINATE_SYSTEM (motion/instr/coord.cpp), and
/// the operations on coordinate systems (motion/instr/coord_system.cpp, with
/// the step of CoordGen, the generator of a member axis's coordinated slot).
/// The coordinate system's state is motion/coord_system.hpp, the path maths
/// motion/coord/ (geometry, PathGenerator). Everything here is noexcept and
/// allocation-free; all but configure are realtime-safe.

#include <array>
#include <cstddef>
#include <cstdint>

#include "motion/coord/path_generator.hpp"
#include "motion/coord_system.hpp"
#include "motion/instr/common.hpp"
#include "motion/units.hpp"

namespace canmotion::motion {

/// MCLM and MCCM (one params type each; `circle` tells them apart).
struct CoordMoveParams {
  CoordSystemId cs = 0;
  bool circle = false;
  MoveType move_type = MoveType::Absolute;  ///< Absolute or Incremental
  std::uint16_t position = 0xFFFF;          ///< REAL[] id of Position
  double position_start = 0.0;
  coord::CircleType circle_type = coord::CircleType::Via;                ///< MCCM
  coord::CircleDirection direction = coord::CircleDirection::Clockwise;  ///< MCCM
  std::uint16_t aux = 0xFFFF;  ///< REAL[] id of Via/Center/Radius
  double aux_start = 0.0;
  RateOperands dyn{};  ///< Speed .. JerkUnits (motion/units.hpp)
  coord::Termination termination = coord::Termination::NoSettle;
  coord::CoordMerge merge = coord::CoordMerge::Disabled;
  MergeSpeed merge_speed = MergeSpeed::Programmed;
  double command_tolerance = 0.0;
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  std::uint16_t event_distance = 0xFFFF, calculated_data = 0xFFFF;
  double event_distance_start = 0.0, calculated_data_start = 0.0;
};
struct MclmParams : CoordMoveParams {
  static constexpr Instr kInstr = Instr::MCLM;
  static MclmParams decode(const Operands& q) noexcept;
};
struct MccmParams : CoordMoveParams {
  static constexpr Instr kInstr = Instr::MCCM;
  static MccmParams decode(const Operands& q) noexcept;
};

/// MCS StopType [RM002H]: the Logix numbers (1 is not used).
enum class CoordStopType : std::uint8_t { All = 0, CoordinatedMove = 2, CoordinatedTransform = 3 };

struct McsParams {
  static constexpr Instr kInstr = Instr::MCS;
  CoordSystemId cs = 0;
  CoordStopType stop_type = CoordStopType::All;
  bool change_decel = false, change_decel_jerk = false;
  double decel = 0.0, decel_jerk = 0.0;
  AccelUnits decel_units = AccelUnits::UnitsPerSec2;
  JerkUnits jerk_units = JerkUnits::UnitsPerSec3;
  static McsParams decode(const Operands& q) noexcept;
};

struct McsdParams {
  static constexpr Instr kInstr = Instr::MCSD;
  CoordSystemId cs = 0;
  static McsdParams decode(const Operands& q) noexcept;
};

struct MccdParams {
  static constexpr Instr kInstr = Instr::MCCD;
  CoordSystemId cs = 0;
  bool change_speed = false, change_accel = false, change_decel = false;
  bool change_accel_jerk = false, change_decel_jerk = false;
  RateOperands dyn{};  ///< Speed .. JerkUnits (motion/units.hpp); MotionType has one value (coordinated move)
  coord::ChangeScope scope = coord::ChangeScope::ActiveMotion;
  static MccdParams decode(const Operands& q) noexcept;
};

struct MdccParams {
  static constexpr Instr kInstr = Instr::MDCC;
  CoordSystemId cs = 0;
  AxisId master = kNoAxis;
  MasterReference master_reference = MasterReference::Actual;
  double nominal_master_velocity = 0.0;
  static MdccParams decode(const Operands& q) noexcept;
};

using CoordInstructions = TypeList<MclmParams, MccmParams, McsParams, McsdParams, MccdParams, MdccParams>;

Err start(Ctx& x, const MclmParams& p) noexcept;
Err start(Ctx& x, const MccmParams& p) noexcept;
Err start(Ctx& x, const McsParams& p) noexcept;
Err start(Ctx& x, const McsdParams& p) noexcept;
Err start(Ctx& x, const MccdParams& p) noexcept;
Err start(Ctx& x, const MdccParams& p) noexcept;

namespace coordsys {
/// Configure coordinate system `id` (non-RT). False for an invalid
/// configuration (dimension, members not configured or repeated, limits).
bool configure(Core& c, CoordSystemId id, const CoordSystemConfig& cfg) noexcept;
/// One cycle of a coordinate system: its path stepped, the events written
/// to the control tags, its tag. Called by the first member that steps.
void step_system(Core& c, CoordSystemRt& s) noexcept;
/// Drop the path at once (MCSD, the last member following it left): every
/// move ends (IP cleared), the members hold where they are.
/// `folding`: a member whose slot is being folded by the caller.
void drop(Core& c, CoordSystemRt& s, const AxisRt* folding = nullptr) noexcept;
/// Break the MDCC links of the system (MCS All, MCSD; a member or master shut down).
void break_links(Core& c, CoordSystemRt& s) noexcept;
/// Start a stop along the path at decel `d` / jerk `jd` (MCS) for `owner`:
/// the active and pending moves end (IP, AC cleared, no PC), StoppingStatus
/// until standstill, then StopDone. A stop that runs is superseded.
void start_stop(Core& c, CoordSystemRt& s, OwnerRef owner, double d, double jd) noexcept;
/// Stop the path along itself at the system's max decel (trapezoidal, as
/// MCS without ChangeDecel) for `owner` (none: an exception or a member that
/// left), unless a stop for that owner runs already. True when the path moves.
bool path_stop(Core& c, CoordSystemRt& s, OwnerRef owner) noexcept;
/// A member stops all its motion (MAS All, MGS, a Stop Planner exception):
/// the path of its coordinate system stops along itself, the member keeps
/// following it (reference: "the path is kept"). True when a path moves.
bool stop_member_path(Core& c, AxisRt& a, OwnerRef owner) noexcept;
/// A path stop for `owner` runs (MAS All / MGS get PC when it ends).
bool stop_owned_by(const Core& c, OwnerRef owner) noexcept;
/// MRP, MAH, MDS on a member while its coordinate system's path moves:
/// ERR 52 (Coordinated Motion In Process, reference ?).
Err check_no_coordinated_motion(const Core& c, const AxisRt& a) noexcept;
/// MAS All, MGS on a member: the MDCC links of its coordinate systems break.
void break_member_links(Core& c, AxisId axis) noexcept;
/// An axis shut down (MASD, MGSD, MCSD, a Shutdown fault): the MDCC links of
/// the systems it is a member or the master of break (seed 001, p.531); a
/// master-driven path of a system whose master was shut down stops along
/// itself (time-driven, max decel) instead of waiting for a master that is gone.
void on_shutdown(Core& c, AxisId axis) noexcept;
/// The tag of every coordinate system (status words, positions): after the
/// axes stepped. Realtime-safe.
void update_tags(Core& c) noexcept;
/// The master's position (drive frame) and velocity of a link, into `now`.
void master_state(const Core& c, const MdccLink& l, coord::Present& now) noexcept;
/// The present state of a system (last cycle's member commands, following
/// error, the master of `link`) for submit and step.
coord::Present present(const Core& c, const CoordSystemRt& s, const MdccLink& link) noexcept;
/// The path went idle and every member folded its slot: fold the path
/// generator too (its offset restarts at 0).
void settle(Core& c, CoordSystemRt& s, const AxisRt* folding = nullptr) noexcept;
/// Give every member a coordinated slot (a new move starts).
void join_members(Core& c, CoordSystemRt& s) noexcept;
/// Write the path's events to the control tags (AC, PC, IP, ER; MCS PC;
/// CalculatedData on activation).
void apply_events(Core& c, CoordSystemRt& s, const coord::Events& ev) noexcept;
/// The pending MDCC takes over the link (seed 001: when an MCLM/MCCM goes IP).
void take_pending_link(Core& c, CoordSystemRt& s) noexcept;
/// The members' slots follow the link's master in the step order.
void refresh_link_master(Core& c, CoordSystemRt& s) noexcept;
}  // namespace coordsys

}  // namespace canmotion::motion
