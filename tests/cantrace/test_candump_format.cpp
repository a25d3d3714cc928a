// Codec tests for the candump text formats: golden strings both ways.
#include "fieldbus/can/candump_format.hpp"
#include "tests/support/random_seed.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace can = canmotion::can;

namespace {

std::string fmt_line(const can::Frame& f, std::int64_t t_ns, std::string_view iface, int digits = 6) {
  std::array<char, can::kCandumpLineMax + 1> buf{};
  const std::size_t n = can::format_candump_line(buf, f, t_ns, iface, digits);
  return std::string(buf.data(), n);
}

can::CandumpLine parse_ok(std::string_view line) {
  can::CandumpLine out;
  const auto r = can::parse_candump_line(line, out);
  EXPECT_EQ(r, can::CandumpParse::kOk) << "line: '" << line << "' reason: " << out.reason;
  return out;
}

}  // namespace

TEST(CandumpFormat, FormatsDataFrameLikeCandump) {
  const can::Frame f(0x181, {0x37, 0x06, 0xA0, 0x86, 0x01, 0x00});
  EXPECT_EQ(fmt_line(f, 1'700'000'000'123'456'789LL, "vcan0"), "(1700000000.123456) vcan0 181#3706A0860100");
  EXPECT_EQ(fmt_line(f, 1'700'000'000'123'456'789LL, "vcan0", 9), "(1700000000.123456789) vcan0 181#3706A0860100");
}

TEST(CandumpFormat, FormatsSpecialFrames) {
  can::Frame sync(0x080, {});
  EXPECT_EQ(fmt_line(sync, 5'000, "can1"), "(0000000000.000005) can1 080#");
  can::Frame rtr(0x701, {});
  rtr.flags = can::kRemote;
  EXPECT_EQ(fmt_line(rtr, 0, "vcan0"), "(0000000000.000000) vcan0 701#R");
  rtr.len = 1;
  EXPECT_EQ(fmt_line(rtr, 0, "vcan0"), "(0000000000.000000) vcan0 701#R1");
  can::Frame ext(0x12345678, {0xDE, 0xAD});
  ext.flags = can::kExtended;
  EXPECT_EQ(fmt_line(ext, 0, "vcan0"), "(0000000000.000000) vcan0 12345678#DEAD");
  can::Frame err(0x004, {0, 0x04, 0, 0, 0, 0, 0, 0});
  err.flags = can::kError;
  EXPECT_EQ(fmt_line(err, 0, "vcan0"), "(0000000000.000000) vcan0 20000004#0004000000000000");
}

TEST(CandumpFormat, FormatRefusesSmallBufferWithoutPartialLine) {
  const can::Frame f(0x181, {1, 2, 3});
  std::array<char, 20> small{};
  small.fill('x');
  EXPECT_EQ(can::format_candump_line(small, f, 1, "vcan0"), 0U);
  EXPECT_EQ(small[0], '\0');
  std::array<char, can::kCandumpLineMax + 1> big{};
  can::Frame full(0x1FFFFFFF, {1, 2, 3, 4, 5, 6, 7, 8});
  full.flags = can::kExtended;
  const std::size_t n = can::format_candump_line(big, full, INT64_MAX, "abcdefghijklmnopqrst", 9);
  EXPECT_GT(n, 0U);
  EXPECT_LE(n, can::kCandumpLineMax);
}

TEST(CandumpFormat, ParsesLogLines) {
  auto l = parse_ok("(1700000000.123456) vcan0 181#3706A0860100\n");
  EXPECT_EQ(l.format, can::CandumpFormat::kLog);
  EXPECT_EQ(l.time, can::CandumpTime::kAbsolute);
  EXPECT_EQ(l.t_ns, 1'700'000'000'123'456'000LL);
  EXPECT_EQ(l.iface, "vcan0");
  EXPECT_EQ(l.frame, can::Frame(0x181, {0x37, 0x06, 0xA0, 0x86, 0x01, 0x00}));

  l = parse_ok("(1700000000.123456789) can0 080#");
  EXPECT_EQ(l.t_ns, 1'700'000'000'123'456'789LL);
  EXPECT_EQ(l.frame.id, 0x80U);
  EXPECT_EQ(l.frame.len, 0U);

  l = parse_ok("(1700000000.000001) vcan0 701#R");
  EXPECT_TRUE(l.frame.remote());
  EXPECT_EQ(l.frame.len, 0U);
  l = parse_ok("(1700000000.000001) vcan0 701#R1");
  EXPECT_TRUE(l.frame.remote());
  EXPECT_EQ(l.frame.len, 1U);

  l = parse_ok("(1700000000.000001) vcan0 12345678#DE.AD");
  EXPECT_TRUE(l.frame.extended());
  EXPECT_EQ(l.frame.id, 0x12345678U);
  EXPECT_EQ(l.frame.len, 2U);

  l = parse_ok("(1700000000.000001) vcan0 20000004#0004000000000000");
  EXPECT_TRUE(l.frame.error());
  EXPECT_FALSE(l.frame.extended());
  EXPECT_EQ(l.frame.id, 0x4U);
  EXPECT_EQ(l.frame.data[1], 0x04);

  l = parse_ok("(1700000000.000001) vcan0 123#1122334455667788_9");
  EXPECT_EQ(l.frame.len, 8U);
  l = parse_ok("(1700000000.000001) vcan0 123#11 R");
  EXPECT_EQ(l.frame.len, 1U);
}

TEST(CandumpFormat, ParsesScreenLines) {
  auto l = parse_ok("  vcan0  181   [6]  37 06 A0 86 01 00");
  EXPECT_EQ(l.format, can::CandumpFormat::kScreen);
  EXPECT_EQ(l.time, can::CandumpTime::kNone);
  EXPECT_EQ(l.frame, can::Frame(0x181, {0x37, 0x06, 0xA0, 0x86, 0x01, 0x00}));

  l = parse_ok(" (1700000000.123456)  vcan0  080   [0] ");
  EXPECT_EQ(l.time, can::CandumpTime::kAbsolute);
  EXPECT_EQ(l.frame.len, 0U);

  l = parse_ok(" (000.001000)  vcan0  181   [2]  37 06");
  EXPECT_EQ(l.time, can::CandumpTime::kRelative);
  EXPECT_EQ(l.t_ns, 1'000'000);

  l = parse_ok(" (2023-11-14 22:13:20.500000)  vcan0  181   [1]  37");
  EXPECT_EQ(l.time, can::CandumpTime::kDate);
  EXPECT_EQ(l.t_ns, 1'700'000'000'500'000'000LL);

  l = parse_ok("  vcan0  701   [1]  remote request");
  EXPECT_TRUE(l.frame.remote());
  EXPECT_EQ(l.frame.len, 1U);

  l = parse_ok("  vcan0  20000040   [8]  00 00 00 00 00 00 00 00   ERRORFRAME");
  EXPECT_TRUE(l.frame.error());
  EXPECT_EQ(l.frame.id, 0x40U);

  l = parse_ok("  vcan0  12345678   [2]  DE AD   '..'");
  EXPECT_TRUE(l.frame.extended());

  l = parse_ok("  vcan0  RX - -  181   [1]  37");
  EXPECT_EQ(l.frame.id, 0x181U);
  l = parse_ok("  vcan0  181   [2]  00110111 00000110");
  EXPECT_EQ(l.frame.data[0], 0x37);
  EXPECT_EQ(l.frame.data[1], 0x06);
}

TEST(CandumpFormat, SkipsBlankCommentAndErrorDetail) {
  can::CandumpLine out;
  EXPECT_EQ(can::parse_candump_line("", out), can::CandumpParse::kSkip);
  EXPECT_EQ(can::parse_candump_line("   \r\n", out), can::CandumpParse::kSkip);
  EXPECT_EQ(can::parse_candump_line("# comment", out), can::CandumpParse::kSkip);
  EXPECT_EQ(can::parse_candump_line("\tbus-off", out), can::CandumpParse::kSkip);
}

TEST(CandumpFormat, ReportsMalformedAndUnsupported) {
  struct Case {
    const char* line;
    can::CandumpParse expect;
  };
  const Case cases[] = {
      {"(1700000000.123456) vcan0 181#3706A08601", can::CandumpParse::kOk},
      {"(1700000000.123456) vcan0 181#3706A0860", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 1811#37", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 800#37", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 181#112233445566778899", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 181#ZZ", can::CandumpParse::kMalformed},
      {"(1700000000.123456 vcan0 181#37", can::CandumpParse::kMalformed},
      {"(17000x0000.123456) vcan0 181#37", can::CandumpParse::kMalformed},
      {"(1700000000.1234567890) vcan0 181#37", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 181#37 garbage", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 181#R9", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 E0000004#00", can::CandumpParse::kMalformed},
      {"(1700000000.123456) vcan0 123##1112233", can::CandumpParse::kUnsupported},
      {"  vcan0  123  [12]  00 11 22 33 44 55 66 77 88 99 AA BB", can::CandumpParse::kUnsupported},
      {"  vcan0  181   [3]  37 06", can::CandumpParse::kMalformed},
      {"  vcan0  181   [1]  37 06", can::CandumpParse::kMalformed},
      {"  vcan0  181   [9]  37", can::CandumpParse::kMalformed},
      {"  vcan0  181   6  37", can::CandumpParse::kMalformed},
      {"hello world", can::CandumpParse::kMalformed},
  };
  for (const auto& c : cases) {
    can::CandumpLine out;
    const auto r = can::parse_candump_line(c.line, out);
    EXPECT_EQ(r, c.expect) << c.line << " -> " << out.reason;
    if (r != can::CandumpParse::kOk) {
      EXPECT_NE(std::string(out.reason), "") << c.line;
    }
  }
}

// Property: every frame formatted by the formatter parses back to itself.
TEST(CandumpFormat, RoundTripRandomFrames) {
  unsigned seed = 12345;
  int count = 20000;
  if (const char* s = std::getenv("CANMOTION_SEED")) seed = static_cast<unsigned>(std::strtoul(s, nullptr, 10));
  if (const char* s = std::getenv("CANMOTION_COUNT")) count = std::atoi(s);
  std::mt19937_64 rng(seed);
  for (int i = 0; i < count; ++i) {
    can::Frame f;
    const auto kind = rng() % 4;
    f.len = static_cast<std::uint8_t>(rng() % 9);
    for (auto& b : f.data) b = static_cast<std::uint8_t>(rng());
    for (std::size_t k = f.len; k < f.data.size(); ++k) f.data[k] = 0;
    if (kind == 0) {
      f.id = static_cast<std::uint32_t>(rng() % 0x800);
    } else if (kind == 1) {
      f.id = static_cast<std::uint32_t>(rng() % 0x20000000);
      f.flags = can::kExtended;
    } else if (kind == 2) {
      f.id = static_cast<std::uint32_t>(rng() % 0x800);
      f.flags = can::kRemote;
      f.data.fill(0);
    } else {
      f.id = static_cast<std::uint32_t>(rng() % 0x200);
      f.flags = can::kError;
      f.len = 8;
    }
    const auto t = static_cast<std::int64_t>(rng() % 4'000'000'000'000'000'000ULL);
    const int digits = (rng() % 2) ? 9 : 6;
    const std::string line = fmt_line(f, t, "vcan0", digits);
    can::CandumpLine out;
    ASSERT_EQ(can::parse_candump_line(line, out), can::CandumpParse::kOk)
        << "seed " << seed << " line " << line << " reason " << out.reason;
    ASSERT_EQ(out.frame, f) << "seed " << seed << " line " << line;
    const std::int64_t expect_t = digits == 9 ? t : (t / 1000) * 1000;
    ASSERT_EQ(out.t_ns, expect_t) << "seed " << seed << " line " << line;
  }
}

// Property: the formatter (written straight into the caller's buffer since
// issue 18) gives the bytes of an snprintf oracle built from the candump -L
// definition, for random frames, times (negative ones clamp to 0), both
// fraction widths and interface names of every length (cut at 15), in a
// buffer that is large enough and one of the exact size the line needs.
TEST(CandumpFormat, MatchesAnSnprintfOracle) {
  const std::uint64_t seed = canmotion::test::test_seed(4242);
  const std::uint64_t count = canmotion::test::test_count(20000);
  std::mt19937_64 rng(seed);
  const std::string names = "abcdefghijklmnopqrstuvwxyz_0123456789";
  for (std::uint64_t i = 0; i < count; ++i) {
    can::Frame f;
    f.id = static_cast<std::uint32_t>(rng());
    f.flags = static_cast<std::uint8_t>(rng() % 8);  // any mix of extended, remote, error
    f.len = static_cast<std::uint8_t>(rng() % 12);   // beyond 8 too: clamped
    for (auto& b : f.data) b = static_cast<std::uint8_t>(rng());
    std::int64_t t = static_cast<std::int64_t>(rng() >> (rng() % 64));
    if (rng() % 10 == 0) t = -t;
    const int digits = (rng() % 2) ? 9 : 6;
    const std::string iface = names.substr(rng() % names.size(), rng() % 20);

    const std::uint64_t tt = t < 0 ? 0 : static_cast<std::uint64_t>(t);
    char want[256];
    int n = digits == 9 ? std::snprintf(want, sizeof(want), "(%010llu.%09llu) %.15s ",
                                        static_cast<unsigned long long>(tt / 1'000'000'000ULL),
                                        static_cast<unsigned long long>(tt % 1'000'000'000ULL), iface.c_str())
                        : std::snprintf(want, sizeof(want), "(%010llu.%06llu) %.15s ",
                                        static_cast<unsigned long long>(tt / 1'000'000'000ULL),
                                        static_cast<unsigned long long>(tt % 1'000'000'000ULL / 1000), iface.c_str());
    if (f.flags & can::kError) {
      n += std::snprintf(want + n, sizeof(want) - n, "%08X#", (f.id & 0x1FFFFFFFU) | 0x20000000U);
    } else if (f.flags & can::kExtended) {
      n += std::snprintf(want + n, sizeof(want) - n, "%08X#", f.id & 0x1FFFFFFFU);
    } else {
      n += std::snprintf(want + n, sizeof(want) - n, "%03X#", f.id & 0x7FFU);
    }
    const unsigned len = f.len > 8 ? 8 : f.len;
    if ((f.flags & can::kRemote) && !(f.flags & can::kError)) {
      n += len ? std::snprintf(want + n, sizeof(want) - n, "R%u", len) : std::snprintf(want + n, sizeof(want) - n, "R");
    } else {
      for (unsigned k = 0; k < len; ++k) n += std::snprintf(want + n, sizeof(want) - n, "%02X", f.data[k]);
    }
    const std::string expect(want, static_cast<std::size_t>(n));
    ASSERT_EQ(fmt_line(f, t, iface, digits), expect) << canmotion::test::seed_note(seed);
    // A buffer of exactly the line plus its NUL works; one byte less gives 0 and an empty string.
    std::vector<char> exact(expect.size() + 1, 'x');
    ASSERT_EQ(can::format_candump_line(exact, f, t, iface, digits), expect.size()) << canmotion::test::seed_note(seed);
    ASSERT_EQ(std::string(exact.data()), expect) << canmotion::test::seed_note(seed);
    std::vector<char> short_by_one(expect.size(), 'x');
    ASSERT_EQ(can::format_candump_line(short_by_one, f, t, iface, digits), 0U) << canmotion::test::seed_note(seed);
    ASSERT_EQ(short_by_one[0], '\0') << canmotion::test::seed_note(seed);
  }
}
