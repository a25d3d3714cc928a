// Randomised property test: random request lines (protocol words, tags,
// instruction calls with random operands, stray punctuation, control bytes,
// long tokens) never take the server down, every line it sends is well
// formed, and it keeps serving. Seed and count: CANMOTION_SEED, CANMOTION_COUNT.
#include <cstdio>
#include <random>

#include "rt/controller/command_verbs.hpp"
#include "tests/ctl/ctl_rig.hpp"
#include "tests/support/random_seed.hpp"

namespace canmotion::rt::ctltest {
namespace {

/// The protocol's verbs (the server's table), then instructions, tags, operands and junk.
std::vector<std::string> vocabulary() {
  std::vector<std::string> words;
  for (const command::Verb& v : command::verbs())
    if (!v.name.empty()) words.emplace_back(v.name);
  words.insert(words.end(), {
      "program", "run", "MSO", "MSF", "MAM", "MAJ", "MAS", "MAG", "MATC", "MCD", "X", "Master", "Nope", "mam1",
      "mso1", "X.ActualPosition", "mam1.DN", "mam1.ERR", "Controller.Time", "Controller.Cycle", "Distance",
      "X.GearingLockStatus", "WAIT", "UNTIL", "PRINT", "TIMEOUT", ":=", "(", ")", ",", ";", "0", "1", "-1", "0.001",
      "1e308", "nan", "inf", "%oftime", "unitspersec", "All", "\"",
      "(*", "*)", "//", "#", "\t", "\\", "\xff\xfe", "\x01", std::string(1, '\0')});
  return words;
}

std::string random_line(std::mt19937_64& rng) {
  static const std::vector<std::string> words = vocabulary();
  std::uniform_int_distribution<int> nwords(0, 24);
  std::uniform_int_distribution<std::size_t> pick(0, words.size() - 1);
  std::uniform_int_distribution<int> kind(0, 999);
  std::string l;
  const int n = nwords(rng);
  for (int i = 0; i < n; ++i) {
    const int k = kind(rng);
    if (k < 1) {
      l += std::string(std::uniform_int_distribution<std::size_t>(1, 2000)(rng), 'A');
    } else if (k < 30) {
      l += static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
    } else {
      l += words[pick(rng)];
    }
    if (kind(rng) < 700) l += ' ';
  }
  return l;
}

bool well_formed(const std::string& l) {
  if (l.rfind("OK", 0) == 0) return l.size() == 2 || l[2] == ' ';
  if (l.rfind("ERR", 0) == 0) return l.size() > 4 && l[3] == ' ';
  return l.find('\0') == std::string::npos;  // a data line
}

TEST(CommandServerProperty, RandomRequestsNeverBreakTheServer) {
  const std::uint64_t seed = test::test_seed(0xC7115EEDULL);
  const std::uint64_t count = test::test_count(40);
  std::mt19937_64 rng(seed);
  Rig r([](CommandServerOptions& o) {
    o.max_line = 1024;
    o.max_output = 64 * 1024;
  });
  std::size_t oks = 0, errs = 0, data = 0, closed = 0;
  for (std::uint64_t it = 0; it < count; ++it) {
    Client c(r.sock);
    ASSERT_TRUE(c.connected()) << "iteration " << it << test::seed_note(seed);
    std::string batch;
    for (int i = 0; i < 50; ++i) batch += random_line(rng) + "\n";
    c.send(batch.substr(0, 60000));  // stays within the socket buffer: send() does not block
    std::vector<std::string> lines;
    r.run_until(
        [&] {
          while (auto l = c.line()) lines.push_back(*l);
          return c.eof();
        },
        300);
    for (const auto& l : lines) {
      ASSERT_TRUE(well_formed(l)) << "'" << l << "'" << test::seed_note(seed);
      (l.rfind("OK", 0) == 0 ? oks : l.rfind("ERR", 0) == 0 ? errs : data) += 1;
    }
    closed += c.eof() ? 1 : 0;
    c.close();
    // Still serving.
    Client probe(r.sock);
    const std::string ok = r.request(probe, "GET Controller.Cycle");
    ASSERT_EQ(ok.rfind("OK Controller.Cycle=", 0), 0u) << ok << test::seed_note(seed);
  }
  std::printf("%zu OK, %zu ERR, %zu data lines; %zu of %llu connections closed by the server\n", oks, errs, data,
              closed, static_cast<unsigned long long>(count));
  EXPECT_GT(errs, count) << "the random requests should mostly be refused" << test::seed_note(seed);
  r.run_until([&] { return r.server->client_count() == 0; }, 100);
  EXPECT_EQ(r.server->client_count(), 0u) << test::seed_note(seed);
}

}  // namespace
}  // namespace canmotion::rt::ctltest
