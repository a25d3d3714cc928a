#pragma once
// canmotionctl: one connection to canmotiond's socket, and the failures the
// tool reports (message to stderr, exit 1).
#include <csignal>
#include <string>

namespace canmotionctl {

/// A failure to report: message to stderr, exit 1.
struct Failure {
  std::string message;
};

/// Set by SIGINT while `watch` runs (install_sigint()).
extern volatile std::sig_atomic_t g_stop;
/// SIGINT sets g_stop and interrupts a waiting read_line() (no SA_RESTART).
void install_sigint();

/// One connection to canmotiond, reading lines with a deadline.
class Connection {
 public:
  /// Connects; throws Failure saying what to do (is canmotiond running, the
  /// socket's group).
  Connection(const std::string& path, double timeout_s);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  void send(const std::string& data);
  void send_line(const std::string& l) { send(l + "\n"); }

  /// The next line (without newline). Throws Failure on timeout or when the
  /// daemon closed the connection.
  std::string read_line();

  /// Read until the final line; data lines go to `data` (called as they come).
  /// Returns the text after OK; throws Failure with the text after ERR.
  template <typename F>
  std::string response(F&& data) {
    for (;;) {
      std::string l = read_line();
      if (l == "OK" || l.rfind("OK ", 0) == 0) return l.size() > 3 ? l.substr(3) : std::string();
      if (l == "ERR" || l.rfind("ERR ", 0) == 0) throw Failure{l.size() > 4 ? l.substr(4) : std::string("error")};
      data(l);
    }
  }
  /// The same, printing the data lines.
  std::string response();

 private:
  std::string path_;
  double timeout_s_;
  int fd_ = -1;
  std::string buf_;
};

}  // namespace canmotionctl
