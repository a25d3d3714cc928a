#include "motion/signatures.hpp"

#include <array>
#include <cmath>

namespace canmotion::motion {
namespace {

using K = OperandKind;
using signature_table::kTable;

constexpr char lower(char c) noexcept { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool iequal(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

}  // namespace

std::optional<Instr> find_instruction(std::string_view name) noexcept {
  for (const auto& s : kTable)
    if (iequal(s.name, name)) return s.id;
  return std::nullopt;
}

std::optional<std::int32_t> find_keyword(std::span<const EnumEntry> e, std::string_view kw) noexcept {
  for (const auto& x : e)
    if (iequal(x.keyword, kw)) return x.value;
  return std::nullopt;
}

bool enum_contains(std::span<const EnumEntry> e, std::int32_t v) noexcept {
  for (const auto& x : e)
    if (x.value == v) return true;
  return false;
}

OperandCheck check_operands(Instr i, std::span<const double> values) noexcept {
  const auto ops = signature(i).operands;
  for (std::size_t k = 0; k < ops.size() && k < values.size(); ++k) {
    const OperandSig& o = ops[k];
    const double v = values[k];
    bool ok = true;
    switch (o.kind) {
      case K::Real:
        ok = std::isfinite(v) && (o.range != Range::Positive || v > 0) && (o.range != Range::NonNegative || v >= 0);
        break;
      case K::Int:
        ok = std::isfinite(v) && v == std::floor(v) &&
             (o.range == Range::Uint32 ? v >= 0 && v <= 4294967295.0 : std::fabs(v) <= 2147483647.0) &&
             (o.range != Range::Positive || v > 0) && (o.range != Range::NonNegative || v >= 0);
        break;
      case K::Enum:
        ok = std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e9 &&
             enum_contains(o.enums, static_cast<std::int32_t>(v));
        break;
      default:
        break;
    }
    if (!ok) return OperandCheck{false, static_cast<int>(k)};
  }
  return OperandCheck{};
}

}  // namespace canmotion::motion
