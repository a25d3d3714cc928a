// The command server's socket: creating it (group, stale file, bind, mode),
// access checks, accepting connections, reading and writing.
#include <fcntl.h>
#include <grp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "rt/controller/command_service.hpp"

namespace canmotion::rt::command {

// ---- set-up ----------------------------------------------------------------

void Service::open() {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (opt.path.empty()) throw std::runtime_error("socket path is empty");
  if (opt.path.size() >= sizeof(addr.sun_path))
    throw std::runtime_error(fmt::format("socket path '{}' is too long ({} bytes; at most {})", opt.path,
                                         opt.path.size(), sizeof(addr.sun_path) - 1));
  std::memcpy(addr.sun_path, opt.path.data(), opt.path.size());
  resolve_group();  // first: nothing is created when the group does not exist
  replace_stale_socket(addr);
  bind_and_listen(addr);
  register_tags();
}

/// sock_gid and group_name from options.group (empty: the daemon's group).
void Service::resolve_group() {
  std::vector<char> buf(16384);
  group g{};
  group* r = nullptr;
  if (opt.group.empty()) {
    sock_gid = getegid();
    group_name = (getgrgid_r(sock_gid, &g, buf.data(), buf.size(), &r) == 0 && r) ? std::string(r->gr_name)
                                                                               : std::to_string(sock_gid);
    return;
  }
  const int e = getgrnam_r(opt.group.c_str(), &g, buf.data(), buf.size(), &r);
  if (e != 0 || !r)
    throw std::runtime_error(fmt::format("socket group '{}' does not exist{} (create it with `groupadd {}` and "
                                         "add the operators to it, or name an existing group)",
                                         opt.group, e != 0 ? ": " + errno_text(e) : std::string(), opt.group));
  sock_gid = r->gr_gid;
  group_name = opt.group;
}

/// A socket file left by a daemon that died: replace it only if nobody listens.
void Service::replace_stale_socket(const sockaddr_un& addr) {
  struct stat st {};
  if (lstat(opt.path.c_str(), &st) != 0) return;
  if (!S_ISSOCK(st.st_mode))
    throw std::runtime_error(
        fmt::format("'{}' exists and is not a socket; remove it or choose another --socket path", opt.path));
  const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (probe >= 0) {
    const bool live = ::connect(probe, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) == 0;
    ::close(probe);
    if (live)
      throw std::runtime_error(
          fmt::format("another process is already listening on '{}' (is canmotiond already running?)", opt.path));
  }
  ::unlink(opt.path.c_str());
}

void Service::bind_and_listen(const sockaddr_un& addr) {
  listen_fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd < 0) throw std::runtime_error(fmt::format("cannot create a UNIX socket: {}", errno_text(errno)));
  // Nobody but us may connect before the mode and group are set.
  const mode_t old_mask = ::umask(0177);
  const int b = ::bind(listen_fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr));
  const int bind_errno = errno;
  ::umask(old_mask);
  if (b != 0) {
    ::close(listen_fd);
    listen_fd = -1;
    std::string dir = opt.path.substr(0, opt.path.rfind('/') == std::string::npos ? 0 : opt.path.rfind('/'));
    if (dir.empty()) dir = ".";
    if (bind_errno == ENOENT)
      throw std::runtime_error(fmt::format("cannot create socket '{}': directory '{}' does not exist (the systemd "
                                           "unit creates /run/canmotion with RuntimeDirectory=canmotion; otherwise "
                                           "create it)",
                                           opt.path, dir));
    throw std::runtime_error(fmt::format("cannot create socket '{}': {}", opt.path, errno_text(bind_errno)));
  }
  if (::chown(opt.path.c_str(), static_cast<uid_t>(-1), sock_gid) != 0) {
    const int e = errno;
    close_listen();
    throw std::runtime_error(fmt::format("cannot give socket '{}' to group '{}': {} (the daemon's user must be root "
                                         "or a member of '{}')",
                                         opt.path, group_name, errno_text(e), group_name));
  }
  if (::chmod(opt.path.c_str(), 0660) != 0) {
    const int e = errno;
    close_listen();
    throw std::runtime_error(fmt::format("cannot set mode 0660 on socket '{}': {}", opt.path, errno_text(e)));
  }
  if (::listen(listen_fd, 16) != 0) {
    const int e = errno;
    close_listen();
    throw std::runtime_error(fmt::format("cannot listen on socket '{}': {}", opt.path, errno_text(e)));
  }
}

/// The executive's statistics as Controller.<field> tags, and the bit names of STATUS.
void Service::register_tags() {
  // The owner of a shared host registers the statistics there itself.
  if (opt.cycle_stats && !opt.shared_host) {
    for (std::string_view name : stat_tag_names()) {
      auto get = opt.cycle_stats;
      const std::string n(name);
      host.tags().add_statistic(n, [get, n] { return static_cast<double>(stat_tag_value(get(), n).value_or(0)); });
    }
  }
  // Bit names for STATUS, from the tag table (one source of truth).
  if (ctl.axis_count() == 0) return;
  const std::string axis = ctl.axis_name(0);
  for (std::string_view m : TagTable::axis_members()) {
    const auto t = host.tags().resolve(axis + "." + std::string(m), nullptr);
    if (!t || t->member >= 32) continue;
    if (t->kind == TagRef::Kind::kMotionBit) motion_bits[t->member] = m;
    if (t->kind == TagRef::Kind::kAxisStatusBit) status_bits[t->member] = m;
    if (t->kind == TagRef::Kind::kAxisFaultBit) fault_bits[t->member] = m;
  }
}

void Service::close_listen() {
  if (listen_fd >= 0) {
    ::close(listen_fd);
    listen_fd = -1;
    ::unlink(opt.path.c_str());
  }
}

// ---- output ----------------------------------------------------------------

void Service::send_line(Client& c, std::string_view line) {
  if (c.dead || c.closing) return;
  if (c.out.size() + line.size() + 1 > opt.max_output) {
    log(fmt::format("client {} (pid {}): does not read its output ({} bytes waiting); disconnected", c.id,
                    c.cred.pid, c.out.size()));
    c.out.clear();
    c.out +=
        fmt::format("ERR output buffer full ({} bytes): the client does not read; disconnected\n", opt.max_output);
    c.closing = true;
    flush(c);  // best effort
    c.dead = true;
    return;
  }
  c.out.append(line);
  c.out.push_back('\n');
}

void Service::fail_and_close(Client& c, const std::string& msg) {
  send_line(c, "ERR " + msg);
  c.closing = true;
}

void Service::flush(Client& c) {
  while (!c.out.empty() && c.fd >= 0) {
    const ssize_t n = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      c.out.erase(0, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (n < 0 && errno == EINTR) continue;
    c.out.clear();
    c.dead = true;  // EPIPE / ECONNRESET: the peer is gone
    return;
  }
}

// ---- connections -----------------------------------------------------------

bool Service::peer_allowed(int fd, const ucred& cr) const {
  if (cr.uid == 0 || cr.uid == ::geteuid() || cr.gid == sock_gid) return true;
  std::array<gid_t, 256> groups{};
  socklen_t len = sizeof(groups);
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERGROUPS, groups.data(), &len) == 0) {
    const std::size_t n = len / sizeof(gid_t);
    for (std::size_t i = 0; i < n && i < groups.size(); ++i)
      if (groups[i] == sock_gid) return true;
  }
  return false;
}

/// Log, answer one ERR line and close a connection that is not served.
void Service::refuse(Client& c, const std::string& log_line, const std::string& reply) {
  log(log_line);
  fail_and_close(c, reply);
  flush(c);
  ::close(c.fd);
}

void Service::accept_all() {
  for (;;) {
    const int fd = ::accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EINTR || errno == ECONNABORTED) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) log(fmt::format("accept: {}", errno_text(errno)));
      return;
    }
    auto c = std::make_unique<Client>();
    c->fd = fd;
    c->id = next_id++;
    socklen_t len = sizeof(c->cred);
    if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &c->cred, &len) != 0) {
      log(fmt::format("client {}: SO_PEERCRED failed ({}); refused", c->id, errno_text(errno)));
      ::close(fd);
      continue;
    }
    const ucred& cr = c->cred;
    if (!peer_allowed(fd, cr)) {
      refuse(*c,
             fmt::format("client {} refused: pid {} uid {} gid {} is not root, the daemon's user, nor in group '{}'",
                         c->id, cr.pid, cr.uid, cr.gid, group_name),
             fmt::format("permission denied: uid {} gid {} is not root, the daemon's user, nor in group '{}'", cr.uid,
                         cr.gid, group_name));
      continue;
    }
    if (clients.size() >= opt.max_clients) {
      refuse(*c,
             fmt::format("client {} (pid {}) refused: {} clients already connected", c->id, cr.pid, clients.size()),
             fmt::format("too many clients ({} connected); try again later", clients.size()));
      continue;
    }
    log(fmt::format("client {} connected: pid {} uid {} gid {}", c->id, cr.pid, cr.uid, cr.gid));
    clients.push_back(std::move(c));
  }
}

void Service::read_from(Client& c) {
  std::array<char, 4096> buf;
  // While busy, stop reading once a line's worth is buffered (back-pressure).
  while (!c.eof && c.in.size() <= opt.max_line) {
    const ssize_t n = ::recv(c.fd, buf.data(), buf.size(), MSG_DONTWAIT);
    if (n > 0) {
      c.in.append(buf.data(), static_cast<std::size_t>(n));
      continue;
    }
    if (n == 0) {
      c.eof = true;
      return;
    }
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) c.dead = true;
    return;
  }
}

}  // namespace canmotion::rt::command
