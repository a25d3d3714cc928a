#pragma once
/// \file motion/instr/gear.hpp
/// Gear family: MAG, and the step of GearGen, the electronic gearing
/// generator (motion/generator.hpp), in motion/instr/gear.cpp.

#include <cstdint>

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct MagParams {
  static constexpr Instr kInstr = Instr::MAG;
  AxisId slave = kNoAxis, master = kNoAxis;
  CamDirection direction = CamDirection::Same;
  double ratio = 1.0;
  double slave_counts = 1.0, master_counts = 1.0;
  MasterReference master_reference = MasterReference::Actual;
  bool fractional = false;  ///< RatioFormat 1
  bool clutch = false;      ///< Clutch 0 = enabled
  double accel_rate = 0.0;
  AccelUnits accel_units = AccelUnits::UnitsPerSec2;
  static MagParams decode(const Operands& q) noexcept;
};
using GearInstructions = TypeList<MagParams>;

Err start(Ctx& x, const MagParams& p) noexcept;

}  // namespace canmotion::motion
