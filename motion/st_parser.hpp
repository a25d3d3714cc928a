#pragma once
/// \file motion/st_parser.hpp
/// Parser for one Logix Structured Text motion instruction call, e.g.
///   MAM(X, mam1, 0, 100, 50, unitspersec, 500, unitspersec2, 500,
///       unitspersec2, trapezoidal, 100, 100, %oftime, disabled, 0, 0, 0, 0, 0);
/// and the binder that turns the parsed call into a planner Request (names ->
/// ids, numeric tags -> values). Both read THE signature table
/// (motion/signatures.hpp). NOT realtime: they allocate (strings, vectors);
/// run them on the command thread and pass the Request through a ring.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "motion/planner.hpp"
#include "motion/signatures.hpp"

namespace canmotion::motion {

/// One operand as written.
struct StOperand {
  enum class Kind : std::uint8_t { Number, Keyword, Tag };
  Kind kind = Kind::Number;
  double number = 0.0;          ///< Number: the literal; Keyword: the enumeration value
  bool integer = false;         ///< Number: written without fraction or exponent
  std::string text;             ///< as written (tag name without the index)
  std::optional<long> index;    ///< Tag: [index] if given
  std::size_t column = 0;       ///< 1-based column in the source
};

/// A syntactically valid call whose operands match the signature.
struct ParsedCall {
  Instr instr = Instr::MSO;
  std::vector<StOperand> operands;
};

/// Parse error: a message naming the instruction, the operand index and name,
/// what was found and what is allowed; plus the 1-based column.
struct ParseError {
  std::string message;
  std::size_t column = 0;
};

/// Parse result: exactly one of call / error.
struct ParseResult {
  std::optional<ParsedCall> call;
  ParseError error;
  bool ok() const noexcept { return call.has_value(); }
};

/// Parse one ST call (a trailing ';' is optional; surrounding whitespace and
/// (* comments *) / // comments are ignored). Not realtime.
ParseResult parse_st_call(std::string_view text);

/// Case-insensitive name -> id tables and numeric tag values used for binding.
struct Symbols {
  struct Less {
    bool operator()(const std::string& a, const std::string& b) const noexcept;
  };
  std::map<std::string, AxisId, Less> axes;
  std::map<std::string, ControlId, Less> controls;
  std::map<std::string, std::uint16_t, Less> groups;
  std::map<std::string, std::uint16_t, Less> coordinate_systems;
  std::map<std::string, std::uint16_t, Less> cams;          ///< CAM[] arrays
  std::map<std::string, std::uint16_t, Less> cam_profiles;  ///< CAM_PROFILE[] arrays
  std::map<std::string, std::uint16_t, Less> real_arrays;   ///< REAL[] arrays
  std::map<std::string, double, Less> numeric_tags;         ///< current values of numeric tags
};

/// Bind a parsed call: resolve tag names. Returns an error message naming the
/// operand on failure. Cam operands: ref = cam id; CamArray also stores the
/// first point index in `value`. Not realtime.
std::optional<std::string> bind_call(const ParsedCall& call, const Symbols& sym, Request& out);

/// Convenience: parse and bind in one step; the error message is returned on failure.
std::optional<std::string> parse_and_bind(std::string_view text, const Symbols& sym, Request& out);

}  // namespace canmotion::motion
