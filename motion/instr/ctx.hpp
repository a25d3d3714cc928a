#pragma once
/// \file motion/instr/ctx.hpp
/// Ctx: one execution of an instruction, as its family's start() sees it.

#include <cstdint>

#include "motion/core.hpp"
#include "motion/units.hpp"

namespace canmotion::motion {

struct Ctx {
  Core& c;             ///< the planner
  const Request& r;    ///< the execution (operands already decoded into the params)
  ControlTag& tag;     ///< its control tag (EN set, the rest cleared: ControlTag::begin_execution)
  OwnerRef self;       ///< owner reference of what this execution starts (generators, handshakes, links)
  std::int8_t exerr = 0;  ///< EXERR written with a non-zero ERR

  AxisRt& axis(AxisId id) noexcept { return c.axes[id]; }

  /// ERR 13 Parameter Out Of Range with the operand's index in EXERR
  /// (e.g. `return x.reject_operand(op<Instr::MAM>("Position"));`).
  Err reject_operand(int operand) noexcept {
    exerr = static_cast<std::int8_t>(operand);
    return Err::ParameterOutOfRange;
  }
  /// The error of a check, or Err::None (EXERR = its operand for ERR 13).
  Err check(const units::Checked& result) noexcept {
    if (result.err == Err::ParameterOutOfRange) exerr = static_cast<std::int8_t>(result.operand);
    return result.err;
  }
  /// The value of a converted operand into `out`, or its error (EXERR = its
  /// operand for ERR 13).
  Err take(const units::Converted& v, double& out) noexcept {
    if (!v.ok()) return check(units::Checked{v.err, v.operand});
    out = v.value;
    return Err::None;
  }
};

}  // namespace canmotion::motion
