#pragma once
/// \file motion/instr/mccp.hpp
/// MCCP (Motion Calculate Cam Profile) as a planner instruction
/// (motion/instr/mccp.cpp; the calculation is motion/cam).

#include <cstdint>

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct MccpParams {
  static constexpr Instr kInstr = Instr::MCCP;
  std::uint16_t cam = 0xFFFF;
  std::int32_t first_point = 0;
  std::int32_t length = 0;
  double start_slope = 0.0, end_slope = 0.0;
  std::uint16_t cam_profile = 0xFFFF;
  static MccpParams decode(const Operands& q) noexcept;
};
using MccpInstructions = TypeList<MccpParams>;

Err start(Ctx& x, const MccpParams& p) noexcept;

}  // namespace canmotion::motion
