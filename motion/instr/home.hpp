#pragma once
/// \file motion/instr/home.hpp
/// Home family: MAH (immediate, or drive homing in CiA 402 mode 6) and MRP
/// (motion/instr/home.cpp).

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct AxisOutput;

struct MahParams {
  static constexpr Instr kInstr = Instr::MAH;
  AxisId axis = kNoAxis;
  static MahParams decode(const Operands& q) noexcept;
};
struct MrpParams {
  static constexpr Instr kInstr = Instr::MRP;
  AxisId axis = kNoAxis;
  bool relative = false;  ///< Type 1
  bool command = false;   ///< PositionSelect 1
  double position = 0.0;
  static MrpParams decode(const Operands& q) noexcept;
};
using HomeInstructions = TypeList<MahParams, MrpParams>;

Err start(Ctx& x, const MahParams& p) noexcept;
Err start(Ctx& x, const MrpParams& p) noexcept;

namespace home {
/// End drive homing (MAS, MGS): IP of the MAH cleared.
void cancel(Core& c, AxisRt& a) noexcept;
/// Drive homing, each cycle while it runs (after the feedback was read):
/// homing attained sets the frame offset (actual = Home Position), homed,
/// PC; a homing error gives ERR 12 EXERR 16.
void feedback(Core& c, AxisRt& a) noexcept;
/// While homing: the homing objects for the drive (mode 6).
void output(AxisRt& a, AxisOutput& out) noexcept;
}  // namespace home

}  // namespace canmotion::motion
