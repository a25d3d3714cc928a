#pragma once
/// \file motion/control_tag.hpp
/// MOTION_INSTRUCTION: the control tag every motion instruction writes
/// (reference section 1.2). Bit numbers are the Logix FLAGS bits.

#include <cstdint>

#include "motion/types.hpp"

namespace canmotion::motion {

/// FLAGS bit numbers of MOTION_INSTRUCTION.
namespace flag {
inline constexpr unsigned EN = 31;
inline constexpr unsigned DN = 29;
inline constexpr unsigned ER = 28;
inline constexpr unsigned PC = 27;
inline constexpr unsigned IP = 26;
inline constexpr unsigned AC = 23;
inline constexpr unsigned TrackingMaster = 2;
inline constexpr unsigned CalculatedDataAvailable = 3;
inline constexpr unsigned DECEL = 1;
inline constexpr unsigned ACCEL = 0;
}  // namespace flag

/// One MOTION_INSTRUCTION tag. Realtime-safe plain data.
struct ControlTag {
  std::uint32_t flags = 0;
  std::int16_t err = 0;
  std::int8_t status = 0;
  std::int8_t state = 0;
  std::int32_t segment = 0;
  std::int8_t exerr = 0;
  /// Incremented on every false-to-true transition (execution) of the
  /// instruction using this tag; lets generators notice that their tag was
  /// reused by a newer execution. Not a Logix member.
  std::uint32_t generation = 0;

  constexpr bool get(unsigned bit) const noexcept { return (flags >> bit) & 1u; }
  constexpr void set(unsigned bit, bool on) noexcept {
    if (on) flags |= (1u << bit); else flags &= ~(1u << bit);
  }
  constexpr bool en() const noexcept { return get(flag::EN); }
  constexpr bool dn() const noexcept { return get(flag::DN); }
  constexpr bool er() const noexcept { return get(flag::ER); }
  constexpr bool pc() const noexcept { return get(flag::PC); }
  constexpr bool ip() const noexcept { return get(flag::IP); }
  constexpr bool ac() const noexcept { return get(flag::AC); }
  constexpr bool accel() const noexcept { return get(flag::ACCEL); }
  constexpr bool decel() const noexcept { return get(flag::DECEL); }
  constexpr Err error() const noexcept { return static_cast<Err>(err); }

  /// One ST execution = one false-to-true rung transition: EN set, DN, ER, PC,
  /// IP, AC, ACCEL, DECEL cleared, ERR/EXERR/STATE zeroed.
  constexpr void begin_execution() noexcept {
    flags = (1u << flag::EN);
    err = 0; exerr = 0; state = 0; segment = 0; status = 0;
    ++generation;
  }
  /// Reject the execution: ER with the code (and operand index for ERR 13).
  constexpr void reject(Err e, std::int8_t ext = 0) noexcept {
    set(flag::ER, true);
    err = static_cast<std::int16_t>(e);
    exerr = ext;
  }
};

/// Index of a control tag in the planner (assigned by the configuration).
using ControlId = std::uint16_t;
/// Index of an axis in the planner.
using AxisId = std::uint16_t;
inline constexpr ControlId kNoControl = 0xFFFF;
inline constexpr AxisId kNoAxis = 0xFFFF;

/// What the planner keeps of the execution that started something (a
/// generator, a handshake, an MDAC link, a pending cam): the control tag and
/// its generation at that execution. A newer execution of the same tag makes
/// the reference stale: the planner then no longer writes the tag.
struct OwnerRef {
  ControlId id = kNoControl;
  std::uint32_t gen = 0;
  constexpr bool valid() const noexcept { return id != kNoControl; }
  friend constexpr bool operator==(const OwnerRef&, const OwnerRef&) noexcept = default;
};

}  // namespace canmotion::motion
