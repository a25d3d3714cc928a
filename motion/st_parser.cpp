#include "motion/st_parser.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

namespace canmotion::motion {
namespace {

char lower(char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

bool ident_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == '%'; }
bool ident_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '%' || c == '.' || c == ':';
}

std::string kind_text(OperandKind k) {
  switch (k) {
    case OperandKind::Axis: return "an axis tag name";
    case OperandKind::Control: return "a MOTION_INSTRUCTION tag name";
    case OperandKind::Group: return "a MOTION_GROUP tag name";
    case OperandKind::CoordSystem: return "a COORDINATE_SYSTEM tag name";
    case OperandKind::CamArray: return "a CAM array element such as cam1[0]";
    case OperandKind::CamProfile: return "a CAM_PROFILE array element [0] such as profile1[0]";
    case OperandKind::Real: return "a REAL literal or numeric tag";
    case OperandKind::Int: return "an integer literal or numeric tag";
    case OperandKind::Enum: return "an enumeration";
    case OperandKind::RealArray: return "a REAL array tag or 0";
  }
  return "?";
}

std::string allowed_enum(const OperandSig& o) {
  std::ostringstream os;
  std::int32_t last = -1000000;
  bool first = true;
  for (const auto& e : o.enums) {
    os << (first ? "" : ", ") << e.keyword << (e.value == last ? "" : "") << " (" << e.value << ")";
    last = e.value;
    first = false;
  }
  if (o.tag_allowed) os << ", or a numeric tag";
  return os.str();
}

std::string found_text(const StOperand& op) {
  std::ostringstream os;
  switch (op.kind) {
    case StOperand::Kind::Number: os << "number " << op.text; break;
    case StOperand::Kind::Keyword:
    case StOperand::Kind::Tag:
      os << "'" << op.text;
      if (op.index) os << "[" << *op.index << "]";
      os << "'";
      break;
  }
  return os.str();
}

struct Lexer {
  std::string_view s;
  std::size_t i = 0;
  void skip() {
    for (;;) {
      while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
      if (i + 1 < s.size() && s[i] == '(' && s[i + 1] == '*') {
        const auto e = s.find("*)", i + 2);
        i = e == std::string_view::npos ? s.size() : e + 2;
        continue;
      }
      if (i + 1 < s.size() && s[i] == '/' && s[i + 1] == '/') {
        const auto e = s.find('\n', i);
        i = e == std::string_view::npos ? s.size() : e + 1;
        continue;
      }
      break;
    }
  }
  bool eat(char c) {
    skip();
    if (i < s.size() && s[i] == c) { ++i; return true; }
    return false;
  }
  std::size_t col() const { return i + 1; }
};

}  // namespace

bool Symbols::Less::operator()(const std::string& a, const std::string& b) const noexcept {
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t k = 0; k < n; ++k) {
    const char x = lower(a[k]), y = lower(b[k]);
    if (x != y) return x < y;
  }
  return a.size() < b.size();
}

namespace {

using Failure = std::optional<ParseError>;

/// A number literal (digits with '_' separators, fraction, exponent), or a
/// tag name with an optional [index]: operand `n` of instruction `iname`.
Failure lex_operand(Lexer& lx, const std::string& iname, std::size_t n, StOperand& op) {
  const std::string_view text = lx.s;
  const auto where = [&] { return iname + " operand " + std::to_string(n); };  // built only for an error
  op.column = lx.col();
  if (lx.i >= text.size()) return ParseError{iname + ": unexpected end of text in operand " + std::to_string(n), lx.col()};
  const char c = text[lx.i];
  if (std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.') {
    std::size_t j = lx.i;
    if (text[j] == '-' || text[j] == '+') ++j;
    bool integer = true;
    while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) || text[j] == '_')) ++j;
    if (j < text.size() && text[j] == '.') { integer = false; ++j; while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j; }
    if (j < text.size() && (text[j] == 'e' || text[j] == 'E')) {
      integer = false;
      ++j;
      if (j < text.size() && (text[j] == '-' || text[j] == '+')) ++j;
      while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
    }
    std::string lit(text.substr(lx.i, j - lx.i));
    std::string digits;
    for (char ch : lit) if (ch != '_') digits += ch;
    if (!digits.empty() && digits[0] == '+') digits.erase(0, 1);
    double v = 0;
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (r.ec != std::errc() || r.ptr != digits.data() + digits.size() || !std::isfinite(v))
      return ParseError{where() + ": malformed number '" + lit + "'", op.column};
    op.kind = StOperand::Kind::Number;
    op.number = v;
    op.integer = integer;
    op.text = lit;
    lx.i = j;
    return std::nullopt;
  }
  if (!ident_start(c)) return ParseError{where() + ": unexpected character '" + std::string(1, c) + "'", op.column};
  std::size_t j = lx.i;
  while (j < text.size() && ident_char(text[j])) ++j;
  op.kind = StOperand::Kind::Tag;
  op.text = std::string(text.substr(lx.i, j - lx.i));
  lx.i = j;
  lx.skip();
  if (lx.i < text.size() && text[lx.i] == '[') {
    ++lx.i;
    lx.skip();
    std::size_t k = lx.i;
    while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
    if (k == lx.i) return ParseError{where() + ": expected an integer array index after '" + op.text + "['", lx.col()};
    long idxv = 0;
    const auto r = std::from_chars(text.data() + lx.i, text.data() + k, idxv);
    if (r.ec != std::errc()) return ParseError{iname + ": array index out of range", lx.col()};
    op.index = idxv;
    lx.i = k;
    if (!lx.eat(']')) return ParseError{where() + ": expected ']'", lx.col()};
  }
  return std::nullopt;
}

/// The operand tokens between '(' (already read) and ')'.
Failure lex_operands(Lexer& lx, const std::string& iname, ParsedCall& call) {
  lx.skip();
  if (lx.i < lx.s.size() && lx.s[lx.i] == ')') {
    ++lx.i;
    return std::nullopt;
  }
  for (;;) {
    lx.skip();
    StOperand op;
    if (Failure f = lex_operand(lx, iname, call.operands.size(), op)) return f;
    call.operands.push_back(std::move(op));
    if (lx.eat(',')) continue;
    if (lx.eat(')')) return std::nullopt;
    return ParseError{iname + ": expected ',' or ')' after operand " + std::to_string(call.operands.size() - 1), lx.col()};
  }
}

/// Operand `k` against its signature `o`: the kind of token it may be, an
/// integer, an enumeration keyword (then its number) or number.
Failure check_operand(const std::string& iname, std::size_t k, const OperandSig& o, StOperand& op) {
  const std::string where = iname + " operand " + std::to_string(k) + " (" + std::string(o.name) + "): ";
  const auto expected = [&] { return ParseError{where + "expected " + kind_text(o.kind) + ", found " + found_text(op), op.column}; };
  switch (o.kind) {
    case OperandKind::Axis:
    case OperandKind::Control:
    case OperandKind::Group:
    case OperandKind::CoordSystem:
      if (op.kind != StOperand::Kind::Tag || op.index) return expected();
      break;
    case OperandKind::CamArray:
      if (op.kind != StOperand::Kind::Tag) return expected();
      if (!op.index) op.index = 0;  // no index: the first element
      break;
    case OperandKind::CamProfile:
      if (op.kind != StOperand::Kind::Tag) return expected();
      if (op.index && *op.index != 0)
        return ParseError{where + "only element [0] of a CAM_PROFILE array is allowed, found " + found_text(op), op.column};
      op.index = 0;
      break;
    case OperandKind::Real:
      break;  // a literal, a numeric tag or a numeric array element tag
    case OperandKind::Int:
      if (op.kind == StOperand::Kind::Number && !op.integer)
        return ParseError{where + "expected an integer, found " + found_text(op), op.column};
      break;
    case OperandKind::Enum:
      if (op.kind == StOperand::Kind::Number) {
        if (!op.integer || !enum_contains(o.enums, static_cast<std::int32_t>(op.number)) || std::fabs(op.number) > 1e9)
          return ParseError{where + "value " + op.text + " is out of range; allowed: " + allowed_enum(o), op.column};
      } else if (!op.index) {
        if (const auto v = find_keyword(o.enums, op.text)) {
          op.kind = StOperand::Kind::Keyword;
          op.number = *v;
        } else if (!o.tag_allowed) {
          return ParseError{where + "unknown keyword '" + op.text + "'; allowed: " + allowed_enum(o), op.column};
        }
      } else if (!o.tag_allowed) {
        return ParseError{where + "found " + found_text(op) + "; allowed: " + allowed_enum(o), op.column};
      }
      break;
    case OperandKind::RealArray:
      if (op.kind == StOperand::Kind::Number && op.number != 0) return expected();
      break;
  }
  return std::nullopt;
}

}  // namespace

ParseResult parse_st_call(std::string_view text) {
  ParseResult res;
  auto fail = [&](ParseError e) {
    res.error = std::move(e);
    return res;
  };
  Lexer lx{text};
  lx.skip();
  const std::size_t name_col = lx.col();
  std::size_t b = lx.i;
  while (lx.i < text.size() && (std::isalnum(static_cast<unsigned char>(text[lx.i])) || text[lx.i] == '_')) ++lx.i;
  const std::string_view name = text.substr(b, lx.i - b);
  if (name.empty()) return fail({"expected a motion instruction name at column " + std::to_string(name_col), name_col});
  const auto instr = find_instruction(name);
  if (!instr) {
    std::string all;
    for (std::size_t k = 0; k < kInstrCount; ++k) all += (k ? ", " : "") + std::string(signature(static_cast<Instr>(k)).name);
    return fail({"unknown instruction '" + std::string(name) + "'; allowed: " + all, name_col});
  }
  const InstrSig& sig = signature(*instr);
  const std::string iname(sig.name);
  if (!lx.eat('(')) return fail({iname + ": expected '(' after the instruction name", lx.col()});
  ParsedCall call;
  call.instr = *instr;
  if (Failure f = lex_operands(lx, iname, call)) return fail(std::move(*f));
  lx.eat(';');
  lx.skip();
  if (lx.i < text.size()) return fail({iname + ": unexpected text after the call: '" + std::string(text.substr(lx.i)) + "'", lx.col()});
  if (call.operands.size() != sig.operands.size()) {
    std::string t = iname + "(";
    for (std::size_t k = 0; k < sig.operands.size(); ++k) t += (k ? ", " : "") + std::string(sig.operands[k].name);
    return fail({iname + " expects " + std::to_string(sig.operands.size()) + " operands, found " +
                     std::to_string(call.operands.size()) + "; signature: " + t + ")",
                 name_col});
  }
  for (std::size_t k = 0; k < sig.operands.size(); ++k)
    if (Failure f = check_operand(iname, k, sig.operands[k], call.operands[k])) return fail(std::move(*f));
  res.call = std::move(call);
  return res;
}

std::optional<std::string> bind_call(const ParsedCall& call, const Symbols& sym, Request& out) {
  const InstrSig& sig = signature(call.instr);
  out = Request{};
  out.instr = call.instr;
  out.count = static_cast<std::uint8_t>(call.operands.size());
  const std::string iname(sig.name);
  for (std::size_t k = 0; k < call.operands.size() && k < kMaxOperands; ++k) {
    const OperandSig& o = sig.operands[k];
    const StOperand& op = call.operands[k];
    const std::string where = iname + " operand " + std::to_string(k) + " (" + std::string(o.name) + "): ";
    auto lookup = [&](const auto& map, const char* what) -> std::optional<std::string> {
      const auto it = map.find(op.text);
      if (it == map.end()) return where + "unknown " + what + " '" + op.text + "'";
      out.op[k].ref = static_cast<std::uint16_t>(it->second);
      return std::nullopt;
    };
    std::optional<std::string> err;
    switch (o.kind) {
      case OperandKind::Axis: err = lookup(sym.axes, "axis"); break;
      case OperandKind::Control:
        if (const auto it = sym.controls.find(op.text); it == sym.controls.end()) {
          err = where + "unknown MOTION_INSTRUCTION tag '" + op.text + "'";
        } else {
          out.control = it->second;
          out.op[k].ref = it->second;
        }
        break;
      case OperandKind::Group: err = lookup(sym.groups, "motion group"); break;
      case OperandKind::CoordSystem: err = lookup(sym.coordinate_systems, "coordinate system"); break;
      case OperandKind::CamArray:
        err = lookup(sym.cams, "CAM array");
        out.op[k].value = static_cast<double>(op.index.value_or(0));
        break;
      case OperandKind::CamProfile: err = lookup(sym.cam_profiles, "CAM_PROFILE array"); break;
      case OperandKind::RealArray:
        if (op.kind == StOperand::Kind::Number) {
          out.op[k].value = 0;  // "none"
        } else {
          err = lookup(sym.real_arrays, "REAL array");
          out.op[k].value = static_cast<double>(op.index.value_or(0));
        }
        break;
      case OperandKind::Real:
      case OperandKind::Int:
      case OperandKind::Enum:
        if (op.kind == StOperand::Kind::Tag) {
          std::string name = op.text;
          if (op.index) name += "[" + std::to_string(*op.index) + "]";
          const auto it = sym.numeric_tags.find(name);
          if (it == sym.numeric_tags.end()) err = where + "unknown numeric tag '" + name + "'";
          else out.op[k].value = it->second;
        } else {
          out.op[k].value = op.number;
        }
        break;
    }
    if (err) return err;
  }
  return std::nullopt;
}

std::optional<std::string> parse_and_bind(std::string_view text, const Symbols& sym, Request& out) {
  const ParseResult r = parse_st_call(text);
  if (!r.ok()) return r.error.message;
  return bind_call(*r.call, sym, out);
}

}  // namespace canmotion::motion
