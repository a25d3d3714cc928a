// The canmotionctl binary against an in-process CommandServer: the test
// thread runs the cycle on a virtual clock while the tool (a child process)
// talks to the server.
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "tests/ctl/ctl_rig.hpp"
#include "tools/canmotionctl/commands.hpp"

extern char** environ;

namespace canmotion::rt::ctltest {
namespace {

struct Result {
  int status = -1;
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Run canmotionctl with `args`, stepping the rig until it exits.
Result ctl(Rig* r, const std::string& dir, std::vector<std::string> args, const std::string& env_socket = "") {
  args.insert(args.begin(), CANMOTIONCTL_PATH);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string out = dir + "/out.txt", err = dir + "/err.txt";
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> envs;
  for (char** e = environ; *e; ++e)
    if (std::string(*e).rfind("CANMOTIOND_SOCKET=", 0) != 0) envs.emplace_back(*e);
  if (!env_socket.empty()) envs.push_back("CANMOTIOND_SOCKET=" + env_socket);
  std::vector<char*> envp;
  for (auto& e : envs) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = 0;
  Result res;
  if (posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), envp.data()) != 0) {
    ADD_FAILURE() << "cannot run " << argv[0];
    return res;
  }
  posix_spawn_file_actions_destroy(&fa);
  int st = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (::waitpid(pid, &st, WNOHANG) == 0) {
    if (r)
      r->step();
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(60)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &st, 0);
      ADD_FAILURE() << "canmotionctl did not finish within 60 s";
      break;
    }
  }
  res.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  res.out = slurp(out);
  res.err = slurp(err);
  return res;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(Canmotionctl, HelpAndBadArguments) {
  TempDir d;
  const Result h = ctl(nullptr, d.path, {"--help"});
  EXPECT_EQ(h.status, 0);
  EXPECT_TRUE(contains(h.out, "Usage: canmotionctl")) << h.out;
  EXPECT_TRUE(contains(h.out, "Options:"));
  EXPECT_TRUE(contains(h.out, "Examples:"));
  EXPECT_TRUE(contains(h.out, "/run/canmotion/canmotiond.sock"));
  EXPECT_EQ(h.out, canmotionctl::usage());  // generated from the command table
  const Result none = ctl(nullptr, d.path, {});
  EXPECT_EQ(none.status, 2);
  EXPECT_TRUE(contains(none.err, "no command given"));
  const Result unknown = ctl(nullptr, d.path, {"frobnicate"});
  EXPECT_EQ(unknown.status, 2);
  EXPECT_EQ(unknown.err,
            "canmotionctl: " + canmotionctl::unknown_command("frobnicate") + "\nTry 'canmotionctl --help'.\n");
  EXPECT_TRUE(contains(unknown.err, ", mode or send")) << unknown.err;  // mode was missing before the table
}

TEST(Canmotionctl, ConnectionFailureSaysWhatToDo) {
  TempDir d;
  const std::string path = d.path + "/nothing.sock";
  const Result r = ctl(nullptr, d.path, {"--socket", path, "status"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "canmotionctl: cannot connect to " + path + ": no such file (is canmotiond running with --socket " +
                       path + "?)\n");
  // $CANMOTIOND_SOCKET is used when --socket is not given.
  const Result e = ctl(nullptr, d.path, {"stats"}, path);
  EXPECT_EQ(e.status, 1);
  EXPECT_TRUE(contains(e.err, "cannot connect to " + path)) << e.err;
}

TEST(Canmotionctl, InstructionGetSetStatusStats) {
  Rig r;
  r.boot();
  const std::string& d = r.dir.path;
  const Result mso = ctl(&r, d, {"--socket", r.sock, "MSO(X, mso1)"});
  EXPECT_EQ(mso.status, 0) << mso.err;
  EXPECT_EQ(mso.out.rfind("mso1 EN=1 ", 0), 0u) << mso.out;
  const auto id = *r.ctl->find_control("mso1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[id].dn(); }, 3000));
  // Unquoted instruction words are joined.
  const Result mv = ctl(&r, d, {"--socket", r.sock, "MAM(X,", "mam1,", "0,", "4,", "100,", "unitspersec,", "500,",
                                 "unitspersec2,", "500,", "unitspersec2,", "trapezoidal,", "100,", "100,", "%oftime,",
                                 "disabled,", "programmed,", "0,", "none,", "0,", "0)"});
  EXPECT_EQ(mv.status, 0) << mv.err;
  EXPECT_TRUE(contains(mv.out, "IP=1")) << mv.out;
  const auto m = *r.ctl->find_control("mam1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[m].pc(); }, 5000));
  const Result bad = ctl(&r, d, {"--socket", r.sock, ctltest::mam("X", "mam2", "1", -5)});
  EXPECT_EQ(bad.status, 1);
  EXPECT_TRUE(contains(bad.err, " ER=1 ")) << bad.err;
  EXPECT_TRUE(contains(bad.err, " ERR=13 EXERR=4 ")) << bad.err;

  const Result get1 = ctl(&r, d, {"--socket", r.sock, "get", "X.CommandPosition"});
  EXPECT_EQ(get1.status, 0) << get1.err;
  EXPECT_EQ(get1.out, "4\n");
  const Result get2 = ctl(&r, d, {"-s", r.sock, "get", "X.CommandPosition", "mam1.PC"});
  EXPECT_EQ(get2.out, "X.CommandPosition=4\nmam1.PC=1\n");
  const Result set = ctl(&r, d, {"-s", r.sock, "set", "Offset", "-5"});
  EXPECT_EQ(set.status, 0) << set.err;
  EXPECT_EQ(ctl(&r, d, {"-s", r.sock, "get", "Offset"}).out, "-5\n");
  const Result ro = ctl(&r, d, {"-s", r.sock, "set", "X.ActualPosition", "1"});
  EXPECT_EQ(ro.status, 1);
  EXPECT_EQ(ro.err, "canmotionctl: tag 'X.ActualPosition' is read-only\n");

  const Result st = ctl(&r, d, {"-s", r.sock, "status"});
  EXPECT_EQ(st.status, 0) << st.err;
  EXPECT_EQ(st.out.rfind("AXIS    TYPE     NODE  STATE", 0), 0u) << st.out;
  EXPECT_TRUE(contains(st.out, "\nX       CIP      2     ServoControl  Operation enabled")) << st.out;
  EXPECT_TRUE(contains(st.out, "X: AxisStatus ServoActionStatus")) << st.out;
  EXPECT_TRUE(contains(st.out, "(2 axes, cycle ")) << st.out;

  const Result stats = ctl(&r, d, {"-s", r.sock, "stats"});
  EXPECT_EQ(stats.status, 0) << stats.err;
  EXPECT_EQ(stats.out.rfind("cycle ", 0), 0u) << stats.out;
  EXPECT_TRUE(contains(stats.out, "\ntime_s ")) << stats.out;
  EXPECT_TRUE(contains(stats.out, "clients                               1")) << stats.out;

  const Result raw = ctl(&r, d, {"-s", r.sock, "send", "GET", "mam1.DN"});
  EXPECT_EQ(raw.out, "OK mam1.DN=1\n");
}

// The drive failure that `status` shows names the object by the drive's EDS
// (DriveConfig::dictionary, from drive.eds in canmotiond), where CiA 301
// would say "Vendor-ID".
TEST(Canmotionctl, StatusNamesObjectsByTheDrivesEds) {
  Rig r({}, [](AxisSpec& x, emulator::EmulatorConfig&) {
    x.drive.identity.has_vendor_id = true;
    x.drive.identity.vendor_id = 0x1234;  // the emulator's is another
    x.drive.dictionary = std::make_shared<const canopen::DeviceDictionary>(
        std::vector<canopen::DeviceDictionary::Entry>{
            {0x1018, 1, canopen::DataType::kUnsigned32, canopen::Access::kRo, "Hersteller-ID"}},
        "acme.eds");
  });
  ASSERT_TRUE(r.run_until([&] { return r.status().axes[1].phase == cia402::Phase::kFailed; }, 3000));
  const Result st = ctl(&r, r.dir.path, {"-s", r.sock, "status"});
  EXPECT_EQ(st.status, 0) << st.err;
  EXPECT_TRUE(contains(st.out, "X: drive failure: node 2: identity 0x1018:1 (Hersteller-ID) is 0x")) << st.out;
}

TEST(Canmotionctl, WatchAndRun) {
  Rig r;
  r.boot();
  const std::string& d = r.dir.path;
  const Result w = ctl(&r, d, {"-s", r.sock, "watch", "Controller.Time", "--interval", "0.02", "--count", "3"});
  EXPECT_EQ(w.status, 0) << w.err;
  std::istringstream in(w.out);
  std::string l;
  std::vector<std::string> lines;
  while (std::getline(in, l)) lines.push_back(l);
  ASSERT_EQ(lines.size(), 3u) << w.out;
  for (int i = 0; i < 2; ++i)
    EXPECT_NEAR(std::stod(lines[i + 1].substr(2)) - std::stod(lines[i].substr(2)), 0.02, 1e-9) << w.out;

  {
    std::ofstream f(d + "/ok.script");
    f << "MSO(X, mso1);\nWAIT UNTIL mso1.DN TIMEOUT 2;\n(* a comment\nEND\n*)\nPRINT X.DriveEnableStatus;\n";
  }
  const Result ok = ctl(&r, d, {"-s", r.sock, "run", d + "/ok.script"});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(contains(ok.out, " X.DriveEnableStatus=1\n")) << ok.out;
  EXPECT_EQ(ok.out.find("END"), std::string::npos) << "a script line END is part of the script, not its end";
  {
    std::ofstream f(d + "/bad.script");
    f << "WAIT UNTIL X.GearingLockStatus TIMEOUT 0.01;\n";
  }
  const Result bad = ctl(&r, d, {"-s", r.sock, "run", d + "/bad.script"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_TRUE(contains(bad.err, "canmotionctl: " + d + "/bad.script:1:")) << bad.err;
  EXPECT_TRUE(contains(bad.err, "timed out")) << bad.err;
  const Result missing = ctl(&r, d, {"-s", r.sock, "run", d + "/missing.script"});
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(contains(missing.err, "cannot read script")) << missing.err;
}

}  // namespace
}  // namespace canmotion::rt::ctltest

namespace canmotion::rt::ctltest {
namespace {

// Issue 16 item 9: `canmotionctl mode program|run` (protocol MODE). A mode
// change (Run <-> Program) breaks every MDAC link [seed 000] and stops the
// motion (cams [seed 004], gears, moves) by each axis' Programmed Stop Mode;
// in Program mode instructions that start motion answer ERR 24 (Illegal
// Controller Mode); `mode` alone prints the mode.
TEST(Canmotionctl, ModeProgramStopsMotionAndRefusesItUntilRun) {
  Rig r;
  r.boot();
  const std::string& d = r.dir.path;
  EXPECT_EQ(ctl(&r, d, {"-s", r.sock, "mode"}).out, "run\n");
  ASSERT_EQ(ctl(&r, d, {"-s", r.sock, "MSO(X, mso1)"}).status, 0);
  const auto id = *r.ctl->find_control("mso1");
  ASSERT_TRUE(r.run_until([&] { return r.status().controls[id].dn(); }, 3000));
  ASSERT_EQ(ctl(&r, d, {"-s", r.sock, "MDAC(X, Master, l1, all, command)"}).status, 0);
  const Result jog = ctl(&r, d, {"-s", r.sock, "MAJ(X, j1, 0, 10, unitspersec, 1000, unitspersec2, 1000, unitspersec2, "
                                              "trapezoidal, 100, 100, %oftime, disabled, programmed, 0, none)"});
  ASSERT_EQ(jog.status, 0) << jog.err;
  r.step();
  const Result prog = ctl(&r, d, {"-s", r.sock, "mode", "program"});
  EXPECT_EQ(prog.status, 0) << prog.err;
  EXPECT_EQ(prog.out, "program\n");
  EXPECT_EQ(r.status().mode, motion::ControllerMode::Program);
  EXPECT_FALSE(r.status().controls[*r.ctl->find_control("l1")].ip());  // link broken
  EXPECT_FALSE(r.status().controls[*r.ctl->find_control("j1")].ip());  // jog ended (FastStop ramp)
  EXPECT_EQ(ctl(&r, d, {"-s", r.sock, "mode"}).out, "program\n");
  const Result refused = ctl(&r, d, {"-s", r.sock, "MAJ(X, j2, 0, 10, unitspersec, 1000, unitspersec2, 1000, "
                                                  "unitspersec2, trapezoidal, 100, 100, %oftime, disabled, programmed, 0, none)"});
  EXPECT_EQ(refused.status, 1);
  EXPECT_TRUE(contains(refused.err, " ERR=24 ")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "Illegal Controller Mode")) << refused.err;
  EXPECT_EQ(ctl(&r, d, {"-s", r.sock, "mode", "run"}).out, "run\n");
  const Result again = ctl(&r, d, {"-s", r.sock, "MAJ(X, j3, 0, 10, unitspersec, 1000, unitspersec2, 1000, "
                                                "unitspersec2, trapezoidal, 100, 100, %oftime, disabled, programmed, 0, none)"});
  EXPECT_EQ(again.status, 0) << again.err;
  const Result bad = ctl(&r, d, {"-s", r.sock, "mode", "remote"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.err, "'remote' is not run or program")) << bad.err;
}

}  // namespace
}  // namespace canmotion::rt::ctltest
