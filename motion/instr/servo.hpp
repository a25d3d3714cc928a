#pragma once
/// \file motion/instr/servo.hpp
/// Servo family: MSO, MSF, MASD, MASR, MAFR, and the MSO/MSF enable
/// handshakes with an AXIS_CIP_DRIVE (motion/instr/servo.cpp).

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct MsoParams {
  static constexpr Instr kInstr = Instr::MSO;
  AxisId axis = kNoAxis;
  static MsoParams decode(const Operands& q) noexcept;
};
struct MsfParams {
  static constexpr Instr kInstr = Instr::MSF;
  AxisId axis = kNoAxis;
  static MsfParams decode(const Operands& q) noexcept;
};
struct MasdParams {
  static constexpr Instr kInstr = Instr::MASD;
  AxisId axis = kNoAxis;
  static MasdParams decode(const Operands& q) noexcept;
};
struct MasrParams {
  static constexpr Instr kInstr = Instr::MASR;
  AxisId axis = kNoAxis;
  static MasrParams decode(const Operands& q) noexcept;
};
struct MafrParams {
  static constexpr Instr kInstr = Instr::MAFR;
  AxisId axis = kNoAxis;
  static MafrParams decode(const Operands& q) noexcept;
};
using ServoInstructions = TypeList<MsoParams, MsfParams, MasdParams, MasrParams, MafrParams>;

Err start(Ctx& x, const MsoParams& p) noexcept;
Err start(Ctx& x, const MsfParams& p) noexcept;
Err start(Ctx& x, const MasdParams& p) noexcept;
Err start(Ctx& x, const MasrParams& p) noexcept;
Err start(Ctx& x, const MafrParams& p) noexcept;

namespace servo {
/// Clear the latched faults and pulse a drive fault reset (MAFR, MASR, MGSR
/// executed as `owner`, an `instr`). Returns whether the reset is done; not
/// when a CIP drive still has to leave Fault or reconnect: then `owner`
/// waits in ServoState::reset (a different execution waiting there gets ERR
/// 12), at most AxisConfig::drive_wait_limit.
bool reset_faults(Core& c, AxisRt& a, OwnerRef owner, Instr instr) noexcept;
/// A waiting fault reset, each cycle after the pulse went out (CIP axes,
/// after the feedback was read): DN when the drive left Fault and is
/// connected (MGSR: with the group's last axis); ERR 12 EXERR 16 when the
/// link failed, on a transition timeout or after AxisConfig::drive_wait_limit.
void reset_feedback(Core& c, AxisRt& a) noexcept;
/// The MSO / MSF handshakes, each cycle while one waits (CIP axes, after the
/// feedback was read): DN on Operation Enabled (MSO) or when the drive left
/// it (MSF); ERR 12 EXERR 16 on a fault, a failed link, a transition timeout
/// or after AxisConfig::drive_wait_limit (Core::end_drive_wait records it).
void feedback(Core& c, AxisRt& a) noexcept;
}  // namespace servo

}  // namespace canmotion::motion
