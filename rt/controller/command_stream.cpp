// The command server's streaming requests: WATCH (a line of tag values every
// interval of controller time) and RUN (a motion script run for one client,
// its PRINT lines streamed as they come).
#include <algorithm>

#include <fmt/format.h>

#include "rt/controller/command_service.hpp"

namespace canmotion::rt::command {

// ---- WATCH -----------------------------------------------------------------

void Service::do_watch(Client& c, const Request& r) {
  const auto& w = r.words;
  if (w.size() < 3)
    return send_line(c, "ERR WATCH needs an interval in seconds and at least one tag: WATCH 0.1 X.ActualPosition");
  const auto iv = number(w[1]);
  if (!iv || *iv <= 0)
    return send_line(c, fmt::format("ERR WATCH interval '{}' is not a positive number of seconds", w[1]));
  constexpr std::size_t kMaxWatch = 64;  // tags per line: a screenful
  if (w.size() - 2 > kMaxWatch) return send_line(c, fmt::format("ERR WATCH takes at most {} tags", kMaxWatch));
  for (std::size_t i = 2; i < w.size(); ++i) {
    std::string e;
    if (!host.tags().resolve(w[i], &e)) return send_line(c, "ERR " + e);
  }
  c.watch.assign(w.begin() + 2, w.end());
  c.interval = std::max(*iv, ctl.period_s());
  c.mode = Mode::kWatch;
  send_line(c, fmt::format("OK watching {} tag{} every {} s", c.watch.size(), c.watch.size() == 1 ? "" : "s",
                           script::format_value(c.interval)));
  c.next = now;
  advance_watch(c);
}

void Service::do_unwatch(Client& c, const Request&) {
  if (c.mode != Mode::kWatch) return send_line(c, "ERR no WATCH is running");
  c.mode = Mode::kIdle;
  c.watch.clear();
  send_line(c, "OK unwatched");
}

void Service::advance_watch(Client& c) {
  // Half a nanosecond of slack absorbs the rounding of cycle * period.
  if (now + 5e-10 < c.next) return;
  const Status& s = status();
  std::string l = fmt::format("t={:.3f}", now);
  for (const std::string& t : c.watch) {
    std::string e;
    const auto v = host.tags().read(s, t, &e);
    l += fmt::format(" {}={}", t, v ? script::format_value(*v) : std::string("?"));
  }
  send_line(c, l);
  c.next += c.interval;
  if (c.next + 5e-10 <= now) c.next = now + c.interval;  // polled late: no burst of stale lines
}

// ---- RUN -------------------------------------------------------------------

void Service::do_run(Client& c, const Request& r) {
  const auto& w = r.words;
  if (w.size() > 2) return send_line(c, "ERR RUN takes at most one word (a name for messages): RUN [name]");
  c.mode = Mode::kScriptText;  // the lines up to END: collect_script_line
  c.script_name = w.size() == 2 ? w[1] : fmt::format("<client {}>", c.id);
  c.script_text.clear();
}

void Service::do_end(Client& c, const Request&) { send_line(c, "ERR END without RUN"); }

void Service::start_script(Client& c) {
  c.mode = Mode::kIdle;
  if (!refusal.empty()) {
    c.script_text.clear();
    return send_line(c, "ERR " + refusal);
  }
  auto run = std::make_unique<ScriptRun>();
  run->host = std::make_unique<ClientHost>(*this);
  try {
    run->script = script::load(c.script_text, c.script_name, *run->host);
  } catch (const std::exception& e) {
    c.script_text.clear();
    return send_line(c, fmt::format("ERR {}", e.what()));
  }
  c.script_text.clear();
  Client* cp = &c;
  run->runner = std::make_unique<script::Runner>(run->script, *run->host,
                                                 [this, cp](const std::string& l) { send_line(*cp, l); });
  c.run = std::move(run);
  c.mode = Mode::kScript;
  advance_script(c);
}

void Service::advance_script(Client& c) {
  const auto st = c.run->runner->step(now);
  if (st == script::Runner::Status::kRunning) return;
  c.mode = Mode::kIdle;
  if (st == script::Runner::Status::kDone)
    send_line(c, fmt::format("OK script done ({} statements)", c.run->script.statements.size()));
  else
    send_line(c, "ERR " + c.run->runner->error());
  c.run.reset();
}

// ---- the host of a client's script -----------------------------------------

std::optional<std::string> ClientHost::check_call(std::string_view call) { return s_.host.check_call(call); }

std::optional<std::string> ClientHost::check_tag(std::string_view tag, bool for_write) {
  return s_.host.check_tag(tag, for_write);
}

std::optional<std::string> ClientHost::execute(std::string_view call, std::string* control_tag) {
  if (auto e = s_.host.execute(call, control_tag)) return e;
  seq_ = s_.host.last_seq();
  return std::nullopt;
}

bool ClientHost::settled() { return s_.status().done_seq >= seq_; }

std::optional<double> ClientHost::read(std::string_view tag, std::string* error) {
  return s_.host.tags().read(s_.status(), tag, error);
}

std::optional<std::string> ClientHost::write(std::string_view tag, double value) {
  const std::uint64_t before = s_.host.last_seq();
  auto e = s_.host.write(tag, value);
  // a write that queued a command (array element): settled() waits for the RT thread
  if (!e && s_.host.last_seq() != before) seq_ = s_.host.last_seq();
  return e;
}

void ClientHost::declare(std::string_view tag) { s_.host.declare(tag); }

}  // namespace canmotion::rt::command
