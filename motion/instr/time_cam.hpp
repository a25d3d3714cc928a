#pragma once
/// \file motion/instr/time_cam.hpp
/// Time cam family: MATC, time driven or master driven (InstructionMode
/// masterdrivenmode through the MDAC link for Time Cam), pending cams, and
/// CamGen, the time cam generator (motion/instr/time_cam.cpp).

#include <cstdint>

#include "motion/cam/cam_motion.hpp"
#include "motion/instr/common.hpp"
#include "motion/master_follow.hpp"

namespace canmotion::motion {

enum class Slot : std::uint8_t;

/// Generator of an MATC: the cam engineer's CamMotion evaluated at cam time,
/// or (master driven) at master travel in the lock direction. O(1) amortised
/// step.
struct CamGen : GenBase {
  cam::CamMotion cm{};
  cam::CamProfile* profile = nullptr;  ///< in use (acquired) while the cam runs
  std::uint64_t t0_cycle = 0;
  double x_offset = 0.0;       ///< cam time = (cycle - t0_cycle) * T - x_offset (pending takeovers)
  std::int64_t last_pass = 0;  ///< pass of the last step (a pending cam waits for its end)
  /// master-driven MATC (InstructionMode masterdrivenmode): cam coordinate =
  /// master travel in the lock direction (md.u - x_offset) instead of time
  bool master_driven = false;
  MasterFollow md{};
  double md_rate = 0.0;            ///< master travel per second in the lock direction, last step
  std::uint64_t md_cycle = ~0ull;  ///< cycle md was last advanced (a takeover steps twice per cycle)

  // generator interface (motion/generator.hpp)
  AxisId master() const noexcept { return master_driven ? md.master : kNoAxis; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core& c, AxisRt& a) noexcept;
};

/// A pending MATC waiting for the end of the current pass (or for an immediate cam).
struct PendingCam {
  cam::CamProfile* profile = nullptr;
  cam::CamMotionConfig cfg{};
  OwnerRef owner{};
  bool master_driven = false;  ///< its InstructionMode: must match the cam it follows [seed 004]
  constexpr bool valid() const noexcept { return profile != nullptr; }
};

struct MatcParams {
  static constexpr Instr kInstr = Instr::MATC;
  AxisId axis = kNoAxis;
  CamDirection direction = CamDirection::Same;
  std::uint16_t cam_profile = 0xFFFF;
  double distance_scaling = 1.0, time_scaling = 1.0;
  std::uint8_t execution_mode = 0;      ///< cam::ExecutionMode: 0 once, 1 continuous
  std::uint8_t execution_schedule = 0;  ///< schedule::Immediate or schedule::Pending
  double lock_position = 0.0;
  LockDirection lock_direction = LockDirection::None;
  bool master_driven = false;  ///< InstructionMode 1
  static MatcParams decode(const Operands& q) noexcept;
};
using TimeCamInstructions = TypeList<MatcParams>;

Err start(Ctx& x, const MatcParams& p) noexcept;

namespace time_cam {
/// Drop the pending MATC (its IP cleared): MAS all/time cam, servo off.
void drop_pending(Core& c, AxisRt& a) noexcept;
}  // namespace time_cam

}  // namespace canmotion::motion
