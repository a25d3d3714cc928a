#include "rt/cycle_stats.hpp"

#include <fmt/format.h>

#include <array>

namespace canmotion::rt {

namespace {

struct TagDef {
  std::string_view name;
  std::int64_t (*get)(const CycleStats&) noexcept;
};

#define CANMOTION_STAT_TAG(field) \
  TagDef { #field, [](const CycleStats& s) noexcept { return static_cast<std::int64_t>(s.field); } }

constexpr std::array kTags{
    CANMOTION_STAT_TAG(period_ns),
    CANMOTION_STAT_TAG(cycles),
    CANMOTION_STAT_TAG(overruns),
    CANMOTION_STAT_TAG(missed_deadlines),
    CANMOTION_STAT_TAG(latency_min_ns),
    CANMOTION_STAT_TAG(latency_mean_ns),
    CANMOTION_STAT_TAG(latency_p50_ns),
    CANMOTION_STAT_TAG(latency_p99_ns),
    CANMOTION_STAT_TAG(latency_p999_ns),
    CANMOTION_STAT_TAG(latency_max_ns),
    CANMOTION_STAT_TAG(exec_min_ns),
    CANMOTION_STAT_TAG(exec_mean_ns),
    CANMOTION_STAT_TAG(exec_p99_ns),
    CANMOTION_STAT_TAG(exec_max_ns),
    CANMOTION_STAT_TAG(measured_period_min_ns),
    CANMOTION_STAT_TAG(measured_period_mean_ns),
    CANMOTION_STAT_TAG(measured_period_max_ns),
    CANMOTION_STAT_TAG(last_latency_ns),
    CANMOTION_STAT_TAG(last_exec_ns),
};
#undef CANMOTION_STAT_TAG

// Every field of CycleStats is an 8-byte integer and has a tag.
static_assert(sizeof(CycleStats) == kTags.size() * 8, "add the new CycleStats field to kTags");

constexpr auto kNames = [] {
  std::array<std::string_view, kTags.size()> n{};
  for (std::size_t i = 0; i < kTags.size(); ++i) {
    n[i] = kTags[i].name;
  }
  return n;
}();

double us(std::int64_t ns) { return static_cast<double>(ns) / 1000.0; }

}  // namespace

std::span<const std::string_view> stat_tag_names() noexcept { return kNames; }

std::optional<std::int64_t> stat_tag_value(const CycleStats& s, std::string_view name) noexcept {
  for (const auto& t : kTags) {
    if (t.name == name) {
      return t.get(s);
    }
  }
  return std::nullopt;
}

std::string format_summary(const CycleStats& s) {
  return fmt::format(
      "cycles {}  overruns {}  missed deadlines {}  period {:.1f} us\n"
      "latency  min {:.1f}  mean {:.1f}  p50 {:.1f}  p99 {:.1f}  p99.9 {:.1f}  max {:.1f} us\n"
      "exec     min {:.1f}  mean {:.1f}  p99 {:.1f}  max {:.1f} us\n"
      "period   min {:.1f}  mean {:.1f}  max {:.1f} us\n",
      s.cycles, s.overruns, s.missed_deadlines, us(s.period_ns), us(s.latency_min_ns), us(s.latency_mean_ns),
      us(s.latency_p50_ns), us(s.latency_p99_ns), us(s.latency_p999_ns), us(s.latency_max_ns),
      us(s.exec_min_ns), us(s.exec_mean_ns), us(s.exec_p99_ns), us(s.exec_max_ns),
      us(s.measured_period_min_ns), us(s.measured_period_mean_ns), us(s.measured_period_max_ns));
}

std::string format_line(const CycleStats& s) {
  return fmt::format(
      "C:{:>9} Lat(us) Min:{:>6.1f} Act:{:>6.1f} Avg:{:>6.1f} P99:{:>6.1f} Max:{:>7.1f} "
      "Exec(us) Avg:{:>6.1f} Max:{:>7.1f} Overruns:{}",
      s.cycles, us(s.latency_min_ns), us(s.last_latency_ns), us(s.latency_mean_ns), us(s.latency_p99_ns),
      us(s.latency_max_ns), us(s.exec_mean_ns), us(s.exec_max_ns), s.overruns);
}

void CycleStatistics::record(Nanos latency, Nanos exec, Nanos measured_period) noexcept {
  latency_.record(latency.count());
  exec_.record(exec.count());
  if (measured_period.count() >= 0) {
    period_hist_.record(measured_period.count());
  }
  last_latency_.store(latency.count(), std::memory_order_relaxed);
  last_exec_.store(exec.count(), std::memory_order_relaxed);
}

void CycleStatistics::record_overrun(std::uint64_t missed) noexcept {
  overruns_.store(overruns_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  missed_.store(missed_.load(std::memory_order_relaxed) + missed, std::memory_order_relaxed);
}

CycleStats CycleStatistics::snapshot() const noexcept {
  CycleStats s;
  s.period_ns = period_.count();
  s.cycles = latency_.count();
  s.overruns = overruns_.load(std::memory_order_relaxed);
  s.missed_deadlines = missed_.load(std::memory_order_relaxed);
  s.latency_min_ns = latency_.min();
  s.latency_mean_ns = latency_.mean();
  s.latency_p50_ns = latency_.percentile(0.50);
  s.latency_p99_ns = latency_.percentile(0.99);
  s.latency_p999_ns = latency_.percentile(0.999);
  s.latency_max_ns = latency_.max();
  s.exec_min_ns = exec_.min();
  s.exec_mean_ns = exec_.mean();
  s.exec_p99_ns = exec_.percentile(0.99);
  s.exec_max_ns = exec_.max();
  s.measured_period_min_ns = period_hist_.min();
  s.measured_period_mean_ns = period_hist_.mean();
  s.measured_period_max_ns = period_hist_.max();
  s.last_latency_ns = last_latency_.load(std::memory_order_relaxed);
  s.last_exec_ns = last_exec_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace canmotion::rt
