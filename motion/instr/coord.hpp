#pragma once
/// \file motion/instr/coord.hpp
/// Coordinated family (issue 14, seed 001): the COORDINATE_SYSTEM objects of
/// the planner, the instructions MCLM, MCCM, MCS, MCSD, MCCD, MDCC
/// (motion/instr/coord.cpp) and CoordGen, the generator of a member axis's
/// coordinated slot (motion/instr/coord_system.cpp). The path maths are in
/// motion/coord/ (geometry, PathGenerator). Everything here is noexcept and
/// allocation-free; all but configure are realtime-safe.

#include <array>
#include <cstddef>
#include <cstdint>

#include "motion/coord/path_generator.hpp"
#include "motion/instr/common.hpp"
#include "motion/units.hpp"

namespace canmotion::motion {

enum class Slot : std::uint8_t;

/// Capacity of coordinate systems. Bound: a Logix motion group holds a few
/// coordinate systems (one per machine section); 8 leaves room, and each is
/// ~3.5 KB of fixed state.
inline constexpr std::size_t kMaxCoordSystems = 8;
/// Index of a coordinate system in the planner (the binder's coordinate_systems id).
using CoordSystemId = std::uint16_t;

/// Configuration of one COORDINATE_SYSTEM (config `coordinate_systems:`).
struct CoordSystemConfig {
  int dim = 0;                                          ///< 1..3 member axes
  std::array<AxisId, coord::kMaxDim> axes{kNoAxis, kNoAxis, kNoAxis};  ///< members in order
  std::array<double, coord::kMaxDim> ratio{1.0, 1.0, 1.0};  ///< coordination units per axis unit
  double max_speed = 0.0, max_accel = 0.0, max_decel = 0.0;  ///< coordination units/s, /s^2 (> 0)
  double max_accel_jerk = 0.0, max_decel_jerk = 0.0;       ///< /s^3 (0: %ofMaximum jerk refused)
  double actual_tolerance = 0.0;   ///< Actual Position Tolerance (TT0)
  double command_tolerance = 0.0;  ///< Command Position Tolerance (TT2)
};

/// What a program reads of a coordinate system (`CS.*` tags).
struct CoordSystemTag {
  std::uint32_t system_status = 0;  ///< CoordinateSystemStatus (coordinate_system_status bits)
  std::uint32_t motion_status = 0;  ///< CoordinateMotionStatus (coordinate_motion_status bits)
  std::array<double, coord::kMaxDim> actual_position{};   ///< members' actual positions x ratio
  std::array<double, coord::kMaxDim> command_position{};  ///< members' command positions x ratio
  double speed = 0.0;  ///< vector speed of the path (coordination units/s)
};

/// The MDCC link of a coordinate system (master-driven coordinated control).
struct MdccLink {
  AxisId master = kNoAxis;
  bool use_actual = false;
  OwnerRef owner{};  ///< the MDCC execution (IP while the link holds)
  constexpr bool valid() const noexcept { return master != kNoAxis; }
};

/// One coordinate system in the planner: its path generator, the control
/// tags of the moves it runs, its MDCC links and its tag.
struct CoordSystemRt {
  /// A path move id and the execution it reports to. Bound: the path holds
  /// an active and a pending move and a stop; 4 leaves one spare.
  struct Owner {
    std::uint32_t id = 0;
    OwnerRef owner{};
    bool mdcc_ac = false;       ///< master-driven: the MDCC's AC follows this move's AC
    std::uint16_t cd = 0xFFFF;  ///< CalculatedData REAL[] id (0xFFFF none)
    std::uint16_t ed = 0xFFFF;  ///< EventDistance REAL[] id
    double cd_start = 0.0, ed_start = 0.0;
    bool stop = false;  ///< a path stop (MCS, MAS All, MGS, a member that left), not a move
  };
  CoordSystemConfig cfg{};
  bool present = false;
  coord::PathGenerator path{};
  coord::Output out{};
  CoordSystemTag tag{};
  std::array<Owner, 4> owners{};
  std::uint32_t next_id = 1;
  std::uint64_t stepped = ~std::uint64_t{0};  ///< cycle of the last step (the first member steps it)
  bool fold_due = false;  ///< the path went idle: fold the generator once the members folded their slots
  bool dropping = false;  ///< drop() runs (a member's fold must not re-enter it)
  MdccLink link{};        ///< the master the path follows
  MdccLink pending{};     ///< an MDCC naming another master: taken at the next MCLM/MCCM (seed 001)
  bool md_last = false;   ///< the last move that went active was master-driven (mode of the system)
  double md_speed = 0.0;  ///< its programmed speed (units per master unit; the 10 % rule)
};

/// Generator of a member axis's coordinated slot: the axis's share of its
/// coordinate system's path (offset / ratio), stepped once per cycle by the
/// first member that steps.
struct CoordGen : GenBase {
  CoordSystemId cs = 0;
  std::uint8_t member = 0;
  AxisId link_master = kNoAxis;  ///< the MDCC master (steps before the members)

  AxisId master() const noexcept { return link_master; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;
};

/// MCLM and MCCM (one params type each; `circle` tells them apart).
struct CoordMoveParams {
  CoordSystemId cs = 0;
  bool circle = false;
  bool incremental = false;
  std::uint16_t position = 0xFFFF;  ///< REAL[] id of Position
  double position_start = 0.0;
  std::uint8_t circle_type = 0, direction = 0;
  std::uint16_t aux = 0xFFFF;  ///< REAL[] id of Via/Center/Radius
  double aux_start = 0.0;
  RateOperands dyn{};  ///< Speed .. JerkUnits (motion/units.hpp)
  std::uint8_t termination = 1;
  std::uint8_t merge = 0;
  MergeSpeed merge_speed = MergeSpeed::Programmed;
  double command_tolerance = 0.0;
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  std::uint16_t event_distance = 0xFFFF, calculated_data = 0xFFFF;
  double event_distance_start = 0.0, calculated_data_start = 0.0;
  int first_dyn_operand = 0;  ///< ST index of Speed (EXERR base)
};
struct MclmParams : CoordMoveParams {
  static constexpr Instr kInstr = Instr::MCLM;
  static MclmParams decode(const Operands& q) noexcept;
};
struct MccmParams : CoordMoveParams {
  static constexpr Instr kInstr = Instr::MCCM;
  static MccmParams decode(const Operands& q) noexcept;
};

struct McsParams {
  static constexpr Instr kInstr = Instr::MCS;
  CoordSystemId cs = 0;
  std::uint8_t stop_type = 0;  ///< 0 all, 2 coordinated move, 3 coordinated transform
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
  RateOperands dyn{};  ///< Speed .. JerkUnits (motion/units.hpp)
  bool active_and_pending = false;
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
