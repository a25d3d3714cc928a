#pragma once
/// \file motion/instr/position_cam.hpp
/// Position cam family: MAPC, pending position cams, the master offset moves
/// (MAM MoveType 5/6, started by the move family in Slot::MasterOffset) and
/// PosCamGen, the position cam generator (motion/instr/position_cam.cpp).

#include <cstdint>

#include "motion/axis.hpp"
#include "motion/cam/cam_motion.hpp"
#include "motion/instr/common.hpp"

namespace canmotion::motion {

enum class Slot : std::uint8_t;

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

  // generator interface (motion/generator.hpp)
  AxisId master() const noexcept { return master_id; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;  ///< release the profile, AC cleared, end the offset move
};

/// A pending MAPC waiting for the end of the current pass (or for a non-pending cam).
struct PendingPosCam {
  cam::CamProfile* profile = nullptr;
  cam::CamMotionConfig cfg{};
  AxisId master = kNoAxis;
  bool use_actual = false;
  std::uint8_t master_dir = 0;
  OwnerRef owner{};
  constexpr bool valid() const noexcept { return profile != nullptr; }
};

struct MapcParams {
  static constexpr Instr kInstr = Instr::MAPC;
  AxisId slave = kNoAxis, master = kNoAxis;
  CamDirection direction = CamDirection::Same;
  std::uint16_t cam_profile = 0xFFFF;
  double slave_scaling = 1.0, master_scaling = 1.0;
  std::uint8_t execution_mode = 0;      ///< cam::ExecutionMode
  std::uint8_t execution_schedule = 0;  ///< schedule::
  double master_lock_position = 0.0, cam_lock_position = 0.0;
  MasterReference master_reference = MasterReference::Actual;
  std::uint8_t master_direction = 0;    ///< master_direction::
  static MapcParams decode(const Operands& q) noexcept;
};
using PositionCamInstructions = TypeList<MapcParams>;

Err start(Ctx& x, const MapcParams& p) noexcept;

namespace position_cam {
/// Drop the pending MAPC (its IP cleared): MAS all/position cam, servo off.
void drop_pending(Core& c, AxisRt& a) noexcept;
/// The configuration of the active position cam's master: the units of a
/// master offset move; null without a position cam (ERR 33).
const AxisConfig* master_config(const Core& c, const AxisRt& a) noexcept;
/// Total master offset the active cam sees (finished + running offset moves).
double master_offset(const AxisRt& a) noexcept;
/// A master offset move ended: its distance shifts the cam's master for good.
void add_master_offset(AxisRt& a, double d) noexcept;
/// PositionCam*, MasterOffsetMove* MotionStatus bits.
void status(const AxisRt& a, std::uint32_t& motion_status) noexcept;
}  // namespace position_cam

}  // namespace canmotion::motion
