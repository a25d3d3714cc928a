#pragma once
/// \file motion/instr/common.hpp
/// What every instruction family header uses: the operand reader and the
/// planner state types it names (defined in motion/core.hpp and
/// motion/generator.hpp, below the families).

#include "motion/control_tag.hpp"
#include "motion/operands.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

struct Ctx;     // motion/instr/ctx.hpp: one execution of an instruction
struct Core;    // motion/core.hpp: the planner's state
struct AxisRt;  // motion/core.hpp: one axis in the planner
struct ProfileGen;  // motion/generator.hpp: moves, jogs and stop ramps

}  // namespace canmotion::motion
