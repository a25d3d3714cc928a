// The command server's verb table (command_verbs.hpp) and what is generated
// from it: HELP and the "unknown request" message. Dispatch is in
// command_requests.cpp, the handlers in command_handlers.cpp and
// command_stream.cpp. The protocol reference is tools/canmotionctl/README.md.
#include "rt/controller/command_verbs.hpp"

#include <fmt/format.h>

#include "rt/controller/command_help.hpp"
#include "rt/controller/command_service.hpp"

namespace canmotion::rt::command {
namespace {

// A data table: one row per verb, in HELP order (exempt from the function length limit).
constexpr Verb kVerbs[] = {
    {"", "", "e.g. MAJ(X, maj1, Forward, 10, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, Trapezoidal, 100, "
             "100, %ofTime, Disabled, Programmed): execute it, wait until the planner ran it, answer with the control "
             "tag: OK|ERR mam1 EN= DN= ER= PC= IP= AC= ERR= EXERR= STATE=",
     &Service::do_call, false},
    {"GET", "tag...", "OK tag=value ...", &Service::do_get, false},
    {"SET", "tag value", "write a writable tag (numeric user tag or array element): OK tag=value", &Service::do_set,
     false},
    {"STATUS", "", "one line per axis (axis=... key=value ...), then OK", &Service::do_status, false},
    {"WATCH", "interval_s tag...",
     "OK, then a line t=<s> tag=value ... every interval (controller time) until UNWATCH", &Service::do_watch, false},
    {"UNWATCH", "", "stop watching: OK", &Service::do_unwatch, true},
    {"RUN", "[name]",
     "followed by script lines and a line END: run the motion script, streaming its PRINT lines (t=...), then OK or "
     "ERR <script error>",
     &Service::do_run, false},
    {"END", "", "ends the script lines of RUN (a script line that must read END is sent as 'END ')", &Service::do_end,
     false},
    {"STATS", "", "controller statistics, key=value lines, then OK", &Service::do_stats, false},
    {"MODE", "[run|program]",
     "the controller mode (OK mode=run|program); program stops every axis by its Programmed Stop Mode, breaks the "
     "MDAC links and refuses motion (ERR 24) until run",
     &Service::do_mode, false},
    {"HELP", "", "this text", &Service::do_help, false},
    {"QUIT", "", "OK, then the server closes the connection", &Service::do_quit, true},
};

constexpr std::size_t kSyntaxWidth = 26;  // "WATCH interval_s tag..." (23) and spaces
constexpr std::size_t kLineWidth = 112;   // HELP's lines, wrapped at spaces

}  // namespace

std::span<const Verb> verbs() noexcept { return kVerbs; }

const Verb* find_verb(std::string_view word) noexcept {
  for (const Verb& v : kVerbs)
    if (!v.name.empty() && iequals(v.name, word)) return &v;
  return nullptr;
}

const Verb& call_verb() noexcept {
  static_assert(kVerbs[0].name.empty(), "the first row is the instruction call");
  return kVerbs[0];
}

std::vector<std::string> help_lines() {
  std::vector<std::string> out{"requests (one per line; every response ends with a line OK ... or ERR <message>):"};
  for (const Verb& v : kVerbs) {
    const std::string syntax = v.name.empty() ? std::string("<instruction call>")
                               : v.args.empty() ? std::string(v.name)
                                                : fmt::format("{} {}", v.name, v.args);
    help_row(out, syntax, v.help, kSyntaxWidth, kLineWidth);
  }
  out.emplace_back(
      "tags: X.ActualPosition X.CommandPosition X.ActualVelocity X.CommandVelocity X.PositionError X.MotionStatus");
  out.emplace_back("      X.AxisStatus X.AxisFault X.AxisState X.<status bit> mam1.DN .ER .ERR .EXERR .STATE "
                   "Controller.Time ...");
  return out;
}

std::string unknown_request(std::string_view word) {
  return fmt::format("unknown request '{}': expected an instruction call like MSO(X, mso1), {}", word,
                     name_list(kVerbs, [](const Verb& v) { return v.name; }));
}

}  // namespace canmotion::rt::command
