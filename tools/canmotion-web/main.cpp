// canmotion-web: a browser view of a running canmotiond. A separate program
// (never inside the daemon): it holds one request connection to the daemon's
// UNIX socket however many browsers connect, polls STATUS and STATS, and
// pushes them as JSON over a WebSocket at /ws; serves www/ and /metrics.
// Commands are refused unless --allow-commands.
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <civetweb.h>
#include <fmt/format.h>

#include "tools/canmotion-web/protocol.hpp"
#include "tools/canmotionctl/connection.hpp"

namespace {

using namespace canmotion::web;

std::atomic<bool> g_quit{false};
void on_signal(int) { g_quit = true; }

struct State {
  std::string socket;
  bool allow_commands = false;
  std::mutex mu;  // guards everything below and the daemon connection
  std::unique_ptr<canmotionctl::Connection> daemon;
  bool reachable = false;
  std::string daemon_error;
  std::vector<Fields> axes;
  std::map<std::string, std::string> stats;
  std::set<mg_connection*> clients;
};

void send_ws(mg_connection* c, const std::string& msg) {
  mg_websocket_write(c, MG_WEBSOCKET_OPCODE_TEXT, msg.data(), msg.size());
}

std::string snapshot_json(State& s) {
  if (!s.reachable)
    return R"({"type":"daemon","reachable":false,"error":)" + json_string(s.daemon_error) + "}";
  std::string out = R"({"type":"status","reachable":true,"commands":)";
  out += s.allow_commands ? "true" : "false";
  out += R"(,"axes":[)";
  for (std::size_t k = 0; k < s.axes.size(); ++k) out += (k ? "," : "") + fields_to_json(s.axes[k]);
  out += R"(],"stats":{)";
  bool first = true;
  for (const auto& [key, v] : s.stats) {
    out += (first ? "" : ",") + json_string(key) + ":" + json_string(v);
    first = false;
  }
  return out + "}}";
}

// One STATUS and one STATS round trip; reconnects when the daemon went away.
void poll_daemon(State& s) {
  std::lock_guard lock(s.mu);
  try {
    if (!s.daemon) s.daemon = std::make_unique<canmotionctl::Connection>(s.socket, 2.0);
    std::vector<Fields> axes;
    std::string err;
    s.daemon->send_line("STATUS");
    s.daemon->response([&](const std::string& l) {
      if (auto f = parse_fields(l, &err)) axes.push_back(std::move(*f));
    });
    std::vector<std::string> lines;
    s.daemon->send_line("STATS");
    s.daemon->response([&](const std::string& l) { lines.push_back(l); });
    s.axes = std::move(axes);
    s.stats = parse_stats(lines, &err);
    s.reachable = true;
  } catch (const canmotionctl::Failure& f) {
    s.daemon.reset();
    if (s.reachable || s.daemon_error != f.message)
      fmt::print(stderr, "canmotion-web: daemon not reachable on {}: {}\n", s.socket, f.message);
    s.reachable = false;
    s.daemon_error = f.message;
    s.axes.clear();  // nothing stale in /metrics while the daemon is away
    s.stats.clear();
  }
  const std::string msg = snapshot_json(s);
  for (auto* c : s.clients) send_ws(c, msg);
}

const std::set<std::string> k_axis_verbs = {"MSO", "MSF", "MAFR", "MAS", "MAH", "MASR"};

// The daemon request line of a command, or an error naming the key.
std::string command_line(const Request& r, std::string* error) {
  const std::string verb = r.get("verb");
  if (verb == "MODE") {
    const std::string m = r.get("mode");
    if (m != "run" && m != "program") { *error = "key 'mode': expected run or program"; return {}; }
    return "MODE " + m;
  }
  if (!k_axis_verbs.count(verb)) {
    *error = "key 'verb': unknown command '" + verb + "' (MSO MSF MAFR MAS MAH MASR MODE)";
    return {};
  }
  const std::string axis = r.get("axis");
  if (axis.empty() || axis.find_first_not_of(
          "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos) {
    *error = "key 'axis': expected an axis name";
    return {};
  }
  std::string tag = "web_" + verb;
  for (auto& ch : tag) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return fmt::format("{}({}, {})", verb, axis, tag);
}

std::string answer(const std::string& id, bool ok, const std::string& text) {
  return fmt::format(R"({{"type":"answer","id":{},"ok":{},"text":{}}})", json_string(id),
                     ok ? "true" : "false", json_string(text));
}

std::string handle_command(State& s, const Request& r, const char* peer) {
  std::string err;
  const std::string line = command_line(r, &err);
  if (line.empty()) return answer(r.get("id"), false, err);
  if (!s.allow_commands) {
    fmt::print(stderr, "canmotion-web: refused command from {} (no --allow-commands): {}\n", peer, line);
    return answer(r.get("id"), false, "commands are disabled: start canmotion-web with --allow-commands");
  }
  fmt::print(stderr, "canmotion-web: command from {}: {}\n", peer, line);
  std::lock_guard lock(s.mu);
  try {
    if (!s.daemon) s.daemon = std::make_unique<canmotionctl::Connection>(s.socket, 2.0);
    s.daemon->send_line(line);
    return answer(r.get("id"), true, s.daemon->response([](const std::string&) {}));
  } catch (const canmotionctl::Failure& f) {
    fmt::print(stderr, "canmotion-web: command from {} failed: {}: {}\n", peer, line, f.message);
    return answer(r.get("id"), false, f.message);
  }
}

int ws_data(mg_connection* c, int bits, char* data, size_t len, void* user) {
  auto& s = *static_cast<State*>(user);
  if ((bits & 0x0f) == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if ((bits & 0x0f) != MG_WEBSOCKET_OPCODE_TEXT) return 1;
  const char* peer = mg_get_request_info(c)->remote_addr;
  std::string err;
  const auto r = parse_request(std::string_view(data, len), &err);
  std::string reply;
  if (!r) reply = answer("", false, err);
  else if (r->get("type") == "command") reply = handle_command(s, *r, peer);
  else reply = answer(r->get("id"), false, "key 'type': unknown request type '" + r->get("type") + "' (command)");
  std::lock_guard lock(s.mu);
  send_ws(c, reply);
  return 1;
}

void ws_ready(mg_connection* c, void* user) {
  auto& s = *static_cast<State*>(user);
  std::lock_guard lock(s.mu);
  s.clients.insert(c);
  send_ws(c, snapshot_json(s));
}

void ws_close(const mg_connection* c, void* user) {
  auto& s = *static_cast<State*>(user);
  std::lock_guard lock(s.mu);
  s.clients.erase(const_cast<mg_connection*>(c));
}

int ws_connect(const mg_connection*, void*) { return 0; }

std::string prom_name(const std::string& key) {
  std::string n = "canmotion_" + key;
  for (auto& ch : n) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return n;
}

int metrics(mg_connection* c, void* user) {
  auto& s = *static_cast<State*>(user);
  std::string out;
  {
    std::lock_guard lock(s.mu);
    out += fmt::format("canmotion_daemon_up {}\n", s.reachable ? 1 : 0);
    for (const auto& [k, v] : s.stats) {
      char* end = nullptr;
      std::strtod(v.c_str(), &end);
      if (!v.empty() && *end == 0) out += prom_name(k) + " " + v + "\n";
    }
    for (const auto& axis : s.axes) {
      std::string name, err = "0", faults = "-";
      for (const auto& [k, v] : axis) {
        if (k == "axis") name = v;
        if (k == "pos_err") err = v;
        if (k == "faults") faults = v;
      }
      const int nfaults = faults == "-" ? 0 : 1 + static_cast<int>(std::count(faults.begin(), faults.end(), ','));
      out += fmt::format("canmotion_axis_position_error{{axis=\"{}\"}} {}\n", name, err);
      out += fmt::format("canmotion_axis_faults{{axis=\"{}\"}} {}\n", name, nfaults);
    }
  }
  mg_send_http_ok(c, "text/plain; version=0.0.4", static_cast<long long>(out.size()));
  mg_write(c, out.data(), out.size());
  return 200;
}

}  // namespace

int main(int argc, char** argv) {
  State s;
  if (const char* env = std::getenv("CANMOTIOND_SOCKET"); env && *env) s.socket = env;
  if (s.socket.empty()) s.socket = "/run/canmotion/canmotiond.sock";
  std::string listen = "127.0.0.1:8080";
  std::string www = CANMOTION_WEB_WWW;
  double interval = 0.25;
  CLI::App app{"canmotion-web: browser view of a running canmotiond (WebSocket at /ws, /metrics)", "canmotion-web"};
  app.add_option("-s,--socket", s.socket, "canmotiond's socket ($CANMOTIOND_SOCKET, else /run/canmotion/canmotiond.sock)");
  app.add_option("-l,--listen", listen, "ADDR:PORT to listen on (default 127.0.0.1:8080)");
  app.add_flag("--allow-commands", s.allow_commands, "accept motion commands from browsers (off by default)");
  app.add_option("--www", www, "folder of the page's files")->check(CLI::ExistingDirectory);
  app.add_option("--interval", interval, "seconds between STATUS/STATS polls")->check(CLI::Range(0.02, 10.0));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);
  mg_init_library(0);
  mg_callbacks cb{};
  const char* opts[] = {"listening_ports", listen.c_str(), "document_root", www.c_str(),
                        "websocket_timeout_ms", "3600000", nullptr};
  mg_context* ctx = mg_start(&cb, &s, opts);
  if (!ctx) {
    fmt::print(stderr, "canmotion-web: --listen {}: cannot listen there (address in use or invalid)\n", listen);
    return 1;
  }
  mg_set_websocket_handler(ctx, "/ws", ws_connect, ws_ready, ws_data, ws_close, &s);
  mg_set_request_handler(ctx, "/metrics", metrics, &s);
  fmt::print(stderr, "canmotion-web: http://{}/ (daemon {}, commands {})\n", listen, s.socket,
             s.allow_commands ? "allowed" : "refused");
  while (!g_quit) {
    poll_daemon(s);
    std::this_thread::sleep_for(std::chrono::duration<double>(interval));
  }
  mg_stop(ctx);
  mg_exit_library();
  return 0;
}
