// Decode throughput of the trace decoder on a 1-million-frame candump log
// (4 CSP drives, 1 ms SYNC: SYNC + 4 RPDO + 4 TPDO per cycle, heartbeats).
// Figures go to BENCHMARKS.md; this is never a timed test.
//
//   cantrace_bench                          run the benchmarks
//   cantrace_bench --write-log FILE N       write an N-frame log (for /usr/bin/time -v cantrace FILE)
#include <benchmark/benchmark.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "fieldbus/can/candump_format.hpp"
#include "fieldbus/trace/analyzer.hpp"
#include "fieldbus/trace/decoder.hpp"
#include "fieldbus/trace/format.hpp"
#include "fieldbus/trace/reader.hpp"

namespace tr = canmotion::trace;
namespace can = canmotion::can;

namespace {

// Calls emit(line) for n frames of a 4-axis CSP bus.
template <typename Emit>
void generate(std::size_t n, Emit emit) {
  std::int64_t t = 1'700'000'000'000'000'000LL;
  std::array<char, can::kCandumpLineMax + 1> buf{};
  std::size_t made = 0;
  std::int32_t pos = 0;
  auto put = [&](const can::Frame& f, std::int64_t at) {
    if (made >= n) return;
    const std::size_t len = can::format_candump_line(buf, f, at, "vcan0");
    emit(std::string_view(buf.data(), len));
    ++made;
  };
  for (std::uint64_t cycle = 0; made < n; ++cycle) {
    pos += 17;
    for (std::uint8_t node = 1; node <= 4; ++node) {
      const auto p = static_cast<std::uint32_t>(pos * node);
      put(can::Frame(0x200U + node, {0x0F, 0x00, static_cast<std::uint8_t>(p), static_cast<std::uint8_t>(p >> 8),
                                     static_cast<std::uint8_t>(p >> 16), static_cast<std::uint8_t>(p >> 24)}),
          t + node * 1000);
    }
    put(can::Frame(0x080, {}), t + 10'000 + static_cast<std::int64_t>(cycle % 7) * 1000);
    for (std::uint8_t node = 1; node <= 4; ++node) {
      const auto p = static_cast<std::uint32_t>(pos * node - 3);
      put(can::Frame(0x180U + node, {0x37, 0x12, static_cast<std::uint8_t>(p), static_cast<std::uint8_t>(p >> 8),
                                     static_cast<std::uint8_t>(p >> 16), static_cast<std::uint8_t>(p >> 24)}),
          t + 20'000 + node * 1000);
    }
    if (cycle % 100 == 0) {
      for (std::uint8_t node = 1; node <= 4; ++node) put(can::Frame(0x700U + node, {0x05}), t + 40'000 + node * 1000);
    }
    t += 1'000'000;
  }
}

const std::vector<std::string>& log_lines() {
  static const std::vector<std::string> lines = [] {
    std::vector<std::string> v;
    v.reserve(1'000'000);
    generate(1'000'000, [&](std::string_view s) { v.emplace_back(s); });
    return v;
  }();
  return lines;
}

void BM_ParseLines(benchmark::State& state) {
  const auto& lines = log_lines();
  for (auto _ : state) {
    tr::LineReader r;
    can::TimedFrame f;
    std::string_view iface;
    for (const auto& l : lines) benchmark::DoNotOptimize(r.feed(l, f, iface));
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines.size()));
}

void BM_ParseAndDecode(benchmark::State& state) {
  const auto& lines = log_lines();
  for (auto _ : state) {
    tr::LineReader r;
    auto dec = std::make_unique<tr::Decoder>();
    can::TimedFrame f;
    std::string_view iface;
    for (const auto& l : lines) {
      if (r.feed(l, f, iface) == tr::LineReader::Status::kFrame) benchmark::DoNotOptimize(dec->decode(f).kind);
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines.size()));
}

// What `cantrace LOG` does per line: parse, decode, render the text line.
void BM_DecodeToText(benchmark::State& state) {
  const auto& lines = log_lines();
  for (auto _ : state) {
    tr::LineReader r;
    auto dec = std::make_unique<tr::Decoder>();
    can::TimedFrame f;
    std::string_view iface;
    fmt::memory_buffer out;
    for (const auto& l : lines) {
      if (r.feed(l, f, iface) != tr::LineReader::Status::kFrame) continue;
      tr::format_text(dec->decode(f), iface, {}, out);
      if (out.size() > (1U << 16)) out.clear();
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines.size()));
}

// `cantrace -s -q LOG`: parse, decode, analyse.
void BM_DecodeAndAnalyze(benchmark::State& state) {
  const auto& lines = log_lines();
  for (auto _ : state) {
    tr::LineReader r;
    auto dec = std::make_unique<tr::Decoder>();
    tr::Analyzer an{tr::AnalyzerOptions{}};
    can::TimedFrame f;
    std::string_view iface;
    for (const auto& l : lines) {
      if (r.feed(l, f, iface) == tr::LineReader::Status::kFrame) an.feed(dec->decode(f), *dec, nullptr);
    }
    an.finish(*dec);
    benchmark::DoNotOptimize(an.bus().frames);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines.size()));
}

void BM_FormatCandumpLine(benchmark::State& state) {
  const can::Frame f(0x181, {0x37, 0x06, 0xA0, 0x86, 0x01, 0x00});
  std::array<char, can::kCandumpLineMax + 1> buf{};
  std::int64_t t = 1'700'000'000'000'000'000LL;
  for (auto _ : state) {
    benchmark::DoNotOptimize(can::format_candump_line(buf, f, t, "vcan0"));
    t += 1000;
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_ParseLines)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ParseAndDecode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeToText)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeAndAnalyze)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FormatCandumpLine);

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::strcmp(argv[1], "--write-log") == 0) {
    std::FILE* f = std::fopen(argv[2], "w");
    if (f == nullptr) {
      std::perror(argv[2]);
      return 1;
    }
    generate(std::strtoull(argv[3], nullptr, 10), [&](std::string_view s) {
      std::fwrite(s.data(), 1, s.size(), f);
      std::fputc('\n', f);
    });
    std::fclose(f);
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
