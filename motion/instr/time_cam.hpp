#pragma once
/// \file motion/instr/time_cam.hpp
/// Time cam family: MATC, time driven or master driven (InstructionMode
/// masterdrivenmode through the MDAC link for Time Cam), pending cams
/// (PendingCam, motion/core.hpp), and the step of CamGen, the time cam
/// generator (motion/generator.hpp), in motion/instr/time_cam.cpp.

#include <cstdint>

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct MatcParams {
  static constexpr Instr kInstr = Instr::MATC;
  AxisId axis = kNoAxis;
  CamDirection direction = CamDirection::Same;
  std::uint16_t cam_profile = 0xFFFF;
  double distance_scaling = 1.0, time_scaling = 1.0;
  std::uint8_t execution_mode = 0;      ///< cam::ExecutionMode: 0 once, 1 continuous
  std::uint8_t execution_schedule = 0;  ///< schedule::Immediate or schedule::Pending
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  bool master_driven = false;  ///< InstructionMode 1
  static MatcParams decode(const Operands& q) noexcept;
};
using TimeCamInstructions = TypeList<MatcParams>;

Err start(Ctx& x, const MatcParams& p) noexcept;

namespace time_cam {
/// Drop the pending MATC (its IP cleared): MAS all/time cam, servo off.
void drop_pending(Core& c, AxisRt& a) noexcept;
}  // namespace time_cam

}  // namespace canmotion::motion
