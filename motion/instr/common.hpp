#pragma once
/// \file motion/instr/common.hpp
/// What every instruction family header uses: the operand reader, the
/// planner state types it names (defined in motion/core.hpp), and GenBase,
/// the part every generator shares.

#include "motion/control_tag.hpp"
#include "motion/operands.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

struct Ctx;     // motion/instr/ctx.hpp: one execution of an instruction
struct Core;    // motion/core.hpp: the planner's state
struct AxisRt;  // motion/core.hpp: one axis in the planner

/// What every generator has (motion/generator.hpp): its output, an offset
/// added to the axis command, and the execution that owns it.
struct GenBase {
  Kin k{};           ///< position (offset), velocity, acceleration after the last step
  OwnerRef owner{};  ///< the control tag it writes (IP, PC, ACCEL, DECEL, ...)
};

}  // namespace canmotion::motion
