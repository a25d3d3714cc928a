#pragma once
/// \file motion/instr/stop.hpp
/// Stop family: MAS, and the group instructions MGS, MGSD, MGSR
/// (motion/instr/stop.cpp). The stop ramps themselves are ProfileGens
/// (Core::stop_slots).

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct MasParams {
  static constexpr Instr kInstr = Instr::MAS;
  AxisId axis = kNoAxis;
  StopType stop_type = StopType::All;
  bool change_decel = false;
  double decel_rate = 0.0;
  AccelUnits decel_units = AccelUnits::UnitsPerSec2;
  bool change_decel_jerk = false;
  double decel_jerk = 0.0;
  JerkUnits jerk_units = JerkUnits::UnitsPerSec3;
  static MasParams decode(const Operands& q) noexcept;
};

struct MgsParams {
  static constexpr Instr kInstr = Instr::MGS;
  std::uint16_t group = 0;
  GroupStopMode mode = GroupStopMode::Programmed;
  static MgsParams decode(const Operands& q) noexcept;
};
struct MgsdParams {
  static constexpr Instr kInstr = Instr::MGSD;
  std::uint16_t group = 0;
  static MgsdParams decode(const Operands& q) noexcept;
};
struct MgsrParams {
  static constexpr Instr kInstr = Instr::MGSR;
  std::uint16_t group = 0;
  static MgsrParams decode(const Operands& q) noexcept;
};
using StopInstructions = TypeList<MasParams, MgsParams, MgsdParams, MgsrParams>;

Err start(Ctx& x, const MasParams& p) noexcept;
Err start(Ctx& x, const MgsParams& p) noexcept;
Err start(Ctx& x, const MgsdParams& p) noexcept;
Err start(Ctx& x, const MgsrParams& p) noexcept;

namespace stop {
/// Once per cycle, after the axes stepped: an MGS whose ramps all ended gets
/// PC (IP cleared).
void finish_group_stops(Core& c) noexcept;
/// Stop one axis the way a Programmed Stop Mode says (MGS, a controller mode
/// change): homing cancelled, its MDAC links broken, then a ramp at the
/// maximum decel (owned by `owner`, followed by servo off or shutdown for the
/// Fast modes) or at once (Hard modes). True when a ramp runs.
bool programmed_stop(Core& c, AxisRt& a, ProgrammedStopMode m, ControlId owner) noexcept;
/// A controller mode change (Run <-> Program, Planner::set_controller_mode):
/// every MDAC link is broken (both directions [seed 000]); into Program mode
/// every axis also stops by its Programmed Stop Mode, pending cams dropped
/// (cam motion stops when the controller changes modes [seed 004]).
void change_mode(Core& c, bool program) noexcept;
}  // namespace stop

}  // namespace canmotion::motion
