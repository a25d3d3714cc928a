#pragma once
// Test rig for the command server: a Controller with one virtual axis
// (Master) and one emulated CiA 402 drive (X, node 2) on a SimBus, a
// CommandServer on a temporary socket, and plain-socket clients. The test
// thread steps the cycle on a virtual clock and polls the server after each
// cycle, exactly like canmotiond's --sim housekeeping.
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rt/controller/command_server.hpp"
#include "rt/controller/controller.hpp"
#include "rt/controller/sim_world.hpp"
#include "tests/support/sim_controller.hpp"

namespace canmotion::rt::ctltest {

constexpr std::int64_t kPeriod = test::SimController::kPeriod;

/// A temporary directory, removed with everything in it.
struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/canmotion-ctl-XXXXXX";
    const char* p = ::mkdtemp(tmpl);
    if (!p) throw std::runtime_error("mkdtemp failed");
    path = p;
  }
  ~TempDir() { (void)std::system(("rm -rf '" + path + "'").c_str()); }
};

/// A plain non-blocking client socket.
class Client {
 public:
  explicit Client(const std::string& path) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, path.c_str(), sizeof(a.sun_path) - 1);
    connected_ = ::connect(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof(a)) == 0;
    ::fcntl(fd_, F_SETFL, O_NONBLOCK);
  }
  ~Client() { close(); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;
  [[nodiscard]] bool connected() const { return connected_; }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  /// Send everything (the test's data is small: the socket buffer takes it).
  void send(const std::string& s) {
    std::size_t off = 0;
    while (off < s.size()) {
      const ssize_t n = ::send(fd_, s.data() + off, s.size() - off, MSG_NOSIGNAL);
      if (n < 0) {
        if (errno == EAGAIN) continue;
        return;
      }
      off += static_cast<std::size_t>(n);
    }
  }
  /// Read what is there; returns false once the server closed the connection.
  bool pump() {
    char buf[65536];
    for (;;) {
      const ssize_t n = ::recv(fd_, buf, sizeof(buf), MSG_DONTWAIT);
      if (n > 0) {
        in_.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n == 0) eof_ = true;
      return !eof_;
    }
  }
  /// The next complete line, if any.
  std::optional<std::string> line() {
    pump();
    const std::size_t nl = in_.find('\n');
    if (nl == std::string::npos) return std::nullopt;
    std::string l = in_.substr(0, nl);
    in_.erase(0, nl + 1);
    return l;
  }
  [[nodiscard]] bool eof() const { return eof_; }
  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_ = -1;
  bool connected_ = false;
  bool eof_ = false;
  std::string in_;
};

inline bool is_final(const std::string& l) {
  return l == "OK" || l.rfind("OK ", 0) == 0 || l == "ERR" || l.rfind("ERR ", 0) == 0;
}

/// The standard test controller plus a CommandServer on a temporary socket,
/// polled after every cycle at the new controller time.
struct Rig : test::SimController {
  TempDir dir;
  std::string sock = dir.path + "/canmotiond.sock";
  std::unique_ptr<CommandServer> server;
  std::vector<std::string> log;

  /// `tweak` changes the server's options, `axis` axis X and its drive's
  /// emulator (test::SimController).
  explicit Rig(std::function<void(CommandServerOptions&)> tweak = {},
               const std::function<void(AxisSpec&, emulator::EmulatorConfig&)>& axis = {})
      : test::SimController(axis) {
    CommandServerOptions o;
    o.path = sock;
    o.log = [this](const std::string& l) { log.push_back(l); };
    if (tweak) tweak(o);
    server = std::make_unique<CommandServer>(*ctl, o);
  }
  void after_cycle() override { server->poll(now_s()); }
  bool run_until(const std::function<bool()>& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      if (done()) return true;
      step();
    }
    return done();
  }
  /// Step until `c` has a complete response; returns all its lines (the
  /// last is OK... or ERR...). Empty when none came within max_cycles.
  std::vector<std::string> response(Client& c, int max_cycles = 5000) {
    std::vector<std::string> lines;
    for (int i = 0; i < max_cycles; ++i) {
      while (auto l = c.line()) {
        lines.push_back(*l);
        if (is_final(*l)) return lines;
      }
      step();
    }
    ADD_FAILURE() << "no final line within " << max_cycles << " cycles; got " << lines.size() << " lines";
    return lines;
  }
  std::string request(Client& c, const std::string& line, int max_cycles = 5000) {
    c.send(line + "\n");
    auto r = response(c, max_cycles);
    return r.empty() ? std::string() : r.back();
  }
  /// Boot the drive to operational.
  void boot() {
    ASSERT_TRUE(run_until([&] { return status().axes[1].phase == cia402::Phase::kOperational; }, 5000))
        << "drive never became operational: " << status().axes[1].failure.to_string();
  }
};

/// MAM(axis, ctl, Absolute, pos, speed, ...) in ST syntax.
inline std::string mam(const std::string& axis, const std::string& ctl, const std::string& pos, double speed) {
  return "MAM(" + axis + ", " + ctl + ", 0, " + pos + ", " + std::to_string(speed) +
         ", unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 100, 100, %oftime, disabled, programmed, "
         "0, none, 0, 0)";
}

}  // namespace canmotion::rt::ctltest
