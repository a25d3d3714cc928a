// fieldbus-demo: the end-to-end fieldbus demo until the daemon exists.
// A CANopen master and emulated CiA 402 drives on the in-process SimBus with
// a virtual clock: boot -> SDO configuration -> NMT start -> enable -> CSP
// motion (ramp on the first drive, sine on the others), as fast as possible.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "fieldbus/can/candump_format.hpp"
#include "fieldbus/emulator/sim_rig.hpp"

using namespace canmotion;

namespace {
constexpr const char* kFooter = R"(Examples:
  fieldbus-demo
      3 drives (nodes 2, 3, 4), 1 ms cycle, 10 simulated seconds
  fieldbus-demo --nodes 2 5 9 --duration 30 --trace demo.log
      also write every frame in candump -L format (decode with cantrace)
  fieldbus-demo --cycle-us 2000 --lag 4
      2 ms cycle, drives that lag their target by 4 SYNCs

Output: one progress line per simulated second, then a summary with the
cycle and frame counts, the largest following error per node (target minus
actual as the master sees it, in counts) and the wall-clock time taken.
Exit status: 0 when every drive booted, enabled and followed; 1 otherwise.)";

/// The command line.
struct Options {
  std::vector<int> nodes{2, 3, 4};
  double duration = 10.0;
  int cycle_us = 1000;
  std::uint32_t lag = 2;
  std::string trace;
};

/// Parse the command line into `o`; an exit status when the program ends
/// here (--help: 0, a bad option: 1).
std::optional<int> parse_args(int argc, char** argv, Options& o) {
  CLI::App app{"fieldbus-demo - CANopen master + emulated CiA 402 drives on the in-process SimBus", "fieldbus-demo"};
  app.footer(kFooter);
  app.add_option("--nodes", o.nodes, "node-IDs of the emulated drives")->check(CLI::Range(1, 126))->default_str("2 3 4");
  app.add_option("--duration", o.duration, "simulated seconds of motion after enabling")->check(CLI::Range(0.1, 3600.0))->default_val(10.0);
  app.add_option("--cycle-us", o.cycle_us, "cycle period in microseconds")->check(CLI::Range(100, 100000))->default_val(1000);
  app.add_option("--lag", o.lag, "drive lag in SYNCs (emulator)")->check(CLI::Range(0, 64))->default_val(2);
  app.add_option("--trace", o.trace, "write every frame to FILE in candump -L format");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 1;
  }
  return std::nullopt;
}

/// The motion profile: drive 0 a trapezoidal ramp, the others a sine, as
/// offsets from their start position.
struct Motion {
  double ramp_velocity = 200'000.0;     // counts/s, node 0
  double ramp_accel = 1'000'000.0;      // counts/s^2
  double sine_amplitude = 100'000.0;    // counts
  double sine_period_s = 2.0;

  /// Offset of drive `i` at time `t` (seconds since the start).
  [[nodiscard]] double target(std::size_t i, double t) const {
    if (i == 0) {
      const double ta = ramp_velocity / ramp_accel;
      return t < ta ? 0.5 * ramp_accel * t * t : 0.5 * ramp_accel * ta * ta + ramp_velocity * (t - ta);
    }
    const double phase = static_cast<double>(i - 1) * 0.5;
    return sine_amplitude * std::sin(2.0 * std::numbers::pi * (t / sine_period_s + phase)) -
           sine_amplitude * std::sin(2.0 * std::numbers::pi * phase);
  }
};

double seconds(std::int64_t ns) { return static_cast<double>(ns) / 1e9; }

/// Write every frame on the bus to `path` in candump -L format; null (and a
/// message) when it cannot be written.
std::FILE* open_trace(emulator::SimRig& rig, const std::string& path) {
  std::FILE* tf = std::fopen(path.c_str(), "w");
  if (!tf) {
    std::fprintf(stderr, "fieldbus-demo: cannot write trace '%s': %s\n", path.c_str(), std::strerror(errno));
    return nullptr;
  }
  rig.bus().set_tap([tf](const can::TimedFrame& f, std::string_view iface) {
    char line[can::kCandumpLineMax + 2];
    const std::size_t n = can::format_candump_line(line, f.frame, f.t_ns, iface, 6);
    line[n] = '\n';
    std::fwrite(line, 1, n + 1, tf);
  });
  return tf;
}

/// Boot, SDO configuration and NMT start of every drive, then enable them.
bool boot_and_enable(emulator::SimRig& rig, const Options& o, double T) {
  auto& net = rig.network();
  rig.power_on();
  std::printf("fieldbus-demo: %zu drive(s), cycle %d us, SimBus with virtual clock\n", o.nodes.size(), o.cycle_us);
  if (!rig.run_until([&] { return net.all_operational() || net.any_failed(); }, static_cast<std::uint64_t>(5.0 / T))) {
    std::fprintf(stderr, "fieldbus-demo: boot did not finish in 5 simulated seconds\n");
    return false;
  }
  for (std::size_t i = 0; i < net.size(); ++i)
    if (net.at(i).failed()) {
      std::fprintf(stderr, "fieldbus-demo: %s\n", net.at(i).failure().to_string().c_str());
      return false;
    }
  unsigned long long transfers = 0;
  for (int n : o.nodes) transfers += net.master().sdo(static_cast<std::uint8_t>(n)).completed();
  std::printf("[%7.3f s] boot + SDO configuration + NMT start done (%llu SDO transfers)\n", seconds(rig.now_ns()), transfers);
  net.enable_all();
  if (!rig.run_until([&] { return net.all_enabled() || net.any_failed(); }, static_cast<std::uint64_t>(1.0 / T)) ||
      net.any_failed()) {
    for (std::size_t i = 0; i < net.size(); ++i)
      if (net.at(i).failed()) std::fprintf(stderr, "fieldbus-demo: %s\n", net.at(i).failure().to_string().c_str());
    std::fprintf(stderr, "fieldbus-demo: enabling failed\n");
    return false;
  }
  std::printf("[%7.3f s] all drives in Operation enabled (transitions 2, 3, 4)\n", seconds(rig.now_ns()));
  return true;
}

/// One progress line: cycles, frames and each drive's position and following error.
void print_progress(emulator::SimRig& rig) {
  auto& net = rig.network();
  std::printf("[%7.3f s] cycles %llu, frames %llu |", seconds(rig.now_ns()), static_cast<unsigned long long>(rig.cycles()),
              static_cast<unsigned long long>(rig.bus().counters().delivered));
  for (std::size_t i = 0; i < net.size(); ++i) {
    const auto& d = net.at(i);
    std::printf(" node %u pos %lld fe %lld |", d.node(), static_cast<long long>(d.feedback().position),
                static_cast<long long>(d.target_position() - d.feedback().position));
  }
  std::printf("\n");
  std::fflush(stdout);
}

/// CSP motion for `duration` seconds, a progress line per simulated second;
/// the largest following error per drive (counts).
std::vector<double> run_motion(emulator::SimRig& rig, double duration, double T) {
  auto& net = rig.network();
  const Motion m;
  std::vector<std::int64_t> start(net.size());
  std::vector<double> max_fe(net.size(), 0.0);
  for (std::size_t i = 0; i < net.size(); ++i) start[i] = net.at(i).feedback().position;
  const auto motion_cycles = static_cast<std::uint64_t>(std::llround(duration / T));
  const auto per_second = static_cast<std::uint64_t>(std::llround(1.0 / T));
  for (std::uint64_t k = 1; k <= motion_cycles; ++k) {
    const double t = static_cast<double>(k) * T;
    for (std::size_t i = 0; i < net.size(); ++i) {
      auto& d = net.at(i);
      d.set_target_position(start[i] + std::llround(m.target(i, t)));
      const double fe = std::abs(static_cast<double>(d.target_position() - d.feedback().position));
      max_fe[i] = std::max(max_fe[i], fe);
    }
    rig.step();
    if (net.any_failed()) break;
    if (k % per_second == 0) print_progress(rig);
  }
  return max_fe;
}

/// The summary; true when every drive is still enabled.
bool print_summary(emulator::SimRig& rig, const Options& o, const std::vector<double>& max_fe, double wall) {
  auto& net = rig.network();
  bool ok = !net.any_failed();
  std::printf("\nsummary\n");
  std::printf("  simulated time   %.3f s (%llu cycles of %d us)\n", seconds(rig.now_ns()),
              static_cast<unsigned long long>(rig.cycles()), o.cycle_us);
  std::printf("  frames on bus    %llu (%.2f per cycle), SYNC %llu\n",
              static_cast<unsigned long long>(rig.bus().counters().delivered),
              static_cast<double>(rig.bus().counters().delivered) / static_cast<double>(rig.cycles()),
              static_cast<unsigned long long>(net.master().syncs_sent()));
  for (std::size_t i = 0; i < net.size(); ++i) {
    const auto& d = net.at(i);
    std::printf("  node %-3u  %-18s max following error %8.0f counts, TPDOs %llu, missed %llu%s\n", d.node(),
                std::string(cia402::state_name(d.state())).c_str(), max_fe[i],
                static_cast<unsigned long long>(d.feedback().tpdo_count),
                static_cast<unsigned long long>(d.feedback().tpdo_missed), d.failed() ? "  FAILED" : "");
    if (d.failed()) std::printf("    %s\n", d.failure().to_string().c_str());
    ok = ok && d.enabled();
  }
  std::printf("  wall time        %.3f s (%.0fx real time)\n", wall, seconds(rig.now_ns()) / wall);
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const auto rc = parse_args(argc, argv, o)) return *rc;

  emulator::SimRigConfig cfg;
  cfg.cycle_ns = static_cast<std::int64_t>(o.cycle_us) * 1000;
  cfg.nodes.clear();
  for (int n : o.nodes) cfg.nodes.push_back(static_cast<std::uint8_t>(n));
  cfg.emulator.lag_cycles = o.lag;
  std::unique_ptr<emulator::SimRig> rig;
  try {
    rig = std::make_unique<emulator::SimRig>(cfg);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fieldbus-demo: %s\n", e.what());
    return 1;
  }
  std::FILE* tf = nullptr;
  if (!o.trace.empty() && (tf = open_trace(*rig, o.trace)) == nullptr) return 1;

  const auto wall0 = std::chrono::steady_clock::now();
  const double T = static_cast<double>(cfg.cycle_ns) / 1e9;
  if (!boot_and_enable(*rig, o, T)) return 1;
  const std::vector<double> max_fe = run_motion(*rig, o.duration, T);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const bool ok = print_summary(*rig, o, max_fe, wall);
  if (tf) {
    std::fclose(tf);
    std::printf("  trace            %s (candump -L)\n", o.trace.c_str());
  }
  return ok ? 0 : 1;
}
