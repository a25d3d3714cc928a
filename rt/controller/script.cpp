#include "rt/controller/script.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

namespace canmotion::rt::script {

ScriptError::ScriptError(const std::string& file, int line_, int column_, const std::string& message)
    : std::runtime_error(fmt::format("{}:{}:{}: {}", file, line_, column_, message)), line(line_), column(column_) {}

bool Condition::holds(double v) const noexcept {
  switch (op) {
    case Op::kTrue: return v != 0.0;
    case Op::kNot: return v == 0.0;
    case Op::kEq: return v == value;
    case Op::kNe: return v != value;
    case Op::kLt: return v < value;
    case Op::kLe: return v <= value;
    case Op::kGt: return v > value;
    case Op::kGe: return v >= value;
  }
  return false;
}

std::string format_value(double v) {
  if (std::isfinite(v) && v == std::trunc(v) && std::abs(v) < 1e15) return fmt::format("{}", static_cast<long long>(v));
  std::string s = fmt::format("{:.6f}", v);
  if (s.find('.') != std::string::npos) {
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";  // a tiny negative value rounds to zero: no sign
  return s;
}

std::string Condition::str() const {
  static constexpr const char* kOps[] = {"", "", "=", "<>", "<", "<=", ">", ">="};
  if (op == Op::kTrue) return tag;
  if (op == Op::kNot) return "NOT " + tag;
  return fmt::format("{} {} {}", tag, kOps[static_cast<int>(op)], format_value(value));
}

namespace {

/// One raw statement: its text without comments, and where it starts.
struct Raw {
  std::string text;
  int line = 1;
  int column = 1;
};

/// Does `text` start with the keyword WHILE (any case)?
bool starts_while(std::string_view text) {
  std::size_t b = 0;
  while (b < text.size() && std::isspace(static_cast<unsigned char>(text[b]))) ++b;
  static constexpr std::string_view kw = "WHILE";
  if (text.size() < b + kw.size() + 1) return false;
  for (std::size_t k = 0; k < kw.size(); ++k)
    if (std::toupper(static_cast<unsigned char>(text[b + k])) != kw[k]) return false;
  return std::isspace(static_cast<unsigned char>(text[b + kw.size()])) != 0;
}

/// Split into statements at `;` outside parentheses (and after the DO of a
/// WHILE), dropping comments.
std::vector<Raw> split(std::string_view src, const std::string& file) {
  std::vector<Raw> out;
  Raw cur;
  bool started = false;
  int line = 1, col = 1, depth = 0;
  int comment_line = 0, comment_col = 0;
  for (std::size_t i = 0; i < src.size(); ++i) {
    const char c = src[i];
    auto advance = [&](char ch) {
      if (ch == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    };
    if (c == '/' && i + 1 < src.size() && src[i + 1] == '/') {  // line comment
      while (i < src.size() && src[i] != '\n') ++i;
      if (i < src.size()) {
        if (started) cur.text += ' ';
        advance('\n');
      }
      continue;
    }
    if (c == '(' && i + 1 < src.size() && src[i + 1] == '*') {  // block comment
      comment_line = line;
      comment_col = col;
      advance(c);
      advance('*');
      i += 2;
      while (i + 1 < src.size() && !(src[i] == '*' && src[i + 1] == ')')) advance(src[i++]);
      if (i + 1 >= src.size()) throw ScriptError(file, comment_line, comment_col, "comment '(*' is never closed with '*)'");
      advance('*');
      advance(')');
      ++i;
      if (started) cur.text += ' ';
      continue;
    }
    if (!started && !std::isspace(static_cast<unsigned char>(c))) {
      started = true;
      cur.line = line;
      cur.column = col;
    }
    if (c == '(') ++depth;
    if (c == ')') {
      if (depth == 0) throw ScriptError(file, line, col, "')' without a matching '('");
      --depth;
    }
    // `WHILE cond DO` ends at its DO (ST puts no ';' there): the body's
    // first statement starts after it.
    if (started && depth == 0 && (c == 'D' || c == 'd') && i + 1 < src.size() && (src[i + 1] == 'O' || src[i + 1] == 'o') &&
        (i + 2 == src.size() || std::isspace(static_cast<unsigned char>(src[i + 2])) || src[i + 2] == '/' ||
         src[i + 2] == '(') &&
        !cur.text.empty() && std::isspace(static_cast<unsigned char>(cur.text.back())) && starts_while(cur.text)) {
      cur.text += "DO";
      out.push_back(cur);
      cur = Raw{};
      started = false;
      advance(c);
      advance(src[++i]);
      continue;
    }
    if (c == ';' && depth == 0) {
      if (!started) throw ScriptError(file, line, col, "empty statement (a lone ';')");
      out.push_back(cur);
      cur = Raw{};
      started = false;
      advance(c);
      continue;
    }
    if (started) cur.text += (c == '\n' || c == '\t' || c == '\r') ? ' ' : c;
    advance(c);
  }
  if (started) {
    while (!cur.text.empty() && std::isspace(static_cast<unsigned char>(cur.text.back()))) cur.text.pop_back();
    throw ScriptError(file, cur.line, cur.column,
                      fmt::format("statement '{}' does not end with ';'", cur.text.substr(0, 40)));
  }
  return out;
}

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

std::string trim(std::string_view s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return std::string(s.substr(b, e - b));
}

bool is_tag(std::string_view s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '[' || c == ']';
  });
}

std::optional<double> number(std::string_view s) {
  const std::string t = trim(s);
  const std::string u = upper(t);
  if (u == "TRUE") return 1.0;
  if (u == "FALSE") return 0.0;
  double v = 0;
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (!t.empty() && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || p != e || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Does `u` (upper case) start with keyword `kw` followed by a space or end?
bool keyword(const std::string& u, std::string_view kw) {
  return u.size() >= kw.size() && u.compare(0, kw.size(), kw) == 0 &&
         (u.size() == kw.size() || std::isspace(static_cast<unsigned char>(u[kw.size()])));
}

Condition parse_condition(const std::string& text, const std::string& file, const Raw& r, std::string_view what) {
  Condition c;
  const std::string u = upper(text);
  if (keyword(u, "NOT")) {
    c.op = Condition::Op::kNot;
    c.tag = trim(text.substr(3));
  } else {
    static const std::pair<const char*, Condition::Op> ops[] = {{"<>", Condition::Op::kNe}, {"<=", Condition::Op::kLe},
                                                                {">=", Condition::Op::kGe}, {"=", Condition::Op::kEq},
                                                                {"<", Condition::Op::kLt},  {">", Condition::Op::kGt}};
    std::size_t best = std::string::npos;
    std::size_t len = 0;
    for (const auto& [sym, op] : ops) {
      const std::size_t at = text.find(sym);
      if (at != std::string::npos && (at < best || (at == best && std::string_view(sym).size() > len))) {
        best = at;
        len = std::string_view(sym).size();
        c.op = op;
      }
    }
    if (best == std::string::npos) {
      c.tag = trim(text);
    } else {
      c.tag = trim(text.substr(0, best));
      const auto v = number(text.substr(best + len));
      if (!v)
        throw ScriptError(file, r.line, r.column,
                          fmt::format("{}: '{}' is not a number (compare a tag with a number: tag >= 5)", what,
                                      trim(text.substr(best + len))));
      c.value = *v;
    }
  }
  if (!is_tag(c.tag))
    throw ScriptError(file, r.line, r.column,
                      fmt::format("{}: '{}' is not a tag name (conditions are: tag, NOT tag, or tag "
                                  "<op> number with op one of = <> < <= > >=)",
                                  what, c.tag));
  return c;
}

Statement parse_statement(const Raw& r, const std::string& file) {
  Statement s;
  s.line = r.line;
  s.column = r.column;
  s.text = trim(r.text);
  const std::string u = upper(s.text);
  if (keyword(u, "WAIT")) {
    std::string rest = trim(s.text.substr(4));
    const std::string ur = upper(rest);
    if (keyword(ur, "UNTIL")) {
      s.kind = Statement::Kind::kWaitUntil;
      rest = trim(rest.substr(5));
      const std::string ur2 = upper(rest);
      std::size_t to = ur2.rfind(" TIMEOUT ");
      if (to == std::string::npos && ur2.size() > 8 && ur2.compare(ur2.size() - 8, 8, " TIMEOUT") == 0)
        throw ScriptError(file, r.line, r.column, "WAIT UNTIL ... TIMEOUT needs a number of seconds");
      if (to != std::string::npos) {
        const auto t = number(rest.substr(to + 9));
        if (!t || *t <= 0)
          throw ScriptError(file, r.line, r.column,
                            fmt::format("TIMEOUT must be a positive number of seconds, got '{}'", trim(rest.substr(to + 9))));
        s.seconds = *t;
        rest = rest.substr(0, to);
      }
      if (trim(rest).empty()) throw ScriptError(file, r.line, r.column, "WAIT UNTIL needs a condition");
      s.cond = parse_condition(rest, file, r, "WAIT UNTIL");
      return s;
    }
    s.kind = Statement::Kind::kWait;
    const auto t = number(rest);
    if (!t || *t < 0)
      throw ScriptError(file, r.line, r.column,
                        fmt::format("WAIT needs a number of seconds >= 0 or UNTIL <condition>, got '{}'", rest));
    s.seconds = *t;
    return s;
  }
  if (keyword(u, "WHILE")) {
    s.kind = Statement::Kind::kWhile;
    const std::string ur = upper(s.text);
    if (ur.size() < 8 || ur.compare(ur.size() - 3, 3, " DO") != 0)
      throw ScriptError(file, r.line, r.column, "WHILE needs DO after its condition: WHILE cond DO ... END_WHILE;");
    const std::string cond = trim(s.text.substr(5, s.text.size() - 5 - 3));
    if (cond.empty()) throw ScriptError(file, r.line, r.column, "WHILE needs a condition: WHILE cond DO ... END_WHILE;");
    s.cond = parse_condition(cond, file, r, "WHILE");
    return s;
  }
  if (u == "END_WHILE") {
    s.kind = Statement::Kind::kEndWhile;
    return s;
  }
  if (keyword(u, "DO") || u == "DO")
    throw ScriptError(file, r.line, r.column, "DO without a WHILE (WHILE cond DO ... END_WHILE;)");
  if (keyword(u, "PRINT")) {
    s.kind = Statement::Kind::kPrint;
    std::string rest = s.text.substr(5);
    std::size_t start = 0;
    while (start <= rest.size()) {
      const std::size_t comma = rest.find(',', start);
      const std::string tag = trim(rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (!is_tag(tag))
        throw ScriptError(file, r.line, r.column,
                          fmt::format("PRINT: '{}' is not a tag name (PRINT tag[, tag...];)", tag));
      s.tags.push_back(tag);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    return s;
  }
  if (const std::size_t as = s.text.find(":="); as != std::string::npos) {
    s.kind = Statement::Kind::kAssign;
    const std::string tag = trim(s.text.substr(0, as));
    if (!is_tag(tag)) throw ScriptError(file, r.line, r.column, fmt::format("'{}' is not a tag name (tag := value;)", tag));
    const auto v = number(s.text.substr(as + 2));
    if (!v)
      throw ScriptError(file, r.line, r.column,
                        fmt::format("'{}' is not a number, TRUE or FALSE (tag := value;)", trim(s.text.substr(as + 2))));
    s.tags.push_back(tag);
    s.value = *v;
    return s;
  }
  const std::size_t paren = s.text.find('(');
  if (paren == std::string::npos || s.text.back() != ')' || !is_tag(trim(s.text.substr(0, paren))))
    throw ScriptError(file, r.line, r.column,
                      fmt::format("'{}' is not a statement: expected an instruction call like MSO(X, mso1), WAIT, "
                                  "WAIT UNTIL, PRINT or tag := value",
                                  s.text.substr(0, 60)));
  s.kind = Statement::Kind::kCall;
  return s;
}

}  // namespace

Script parse(std::string_view text, const std::string& file) {
  Script sc;
  sc.file = file;
  std::vector<std::size_t> open;  // the WHILEs not yet closed, innermost last
  for (const Raw& r : split(text, file)) {
    sc.statements.push_back(parse_statement(r, file));
    Statement& s = sc.statements.back();
    const std::size_t at = sc.statements.size() - 1;
    if (s.kind == Statement::Kind::kWhile) {
      open.push_back(at);
    } else if (s.kind == Statement::Kind::kEndWhile) {
      if (open.empty()) throw ScriptError(file, s.line, s.column, "END_WHILE without a WHILE before it");
      s.jump = open.back();
      sc.statements[open.back()].jump = at + 1;
      open.pop_back();
    }
  }
  if (!open.empty()) {
    const Statement& w = sc.statements[open.back()];
    throw ScriptError(file, w.line, w.column, "WHILE is never closed: END_WHILE; is missing");
  }
  return sc;
}

Script load(std::string_view text, const std::string& file, ScriptHost& host) {
  Script sc = parse(text, file);
  for (const Statement& s : sc.statements) {
    std::optional<std::string> err;
    switch (s.kind) {
      case Statement::Kind::kCall: err = host.check_call(s.text); break;
      case Statement::Kind::kWaitUntil:
      case Statement::Kind::kWhile: err = host.check_tag(s.cond.tag, false); break;
      case Statement::Kind::kEndWhile: break;
      case Statement::Kind::kPrint:
        for (const auto& t : s.tags)
          if ((err = host.check_tag(t, false))) break;
        break;
      case Statement::Kind::kAssign:
        err = host.check_tag(s.tags[0], true);
        if (!err) host.declare(s.tags[0]);
        break;
      case Statement::Kind::kWait: break;
    }
    if (err) throw ScriptError(file, s.line, s.column, *err);
  }
  return sc;
}

Script load_file(const std::string& path, ScriptHost& host) {
  std::ifstream in(path);
  if (!in) throw std::system_error(errno, std::generic_category(), "cannot read script '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return load(ss.str(), path, host);
}

Runner::Runner(const Script& script, ScriptHost& host, std::function<void(const std::string&)> out)
    : script_(script), host_(host), out_(std::move(out)) {}

Runner::Status Runner::fail(const Statement& s, const std::string& message) {
  error_ = fmt::format("{}:{}: {}", script_.file, s.line, message);
  status_ = Status::kFailed;
  return status_;
}

std::optional<std::string> Runner::errored(const Condition& c) {
  // WAIT UNTIL t.DN / t.PC (as written, not negated or compared) on a
  // control tag whose .ER is set: the instruction ended with an error, its
  // DN or PC never comes. Fail now with its ERR, not at the timeout (or never).
  if (c.op != Condition::Op::kTrue) return std::nullopt;
  const auto dot = c.tag.rfind('.');
  if (dot == std::string::npos) return std::nullopt;
  std::string member = c.tag.substr(dot + 1);
  for (char& ch : member) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (member != "DN" && member != "PC") return std::nullopt;
  const std::string base = c.tag.substr(0, dot);
  std::string e;
  const auto er = host_.read(base + ".ER", &e);
  if (!er || *er == 0.0) return std::nullopt;
  const auto err = host_.read(base + ".ERR", &e);
  const auto exerr = host_.read(base + ".EXERR", &e);
  return fmt::format("WAIT UNTIL {}: {}.ER is set (ERR {} EXERR {}): the instruction ended with an error, {} never comes",
                     c.str(), base, format_value(err.value_or(-1)), format_value(exerr.value_or(0)), c.tag);
}

Runner::Status Runner::step(double now_s) {
  if (status_ != Status::kRunning) return status_;
  if (pending_call_) {
    if (!host_.settled()) return status_;
    pending_call_ = false;
    const Statement& prev = script_.statements[pc_ - 1];
    if (!pending_ctl_.empty()) {
      std::string e;
      const auto er = host_.read(pending_ctl_ + ".ER", &e);
      if (er && *er != 0.0) {
        const auto err = host_.read(pending_ctl_ + ".ERR", &e);
        const auto exerr = host_.read(pending_ctl_ + ".EXERR", &e);
        out_(fmt::format("t={:.3f} {}:{}: {} set {}.ER: ERR {} EXERR {}", now_s, script_.file, prev.line,
                         prev.text.substr(0, prev.text.find('(')), pending_ctl_, format_value(err.value_or(-1)),
                         format_value(exerr.value_or(0))));
      }
    }
  }
  while (pc_ < script_.statements.size()) {
    const Statement& s = script_.statements[pc_];
    switch (s.kind) {
      case Statement::Kind::kCall: {
        pending_ctl_.clear();
        if (auto e = host_.execute(s.text, &pending_ctl_)) return fail(s, *e);
        ++pc_;
        pending_call_ = true;
        return status_;  // the planner runs it in the next cycle
      }
      case Statement::Kind::kWait:
        if (!waiting_) {
          waiting_ = true;
          wait_start_ = now_s;
        }
        // Half a nanosecond of slack absorbs the rounding of cycle * period.
        if (now_s - wait_start_ + 5e-10 < s.seconds) return status_;
        waiting_ = false;
        ++pc_;
        break;
      case Statement::Kind::kWaitUntil: {
        if (!waiting_) {
          waiting_ = true;
          wait_start_ = now_s;
        }
        std::string e;
        const auto v = host_.read(s.cond.tag, &e);
        if (!v) return fail(s, e);
        if (!s.cond.holds(*v)) {
          if (auto why = errored(s.cond)) return fail(s, *why);
          if (s.seconds > 0 && now_s - wait_start_ + 5e-10 >= s.seconds)
            return fail(s, fmt::format("WAIT UNTIL {} timed out after {} s ({} = {})", s.cond.str(),
                                       format_value(s.seconds), s.cond.tag, format_value(*v)));
          return status_;
        }
        waiting_ = false;
        ++pc_;
        break;
      }
      case Statement::Kind::kPrint: {
        std::string line = fmt::format("t={:.3f}", now_s);
        for (const auto& t : s.tags) {
          std::string e;
          const auto v = host_.read(t, &e);
          if (!v) return fail(s, e);
          line += fmt::format(" {}={}", t, format_value(*v));
        }
        out_(line);
        ++pc_;
        break;
      }
      case Statement::Kind::kWhile: {
        std::string e;
        const auto v = host_.read(s.cond.tag, &e);
        if (!v) return fail(s, e);
        pc_ = s.cond.holds(*v) ? pc_ + 1 : s.jump;
        break;
      }
      case Statement::Kind::kEndWhile:
        pc_ = s.jump;
        return status_;  // one pass per cycle at most: a loop that waits on nothing cannot hang the step
      case Statement::Kind::kAssign:
        if (auto e = host_.write(s.tags[0], s.value)) return fail(s, *e);
        ++pc_;
        pending_call_ = true;  // the write reaches the planner next cycle
        pending_ctl_.clear();
        return status_;
    }
  }
  status_ = Status::kDone;
  return status_;
}

}  // namespace canmotion::rt::script
