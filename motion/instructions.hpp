#pragma once
/// \file motion/instructions.hpp
/// Typed parameters of every motion instruction ("params" of the instruction
/// shape params / start / generator). Each instruction family
/// (motion/instr/<family>.hpp) declares its params structs, with their
/// instruction (`kInstr`) and `decode()`, and lists them; `Params` is the
/// closed variant of all of them. `decode()` turns a Request whose operands
/// passed the signature table check into its params; Planner::execute hands
/// them to the family's `start(Ctx&, const XParams&)` with one std::visit (an
/// instruction without a start overload does not compile). Realtime-safe.

#include <variant>

#include "motion/instr/coord.hpp"
#include "motion/instr/direct.hpp"
#include "motion/instr/gear.hpp"
#include "motion/instr/home.hpp"
#include "motion/instr/mccp.hpp"
#include "motion/instr/mdac.hpp"
#include "motion/instr/move.hpp"
#include "motion/instr/position_cam.hpp"
#include "motion/instr/servo.hpp"
#include "motion/instr/stop.hpp"
#include "motion/instr/time_cam.hpp"
#include "motion/io.hpp"

namespace canmotion::motion {

/// An instruction the signature table marks not executable (the coordinated
/// MCLM, MCCM, MCS, MCSD, MCCD, MDCC): parsed and validated, answered with
/// ERR 75 (Instruction Not Supported).
struct NotExecutableParams {
  Instr instr = Instr::MCLM;
};
Err start(Ctx& x, const NotExecutableParams& p) noexcept;

namespace detail {
template <class... L>
struct ParamsOf;
template <class... A>
struct ParamsOf<TypeList<A...>> {
  using type = std::variant<A..., NotExecutableParams>;
};
template <class... A, class... B, class... R>
struct ParamsOf<TypeList<A...>, TypeList<B...>, R...> : ParamsOf<TypeList<A..., B...>, R...> {};
}  // namespace detail

/// The closed set of instruction parameters: every family's list.
using Params = detail::ParamsOf<ServoInstructions, HomeInstructions, MoveInstructions, StopInstructions,
                                GearInstructions, TimeCamInstructions, PositionCamInstructions, MdacInstructions,
                                DirectInstructions, MccpInstructions, CoordInstructions>::type;

/// Decode a request (operand count and values already checked against the
/// signature table). Realtime-safe.
Params decode(const Request& r) noexcept;

}  // namespace canmotion::motion
