// CommandServer: the poll loop and the requests that wait for the planner.
// The parts are listed in command_service.hpp.
#include "rt/controller/command_server.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "rt/controller/command_service.hpp"

namespace canmotion::rt {
namespace command {

std::string errno_text(int e) { return std::strerror(e); }

void Service::log(const std::string& l) const {
  if (opt.log)
    opt.log(l);
  else
    fmt::print(stderr, "command server: {}\n", l);
}

const Status& Service::status() {
  if (!fresh) {
    ctl.read_status(*snap);
    fresh = true;
  }
  return *snap;
}

void Service::make_pending(Client& c, std::string reply) {
  c.reply = std::move(reply);
  c.seq = host.last_seq();
  c.since = Wall::now();
  c.mode = Mode::kPending;
}

void Service::advance_pending(Client& c) {
  if (status().done_seq >= c.seq) {
    finish_call(c);
  } else if (std::chrono::duration<double>(Wall::now() - c.since).count() > opt.instruction_timeout_s) {
    c.mode = Mode::kIdle;
    c.reply.clear();
    send_line(c, fmt::format("ERR timeout: the controller did not execute the instruction within {} s (is "
                             "the cycle running?)",
                             script::format_value(opt.instruction_timeout_s)));
  }
}

/// Advance the client's waiting request (no system call).
void Service::advance(Client& c) {
  try {
    switch (c.mode) {
      case Mode::kPending: advance_pending(c); break;
      case Mode::kScript: advance_script(c); break;
      case Mode::kWatch: advance_watch(c); break;
      default: break;
    }
  } catch (const std::exception& e) {
    log(fmt::format("client {}: request failed: {}; disconnected", c.id, e.what()));
    c.mode = Mode::kIdle;
    c.run.reset();
    fail_and_close(c, fmt::format("internal error: {}", e.what()));
  }
}

void Service::drop(Client& c, const char* why) {
  if (c.fd >= 0) {
    log(fmt::format("client {} (pid {}) {}{}", c.id, c.cred.pid, why,
                    c.mode == Mode::kPending   ? " while its instruction was pending (it still executes)"
                    : c.mode == Mode::kScript  ? "; its script was stopped (motion already started continues)"
                                               : ""));
    ::close(c.fd);
    c.fd = -1;
  }
}

/// Whether this poll() makes system calls (io_interval_s).
bool Service::io_due() {
  const auto wall = Wall::now();
  if (!first_io && opt.io_interval_s > 0 && std::chrono::duration<double>(wall - last_io).count() < opt.io_interval_s)
    return false;
  first_io = false;
  last_io = wall;
  return true;
}

/// One poll(2) over the listening socket and every client: read, handle, write, accept.
void Service::poll_sockets() {
  pfds.clear();
  pfds.push_back(pollfd{listen_fd, POLLIN, 0});
  for (auto& c : clients) {
    short ev = POLLRDHUP;
    if (!c->eof && c->in.size() <= opt.max_line) ev = static_cast<short>(ev | POLLIN);
    if (!c->out.empty()) ev = static_cast<short>(ev | POLLOUT);
    pfds.push_back(pollfd{c->fd, ev, 0});
  }
  const int r = ::poll(pfds.data(), static_cast<nfds_t>(pfds.size()), 0);
  if (r < 0 && errno != EINTR) log(fmt::format("poll: {}", errno_text(errno)));
  if (r > 0) {
    for (std::size_t i = 0; i < clients.size(); ++i) {
      Client& c = *clients[i];
      const short re = pfds[i + 1].revents;
      if (re & POLLNVAL) {
        c.dead = true;
        continue;
      }
      if (re & (POLLIN | POLLRDHUP | POLLHUP | POLLERR)) read_from(c);
      if (re & (POLLHUP | POLLERR)) c.dead = true;  // the peer closed its socket: nobody to answer
    }
  }
  for (auto& c : clients) {
    if (c->dead) continue;
    handle_input(*c);
    if (c->eof && c->mode == Mode::kScriptText && c->in.find('\n') == std::string::npos) {
      c->mode = Mode::kIdle;
      c->script_text.clear();
      fail_and_close(*c, "end of input inside RUN: the script text must end with a line END");
    }
  }
  for (auto& c : clients)
    if (!c->dead && !c->out.empty()) flush(*c);
  if (r > 0 && (pfds[0].revents & POLLIN)) accept_all();  // new clients are read at the next poll
}

void Service::remove_finished() {
  for (auto& c : clients) {
    if (c->dead) {
      drop(*c, "disconnected");
    } else if (c->closing && c->out.empty()) {
      drop(*c, "closed");
    } else if (c->eof && c->mode == Mode::kIdle && c->out.empty() && c->in.find('\n') == std::string::npos) {
      drop(*c, "finished");
    }
  }
  std::erase_if(clients, [](const std::unique_ptr<Client>& c) { return c->fd < 0; });
}

void Service::poll_once(double now_s) {
  now = now_s;
  fresh = false;
  for (auto& c : clients)
    if (c->mode == Mode::kPending || c->mode == Mode::kScript || c->mode == Mode::kWatch) {
      advance(*c);
      handle_input(*c);  // lines that waited for this request
    }
  if (!io_due()) return;
  poll_sockets();
  remove_finished();
}

}  // namespace command

// ---------------------------------------------------------------------------

CommandServer::CommandServer(Controller& controller, CommandServerOptions options)
    : impl_(std::make_unique<command::Service>(controller, std::move(options))) {
  impl_->open();
  impl_->log(fmt::format("listening on {} (mode 0660, group {})", impl_->opt.path, impl_->group_name));
}

CommandServer::~CommandServer() {
  for (auto& c : impl_->clients) {
    if (c->fd < 0) continue;
    if (c->mode != command::Mode::kIdle) {
      impl_->send_line(*c, "ERR canmotiond is stopping");
      impl_->flush(*c);
    }
    ::close(c->fd);
    c->fd = -1;
  }
  impl_->close_listen();
}

void CommandServer::poll(double now_s) { impl_->poll_once(now_s); }

void CommandServer::refuse_motion(std::string reason) {
  if (reason.empty()) reason = "motion is refused";
  impl_->refusal = std::move(reason);
  for (auto& c : impl_->clients) {
    if (c->fd < 0 || c->mode != command::Mode::kScript) continue;
    c->mode = command::Mode::kIdle;
    c->run.reset();
    impl_->send_line(*c, "ERR script stopped: " + impl_->refusal);
  }
}

std::size_t CommandServer::client_count() const noexcept { return impl_->clients.size(); }
const std::string& CommandServer::path() const noexcept { return impl_->opt.path; }
ControllerHost& CommandServer::host() noexcept { return impl_->host; }

}  // namespace canmotion::rt
