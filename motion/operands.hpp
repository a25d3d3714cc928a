#pragma once
/// \file motion/operands.hpp
/// Typed read access to the operands of a request that passed the signature
/// table check, by ST position. Positions come from the signature table at
/// compile time: `q.real(op<Instr::MAM>("Position"))`. Realtime-safe.

#include <cstddef>
#include <cstdint>

#include "motion/io.hpp"
#include "motion/signatures.hpp"

namespace canmotion::motion {

/// A list of types (the params of an instruction family).
template <class... T>
struct TypeList {};

struct Operands {
  const Request& r;
  /// Real / Int / Enum operands: the value (enumerations as their number).
  double real(int i) const noexcept { return r.op[static_cast<std::size_t>(i)].value; }
  /// Axis, Group, Cam, CamProfile, RealArray operands: the id (0xFFFF: none).
  std::uint16_t ref(int i) const noexcept { return r.op[static_cast<std::size_t>(i)].ref; }
  std::int32_t integer(int i) const noexcept { return static_cast<std::int32_t>(real(i)); }
  /// An enumeration's number.
  std::uint8_t number(int i) const noexcept { return static_cast<std::uint8_t>(static_cast<int>(real(i))); }
  /// An enumeration {no, yes} (or another whose second entry means "yes").
  bool yes(int i) const noexcept { return static_cast<int>(real(i)) == 1; }
  /// An enumeration as its typed enum (the signature table checked the number).
  template <class E>
  E enumeration(int i) const noexcept { return static_cast<E>(number(i)); }
};

}  // namespace canmotion::motion
