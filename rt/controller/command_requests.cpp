// Request lines: framing (line length, CR, blank lines and comments), the
// script text of RUN, parsing into words, and dispatch through the verb
// table (command_verbs.cpp).
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "rt/controller/command_service.hpp"

namespace canmotion::rt::command {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

/// Split on whitespace.
std::vector<std::string> words(std::string_view s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    const std::size_t b = i;
    while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i > b) out.emplace_back(s.substr(b, i - b));
  }
  return out;
}

}  // namespace

bool iequals(std::string_view a, std::string_view b) noexcept {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::optional<double> number(const std::string& w) {
  if (w.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(w.c_str(), &end);
  if (end != w.c_str() + w.size() || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Handle complete lines while the client is ready for them.
void Service::handle_input(Client& c) {
  while (!c.dead && !c.closing && (c.mode == Mode::kIdle || c.mode == Mode::kScriptText || c.mode == Mode::kWatch)) {
    const std::size_t nl = c.in.find('\n');
    if (nl == std::string::npos) {
      if (c.in.size() > opt.max_line) {
        log(fmt::format("client {} (pid {}): request longer than {} bytes; disconnected", c.id, c.cred.pid,
                        opt.max_line));
        c.in.clear();
        fail_and_close(c, fmt::format("request line longer than {} bytes; disconnected", opt.max_line));
      }
      return;
    }
    std::string line = c.in.substr(0, nl);
    c.in.erase(0, nl + 1);
    if (line.size() > opt.max_line) {
      fail_and_close(c, fmt::format("request line longer than {} bytes; disconnected", opt.max_line));
      return;
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    try {
      handle_line(c, line);
    } catch (const std::exception& e) {
      // Nothing a client sends may take the daemon down: this client goes.
      log(fmt::format("client {}: request failed: {}; disconnected", c.id, e.what()));
      fail_and_close(c, fmt::format("internal error: {}", e.what()));
    }
  }
}

/// A line between RUN and END.
void Service::collect_script_line(Client& c, const std::string& raw) {
  if (raw == "END") {  // exactly: a client sends a script line "END" as "END " (see README)
    start_script(c);
    return;
  }
  if (c.script_text.size() + raw.size() + 1 > opt.max_script) {
    c.mode = Mode::kIdle;
    c.script_text.clear();
    fail_and_close(c, fmt::format("script longer than {} bytes", opt.max_script));
    return;
  }
  c.script_text += raw;
  c.script_text += '\n';
}

void Service::handle_line(Client& c, const std::string& raw) {
  if (c.mode == Mode::kScriptText) return collect_script_line(c, raw);
  Request r;
  r.line = trim(raw);
  if (r.line.empty() || r.line.front() == '#') return;  // blank lines and comments: no response
  for (std::size_t i = 0; i < r.line.size(); ++i) {
    const auto ch = static_cast<unsigned char>(r.line[i]);
    if ((ch < 0x20 && ch != '\t') || ch == 0x7F)
      return send_line(c, fmt::format("ERR malformed request: control character 0x{:02X} at column {}", ch, i + 1));
  }
  r.words = words(r.line);
  const Verb* v = find_verb(r.words[0]);
  if (!v && r.line.find('(') != std::string_view::npos) v = &call_verb();
  if (c.mode == Mode::kWatch && !(v && v->while_watching))
    return send_line(c, "ERR a WATCH is running: send UNWATCH first");
  if (!v) return send_line(c, "ERR " + unknown_request(std::string_view(r.words[0]).substr(0, 64)));
  (this->*(v->handler))(c, r);
}

}  // namespace canmotion::rt::command
