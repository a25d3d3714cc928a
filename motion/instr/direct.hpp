#pragma once
/// \file motion/instr/direct.hpp
/// Direct family: MDS (Motion Drive Start), direct velocity or torque control
/// of an AXIS_CIP_DRIVE: the drive enable handshake, the live command and
/// what the runtime sends (motion/instr/direct.cpp).

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct AxisOutput;

struct MdsParams {
  static constexpr Instr kInstr = Instr::MDS;
  AxisId axis = kNoAxis;
  double speed = 0.0;
  bool percent_of_maximum = false;  ///< SpeedUnits 0 (seed numbering)
  static MdsParams decode(const Operands& q) noexcept;
};
using DirectInstructions = TypeList<MdsParams>;

Err start(Ctx& x, const MdsParams& p) noexcept;

namespace direct {
/// End direct control: the MDS's IP cleared, the command zeroed; with
/// `keep_status` (MAS) DirectControlStatus stays until standstill.
void end(Core& c, AxisRt& a, bool keep_status) noexcept;
/// An MAS stopping direct motion: IP, then PC at standstill (the drive ramps).
void begin_stop(Core& c, AxisRt& a, OwnerRef mas) noexcept;
/// Each cycle while an MDS waits for the drive enable or an MAS waits for
/// standstill (after the feedback was read).
void feedback(Core& c, AxisRt& a) noexcept;
/// Under direct control: CSV or CST, the command as the target.
void output(const AxisRt& a, AxisOutput& out) noexcept;
/// The program writes the direct command (velocity or torque) / the SLAT
/// velocity command (torque mode). False if not under an active MDS.
bool set_command(Core& c, AxisId id, double value) noexcept;
bool set_velocity_command(Core& c, AxisId id, double value) noexcept;
}  // namespace direct

}  // namespace canmotion::motion
