#pragma once
/// \file
/// Motion scripts: a text file of statements, each ending in `;`, with
/// comments `// ...` and `(* ... *)`. The way users and tests program a
/// sequence without writing C++ (`canmotiond --script`, `canmotionctl run`).
///
///     MSO(X, mso1);                          // any Logix motion instruction call (ST syntax)
///     WAIT UNTIL mso1.DN TIMEOUT 2;          // boolean tag, NOT tag, or tag <op> number
///     MAM(X, mam1, 0, 100, 50, ...);
///     WAIT 0.5;                              // seconds
///     PRINT X.ActualPosition, X.CommandVelocity;
///     X.SomeWritableTag := 3;
///     WHILE Controller.Time < 3600 DO       // same conditions as WAIT UNTIL; nests
///       MAM(X, mam2, 1, 10, 50, ...);       // (each pass takes at least one cycle)
///       WAIT UNTIL mam2.PC;
///     END_WHILE;
///
/// Parsing is not realtime (it allocates). The Runner is stepped once per
/// cycle by whoever owns the controller's non-RT side (inline in --sim, so
/// runs are deterministic); it talks to the controller only through the
/// ScriptHost interface.

#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace canmotion::rt::script {

/// A parse or load error: `file:line:column: message`.
class ScriptError : public std::runtime_error {
 public:
  ScriptError(const std::string& file, int line, int column, const std::string& message);
  int line = 0;
  int column = 0;
};

/// A condition of WAIT UNTIL.
struct Condition {
  enum class Op : std::uint8_t { kTrue, kNot, kEq, kNe, kLt, kLe, kGt, kGe };
  std::string tag;
  Op op = Op::kTrue;
  double value = 0.0;
  /// Evaluate against the tag's value.
  [[nodiscard]] bool holds(double tag_value) const noexcept;
  /// `tag`, `NOT tag`, `tag >= 5` as written.
  [[nodiscard]] std::string str() const;
};

/// One statement.
struct Statement {
  enum class Kind : std::uint8_t { kCall, kWait, kWaitUntil, kPrint, kAssign, kWhile, kEndWhile };
  Kind kind = Kind::kCall;
  int line = 0;
  int column = 0;
  std::string text;                  ///< kCall: the whole call `MAM(...)`; others: the statement as written
  double seconds = 0.0;              ///< kWait; kWaitUntil timeout (0 = none)
  Condition cond;                    ///< kWaitUntil, kWhile
  std::size_t jump = 0;              ///< kWhile: the statement after its END_WHILE; kEndWhile: its WHILE
  std::vector<std::string> tags;     ///< kPrint: tags; kAssign: the one tag
  double value = 0.0;                ///< kAssign
};

/// A parsed script.
struct Script {
  std::string file;
  std::vector<Statement> statements;
};

/// What the controller side offers a script. Every error string should say
/// what was wrong and what would be valid.
class ScriptHost {
 public:
  virtual ~ScriptHost() = default;
  /// Check an instruction call at load time (instruction, operand count,
  /// keywords, tag names). Return an error message, or nullopt if valid.
  virtual std::optional<std::string> check_call(std::string_view call) = 0;
  /// Check that a tag name exists (and is writable, if `for_write`).
  virtual std::optional<std::string> check_tag(std::string_view tag, bool for_write) = 0;
  /// Execute an instruction call (one false-to-true rung transition).
  /// Return an error message when it could not be submitted. Sets
  /// `control_tag` to the name of the call's MOTION_INSTRUCTION tag (or
  /// empty), so the runner can report an ER with its ERR code.
  virtual std::optional<std::string> execute(std::string_view call, std::string* control_tag) = 0;
  /// True once everything submitted so far has been executed by the planner
  /// and is visible through read() (the script waits for it after a call).
  virtual bool settled() = 0;
  /// Read a tag's value (bits read as 0/1).
  virtual std::optional<double> read(std::string_view tag, std::string* error) = 0;
  /// Write a writable tag.
  virtual std::optional<std::string> write(std::string_view tag, double value) = 0;
  /// Make sure a numeric tag assigned by the script exists (value 0 if new),
  /// so that later statements may read it or pass it as an operand. Called
  /// by load() for every `tag := value;` before checking later statements.
  virtual void declare(std::string_view tag) = 0;
};

/// Parse script text. Throws ScriptError naming the file, line and column.
[[nodiscard]] Script parse(std::string_view text, const std::string& file = "<script>");

/// Parse and check every call and tag against `host` (before anything runs).
[[nodiscard]] Script load(std::string_view text, const std::string& file, ScriptHost& host);

/// Read a file and load() it. Throws ScriptError or std::system_error.
[[nodiscard]] Script load_file(const std::string& path, ScriptHost& host);

/// Executes a Script step by step against a ScriptHost.
class Runner {
 public:
  enum class Status : std::uint8_t { kRunning, kDone, kFailed };
  /// `out` receives PRINT lines and notes (an instruction that set ER), one
  /// line per call, without newline.
  Runner(const Script& script, ScriptHost& host, std::function<void(const std::string&)> out);

  /// Advance at controller time `now_s`: run statements until one blocks
  /// (WAIT not over, WAIT UNTIL false, a call not yet settled). Not realtime.
  Status step(double now_s);

  [[nodiscard]] Status status() const noexcept { return status_; }
  /// Why the script failed (file:line: message), empty otherwise.
  [[nodiscard]] const std::string& error() const noexcept { return error_; }
  /// Index of the statement being executed (== size when done).
  [[nodiscard]] std::size_t position() const noexcept { return pc_; }

 private:
  Status fail(const Statement& s, const std::string& message);
  /// The reason a WAIT UNTIL on `c` can never hold: its control tag ended with ER (see script.cpp).
  std::optional<std::string> errored(const Condition& c);
  const Script& script_;
  ScriptHost& host_;
  std::function<void(const std::string&)> out_;
  std::size_t pc_ = 0;
  bool waiting_ = false;      ///< a WAIT/WAIT UNTIL is in progress
  double wait_start_ = 0.0;
  bool pending_call_ = false; ///< a call was submitted; wait until settled
  std::string pending_ctl_;   ///< control tag of the pending call, for the ER note
  Status status_ = Status::kRunning;
  std::string error_;
};

/// Format a value for PRINT: integers without decimals, reals with up to 6
/// decimals and no trailing zeros.
[[nodiscard]] std::string format_value(double v);

}  // namespace canmotion::rt::script
