// The two command tables, canmotionctl's (tools/canmotionctl/commands.cpp)
// and the command server's (rt/controller/command_verbs.cpp), agree: every
// request verb the server knows is sent by a canmotionctl command and every
// request canmotionctl sends is a server verb; and each side's help and
// "unknown" message list exactly its table's rows. (The lists had drifted
// before the tables: canmotionctl's "unknown command" message left out mode.)
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "rt/controller/command_verbs.hpp"
#include "tools/canmotionctl/commands.hpp"

namespace {

namespace cmd = canmotion::rt::command;

/// The server's named verbs.
std::set<std::string> server_verbs() {
  std::set<std::string> s;
  for (const cmd::Verb& v : cmd::verbs())
    if (!v.name.empty()) s.emplace(v.name);
  return s;
}

/// Every request verb canmotionctl's table says it sends.
std::set<std::string> ctl_requests() {
  std::set<std::string> s;
  for (const canmotionctl::Command& c : canmotionctl::commands())
    for (std::size_t i = 0; !canmotionctl::request(c, i).empty(); ++i) s.insert(canmotionctl::request(c, i));
  return s;
}

std::set<std::string> ctl_names() {
  std::set<std::string> s;
  for (const canmotionctl::Command& c : canmotionctl::commands())
    if (!c.name.empty()) s.emplace(c.name);
  return s;
}

/// The words of a list "a, b, c or d" that ends the text after `after`.
std::set<std::string> listed(const std::string& text, const std::string& after, const std::string& until = "") {
  std::string rest = text.substr(text.find(after) + after.size());
  if (!until.empty()) rest = rest.substr(0, rest.find(until));
  for (char& ch : rest)
    if (ch == ',') ch = ' ';
  std::istringstream in(rest);
  std::set<std::string> s;
  for (std::string w; in >> w;)
    if (w != "or") s.insert(w);
  return s;
}

std::string joined(const std::set<std::string>& s) {
  std::string o;
  for (const auto& w : s) o += (o.empty() ? "" : " ") + w;
  return o;
}

TEST(CommandTables, EveryServerVerbIsSentByACanmotionctlCommand) {
  std::set<std::string> missing;
  const auto sent = ctl_requests();
  for (const auto& v : server_verbs())
    if (!sent.count(v)) missing.insert(v);
  EXPECT_TRUE(missing.empty()) << "server verbs that no canmotionctl command sends (add a command, or list the verb "
                                  "in the `requests` of the command that reaches it): "
                               << joined(missing);
}

TEST(CommandTables, EveryRequestCanmotionctlSendsIsAServerVerb) {
  for (const canmotionctl::Command& c : canmotionctl::commands())
    for (std::size_t i = 0; !canmotionctl::request(c, i).empty(); ++i) {
      const std::string r = canmotionctl::request(c, i);
      EXPECT_NE(cmd::find_verb(r), nullptr) << "canmotionctl " << c.name << " sends " << r
                                            << ", which the server does not know";
    }
}

TEST(CommandTables, BothSidesHaveTheInstructionCallAndUniqueNames) {
  EXPECT_TRUE(cmd::call_verb().name.empty());
  const canmotionctl::Command* call = canmotionctl::find_command("MSO(X,");
  ASSERT_NE(call, nullptr);
  EXPECT_TRUE(call->name.empty());
  EXPECT_TRUE(call->requests.empty());
  EXPECT_EQ(server_verbs().size() + 1, cmd::verbs().size()) << "a server verb is listed twice";
  EXPECT_EQ(ctl_names().size() + 1, canmotionctl::commands().size()) << "a canmotionctl command is listed twice";
  for (const canmotionctl::Command& c : canmotionctl::commands()) {
    if (c.name.empty()) continue;
    EXPECT_EQ(canmotionctl::find_command(c.name), &c) << c.name;
  }
  for (const cmd::Verb& v : cmd::verbs()) {
    if (v.name.empty()) continue;
    EXPECT_EQ(cmd::find_verb(v.name), &v) << v.name;
  }
  EXPECT_EQ(canmotionctl::find_command("frobnicate"), nullptr);
  EXPECT_EQ(cmd::find_verb("frobnicate"), nullptr);
  EXPECT_EQ(cmd::find_verb("get"), cmd::find_verb("GET"));  // the protocol is case-insensitive
}

TEST(CommandTables, CanmotionctlUnknownCommandListsExactlyTheCommands) {
  const std::string m = canmotionctl::unknown_command("frobnicate");
  EXPECT_EQ(m.rfind("unknown command 'frobnicate': ", 0), 0u) << m;
  EXPECT_EQ(joined(listed(m, "'MSO(X, mso1)', ", " (see --help)")), joined(ctl_names())) << m;
}

TEST(CommandTables, CanmotionctlHelpListsExactlyTheCommands) {
  const std::string u = canmotionctl::usage();
  const std::size_t from = u.find("\nCommands:\n"), to = u.find("\nOptions:\n");
  ASSERT_NE(from, std::string::npos) << u;
  ASSERT_NE(to, std::string::npos) << u;
  std::istringstream in(u.substr(from + 11, to - from - 11));
  std::set<std::string> names;
  bool call = false;
  for (std::string l; std::getline(in, l);) {
    if (l.size() < 3 || l[2] == ' ') continue;  // continuation lines
    const std::string w = l.substr(2, l.find(' ', 2) - 2);
    if (w == "'INSTR(operands)'")
      call = true;
    else
      names.insert(w);
  }
  EXPECT_TRUE(call) << u;
  EXPECT_EQ(joined(names), joined(ctl_names())) << u;
  for (const canmotionctl::Command& c : canmotionctl::commands())
    EXPECT_NE(u.find(std::string(c.help.substr(0, 20))), std::string::npos) << "help of " << c.name << " missing";
}

TEST(CommandTables, ServerHelpAndUnknownRequestListExactlyTheVerbs) {
  const std::string m = cmd::unknown_request("FROB");
  EXPECT_EQ(m.rfind("unknown request 'FROB': ", 0), 0u) << m;
  EXPECT_EQ(joined(listed(m, "MSO(X, mso1), ")), joined(server_verbs())) << m;
  std::set<std::string> names;
  bool call = false;
  for (const std::string& l : cmd::help_lines()) {
    if (l.size() < 3 || l.rfind("  ", 0) != 0 || l[2] == ' ') continue;  // title, tags, continuation lines
    if (l.rfind("  <instruction call>", 0) == 0)
      call = true;
    else
      names.insert(l.substr(2, l.find(' ', 2) - 2));
  }
  EXPECT_TRUE(call);
  EXPECT_EQ(joined(names), joined(server_verbs()));
}

TEST(CommandTables, TheReadmeShowsWhatHelpPrints) {
  const std::string path = std::string(CANMOTION_SOURCE_DIR) + "/tools/canmotionctl/README.md";
  std::ifstream f(path);
  ASSERT_TRUE(f) << path;
  const std::string readme((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const std::string u = canmotionctl::usage();
  const std::string shown = u.substr(0, u.find("\nExamples:\n"));  // Usage, Commands and Options
  EXPECT_NE(readme.find("```\n" + shown + "```\n"), std::string::npos)
      << path << ": the Usage block is not what canmotionctl --help prints; it prints:\n"
      << shown;
}

TEST(CommandTables, HelpLinesStayWithinTheirWidth) {
  for (const std::string& l : cmd::help_lines()) EXPECT_LE(l.size(), 112u) << l;
  std::istringstream in(canmotionctl::usage());
  bool commands = false;
  for (std::string l; std::getline(in, l);) {
    if (l == "Commands:") commands = true;
    if (l == "Options:") commands = false;
    if (commands) {
      EXPECT_LE(l.size(), 84u) << l;
    }
  }
}

}  // namespace
