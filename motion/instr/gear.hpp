#pragma once
/// \file motion/instr/gear.hpp
/// Gear family: MAG and GearGen, the electronic gearing generator
/// (motion/instr/gear.cpp).

#include <cstdint>

#include "motion/instr/common.hpp"

namespace canmotion::motion {

enum class Slot : std::uint8_t;

/// Generator of an MAG: the slave offset follows the master position (drive
/// frame) at the ratio; O(1) step. No axis limits apply.
struct GearGen : GenBase {
  AxisId master_id = kNoAxis;
  bool use_actual = false;     ///< master reference actual (CIP masters only)
  bool fractional = false;     ///< RatioFormat fraction: exact integer counts
  double ratio = 1.0;          ///< signed real ratio, direction included
  std::int64_t slave_counts = 1, master_counts = 1;  ///< signed fraction, direction included
  double cc_master = 1.0, cc_slave = 1.0;            ///< conversion constants (counts/unit)
  bool locked = false;         ///< GearingLockStatus
  double clutch_accel = 0.0;   ///< units/s^2 while clutching
  double master_ref = 0.0;     ///< master position at lock (units, drive frame)
  std::int64_t master_ref_counts = 0;
  double offset_at_lock = 0.0;

  // generator interface (motion/generator.hpp); gear ramps are trapezoidal
  AxisId master() const noexcept { return master_id; }
  void step(Core& c, AxisRt& a, Slot s) noexcept;
  void on_fold(Core&, AxisRt&) noexcept {}
};

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
