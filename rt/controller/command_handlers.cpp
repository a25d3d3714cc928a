// The handlers of the command server's verbs (rows of command_verbs.cpp) that
// answer at once or once the RT thread applied them: instruction calls, GET,
// SET, STATUS, STATS, MODE, HELP, QUIT. WATCH and RUN: command_stream.cpp.
#include <algorithm>

#include <fmt/format.h>

#include "rt/controller/command_service.hpp"

namespace canmotion::rt::command {
namespace {

/// Quote a value that has spaces (STATUS fields); `"` inside becomes `'`.
std::string quoted(std::string_view s) {
  std::string o = "\"";
  for (char c : s) o += (c == '"' || c == '\n' || c == '\r') ? '\'' : c;
  return o + "\"";
}

std::string_view axis_state_name(motion::AxisState s) {
  using motion::AxisState;
  switch (s) {
    case AxisState::Ready: return "Ready";
    case AxisState::DriveEnable: return "DriveEnable";
    case AxisState::ServoControl: return "ServoControl";
    case AxisState::Faulted: return "Faulted";
    case AxisState::Shutdown: return "Shutdown";
    case AxisState::Inhibited: return "Inhibited";
    case AxisState::Ungrouped: return "Ungrouped";
    case AxisState::NoModule: return "NoModule";
    case AxisState::Configuring: return "Configuring";
  }
  return "?";
}

/// The names of the set bits, comma-separated; "-" when none.
std::string bit_names(std::uint32_t bits, const std::array<std::string_view, 32>& names) {
  std::string s;
  for (unsigned b = 0; b < 32; ++b) {
    if (!((bits >> b) & 1u)) continue;
    if (!s.empty()) s += ',';
    s += names[b].empty() ? fmt::format("bit{}", b) : std::string(names[b]);
  }
  return s.empty() ? "-" : s;
}

std::string_view mode_name(motion::ControllerMode m) {
  return m == motion::ControllerMode::Program ? "program" : "run";
}

}  // namespace

void Service::do_call(Client& c, const Request& r) {
  std::string call(r.line);
  if (!call.empty() && call.back() == ';') call.pop_back();
  if (!refusal.empty()) return send_line(c, "ERR " + refusal);
  c.control.clear();
  if (auto e = host.execute(call, &c.control)) return send_line(c, "ERR " + *e);
  make_pending(c, "");
}

/// The answer to a pending request, once the RT thread ran it.
void Service::finish_call(Client& c) {
  c.mode = Mode::kIdle;
  if (!c.reply.empty()) {  // a SET of an array element, a MODE change
    send_line(c, c.reply);
    c.reply.clear();
    return;
  }
  if (c.control.empty()) return send_line(c, "OK executed");
  const auto id = ctl.find_control(c.control);
  if (!id) return send_line(c, fmt::format("ERR control tag '{}' vanished", c.control));
  const motion::ControlTag& t = status().controls[*id];
  std::string fields = fmt::format("{} EN={} DN={} ER={} PC={} IP={} AC={} ERR={} EXERR={} STATE={}", c.control,
                                   int(t.en()), int(t.dn()), int(t.er()), int(t.pc()), int(t.ip()), int(t.ac()),
                                   t.err, int(t.exerr), int(t.state));
  if (t.er())
    send_line(c, fmt::format("ERR {} ({})", fields, motion::err_name(t.error())));
  else
    send_line(c, "OK " + fields);
}

void Service::do_get(Client& c, const Request& r) {
  const auto& w = r.words;
  if (w.size() < 2) return send_line(c, "ERR GET needs at least one tag: GET X.ActualPosition mam1.DN");
  std::string reply = "OK";
  for (std::size_t i = 1; i < w.size(); ++i) {
    std::string e;
    const auto v = host.tags().read(status(), w[i], &e);
    if (!v) return send_line(c, "ERR " + e);
    reply += fmt::format(" {}={}", w[i], script::format_value(*v));
  }
  send_line(c, reply);
}

void Service::do_set(Client& c, const Request& r) {
  const auto& w = r.words;
  if (w.size() != 3) return send_line(c, "ERR SET needs a tag and a value: SET Distance 12.5");
  const auto v = number(w[2]);
  if (!v) return send_line(c, fmt::format("ERR SET {}: '{}' is not a finite number", w[1], w[2]));
  const std::uint64_t before = host.last_seq();
  if (auto e = host.write(w[1], *v)) return send_line(c, "ERR " + *e);
  std::string reply = fmt::format("OK {}={}", w[1], script::format_value(*v));
  if (host.last_seq() != before) return make_pending(c, std::move(reply));  // an array element: once applied
  send_line(c, reply);
}

/// MODE [run|program]: the controller mode (issue 16); a change is answered
/// once the RT thread applied it.
void Service::do_mode(Client& c, const Request& r) {
  const auto& w = r.words;
  if (w.size() == 1) return send_line(c, fmt::format("OK mode={}", mode_name(status().mode)));
  if (w.size() != 2 || !(iequals(w[1], "run") || iequals(w[1], "program")))
    return send_line(c, "ERR MODE takes run or program (or nothing to read the mode): MODE program");
  const auto m = iequals(w[1], "program") ? motion::ControllerMode::Program : motion::ControllerMode::Run;
  if (auto e = host.set_mode(m)) return send_line(c, "ERR " + *e);
  make_pending(c, fmt::format("OK mode={}", mode_name(m)));
}

/// One STATUS data line.
std::string Service::status_line(std::size_t axis, const AxisSnapshot& x) {
  const AxisSpec& spec = ctl.axis_spec(static_cast<motion::AxisId>(axis));
  const bool cip = spec.config.type == motion::AxisType::CipDrive;
  std::string l = fmt::format("axis={} type={} node={} state={}", spec.name, cip ? "CIP" : "virtual",
                              cip ? std::to_string(spec.drive.node) : std::string("-"), axis_state_name(x.tag.state));
  if (cip)
    l += fmt::format(" drive={} phase={}", quoted(cia402::state_name(x.drive_state)),
                     quoted(cia402::phase_name(x.phase)));
  else
    l += " drive=- phase=-";
  l += fmt::format(" cmd_pos={} act_pos={} cmd_vel={} act_vel={} pos_err={}",
                   script::format_value(x.tag.command_position), script::format_value(x.tag.actual_position),
                   script::format_value(x.tag.command_velocity), script::format_value(x.tag.actual_velocity),
                   script::format_value(x.tag.position_error));
  l += fmt::format(" motion_status=0x{:08X} axis_status=0x{:08X} axis_fault=0x{:08X}", x.tag.motion_status,
                   x.tag.axis_status, x.tag.axis_fault);
  l += fmt::format(" motion_bits={} status_bits={} faults={}", bit_names(x.tag.motion_status, motion_bits),
                   bit_names(x.tag.axis_status, status_bits), bit_names(x.tag.axis_fault, fault_bits));
  if (cip) {
    l += fmt::format(" statusword=0x{:04X} last_emcy=0x{:04X} tpdo_missed={}", x.statusword, x.last_emcy,
                     x.tpdo_missed);
    if (x.failure.kind != cia402::FailureKind::kNone) l += " failure=" + quoted(x.failure.to_string());
  }
  return l;
}

void Service::do_status(Client& c, const Request& r) {
  if (r.words.size() > 1) return send_line(c, "ERR STATUS takes no arguments");
  const Status& s = status();
  const std::size_t n = std::min<std::size_t>(ctl.axis_count(), s.axis_count);
  for (std::size_t a = 0; a < n; ++a) send_line(c, status_line(a, s.axes[a]));
  send_line(c, fmt::format("OK {} axes, cycle {}, t={}", n, s.cycle,
                           script::format_value(static_cast<double>(s.cycle) * ctl.period_s())));
}

void Service::do_stats(Client& c, const Request&) {
  const Status& s = status();
  send_line(c, fmt::format("cycle={}", s.cycle));  // the controller's; the executive's `cycles` follow
  send_line(c, fmt::format("time_s={}", script::format_value(static_cast<double>(s.cycle) * ctl.period_s())));
  send_line(c, fmt::format("period_ms={}", script::format_value(ctl.period_s() * 1e3)));
  send_line(c, fmt::format("axes={}", ctl.axis_count()));
  send_line(c, fmt::format("commands_deferred={}", s.commands_deferred));
  send_line(c, fmt::format("trace_dropped={}", s.trace_dropped));
  send_line(c, fmt::format("telemetry_dropped={}", s.telemetry_dropped));
  send_line(c, fmt::format("clients={}", clients.size()));
  if (opt.cycle_stats) {
    const CycleStats st = opt.cycle_stats();
    for (std::string_view n : stat_tag_names())
      send_line(c, fmt::format("{}={}", n, stat_tag_value(st, n).value_or(0)));
  }
  send_line(c, "OK");
}

void Service::do_help(Client& c, const Request&) {
  for (const std::string& h : help_lines()) send_line(c, h);
  send_line(c, "OK");
}

void Service::do_quit(Client& c, const Request&) {
  if (c.mode == Mode::kWatch) {
    c.mode = Mode::kIdle;
    c.watch.clear();
  }
  send_line(c, "OK bye");
  c.closing = true;
}

}  // namespace canmotion::rt::command
