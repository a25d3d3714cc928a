// Motion script parsing and execution against a fake host, stepped on a
// virtual clock (1 ms cycles).
#include <gtest/gtest.h>

#include <map>

#include "rt/controller/script.hpp"

namespace canmotion::rt::script {
namespace {

/// A host whose tags live in a map; calls are recorded and "execute" one
/// cycle later (settled() turns true at the next step).
class FakeHost : public ScriptHost {
 public:
  std::map<std::string, double> tags{{"X.ActualPosition", 0}, {"mso1.DN", 0}, {"mam1.ER", 0}, {"mam1.ERR", 0},
                                     {"mam1.EXERR", 0}, {"Speed", 0}};
  std::vector<std::string> calls;
  int lag = 0;  ///< extra cycles before a call or write is visible
  int unsettled = 0;

  std::optional<std::string> check_call(std::string_view call) override {
    if (call.rfind("MSO(", 0) == 0 || call.rfind("MAM(", 0) == 0) return std::nullopt;
    return "unknown instruction in '" + std::string(call) + "'";
  }
  std::optional<std::string> check_tag(std::string_view tag, bool for_write) override {
    if (for_write) {
      if (tags.count(std::string(tag)) && tag != "Speed" && tag != "Target") return "tag '" + std::string(tag) + "' is read-only";
      return std::nullopt;
    }
    if (!tags.count(std::string(tag))) return "no tag named '" + std::string(tag) + "'";
    return std::nullopt;
  }
  std::optional<std::string> execute(std::string_view call, std::string* ctl) override {
    calls.emplace_back(call);
    *ctl = call.rfind("MAM(", 0) == 0 ? "mam1" : "mso1";
    unsettled = lag;
    return std::nullopt;
  }
  bool settled() override { return unsettled-- <= 0; }
  std::optional<double> read(std::string_view tag, std::string* e) override {
    auto it = tags.find(std::string(tag));
    if (it == tags.end()) {
      *e = "no tag";
      return std::nullopt;
    }
    return it->second;
  }
  void declare(std::string_view tag) override { tags.emplace(std::string(tag), 0.0); }
  std::optional<std::string> write(std::string_view tag, double v) override {
    tags[std::string(tag)] = v;
    unsettled = lag;
    return std::nullopt;
  }
};

struct ScriptRun {
  FakeHost host;
  std::vector<std::string> lines;
  Script script;
  std::unique_ptr<Runner> runner;
  explicit ScriptRun(const std::string& text) : script(load(text, "t.script", host)) {
    runner = std::make_unique<Runner>(script, host, [this](const std::string& l) { lines.push_back(l); });
  }
  /// Step cycle by cycle until not running or `max` cycles; returns the cycle it stopped at.
  std::uint64_t until_end(std::uint64_t max, const std::function<void(std::uint64_t)>& each = {}) {
    for (std::uint64_t c = 0; c < max; ++c) {
      if (each) each(c);
      if (runner->step(static_cast<double>(c) * 0.001) != Runner::Status::kRunning) return c;
    }
    return max;
  }
};

/// parse()'s error message for `text`, or "accepted".
std::string parse_message(const std::string& text, const std::string& file) {
  try {
    (void)parse(text, file);
  } catch (const ScriptError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ScriptParse, StatementsCommentsAndKeywords) {
  const Script s = parse(
      "// header\nMSO(X, mso1);  (* block\n comment *) wait until MSO1.dn timeout 2;\n"
      "WAIT 0.5; PRINT X.ActualPosition , Speed;\nSpeed := 12.5;\nWAIT UNTIL NOT mso1.DN;\n"
      "WAIT UNTIL X.ActualPosition >= -3;\nWAIT UNTIL Speed<>1;\n",
      "f");
  ASSERT_EQ(s.statements.size(), 8u);
  EXPECT_EQ(s.statements[0].kind, Statement::Kind::kCall);
  EXPECT_EQ(s.statements[0].text, "MSO(X, mso1)");
  EXPECT_EQ(s.statements[1].kind, Statement::Kind::kWaitUntil);
  EXPECT_EQ(s.statements[1].cond.tag, "MSO1.dn");
  EXPECT_DOUBLE_EQ(s.statements[1].seconds, 2.0);
  EXPECT_EQ(s.statements[1].line, 3);  // after the block comment
  EXPECT_EQ(s.statements[2].kind, Statement::Kind::kWait);
  EXPECT_EQ(s.statements[3].tags, (std::vector<std::string>{"X.ActualPosition", "Speed"}));
  EXPECT_EQ(s.statements[4].kind, Statement::Kind::kAssign);
  EXPECT_DOUBLE_EQ(s.statements[4].value, 12.5);
  EXPECT_EQ(s.statements[5].cond.op, Condition::Op::kNot);
  EXPECT_EQ(s.statements[6].cond.op, Condition::Op::kGe);
  EXPECT_DOUBLE_EQ(s.statements[6].cond.value, -3);
  EXPECT_EQ(s.statements[7].cond.op, Condition::Op::kNe);
}

TEST(ScriptParse, ErrorsNameLineAndColumn) {
  auto msg = [](const std::string& text) { return parse_message(text, "bad.script"); };
  EXPECT_EQ(msg("MSO(X, mso1)\n"), "bad.script:1:1: statement 'MSO(X, mso1)' does not end with ';'");
  EXPECT_EQ(msg("WAIT 1;\n  WAIT soon;"), "bad.script:2:3: WAIT needs a number of seconds >= 0 or UNTIL <condition>, got 'soon'");
  EXPECT_EQ(msg("(* open"), "bad.script:1:1: comment '(*' is never closed with '*)'");
  EXPECT_NE(msg("WAIT UNTIL x > fast;").find("'fast' is not a number"), std::string::npos);
  EXPECT_NE(msg("WAIT UNTIL mso1.DN TIMEOUT -1;").find("TIMEOUT must be a positive number"), std::string::npos);
  EXPECT_NE(msg("hello world;").find("is not a statement"), std::string::npos);
  EXPECT_NE(msg("PRINT a,,b;").find("PRINT: '' is not a tag name"), std::string::npos);
  EXPECT_NE(msg("MSO(X;").find("does not end with ';'"), std::string::npos);
}

TEST(ScriptLoad, HostChecksCallsAndTags) {
  FakeHost h;
  EXPECT_THROW((void)load("MAX(X, y);", "s", h), ScriptError);
  try {
    (void)load("WAIT 1;\nPRINT Nope;", "s", h);
    FAIL();
  } catch (const ScriptError& e) {
    EXPECT_STREQ(e.what(), "s:2:1: no tag named 'Nope'");
  }
  EXPECT_THROW((void)load("X.ActualPosition := 1;", "s", h), ScriptError);
}

TEST(ScriptRunner, WaitIsMeasuredOnTheClock) {
  ScriptRun r("WAIT 0.25; PRINT Speed;");
  EXPECT_EQ(r.until_end(1000), 250u);
  ASSERT_EQ(r.lines.size(), 1u);
  EXPECT_EQ(r.lines[0], "t=0.250 Speed=0");
  EXPECT_EQ(r.runner->status(), Runner::Status::kDone);
}

TEST(ScriptRunner, CallThenWaitUntilDone) {
  ScriptRun r("MSO(X, mso1); WAIT UNTIL mso1.DN TIMEOUT 1; PRINT X.ActualPosition;");
  const auto end = r.until_end(1000, [&](std::uint64_t c) {
    if (c == 40) r.host.tags["mso1.DN"] = 1;
    r.host.tags["X.ActualPosition"] = static_cast<double>(c) * 0.5;
  });
  EXPECT_EQ(end, 40u);
  ASSERT_EQ(r.host.calls.size(), 1u);
  EXPECT_EQ(r.lines, (std::vector<std::string>{"t=0.040 X.ActualPosition=20"}));
}

TEST(ScriptRunner, WaitUntilTimeoutFailsWithValue) {
  ScriptRun r("WAIT UNTIL X.ActualPosition > 10 TIMEOUT 0.1;");
  r.until_end(1000);
  EXPECT_EQ(r.runner->status(), Runner::Status::kFailed);
  EXPECT_EQ(r.runner->error(), "t.script:1: WAIT UNTIL X.ActualPosition > 10 timed out after 0.1 s (X.ActualPosition = 0)");
}

// The instruction a WAIT UNTIL waits for ended with ER while it waited (an
// MSO whose drive never came): its DN never comes, the script fails at once
// with the ERR, not at the timeout, and not never without a timeout (issue 26:
// the burst test waited 60 s for an MSO that had ended with ERR 12 at 5 s).
TEST(ScriptRunner, WaitUntilDoneFailsAtOnceWhenTheInstructionEndsWithAnError) {
  ScriptRun r("MSO(X, mso1); WAIT UNTIL mso1.DN;");
  r.host.tags["mso1.ER"] = 0;
  r.host.tags["mso1.ERR"] = 0;
  r.host.tags["mso1.EXERR"] = 0;
  const auto end = r.until_end(100000, [&](std::uint64_t c) {
    if (c == 500) {
      r.host.tags["mso1.ER"] = 1;
      r.host.tags["mso1.ERR"] = 12;
      r.host.tags["mso1.EXERR"] = 16;
    }
  });
  EXPECT_EQ(end, 500u);
  EXPECT_EQ(r.runner->status(), Runner::Status::kFailed);
  EXPECT_EQ(r.runner->error(), "t.script:1: WAIT UNTIL mso1.DN: mso1.ER is set (ERR 12 EXERR 16): the instruction "
                               "ended with an error, mso1.DN never comes");
  // A condition that is not DN/PC as written (negated, compared) is not affected.
  ScriptRun n("WAIT UNTIL NOT mso1.DN; PRINT Speed;");
  n.host.tags["mso1.ER"] = 1;
  n.until_end(10);
  EXPECT_EQ(n.runner->status(), Runner::Status::kDone);
}

TEST(ScriptRunner, InstructionErrorIsReportedAndScriptGoesOn) {
  ScriptRun r("MAM(X, mam1); PRINT Speed;");
  r.host.tags["mam1.ER"] = 1;
  r.host.tags["mam1.ERR"] = 13;
  r.host.tags["mam1.EXERR"] = 3;
  r.until_end(100);
  EXPECT_EQ(r.runner->status(), Runner::Status::kDone);
  ASSERT_EQ(r.lines.size(), 2u);
  EXPECT_EQ(r.lines[0], "t=0.001 t.script:1: MAM set mam1.ER: ERR 13 EXERR 3");
}

TEST(ScriptRunner, AssignWritesTheTag) {
  ScriptRun r("Speed := 7; PRINT Speed;");
  r.until_end(10);
  EXPECT_EQ(r.lines, (std::vector<std::string>{"t=0.001 Speed=7"}));
}

TEST(ScriptRunner, WaitsUntilTheHostHasSettled) {
  ScriptRun r("Speed := 7; PRINT Speed;");
  r.host.lag = 5;
  r.until_end(100);
  EXPECT_EQ(r.lines, (std::vector<std::string>{"t=0.006 Speed=7"}));
}

TEST(ScriptLoad, AssignedTagsMayBeReadLater) {
  ScriptRun r("Target := 5; PRINT Target; WAIT UNTIL Target >= 5 TIMEOUT 1;");
  r.until_end(10);
  EXPECT_EQ(r.runner->status(), Runner::Status::kDone) << r.runner->error();
  EXPECT_EQ(r.lines, (std::vector<std::string>{"t=0.001 Target=5"}));
}

// WHILE cond DO ... END_WHILE; (ST): the condition as in WAIT UNTIL, tested
// before each pass; loops nest; each pass takes at least one cycle, so a
// loop that waits on nothing cannot hang a step.
TEST(ScriptParse, WhileLoopsNestAndJump) {
  const Script s = parse(
      "WHILE Speed < 3 DO\n  MSO(X, mso1);\n  while X.ActualPosition do PRINT Speed; END_WHILE;\nEND_WHILE;\nPRINT Speed;",
      "f");
  ASSERT_EQ(s.statements.size(), 7u);
  EXPECT_EQ(s.statements[0].kind, Statement::Kind::kWhile);
  EXPECT_EQ(s.statements[0].cond.tag, "Speed");
  EXPECT_EQ(s.statements[0].cond.op, Condition::Op::kLt);
  EXPECT_EQ(s.statements[0].jump, 6u);  // past its END_WHILE
  EXPECT_EQ(s.statements[1].line, 2);
  EXPECT_EQ(s.statements[2].kind, Statement::Kind::kWhile);
  EXPECT_EQ(s.statements[2].cond.tag, "X.ActualPosition");
  EXPECT_EQ(s.statements[2].jump, 5u);
  EXPECT_EQ(s.statements[3].kind, Statement::Kind::kPrint);
  EXPECT_EQ(s.statements[3].line, 3);
  EXPECT_EQ(s.statements[3].column, 29);
  EXPECT_EQ(s.statements[4].kind, Statement::Kind::kEndWhile);
  EXPECT_EQ(s.statements[4].jump, 2u);
  EXPECT_EQ(s.statements[5].kind, Statement::Kind::kEndWhile);
  EXPECT_EQ(s.statements[5].jump, 0u);
  EXPECT_EQ(s.statements[5].line, 4);
}

TEST(ScriptParse, WhileErrorsNameLineAndColumn) {
  auto msg = [](const std::string& text) { return parse_message(text, "w.script"); };
  EXPECT_EQ(msg("WAIT 1;\n WHILE Speed DO\nPRINT Speed;"), "w.script:2:2: WHILE is never closed: END_WHILE; is missing");
  EXPECT_EQ(msg("PRINT Speed;\n  END_WHILE;"), "w.script:2:3: END_WHILE without a WHILE before it");
  EXPECT_EQ(msg("WHILE Speed;"), "w.script:1:1: WHILE needs DO after its condition: WHILE cond DO ... END_WHILE;");
  EXPECT_EQ(msg("WHILE DO END_WHILE;"), "w.script:1:1: WHILE needs a condition: WHILE cond DO ... END_WHILE;");
  EXPECT_NE(msg("WHILE Speed > slow DO END_WHILE;").find("WHILE: 'slow' is not a number"), std::string::npos);
  // A tag that merely starts with DO does not end the condition.
  EXPECT_EQ(msg("WHILE DONE DO END_WHILE;"), "accepted");
}

TEST(ScriptLoad, WhileConditionTagIsChecked) {
  FakeHost h;
  try {
    (void)load("WHILE Nope DO\nEND_WHILE;", "s", h);
    FAIL();
  } catch (const ScriptError& e) {
    EXPECT_STREQ(e.what(), "s:1:1: no tag named 'Nope'");
  }
}

TEST(ScriptRunner, WhileRepeatsUntilTheConditionFails) {
  // Three passes of a body that waits 10 ms; the host's Speed counts passes.
  ScriptRun r("WHILE Speed < 3 DO WAIT 0.01; PRINT Speed; END_WHILE; PRINT X.ActualPosition;");
  const auto end = r.until_end(1000, [&](std::uint64_t) {
    if (!r.lines.empty()) r.host.tags["Speed"] = static_cast<double>(r.lines.size());
  });
  EXPECT_EQ(r.runner->status(), Runner::Status::kDone);
  EXPECT_EQ(r.lines, (std::vector<std::string>{"t=0.010 Speed=0", "t=0.021 Speed=1", "t=0.032 Speed=2",
                                               "t=0.033 X.ActualPosition=0"}));
  EXPECT_EQ(end, 33u);
}

TEST(ScriptRunner, AWhileThatWaitsOnNothingTakesOneCyclePerPass) {
  ScriptRun r("WHILE NOT mso1.DN DO PRINT Speed; END_WHILE;");
  const auto end = r.until_end(1000, [&](std::uint64_t c) {
    if (c == 5) r.host.tags["mso1.DN"] = 1;
  });
  EXPECT_EQ(end, 5u);
  EXPECT_EQ(r.lines.size(), 5u);  // cycles 0..4, one pass each
  EXPECT_EQ(r.runner->status(), Runner::Status::kDone);
}

TEST(ScriptFormat, Values) {
  EXPECT_EQ(format_value(3), "3");
  EXPECT_EQ(format_value(-0.5), "-0.5");
  EXPECT_EQ(format_value(-1e-9), "0") << "no '-0' for a value that rounds to zero";
  EXPECT_EQ(format_value(-0.0), "0");
  EXPECT_EQ(format_value(-0.0000004), "0");
  EXPECT_EQ(format_value(-0.000001), "-0.000001");
  EXPECT_EQ(format_value(1.0 / 3.0), "0.333333");
  EXPECT_EQ(format_value(100.25), "100.25");
}

}  // namespace
}  // namespace canmotion::rt::script
