#pragma once
/// \file motion/instr/position_cam.hpp
/// Position cam family: MAPC, pending position cams (PendingPosCam,
/// motion/core.hpp), the master offset moves (MAM MoveType 5/6, started by
/// the move family in Slot::MasterOffset) and the step of PosCamGen, the
/// position cam generator (motion/generator.hpp), in
/// motion/instr/position_cam.cpp.

#include <cstdint>

#include "motion/axis.hpp"
#include "motion/instr/common.hpp"

namespace canmotion::motion {

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
}  // namespace position_cam

}  // namespace canmotion::motion
