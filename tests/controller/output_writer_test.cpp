// canmotiond's --csv rows and --trace lines without stdio: the same bytes as
// the printf/fwrite code they replace. format_telemetry_csv_row against
// snprintf with the old format (golden lines for edge values, seeded random
// samples); OutputWriter inline and threaded against the reference text of
// more records than its batches hold (the caller waits, nothing is dropped).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "fieldbus/can/candump_format.hpp"
#include "rt/controller/output_writer.hpp"
#include "rt/controller/telemetry_csv.hpp"
#include "tests/support/random_seed.hpp"

namespace canmotion::rt {
namespace {

using test::seed_note;
using test::test_count;
using test::test_seed;

// The format canmotiond's Outputs::drain used up to issue 18.
std::string old_row(const Sample& s, double T, const std::string& axis) {
  std::string out(telemetry_csv_row_max(axis.size()) + 1, '\0');
  const int n = std::snprintf(out.data(), out.size(), "%llu,%.6f,%s,%.6f,%.6f,%.6f,%.6f,%u,%u\n",
                              static_cast<unsigned long long>(s.cycle), static_cast<double>(s.cycle) * T,
                              axis.c_str(), s.cmd_pos, s.act_pos, s.cmd_vel, s.act_vel, s.motion_status,
                              s.axis_status);
  out.resize(static_cast<std::size_t>(n));
  return out;
}

std::string new_row(const Sample& s, double T, const std::string& axis) {
  std::string out(telemetry_csv_row_max(axis.size()), '\0');
  char* end = format_telemetry_csv_row(out.data(), s, T, axis);
  out.resize(static_cast<std::size_t>(end - out.data()));
  return out;
}

Sample sample(std::uint64_t cycle, double a, double b, double c, double d, std::uint32_t ms, std::uint32_t as) {
  Sample s;
  s.cycle = cycle;
  s.cmd_pos = a;
  s.act_pos = b;
  s.cmd_vel = c;
  s.act_vel = d;
  s.motion_status = ms;
  s.axis_status = as;
  return s;
}

// "" when equal, else where they part (gtest's diff of megabytes is too slow).
std::string first_difference(const std::string& got, const std::string& want) {
  if (got == want) return "";
  std::size_t i = 0;
  while (i < got.size() && i < want.size() && got[i] == want[i]) ++i;
  const std::size_t from = i < 40 ? 0 : i - 40;
  return "sizes " + std::to_string(got.size()) + " / " + std::to_string(want.size()) + ", first difference at byte " +
         std::to_string(i) + ": got '" + got.substr(from, 80) + "', want '" + want.substr(from, 80) + "'";
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(TelemetryCsv, GoldenRowsForEdgeValues) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const struct {
    Sample s;
    double T;
    const char* axis;
    const char* row;
  } cases[] = {
      {sample(0, 0, 0, 0, 0, 0, 64), 0.001, "A0", "0,0.000000,A0,0.000000,0.000000,0.000000,0.000000,0,64\n"},
      {sample(1234, -12.5, -0.0000004, 100, -100.0000005, 1, 2), 0.001, "Gear",
       "1234,1.234000,Gear,-12.500000,-0.000000,100.000000,-100.000000,1,2\n"},
      {sample(7, 1e12, -123456.789, 3.25e-7, 42, 4294967295u, 4294967295u), 0.004, "X",
       "7,0.028000,X,1000000000000.000000,-123456.789000,0.000000,42.000000,4294967295,4294967295\n"},
      {sample(18446744073709551615ULL, nan, -inf, inf, -nan, 0, 0), 0.00025, "Slave_1",
       "18446744073709551615,4611686018427388.000000,Slave_1,nan,-inf,inf,-nan,0,0\n"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(new_row(c.s, c.T, c.axis), c.row);
    EXPECT_EQ(old_row(c.s, c.T, c.axis), c.row) << "the golden row is what printf wrote";
  }
  EXPECT_EQ(kTelemetryCsvHeader, "cycle,time,axis,cmd_pos,act_pos,cmd_vel,act_vel,motion_status,axis_status\n");
  // The longest row fits the bound.
  const double big = -std::numeric_limits<double>::max();
  const Sample worst = sample(18446744073709551615ULL, big, big, big, big, 4294967295u, 4294967295u);
  const std::string name(40, 'n');
  EXPECT_EQ(new_row(worst, 1e300, name), old_row(worst, 1e300, name));
  EXPECT_LE(new_row(worst, -1e300, name).size(), telemetry_csv_row_max(name.size()));
}

TEST(TelemetryCsv, RandomSamplesMatchTheOldPrintf) {
  const std::uint64_t seed = test_seed(18);
  const std::uint64_t count = test_count(50000);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-10000.0, 10000.0);
  const double periods[] = {0.001, 0.004, 0.00025, 0.002, 0.1};
  for (std::uint64_t i = 0; i < count; ++i) {
    Sample s = sample(rng() % 100'000'000, pos(rng), pos(rng), pos(rng) * 1e-3, pos(rng) * 1e3,
                      static_cast<std::uint32_t>(rng()), static_cast<std::uint32_t>(rng() % 1024));
    if (i % 7 == 0) s.act_vel = std::bit_cast<double>(rng());  // any bit pattern
    const double T = periods[rng() % 5];
    const std::string axis = "Axis" + std::to_string(rng() % 64);
    ASSERT_EQ(new_row(s, T, axis), old_row(s, T, axis)) << seed_note(seed);
  }
}

// OutputWriter, inline (real time) and threaded (--sim), against the bytes
// the old code wrote: the header, format_candump_line + '\n', the printf row.
TEST(OutputWriter, InlineAndThreadedWriteTheOldBytes) {
  const std::uint64_t seed = test_seed(1818);
  std::mt19937_64 rng(seed);
  const std::vector<std::string> buses = {"can0", "vcan1", "bus_with_a_long_name_x"};
  const std::vector<std::string> axes = {"Master", "Gear", "X"};
  const double T = 0.001;
  // More records than the writer's batches hold, so that the caller waits.
  const std::size_t n = OutputWriter::kBatchRecords * (OutputWriter::kBatches + 2) + 123;
  struct Rec {
    can::Frame f;
    std::int64_t t;
    std::uint8_t bus;
    Sample s;
  };
  std::vector<Rec> recs(n);
  std::string trace_ref = "";
  std::string csv_ref(kTelemetryCsvHeader);
  for (std::size_t i = 0; i < n; ++i) {
    Rec& r = recs[i];
    r.f = can::Frame(static_cast<std::uint32_t>(0x180 + rng() % 0x100), {});
    r.f.len = static_cast<std::uint8_t>(rng() % 9);
    for (std::size_t k = 0; k < r.f.len; ++k) r.f.data[k] = static_cast<std::uint8_t>(rng());
    r.t = static_cast<std::int64_t>(1'700'000'000'000'000'000LL + static_cast<std::int64_t>(i) * 1000);
    r.bus = static_cast<std::uint8_t>(rng() % buses.size());
    r.s = sample(i / 3, std::ldexp(static_cast<double>(rng() % 100000) - 50000, -7), 1.5, -2.25, 0, 3,
                 static_cast<std::uint32_t>(i % 3));
    r.s.axis = static_cast<std::uint16_t>(i % 3);
    char line[can::kCandumpLineMax + 1];
    const std::size_t len = can::format_candump_line(line, r.f, r.t, buses[r.bus]);
    trace_ref.append(line, len);
    trace_ref += '\n';
    csv_ref += old_row(r.s, T, axes[r.s.axis]);
  }
  for (const bool threaded : {false, true}) {
    const std::string base = std::string(::testing::TempDir()) + "/ow" + std::to_string(::getpid()) +
                             (threaded ? "t" : "i");
    OutputWriterConfig c;
    c.trace_path = base + ".log";
    c.csv_path = base + ".csv";
    c.trace_names = buses;
    c.axis_names = axes;
    c.period_s = T;
    c.threaded = threaded;
    c.buffer_bytes = 8192;
    {
      OutputWriter w(c);
      EXPECT_TRUE(w.tracing());
      EXPECT_TRUE(w.recording_csv());
      for (const Rec& r : recs) {
        w.trace(r.f, r.t, r.bus);
        w.sample(r.s);
      }
      EXPECT_EQ(w.close(), "");
      w.trace(recs[0].f, 0, 0);  // after close: ignored
    }
    EXPECT_EQ(first_difference(slurp(c.trace_path), trace_ref), "") << (threaded ? "threaded" : "inline")
                                                                      << seed_note(seed);
    EXPECT_EQ(first_difference(slurp(c.csv_path), csv_ref), "") << (threaded ? "threaded" : "inline")
                                                                  << seed_note(seed);
    ::unlink(c.trace_path.c_str());
    ::unlink(c.csv_path.c_str());
  }
}

TEST(OutputWriter, ErrorsNameTheFile) {
  OutputWriterConfig c;
  c.csv_path = "/nonexistent-dir/run.csv";
  try {
    OutputWriter w(c);
    FAIL() << "opened a CSV file in a folder that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write CSV file '/nonexistent-dir/run.csv'"), std::string::npos)
        << e.what();
  }
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  c.csv_path = "";
  c.trace_path = "/dev/full";
  c.threaded = true;
  c.trace_names = {"can0"};
  OutputWriter w(c);
  for (int i = 0; i < 100000; ++i) w.trace(can::Frame(0x181, {1, 2, 3}), i, 0);
  EXPECT_NE(w.close().find("writing '/dev/full' failed: No space left on device"), std::string::npos);
  EXPECT_FALSE(w.recording_csv());
}

}  // namespace
}  // namespace canmotion::rt
