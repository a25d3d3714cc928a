// CommandServer on a Controller with an emulated drive, cycle by cycle on a
// virtual clock; clients are plain UNIX sockets in the test thread.
#include <grp.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <cmath>
#include <thread>

#include "rt/controller/command_verbs.hpp"
#include "tests/ctl/ctl_rig.hpp"

namespace canmotion::rt::ctltest {
namespace {

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

/// Value of `key=` in a reply line.
std::string field(const std::string& line, const std::string& key) {
  const std::size_t p = line.find(" " + key + "=");
  if (p == std::string::npos) return "<missing " + key + ">";
  const std::size_t b = p + key.size() + 2;
  return line.substr(b, line.find(' ', b) - b);
}

/// MSO(X, mso1) and wait until the drive is enabled (DN).
void servo_on(Rig& r, Client& c) {
  ASSERT_EQ(r.request(c, "MSO(X, mso1)").rfind("OK mso1", 0), 0u);
  const auto id = *r.ctl->find_control("mso1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[id].dn(); }, 3000));
}

TEST(CommandServer, SocketIsMode0660AndOwnedByTheGroup) {
  Rig r;
  struct stat st {};
  ASSERT_EQ(::lstat(r.sock.c_str(), &st), 0);
  EXPECT_TRUE(S_ISSOCK(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0660u);
  EXPECT_EQ(st.st_gid, ::getegid());
  const std::string path = r.sock;
  r.server.reset();
  EXPECT_NE(::lstat(path.c_str(), &st), 0) << "the socket file is removed on destruction";
}

TEST(CommandServer, SetUpErrorsNameTheProblem) {
  Rig r;
  auto make = [&](const std::string& path, const std::string& group) -> std::string {
    CommandServerOptions o;
    o.path = path;
    o.group = group;
    o.log = [](const std::string&) {};
    try {
      CommandServer s(*r.ctl, o);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  const std::string g = make(r.dir.path + "/other.sock", "no-such-group-xyz");
  EXPECT_TRUE(contains(g, "socket group 'no-such-group-xyz' does not exist")) << g;
  struct stat st {};
  EXPECT_NE(::lstat((r.dir.path + "/other.sock").c_str(), &st), 0) << "nothing is created for a bad group";
  const std::string d = make(r.dir.path + "/missing/canmotiond.sock", "");
  EXPECT_TRUE(contains(d, "directory '" + r.dir.path + "/missing' does not exist")) << d;
  const std::string live = make(r.sock, "");
  EXPECT_TRUE(contains(live, "already listening on '" + r.sock + "'")) << live;
  const std::string longp = make("/tmp/" + std::string(200, 'a'), "");
  EXPECT_TRUE(contains(longp, "too long")) << longp;
  // A stale socket file (its server gone without removing it) is replaced.
  {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    const std::string stale = r.dir.path + "/stale.sock";
    std::strncpy(a.sun_path, stale.c_str(), sizeof(a.sun_path) - 1);
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    ::close(fd);
    EXPECT_EQ(make(stale, ""), "");
  }
  // A path that is not a socket is left alone.
  const std::string file = r.dir.path + "/file";
  ASSERT_EQ(std::system(("touch '" + file + "'").c_str()), 0);
  EXPECT_TRUE(contains(make(file, ""), "exists and is not a socket"));
}

TEST(CommandServer, InstructionRepliesWithTheControlTagAfterThePlannerRanIt) {
  Rig r;
  r.boot();
  Client c(r.sock);
  ASSERT_TRUE(c.connected());
  c.send("MSO(X, mso1)\n");
  const auto lines = r.response(c);
  ASSERT_EQ(lines.size(), 1u);
  const std::string& ok = lines[0];
  EXPECT_EQ(ok.rfind("OK mso1 ", 0), 0u) << ok;
  EXPECT_EQ(field(ok, "EN"), "1");
  EXPECT_EQ(field(ok, "ER"), "0");
  EXPECT_EQ(field(ok, "ERR"), "0");
  // The reply came after the planner executed it: the snapshot agrees.
  const auto id = *r.ctl->find_control("mso1");
  EXPECT_TRUE(r.status().controls[id].en());
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[id].dn(); }, 3000));

  // A move: the reply shows it in process, and the axis then gets there.
  const std::string mv = r.request(c, mam("X", "mam1", "10", 50) + ";");
  EXPECT_EQ(mv.rfind("OK mam1 ", 0), 0u) << mv;
  EXPECT_EQ(field(mv, "IP"), "1") << mv;
  EXPECT_EQ(field(mv, "PC"), "0") << mv;
  const auto m = *r.ctl->find_control("mam1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[m].pc(); }, 5000));
  EXPECT_DOUBLE_EQ(r.status().axes[1].tag.command_position, 10.0);

  // Rejected by the planner: ERR with ER, ERR and EXERR (13 = parameter out of range).
  const std::string bad = r.request(c, mam("X", "mam2", "10", -5));
  EXPECT_EQ(bad.rfind("ERR mam2 ", 0), 0u) << bad;
  EXPECT_EQ(field(bad, "ER"), "1") << bad;
  EXPECT_EQ(field(bad, "ERR"), "13") << bad;
  EXPECT_NE(field(bad, "EXERR"), "0") << bad;
  // Rejected by the parser or binder: ERR naming the problem.
  const std::string parse = r.request(c, "MAM(X, mam3)");
  EXPECT_EQ(parse.rfind("ERR ", 0), 0u) << parse;
  const std::string axis = r.request(c, "MSO(Nope, mso9)");
  EXPECT_TRUE(contains(axis, "Nope")) << axis;
}

TEST(CommandServer, RequestsWaitInOrderBehindAPendingInstruction) {
  Rig r;
  r.boot();
  Client c(r.sock);
  // Pipelined: the GET is answered only after the MSO's reply, and sees its effect.
  c.send("MSO(X, mso1)\nGET mso1.EN Controller.Cycle\n");
  const auto a = r.response(c);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a.back().rfind("OK mso1 ", 0), 0u) << a.back();
  const auto b = r.response(c);
  ASSERT_FALSE(b.empty());
  EXPECT_EQ(field(b.back(), "mso1.EN"), "1") << b.back();
}

TEST(CommandServer, GetAndSet) {
  Rig r;
  r.boot();
  Client c(r.sock);
  r.step();
  const std::string cyc = r.request(c, "GET Controller.Cycle Controller.Time X.AxisState x.drivestate");
  EXPECT_EQ(cyc.rfind("OK Controller.Cycle=", 0), 0u) << cyc;
  EXPECT_GT(std::stod(field(cyc, "Controller.Cycle")), 0.0) << cyc;
  EXPECT_EQ(r.request(c, "SET Distance 12.5"), "OK Distance=12.5");
  EXPECT_EQ(r.request(c, "GET Distance"), "OK Distance=12.5");
  EXPECT_EQ(r.request(c, "set distance -2.25"), "OK distance=-2.25");
  // A SET tag binds as an operand.
  servo_on(r, c);
  EXPECT_EQ(r.request(c, mam("X", "mam1", "Distance", 50)).rfind("OK", 0), 0u);
  const auto m = *r.ctl->find_control("mam1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[m].pc() || r.status().controls[m].er(); }, 5000));
  EXPECT_DOUBLE_EQ(r.status().axes[1].tag.command_position, -2.25);
  // Errors.
  EXPECT_TRUE(contains(r.request(c, "SET X.ActualPosition 1"), "read-only"));
  EXPECT_TRUE(contains(r.request(c, "SET Distance abc"), "ERR SET Distance: 'abc' is not a finite number"));
  EXPECT_TRUE(contains(r.request(c, "SET Distance"), "ERR SET needs a tag and a value"));
  EXPECT_TRUE(contains(r.request(c, "GET X.NoSuchAttribute"), "ERR axis 'X' has no attribute 'NoSuchAttribute'"));
  EXPECT_TRUE(contains(r.request(c, "GET"), "ERR GET needs at least one tag"));
}

TEST(CommandServer, StatusHasOneLinePerAxis) {
  Rig r;
  r.boot();
  Client c(r.sock);
  servo_on(r, c);
  ASSERT_EQ(r.request(c, mam("X", "mam1", "100", 50)).rfind("OK", 0), 0u);
  r.run_until([] { return false; }, 100);
  c.send("STATUS\n");
  const auto lines = r.response(c);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].rfind("axis=Master type=virtual node=- state=", 0), 0u) << lines[0];
  const std::string& x = lines[1];
  EXPECT_EQ(x.rfind("axis=X type=CIP node=2 state=ServoControl ", 0), 0u) << x;
  EXPECT_TRUE(contains(x, " drive=\"Operation enabled\" ")) << x;
  EXPECT_TRUE(contains(x, " phase=\"operational\" ")) << x;
  EXPECT_TRUE(contains(x, "MoveStatus")) << x;
  EXPECT_TRUE(contains(x, "ServoActionStatus")) << x;
  EXPECT_EQ(field(x, "faults"), "-") << x;
  EXPECT_EQ(field(x, "last_emcy"), "0x0000") << x;
  const Status s = r.status();
  EXPECT_NEAR(std::stod(field(x, "cmd_vel")), 50.0, 1e-9) << x;
  EXPECT_GT(std::stod(field(x, "cmd_pos")), 0.0);
  EXPECT_LE(std::stod(field(x, "cmd_pos")), s.axes[1].tag.command_position);
  EXPECT_EQ(lines[2].rfind("OK 2 axes, cycle ", 0), 0u) << lines[2];
  EXPECT_TRUE(contains(r.request(c, "STATUS X"), "ERR STATUS takes no arguments"));
}

TEST(CommandServer, WatchSendsALinePerIntervalUntilUnwatch) {
  Rig r;
  Client c(r.sock);
  c.send("WATCH 0.01 Controller.Time Controller.Cycle\n");
  const auto ok = r.response(c);
  ASSERT_EQ(ok.size(), 1u);
  EXPECT_EQ(ok[0], "OK watching 2 tags every 0.01 s");
  std::vector<std::string> lines;
  r.run_until(
      [&] {
        while (auto l = c.line()) lines.push_back(*l);
        return lines.size() >= 6;
      },
      1000);
  ASSERT_GE(lines.size(), 6u);
  double prev = -1;
  for (const auto& l : lines) {
    ASSERT_EQ(l.rfind("t=", 0), 0u) << l;
    const double t = std::stod(l.substr(2));
    if (prev >= 0) {
      EXPECT_NEAR(t - prev, 0.01, 1e-9) << l;
    }
    EXPECT_NEAR(std::stod(field(l, "Controller.Time")), t, 1e-9) << l;
    prev = t;
  }
  // Other requests are refused while watching; UNWATCH ends it, nothing follows its OK.
  c.send("GET Controller.Time\n");
  auto refused = r.response(c);
  EXPECT_EQ(refused.back(), "ERR a WATCH is running: send UNWATCH first");
  c.send("UNWATCH\n");
  auto un = r.response(c);
  EXPECT_EQ(un.back(), "OK unwatched");
  r.run_until([] { return false; }, 100);
  EXPECT_FALSE(c.line().has_value()) << "no WATCH line after UNWATCH's OK";
  EXPECT_EQ(r.request(c, "GET Controller.Cycle").rfind("OK", 0), 0u);
  // Bad WATCH requests.
  EXPECT_TRUE(contains(r.request(c, "WATCH 0 X.ActualPosition"), "not a positive number"));
  EXPECT_TRUE(contains(r.request(c, "WATCH 0.1 X.Bogus"), "no attribute 'Bogus'"));
  EXPECT_TRUE(contains(r.request(c, "WATCH 0.1"), "at least one tag"));
  EXPECT_EQ(r.request(c, "UNWATCH"), "ERR no WATCH is running");
}

TEST(CommandServer, RunStreamsPrintLinesThenOk) {
  Rig r;
  r.boot();
  Client c(r.sock);
  c.send("RUN test.script\n"
         "// a comment\n"
         "MSO(X, mso1);\n"
         "WAIT UNTIL mso1.DN TIMEOUT 2;\n"
         "PRINT X.DriveEnableStatus;\n"
         "Target := 5;\n"
         "MAM(X, mam1, 0, 5, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 100, 100,\n"
         "    %oftime, disabled, programmed, 0, none, 0, 0);\n"
         "WAIT 0.05;\n"
         "WAIT UNTIL mam1.PC TIMEOUT 5;\n"
         "PRINT X.CommandPosition;\n"
         "END\n");
  const auto lines = r.response(c, 20000);
  ASSERT_EQ(lines.size(), 3u) << (lines.empty() ? "" : lines.back());
  EXPECT_EQ(lines[0].rfind("t=", 0), 0u);
  EXPECT_TRUE(contains(lines[0], " X.DriveEnableStatus=1")) << lines[0];
  EXPECT_TRUE(contains(lines[1], " X.CommandPosition=5")) << lines[1];
  EXPECT_EQ(r.request(c, "GET Target"), "OK Target=5") << "the script's assignment is a server tag";
  const double t0 = std::stod(lines[0].substr(2)), t1 = std::stod(lines[1].substr(2));
  EXPECT_GE(t1 - t0, 0.1) << "5 mm at 50 mm/s takes 0.1 s at least";
  EXPECT_EQ(lines[2], "OK script done (8 statements)");

  // A load error names the script, line and column; nothing runs.
  c.send("RUN bad.script\nMSO(X, mso2);\nWAIT UNTIL;\nEND\n");
  const auto bad = r.response(c);
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_EQ(bad[0].rfind("ERR bad.script:2:", 0), 0u) << bad[0];
  EXPECT_FALSE(r.ctl->find_control("mso2").has_value() && r.status().controls[*r.ctl->find_control("mso2")].en());
  // A run-time failure: WAIT UNTIL times out.
  c.send("RUN\nWAIT UNTIL X.GearingLockStatus TIMEOUT 0.02;\nEND\n");
  const auto to = r.response(c);
  ASSERT_EQ(to.size(), 1u);
  EXPECT_TRUE(contains(to[0], "timed out after 0.02 s")) << to[0];
  EXPECT_EQ(to[0].rfind("ERR <client ", 0), 0u) << to[0];
  EXPECT_EQ(r.request(c, "END"), "ERR END without RUN");
}

TEST(CommandServer, TwoClientsAtOnce) {
  Rig r;
  r.boot();
  Client a(r.sock), b(r.sock);
  ASSERT_TRUE(a.connected() && b.connected());
  a.send("WATCH 0.005 X.CommandPosition\n");
  b.send("MSO(X, mso1)\n");
  std::vector<std::string> la, lb;
  r.run_until(
      [&] {
        while (auto l = a.line()) la.push_back(*l);
        while (auto l = b.line()) lb.push_back(*l);
        return !lb.empty();
      },
      3000);
  ASSERT_EQ(lb.size(), 1u);
  EXPECT_EQ(lb[0].rfind("OK mso1", 0), 0u);
  const auto mso = *r.ctl->find_control("mso1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[mso].dn(); }, 3000));
  b.send(mam("X", "mam1", "3", 100) + "\n");
  lb = r.response(b);
  EXPECT_EQ(lb.back().rfind("OK mam1", 0), 0u) << lb.back();
  r.run_until(
      [&] {
        while (auto l = a.line()) la.push_back(*l);
        return !la.empty() && contains(la.back(), "X.CommandPosition=3");
      },
      3000);
  ASSERT_GE(la.size(), 3u);
  EXPECT_EQ(la[0], "OK watching 1 tag every 0.005 s");
  EXPECT_TRUE(contains(la.back(), "X.CommandPosition=3")) << "client A saw client B's move";
  EXPECT_EQ(r.server->client_count(), 2u);
  EXPECT_EQ(r.request(b, "GET X.CommandPosition"), "OK X.CommandPosition=3");
}

TEST(CommandServer, ClientThatDisconnectsMidRequest) {
  Rig r;
  r.boot();
  {
    Client a(r.sock);
    r.step();  // accepted
    EXPECT_EQ(r.server->client_count(), 1u);
    a.send("MSO(X, mso1)\n");
    r.step();  // read and submitted; the reply waits for the planner
    a.send("RUN\nWAIT 10;\n");  // and half a script
  }  // gone
  r.run_until([&] { return r.server->client_count() == 0; }, 100);
  EXPECT_EQ(r.server->client_count(), 0u);
  bool logged = false;
  for (const auto& l : r.log) logged |= contains(l, "disconnected");
  EXPECT_TRUE(logged);
  // Its instruction still executed, and the server serves the next client.
  const auto mso = *r.ctl->find_control("mso1");
  EXPECT_TRUE(r.status().controls[mso].en());
  Client b(r.sock);
  EXPECT_EQ(r.request(b, "GET mso1.EN"), "OK mso1.EN=1");
  // A client that disconnects during a script: the script stops with it.
  {
    Client s(r.sock);
    s.send("RUN\nWAIT 1;\nSET_NOT_REACHED := 1;\nEND\n");
    r.run_until([] { return false; }, 50);
  }
  r.run_until([] { return false; }, 2000);
  // Loading the script declared the tag (value 0); the assignment never ran.
  EXPECT_EQ(r.request(b, "GET SET_NOT_REACHED"), "OK SET_NOT_REACHED=0");
}

TEST(CommandServer, MalformedInputGetsErrAndTheConnectionStaysUsable) {
  Rig r;
  Client c(r.sock);
  EXPECT_TRUE(contains(r.request(c, "FROB 1 2"), "ERR unknown request 'FROB'"));
  EXPECT_TRUE(contains(r.request(c, "MAM("), "ERR "));
  EXPECT_TRUE(contains(r.request(c, "MAM(X, mam1, 0, 1, 2, 3))))"), "ERR "));
  EXPECT_TRUE(contains(r.request(c, "GET \x01\x02"), "ERR malformed request: control character 0x01 at column 5"));
  EXPECT_TRUE(contains(r.request(c, "RUN a b c"), "ERR RUN takes at most one word"));
  EXPECT_TRUE(contains(r.request(c, std::string("GET X.ActualPosition\xff\xfe")), "ERR "));
  c.send(std::string("\0\0\0\n", 4));
  EXPECT_TRUE(contains(r.response(c).back(), "ERR malformed request: control character 0x00"));
  // Blank lines and comments get no response; CRLF is accepted.
  c.send("\n   \n# comment\nGET Controller.Cycle\r\n");
  const auto lines = r.response(c);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].rfind("OK Controller.Cycle=", 0), 0u);
  c.send("HELP\n");
  const auto help = r.response(c);
  EXPECT_GT(help.size(), 8u);
  EXPECT_EQ(help.back(), "OK");
  EXPECT_EQ(r.request(c, "QUIT"), "OK bye");
  r.run_until([&] { return !c.pump(); }, 100);
  EXPECT_TRUE(c.eof());
}

TEST(CommandServer, HelpDispatchAndUnknownRequestComeFromTheVerbTable) {
  Rig r;
  Client c(r.sock);
  c.send("HELP\n");
  std::vector<std::string> want = command::help_lines();
  want.emplace_back("OK");
  EXPECT_EQ(r.response(c), want);
  EXPECT_EQ(r.request(c, "FROB 1 2"), "ERR " + command::unknown_request("FROB"));
  // Every verb of the table reaches its handler (none is answered as unknown).
  for (const command::Verb& v : command::verbs()) {
    if (v.name.empty() || v.name == "QUIT") continue;
    const std::string line = v.name == "RUN" ? "RUN\nEND" : std::string(v.name);
    const std::string reply = r.request(c, line);
    EXPECT_FALSE(reply.empty()) << v.name;
    EXPECT_FALSE(contains(reply, "unknown request")) << v.name << ": " << reply;
  }
  EXPECT_EQ(r.request(c, "RUN\nEND"), "OK script done (0 statements)");
  EXPECT_EQ(r.request(c, "end"), "ERR END without RUN");
  // While a WATCH runs, only the rows marked while_watching are served.
  EXPECT_EQ(r.request(c, "WATCH 1 Controller.Cycle").rfind("OK watching", 0), 0u);
  for (const command::Verb& v : command::verbs()) {
    if (v.while_watching) continue;
    const std::string line = v.name.empty() ? "MSO(X, mso1)" : std::string(v.name);
    EXPECT_EQ(r.request(c, line), "ERR a WATCH is running: send UNWATCH first") << line;  // after WATCH lines
  }
  EXPECT_EQ(r.request(c, "UNWATCH"), "OK unwatched");
  EXPECT_EQ(r.request(c, "QUIT"), "OK bye");
}

TEST(CommandServer, OverlongLineDisconnectsWithAnErrLine) {
  Rig r([](CommandServerOptions& o) { o.max_line = 256; });
  Client bad(r.sock), good(r.sock);
  bad.send(std::string(10000, 'A'));
  std::vector<std::string> lines;
  r.run_until(
      [&] {
        while (auto l = bad.line()) lines.push_back(*l);
        return bad.eof();
      },
      100);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "ERR request line longer than 256 bytes; disconnected");
  EXPECT_TRUE(bad.eof());
  // An overlong line ended by a newline, too.
  Client bad2(r.sock);
  bad2.send(std::string(300, 'B') + "\n");
  lines.clear();
  r.run_until(
      [&] {
        while (auto l = bad2.line()) lines.push_back(*l);
        return bad2.eof();
      },
      100);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(contains(lines[0], "longer than 256 bytes"));
  EXPECT_EQ(r.request(good, "GET Controller.Cycle").rfind("OK", 0), 0u);
  EXPECT_EQ(r.server->client_count(), 1u);
}

TEST(CommandServer, ClientThatDoesNotReadIsDisconnected) {
  Rig r([](CommandServerOptions& o) { o.max_output = 4096; });
  Client slow(r.sock), good(r.sock);
  // A line per cycle of 16 tags, never read: the kernel's socket buffer fills,
  // then the server's 4 KiB, then the client goes.
  std::string req = "WATCH 0.001";
  for (int i = 0; i < 16; ++i) req += " X.ActualPosition";
  slow.send(req + "\n");
  ASSERT_TRUE(r.run_until([&] { return r.server->client_count() == 1; }, 200000))
      << "the non-reading client was never disconnected";
  bool logged = false;
  for (const auto& l : r.log) logged |= contains(l, "does not read its output");
  EXPECT_TRUE(logged);
  EXPECT_EQ(r.request(good, "GET Controller.Cycle").rfind("OK", 0), 0u);
}

TEST(CommandServer, TooManyClientsAreTurnedAway) {
  Rig r([](CommandServerOptions& o) { o.max_clients = 2; });
  Client a(r.sock), b(r.sock);
  r.step();
  Client c(r.sock);
  std::vector<std::string> lines;
  r.run_until(
      [&] {
        while (auto l = c.line()) lines.push_back(*l);
        return c.eof();
      },
      100);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "ERR too many clients (2 connected); try again later");
  EXPECT_EQ(r.request(a, "GET Controller.Cycle").rfind("OK", 0), 0u);
}

/// Send `line` and poll the server without running cycles (the planner never
/// takes the command) until the first line of the answer, at most 10 s.
std::string answer_without_cycles(Rig& r, Client& c, const std::string& line) {
  c.send(line + "\n");
  std::optional<std::string> l;
  const auto t0 = std::chrono::steady_clock::now();
  while (!(l = c.line()) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(10)) {
    r.server->poll(r.now_s());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // wall-time timeout: nothing virtual to step
  }
  return l.value_or("<no answer within 10 s>");
}

TEST(CommandServer, InstructionTimesOutWhenTheCycleDoesNotRun) {
  Rig r([](CommandServerOptions& o) { o.instruction_timeout_s = 0.05; });
  Client c(r.sock);
  const std::string l = answer_without_cycles(r, c, "MSO(X, mso1)");
  EXPECT_TRUE(contains(l, "ERR timeout: the controller did not execute the instruction within 0.05 s")) << l;
}

// A MODE change that timed out (the cycle did not run) leaves no reply
// behind: the next instruction call is answered with its own control tag.
TEST(CommandServer, ATimedOutRequestDoesNotAnswerTheNextCall) {
  Rig r([](CommandServerOptions& o) { o.instruction_timeout_s = 0.05; });
  Client c(r.sock);
  const std::string l = answer_without_cycles(r, c, "MODE program");
  EXPECT_TRUE(contains(l, "ERR timeout")) << l;
  r.boot();
  const std::string reply = r.request(c, "MSO(X, mso1)");
  EXPECT_EQ(reply.rfind("OK mso1 EN=1", 0), 0u) << reply;
}

/// Connect as another user in a forked child; returns the first line the
/// server sent (or an error text).
std::string connect_as(Rig& r, uid_t uid, gid_t gid) {
  int pipefd[2];
  if (::pipe(pipefd) != 0) return "pipe failed";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipefd[0]);
    std::string result;
    if (::setgroups(0, nullptr) != 0 || ::setgid(gid) != 0 || ::setuid(uid) != 0) {
      result = "setuid failed";
    } else {
      const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
      sockaddr_un a{};
      a.sun_family = AF_UNIX;
      std::strncpy(a.sun_path, r.sock.c_str(), sizeof(a.sun_path) - 1);
      if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0) {
        result = std::string("connect: ") + std::strerror(errno);
      } else {
        // send(MSG_NOSIGNAL), as canmotionctl: the server may refuse and
        // close before this request is written (seen under ASan in CI), and a
        // plain write(2) would then kill the child with SIGPIPE before it
        // reads the refusal, which is already in its socket.
        const std::string req = "GET Controller.Cycle\n";
        (void)!::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
        char ch;
        while (::read(fd, &ch, 1) == 1 && ch != '\n') result += ch;
      }
    }
    (void)!::write(pipefd[1], result.data(), result.size());
    ::_exit(0);
  }
  ::close(pipefd[1]);
  int st = 0;
  // The child blocks on the server, which this thread runs.
  while (::waitpid(pid, &st, WNOHANG) == 0) {
    r.step();
    std::this_thread::yield();
  }
  std::string out;
  char buf[512];
  ssize_t n;
  while ((n = ::read(pipefd[0], buf, sizeof(buf))) > 0) out.append(buf, static_cast<std::size_t>(n));
  ::close(pipefd[0]);
  return out;
}

TEST(CommandServer, PeerCredentialsAreChecked) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to connect as another user (setuid in a forked child)";
  group* ng = ::getgrnam("nogroup");
  if (!ng) GTEST_SKIP() << "no group 'nogroup' on this system";
  const gid_t nog = ng->gr_gid;
  Rig r([](CommandServerOptions& o) { o.group = "nogroup"; });
  struct stat st {};
  ASSERT_EQ(::lstat(r.sock.c_str(), &st), 0);
  EXPECT_EQ(st.st_gid, nog) << "the socket belongs to the configured group";
  // Open the file permissions so that the peer check itself is what refuses.
  ASSERT_EQ(::chmod(r.dir.path.c_str(), 0755), 0);  // mkdtemp made it 0700
  ASSERT_EQ(::chmod(r.sock.c_str(), 0666), 0);
  const std::string refused = connect_as(r, 65534, 1);
  EXPECT_EQ(refused, "ERR permission denied: uid 65534 gid 1 is not root, the daemon's user, nor in group 'nogroup'");
  bool logged = false;
  for (const auto& l : r.log) logged |= contains(l, "refused: pid ") && contains(l, "uid 65534 gid 1");
  EXPECT_TRUE(logged);
  const std::string member = connect_as(r, 65534, nog);
  EXPECT_EQ(member.rfind("OK Controller.Cycle=", 0), 0u) << member;
  // With the socket's own mode (0660, group nogroup), a stranger cannot even connect.
  ASSERT_EQ(::chmod(r.sock.c_str(), 0660), 0);
  EXPECT_EQ(connect_as(r, 65534, 1), "connect: Permission denied");
}

}  // namespace
}  // namespace canmotion::rt::ctltest

namespace canmotion::rt::ctltest {
namespace {

TEST(CommandServer, HalfClosedClientGetsItsAnswersThenEof) {
  // `printf 'GET ...\n' | socat - UNIX-CONNECT:...` sends, then shuts down its
  // sending side: every request is still answered, then the server closes.
  Rig r;
  Client c(r.sock);
  c.send("GET Controller.Cycle\nMSO(Master, mso1)\nSTATUS\n");
  ASSERT_EQ(::shutdown(c.fd(), SHUT_WR), 0);
  std::vector<std::string> lines;
  ASSERT_TRUE(r.run_until(
      [&] {
        while (auto l = c.line()) lines.push_back(*l);
        return c.eof();
      },
      1000));
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].rfind("OK Controller.Cycle=", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1].rfind("OK mso1 EN=1", 0), 0u) << lines[1];
  EXPECT_EQ(lines[4].rfind("OK 2 axes", 0), 0u) << lines[4];
  r.step();
  EXPECT_EQ(r.server->client_count(), 0u);
}

}  // namespace
}  // namespace canmotion::rt::ctltest

namespace canmotion::rt::ctltest {
namespace {

TEST(CommandServer, EndOfInputInsideRunIsAnError) {
  Rig r;
  Client c(r.sock);
  c.send("RUN\nWAIT 0.1;\n");
  ASSERT_EQ(::shutdown(c.fd(), SHUT_WR), 0);
  std::vector<std::string> lines;
  ASSERT_TRUE(r.run_until(
      [&] {
        while (auto l = c.line()) lines.push_back(*l);
        return c.eof();
      },
      1000));
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "ERR end of input inside RUN: the script text must end with a line END");
}

}  // namespace
TEST(CommandServer, RefuseMotionStopsScriptsAndRefusesCallsButKeepsReads) {
  Rig r;
  r.boot();
  Client c(r.sock), s(r.sock);
  servo_on(r, c);
  // A script that would move later: it is waiting when the stop begins.
  s.send("RUN late.script\nWAIT 10;\nMAJ(X, maj_late, 0, 10, unitspersec, 100, unitspersec2, 100, unitspersec2, "
         "trapezoidal, 100, 100, %oftime, disabled, programmed, 0, none);\nEND\n");
  for (int i = 0; i < 20; ++i) r.step();
  r.server->refuse_motion("canmotiond is stopping");
  const auto stopped = r.response(s);
  ASSERT_EQ(stopped.size(), 1u);
  EXPECT_EQ(stopped[0], "ERR script stopped: canmotiond is stopping");
  EXPECT_EQ(r.request(c, mam("X", "mam9", "5", 50)), "ERR canmotiond is stopping");
  EXPECT_FALSE(r.ctl->find_control("mam9").has_value()) << "a refused call creates no control tag";
  c.send("RUN\nPRINT X.CommandPosition;\nEND\n");
  const auto run = r.response(c);
  ASSERT_EQ(run.size(), 1u);
  EXPECT_EQ(run[0], "ERR canmotiond is stopping");
  // Reads and tag writes still work.
  EXPECT_EQ(r.request(c, "SET Distance 3"), "OK Distance=3");
  EXPECT_EQ(r.request(c, "GET Distance"), "OK Distance=3");
  EXPECT_EQ(r.request(c, "GET X.CommandVelocity"), "OK X.CommandVelocity=0");
  for (int i = 0; i < 12000; ++i) r.step();
  const auto late = r.ctl->find_control("maj_late");  // created when the script was loaded
  ASSERT_TRUE(late.has_value());
  EXPECT_FALSE(r.status().controls[*late].en()) << "the stopped script never ran its MAJ";
  EXPECT_EQ(r.status().axes[1].tag.command_velocity, 0.0);
}

TEST(CommandServer, SharedHostSharesUserTagsWithTheOwner) {
  std::unique_ptr<ControllerHost> owner;
  Rig r([&owner](CommandServerOptions&) {});
  owner = std::make_unique<ControllerHost>(*r.ctl);
  // A second server on the same controller, sharing the owner's host.
  CommandServerOptions o;
  o.path = r.dir.path + "/shared.sock";
  o.log = [](const std::string&) {};
  o.shared_host = owner.get();
  CommandServer shared(*r.ctl, o);
  EXPECT_EQ(&shared.host(), owner.get());
  Client c(shared.path());
  std::optional<std::string> reply;
  c.send("SET Speed 42\n");
  for (int i = 0; i < 100 && !reply; ++i) {
    r.step();
    shared.poll(r.now_s());
    reply = c.line();
  }
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(*reply, "OK Speed=42");
  std::string err;
  const auto v = owner->read("Speed", &err);
  ASSERT_TRUE(v.has_value()) << err;
  EXPECT_EQ(*v, 42.0) << "the owner's script sees the client's SET";
  EXPECT_FALSE(r.server->host().read("Speed", &err).has_value()) << "the other server's own host does not";
}

}  // namespace canmotion::rt::ctltest
