// canmotionctl: the connection to canmotiond (see connection.hpp).
#include "tools/canmotionctl/connection.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include <fmt/format.h>

namespace canmotionctl {

volatile std::sig_atomic_t g_stop = 0;

namespace {

void on_sigint(int) { g_stop = 1; }

std::string error_word(int e) {
  switch (e) {
    case ENOENT: return "no such file";
    case ECONNREFUSED: return "connection refused";
    case EACCES: return "permission denied";
    default: return std::strerror(e);
  }
}

}  // namespace

void install_sigint() {
  struct sigaction sa {};
  sa.sa_handler = on_sigint;
  sigaction(SIGINT, &sa, nullptr);  // no SA_RESTART: poll returns EINTR
}

Connection::Connection(const std::string& path, double timeout_s) : path_(path), timeout_s_(timeout_s) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof(addr.sun_path))
    throw Failure{fmt::format("socket path '{}' is too long ({} bytes; at most {})", path, path.size(),
                              sizeof(addr.sun_path) - 1)};
  std::memcpy(addr.sun_path, path.data(), path.size());
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw Failure{fmt::format("cannot create a socket: {}", std::strerror(errno))};
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    std::string hint;
    if (e == ENOENT || e == ECONNREFUSED)
      hint = " (is canmotiond running with --socket " + path + "?)";
    else if (e == EACCES)
      hint = " (the socket is mode 0660: add your user to its group, e.g. `sudo usermod -aG canmotion $USER`, "
             "and log in again)";
    throw Failure{fmt::format("cannot connect to {}: {}{}", path, error_word(e), hint)};
  }
}

Connection::~Connection() {
  if (fd_ >= 0) ::close(fd_);
}

void Connection::send(const std::string& data) {
  std::size_t off = 0;
  while (off < data.size()) {
    const ssize_t n = ::send(fd_, data.data() + off, data.size() - off, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Failure{fmt::format("lost the connection to {}: {}", path_, std::strerror(errno))};
    off += static_cast<std::size_t>(n);
  }
}

std::string Connection::read_line() {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s_);
  for (;;) {
    if (const std::size_t nl = buf_.find('\n'); nl != std::string::npos) {
      std::string l = buf_.substr(0, nl);
      buf_.erase(0, nl + 1);
      if (!l.empty() && l.back() == '\r') l.pop_back();
      return l;
    }
    int wait_ms = -1;
    if (timeout_s_ > 0) {
      const auto left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) throw Failure{fmt::format("no answer from canmotiond within {} s", timeout_s_)};
      wait_ms = static_cast<int>(std::min(left * 1000.0 + 1.0, 1e9));
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, wait_ms);
    if (r < 0 && errno == EINTR && g_stop) throw Failure{"interrupted"};
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw Failure{fmt::format("poll: {}", std::strerror(errno))};
    if (r == 0) continue;  // the deadline check above reports it
    char tmp[4096];
    const ssize_t n = ::recv(fd_, tmp, sizeof(tmp), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Failure{fmt::format("lost the connection to {}: {}", path_, std::strerror(errno))};
    if (n == 0) throw Failure{fmt::format("canmotiond closed the connection on {} before answering", path_)};
    buf_.append(tmp, static_cast<std::size_t>(n));
  }
}

std::string Connection::response() {
  return response([](const std::string& l) { fmt::print("{}\n", l); });
}

}  // namespace canmotionctl
