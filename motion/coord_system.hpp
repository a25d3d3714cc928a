#pragma once
/// \file motion/coord_system.hpp
/// A COORDINATE_SYSTEM in the planner (issue 14, seed 001): its
/// configuration, its tag, and its state in Core::systems (the path
/// generator of motion/coord/, the control tags of its moves, its MDCC
/// links). The instructions on it are the coord family
/// (motion/instr/coord.hpp); each member axis runs its share of the path in a
/// CoordGen (motion/generator.hpp). Fixed-size data; realtime-safe.

#include <array>
#include <cstddef>
#include <cstdint>

#include "motion/control_tag.hpp"
#include "motion/coord/path_generator.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

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

}  // namespace canmotion::motion
