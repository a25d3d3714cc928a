#pragma once
/// \file motion/generator.hpp
/// Generators: the running motion of an axis, one per slot, superposed.
///
/// A generator type G (ProfileGen, GearGen, CamGen, PosCamGen) derives from
/// GenBase (its output `k`, an offset added to the axis command, and its
/// `owner`) and has:
///   AxisId master() const;            // the axis it follows, or kNoAxis (step order: masters first)
///   void step(Core&, AxisRt&, Slot);  // advance one cycle: set k; may fold itself or hand its slot over
///   void on_fold(Core&, AxisRt&);     // it ends: release what it holds (cam profile, MDAC AC, ...)
/// The planner reaches them only through one std::visit (with_generator(),
/// gen_base(), master_of()): a new generator type is one more alternative of
/// `Generator` and these four members. A generator may take its output from
/// state shared by several axes (its step reads it through Core), e.g. a
/// path of a coordinate system stepped once per cycle.

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <variant>

#include "motion/instr/coord.hpp"
#include "motion/instr/gear.hpp"
#include "motion/instr/move.hpp"
#include "motion/instr/position_cam.hpp"
#include "motion/instr/time_cam.hpp"

namespace canmotion::motion {

/// Per-axis generator slots, in step order. Generators superpose: the command
/// position is base + the sum of the slot offsets. The master offset move
/// (master units, it shifts the position cam's master) steps before the
/// position cam and is not part of the sum. Bound: one slot per kind of
/// motion Logix can run at the same time on one axis (move, jog, gear, time
/// cam, master offset move, position cam) plus one for a stop of all motion,
/// and one for the member's share of a coordinate system's path (issue 14).
enum class Slot : std::uint8_t { Move = 0, Jog, Gear, TimeCam, MasterOffset, PositionCam, StopAll, Coord, Count };
inline constexpr std::size_t kSlots = static_cast<std::size_t>(Slot::Count);
constexpr std::size_t index(Slot s) noexcept { return static_cast<std::size_t>(s); }
/// Bit of a slot in AxisRt::live and in stop masks.
constexpr std::uint32_t slot_bit(Slot s) noexcept { return 1u << index(s); }
/// Every slot (MAS All, MGS, exception stops).
inline constexpr std::uint32_t kAllSlots = (1u << kSlots) - 1u;

/// The slots in the order of their numbers before the master offset move's
/// slot was put ahead of the position cam's (issue 13). The two loops whose
/// results depend on the slot order without stepping use it, so that the
/// results stay as they were: the speed an MAS stops from (a floating-point
/// sum) and the order in which the step-order walk visits masters.
inline constexpr std::array<Slot, kSlots> kLegacySlotOrder{Slot::Move, Slot::Jog, Slot::Gear, Slot::TimeCam,
                                                           Slot::PositionCam, Slot::MasterOffset, Slot::StopAll,
                                                           Slot::Coord};
static_assert([] {
  std::uint32_t seen = 0;
  for (const Slot s : kLegacySlotOrder) seen |= slot_bit(s);
  return seen == (1u << kSlots) - 1u;
}(), "kLegacySlotOrder lists every slot once (a new slot goes into it too)");

/// The closed set of generator states.
using Generator = std::variant<std::monostate, ProfileGen, GearGen, CamGen, PosCamGen, CoordGen>;

/// Call f(generator) with the generator `g` holds (nothing for an empty slot).
template <class F>
inline void with_generator(Generator& g, F&& f) noexcept {
  std::visit(
      [&](auto& x) noexcept {
        if constexpr (!std::is_same_v<std::decay_t<decltype(x)>, std::monostate>) f(x);
      },
      g);
}

/// The output and owner of the generator `g` holds, or null for an empty slot.
inline GenBase* gen_base(Generator& g) noexcept {
  return std::visit(
      [](auto& x) noexcept -> GenBase* {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::monostate>) return nullptr;
        else return &x;
      },
      g);
}
inline const GenBase* gen_base(const Generator& g) noexcept { return gen_base(const_cast<Generator&>(g)); }

/// The axis the generator in `g` follows, or kNoAxis.
inline AxisId master_of(const Generator& g) noexcept {
  return std::visit(
      [](const auto& x) noexcept -> AxisId {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::monostate>) return kNoAxis;
        else return x.master();
      },
      g);
}

}  // namespace canmotion::motion
