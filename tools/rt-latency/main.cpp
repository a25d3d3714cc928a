// rt-latency: runs canmotion's cyclic executive with an empty (or
// configurable-cost) cycle and prints its wake-up latency statistics once a
// second and at the end, like cyclictest. See tools/rt-latency/README.md.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include "rt/clock.hpp"
#include "rt/cyclic_executive.hpp"

using namespace canmotion::rt;

namespace {

std::atomic<CyclicExecutive*> g_exec{nullptr};
std::atomic<bool> g_print_request{false};

extern "C" void on_usr1(int) { g_print_request.store(true); }

extern "C" void on_signal(int) {
  if (CyclicExecutive* e = g_exec.load()) {
    e->request_stop();  // one atomic store: async-signal-safe
  }
}

double us(std::int64_t ns) { return static_cast<double>(ns) / 1000.0; }

/// The command line.
struct Options {
  std::int64_t interval_us = 1000;
  int priority = 80;
  int cpu = -1;
  double duration_s = 10.0;
  std::uint64_t loops = 0;
  std::int64_t cost_us = 0;
  bool no_mlock = false;
  bool quiet = false;
  bool no_dma_latency = false;
  std::string histogram_file;
  bool check_args = false;
};

/// Parse the command line into `o`; an exit status when the program ends
/// here (--help and --check-args: 0, a bad option: 1).
std::optional<int> parse_args(int argc, char** argv, Options& o) {
  CLI::App app{
      "rt-latency: wake-up latency of canmotion's real-time cycle (like cyclictest).\n"
      "Runs the cyclic executive (SCHED_FIFO, mlockall, absolute CLOCK_MONOTONIC deadlines)\n"
      "with an empty cycle, or one that busy-waits --cost microseconds, and prints the\n"
      "latency statistics once a second and a summary at the end.",
      "rt-latency"};
  app.footer(
      "Examples:\n"
      "  rt-latency -p 80 -i 1000 -l 20000        # 20000 cycles of 1 ms at SCHED_FIFO 80\n"
      "  rt-latency -i 500 -D 60 -c 100 -a 1      # 60 s, 0.5 ms period, 100 us work, CPU 1\n"
      "  rt-latency -q -l 20000 --histogram h.txt # quiet, write the histogram\n"
      "Compare with cyclictest: tools/rt-latency/compare-cyclictest.sh\n"
      "Signals: SIGUSR1 prints the full summary now; SIGINT/SIGTERM stop at a cycle boundary.\n"
      "Exit status: 0 on success, 1 on error (e.g. an invalid CPU).");
  app.add_option("-i,--interval", o.interval_us, "cycle period in microseconds")->capture_default_str()->check(CLI::Range(10, 10'000'000));
  app.add_option("-p,--priority", o.priority, "SCHED_FIFO priority 1..99, 0 = normal scheduling")->capture_default_str()->check(CLI::Range(0, 99));
  app.add_option("-a,--affinity", o.cpu, "pin the cycle thread to this CPU (-1 = no pinning)")->capture_default_str();
  app.add_option("-D,--duration", o.duration_s, "run time in seconds (ignored with --loops)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("-l,--loops", o.loops, "number of cycles (0 = use --duration)")->capture_default_str();
  app.add_option("-c,--cost", o.cost_us, "busy-wait this many microseconds in every cycle")->capture_default_str()->check(CLI::Range(0, 10'000'000));
  app.add_flag("--no-mlock", o.no_mlock, "do not mlockall()");
  app.add_flag("--no-dma-latency", o.no_dma_latency,
               "do not hold /dev/cpu_dma_latency at 0 (cyclictest holds it by default)");
  app.add_flag("-q,--quiet", o.quiet, "print only the final summary");
  app.add_option("--histogram", o.histogram_file, "write the latency histogram (lower_ns upper_ns count per line) to FILE");
  app.add_flag("--check-args", o.check_args, "parse and check the arguments, then exit (0 = valid) without measuring");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;  // can-utils convention: exit 1 on error
  }
  if (o.check_args) {
    std::printf("rt-latency: arguments OK; nothing was run\n");
    return 0;
  }
  return std::nullopt;
}

/// The executive's configuration: period, RT set-up, and like cyclictest the
/// CPUs kept out of deep idle states while we measure (PM QoS,
/// /dev/cpu_dma_latency held at 0 us; one of the RT set-up steps).
ExecutiveConfig executive_config(const Options& o) {
  ExecutiveConfig cfg;
  cfg.period = Nanos{o.interval_us * 1000};
  cfg.rt.lock_memory = !o.no_mlock;
  cfg.rt.priority = o.priority;
  cfg.rt.cpu = o.cpu;
  cfg.rt.cpu_dma_latency_us = o.no_dma_latency ? -1 : 0;
  cfg.thread_name = "rt-latency";
  cfg.warn = [](std::string_view w) { fmt::print(stderr, "rt-latency: warning: {}\n", w); };
  return cfg;
}

/// The run's settings and the RT set-up report, as `#` comment lines.
void print_setup(const CyclicExecutive& exec, const Options& o) {
  fmt::print("# period {} us, priority {}, cpu {}, {} cycles, cost {} us, mlockall {}, cpu_dma_latency {}\n",
             o.interval_us, o.priority, o.cpu, o.loops, o.cost_us, o.no_mlock ? "off" : "on",
             exec.setup_report().outcome(RtStep::cpu_latency).done() ? "0 us" : "not set");
  std::string setup = exec.setup_report().describe();
  for (std::size_t pos = 0; (pos = setup.find('\n', pos)) != std::string::npos && pos + 1 < setup.size();) {
    setup.replace(pos, 1, "\n# ");
    pos += 3;
  }
  fmt::print("# {}", setup);
}

/// Until the executive stops: a line a second (unless quiet), the full
/// summary on SIGUSR1.
void watch(const CyclicExecutive& exec, bool quiet) {
  while (exec.running()) {
    // Wake up often enough to notice the end, print once a second.
    for (int i = 0; i < 20 && exec.running(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (g_print_request.exchange(false)) {  // kill -USR1: the full summary now
        fmt::print("{}", format_summary(exec.stats()));
        std::fflush(stdout);
      }
    }
    if (!quiet && exec.running()) {
      fmt::print("{}\n", format_line(exec.stats()));
      std::fflush(stdout);
    }
  }
}

/// The summary and the RESULT line for scripts.
void print_result(const CyclicExecutive& exec) {
  const CycleStats s = exec.stats();
  fmt::print("{}", format_summary(s));
  fmt::print("RESULT cycles={} min_us={:.2f} mean_us={:.2f} p50_us={:.2f} p99_us={:.2f} p999_us={:.2f} "
             "max_us={:.2f} exec_max_us={:.2f} overruns={} realtime={}\n",
             s.cycles, us(s.latency_min_ns), us(s.latency_mean_ns), us(s.latency_p50_ns), us(s.latency_p99_ns),
             us(s.latency_p999_ns), us(s.latency_max_ns), us(s.exec_max_ns), s.overruns,
             exec.setup_report().realtime() ? "yes" : "no");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const auto rc = parse_args(argc, argv, o)) return *rc;
  const ExecutiveConfig cfg = executive_config(o);
  if (o.loops == 0) {
    o.loops = static_cast<std::uint64_t>(o.duration_s * 1e9 / static_cast<double>(cfg.period.count()));
    if (o.loops == 0) o.loops = 1;
  }

  MonotonicClock clock;
  CyclicExecutive exec(cfg, clock);
  const Nanos cost{o.cost_us * 1000};
  const std::uint64_t last = o.loops;
  exec.set_cycle([&clock, cost, last](const CycleInfo& c) noexcept {
    if (cost.count() > 0) {
      while (clock.now() - c.wake < cost) {
      }
    }
    return c.cycle + 1 >= last ? CycleResult::stop : CycleResult::run_on;
  });

  g_exec.store(&exec);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGUSR1, on_usr1);

  if (const std::error_code ec = exec.start()) {
    const std::string why = exec.setup_report().error_message();
    fmt::print(stderr, "rt-latency: cannot start: {}\n", why.empty() ? ec.message() : why);
    return 1;
  }
  if (!o.quiet) print_setup(exec, o);
  watch(exec, o.quiet);
  exec.join();
  g_exec.store(nullptr);
  print_result(exec);
  if (!o.histogram_file.empty()) {
    std::ofstream out(o.histogram_file);
    if (!out) {
      fmt::print(stderr, "rt-latency: cannot write {}\n", o.histogram_file);
      return 1;
    }
    out << histogram_text(exec.statistics().latency());
  }
  return 0;
}
