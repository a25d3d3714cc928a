// format_fixed6 gives printf("%.6f")'s bytes for every double (golden lines
// for the edge values, snprintf for seeded random ones); OutputFile writes
// what was committed, in order, and reports errors naming the file.
#include "rt/text_output.hpp"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "tests/support/random_seed.hpp"

using namespace canmotion::rt;
using canmotion::test::seed_note;
using canmotion::test::test_count;
using canmotion::test::test_seed;

namespace {

std::string fixed6(double v) {
  char buf[kFixed6Max + 1];
  char* end = format_fixed6(buf, v);
  EXPECT_LE(static_cast<std::size_t>(end - buf), kFixed6Max);
  return std::string(buf, end);
}

std::string printf6(double v) {
  char buf[kFixed6Max + 16];
  const int n = std::snprintf(buf, sizeof(buf), "%.6f", v);
  return std::string(buf, static_cast<std::size_t>(n));
}

std::string temp_path(const char* name) {
  return std::string(::testing::TempDir()) + "/" + name + "." + std::to_string(::getpid());
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

// Golden lines: what the daemon's old fprintf wrote for values that matter.
TEST(TextOutput, Fixed6GoldenEdgeValues) {
  const struct {
    double v;
    const char* text;
  } cases[] = {
      {0.0, "0.000000"},
      {-0.0, "-0.000000"},
      {1.0, "1.000000"},
      {-1.0, "-1.000000"},
      {0.1, "0.100000"},
      {123.456789, "123.456789"},
      {-98.7654321, "-98.765432"},
      {1e-9, "0.000000"},
      {-1e-9, "-0.000000"},          // printf keeps the sign of a value that rounds to zero
      {0.0000005, "0.000000"},       // just below 5e-7 in binary
      {0.0000015, "0.000002"},       // just above 1.5e-6 in binary
      {0.0078125, "0.007812"},       // 1/128: an exact tie, to even
      {0.0234375, "0.023438"},       // 3/128: an exact tie, to even
      {-0.0078125, "-0.007812"},
      {2.5e-6, "0.000003"},          // 2.5e-6 in binary is above the tie
      {999999.9999995, "999999.999999"},   // just below the tie in binary
      {999999.9999996, "1000000.000000"},  // carries into the integer part
      {4294967295.0, "4294967295.000000"},
      {1e15, "1000000000000000.000000"},
      {123456789012345.678, "123456789012345.671875"},
      {std::numeric_limits<double>::denorm_min(), "0.000000"},
      {std::numeric_limits<double>::infinity(), "inf"},
      {-std::numeric_limits<double>::infinity(), "-inf"},
      {std::numeric_limits<double>::quiet_NaN(), "nan"},
      {-std::numeric_limits<double>::quiet_NaN(), "-nan"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(fixed6(c.v), c.text) << c.v;
    EXPECT_EQ(printf6(c.v), c.text) << "the golden line is printf's: " << c.v;
  }
  const double big = std::numeric_limits<double>::max();
  EXPECT_EQ(fixed6(big), printf6(big));
  EXPECT_EQ(fixed6(-big).size(), 1 + 309 + 1 + 6u);
  EXPECT_EQ(fixed6(-big).size(), kFixed6Max);
}

// Seeded random values in every range the formatter distinguishes, compared
// with snprintf: uniform values of the daemon's magnitudes, random bit
// patterns (every exponent, subnormals, NaN payloads), exact ties k/2^n, and
// the neighbours of rounding boundaries (n + 1/2) x 10^-6.
TEST(TextOutput, Fixed6MatchesSnprintfOnRandomValues) {
  const std::uint64_t seed = test_seed(20261125);
  const std::uint64_t count = test_count(200000);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mm(-5000.0, 5000.0);
  std::uniform_int_distribution<int> exp10(-12, 16);
  for (std::uint64_t i = 0; i < count; ++i) {
    double v = 0;
    switch (i % 5) {
      case 0: v = mm(rng); break;
      case 1: v = mm(rng) * std::pow(10.0, exp10(rng)); break;
      case 2: v = std::bit_cast<double>(rng()); break;
      case 3: v = std::ldexp(static_cast<double>(static_cast<std::int64_t>(rng() % 2'000'000) - 1'000'000),
                              -static_cast<int>(rng() % 40)); break;
      case 4: {
        const double boundary = (static_cast<double>(rng() % 10'000'000'000ULL) + 0.5) / 1e6;
        v = boundary;
        for (std::uint64_t k = rng() % 4; k > 0; --k) v = std::nextafter(v, (rng() & 1) ? 1e300 : -1e300);
        if (rng() & 1) v = -v;
        break;
      }
    }
    ASSERT_EQ(fixed6(v), printf6(v)) << "value " << std::hexfloat << v << seed_note(seed);
  }
}

TEST(TextOutput, U64) {
  char buf[20];
  EXPECT_EQ(std::string(buf, format_u64(buf, 0)), "0");
  EXPECT_EQ(std::string(buf, format_u64(buf, 18446744073709551615ULL)), "18446744073709551615");
}

TEST(TextOutput, FileKeepsWhatWasCommittedInOrder) {
  const std::string path = temp_path("text_output");
  std::string expect;
  {
    OutputFile f;
    f.open(path, 4096);  // small: many flushes
    EXPECT_TRUE(f.is_open());
    for (int i = 0; i < 5000; ++i) {
      char* p = f.reserve(kFixed6Max + 1);
      char* end = format_fixed6(p, i * 0.25 - 7.0);
      *end++ = '\n';
      expect.append(p, end);
      f.commit(end);
      if (i % 700 == 0) {
        const std::string big(10000, static_cast<char>('a' + i % 26));  // larger than the buffer
        f.write(big);
        expect += big;
      }
    }
    f.close();
    EXPECT_EQ(f.error(), 0);
    f.close();  // twice: nothing
  }
  EXPECT_EQ(slurp(path), expect);
  ::unlink(path.c_str());
}

TEST(TextOutput, OpenErrorNamesTheFileAndWriteErrorsAreKept) {
  OutputFile f;
  try {
    f.open("/nonexistent-dir/x.csv");
    FAIL() << "opened a file in a folder that does not exist";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.csv"), std::string::npos) << e.what();
    EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
  }
  EXPECT_FALSE(f.is_open());
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  f.open("/dev/full", 4096);
  f.write(std::string(10000, 'x'));  // two flushes on the way
  f.close();
  EXPECT_EQ(f.error(), ENOSPC);
}
