#pragma once
/// \file motion/signatures.hpp
/// THE table of motion instruction signatures: operand order, names, kinds,
/// enumerations (ST keyword and number) and basic ranges. Both the ST call
/// parser (motion/st_parser.hpp) and the planner's operand validation
/// (ERR 13 with the operand index in EXERR) read it; nothing else spells out
/// an operand list. Constant data; realtime-safe.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace canmotion::motion {

/// Every instruction the ST parser accepts (reference scope, 26 instructions).
enum class Instr : std::uint8_t {
  MSO, MSF, MASD, MASR, MAFR, MAS, MAH, MAJ, MAM, MAG, MCD, MRP, MCCP, MAPC,
  MATC, MDAC, MDS, MGS, MGSD, MGSR, MCLM, MCCM, MCS, MCSD, MCCD, MDCC,
  Count
};
inline constexpr std::size_t kInstrCount = static_cast<std::size_t>(Instr::Count);

/// Largest operand count of any instruction (MCCM: 25).
inline constexpr std::size_t kMaxOperands = 25;

/// What an operand is in ST.
enum class OperandKind : std::uint8_t {
  Axis,         ///< axis tag name
  Control,      ///< MOTION_INSTRUCTION tag name
  Group,        ///< MOTION_GROUP tag name
  CoordSystem,  ///< COORDINATE_SYSTEM tag name
  CamArray,     ///< CAM[] element, e.g. cam1[0] (index = first point)
  CamProfile,   ///< CAM_PROFILE[] element; must be [0]
  Real,         ///< REAL immediate or numeric tag
  Int,          ///< DINT immediate or numeric tag (integral value)
  Enum,         ///< enumeration: keyword (case-insensitive) or its number
  RealArray,    ///< REAL[] tag, or the literal 0 for "none"
};

/// Basic value rule checked for every execution (ERR 13 when violated).
/// Instruction-specific conditional rules (e.g. "jerk > 0 only for S-curve")
/// are checked by the instruction's start().
enum class Range : std::uint8_t {
  Any,          ///< any finite value
  Positive,     ///< > 0
  NonNegative,  ///< >= 0
};

/// One enumeration entry: ST keyword (lower case, spaces removed) and number.
struct EnumEntry {
  std::string_view keyword;
  std::int32_t value;
};

/// One operand of an instruction.
struct OperandSig {
  std::string_view name;
  OperandKind kind;
  std::span<const EnumEntry> enums{};  ///< for Enum operands
  Range range = Range::Any;
  bool tag_allowed = true;  ///< Real/Int/Enum: may be given as a numeric tag
};

/// One instruction.
struct InstrSig {
  Instr id;
  std::string_view name;
  std::span<const OperandSig> operands;
  bool executable;  ///< the planner runs it (else it is parsed and rejected with ERR 75)
};

/// Signature of an instruction. Realtime-safe.
const InstrSig& signature(Instr i) noexcept;
/// Find an instruction by name, case-insensitive. Realtime-safe.
std::optional<Instr> find_instruction(std::string_view name) noexcept;
/// Keyword lookup in an enumeration, case-insensitive. Realtime-safe.
std::optional<std::int32_t> find_keyword(std::span<const EnumEntry> e, std::string_view kw) noexcept;
/// True if `v` is one of the enumeration's numbers. Realtime-safe.
bool enum_contains(std::span<const EnumEntry> e, std::int32_t v) noexcept;
/// Index of the operand called `name` in instruction `i` (compile-time helper
/// for the planner; -1 if absent). Realtime-safe.
int operand_index(Instr i, std::string_view name) noexcept;

/// Result of checking one operand value against the table.
struct OperandCheck {
  bool ok = true;
  int index = -1;  ///< first offending operand (ST index, = EXERR for ERR 13)
};
/// Check numeric operand values (indexed by ST operand position; non-numeric
/// operands are skipped) against enumerations and ranges. Realtime-safe.
OperandCheck check_operands(Instr i, std::span<const double> values) noexcept;

}  // namespace canmotion::motion
