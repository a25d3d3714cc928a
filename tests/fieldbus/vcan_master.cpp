// fieldbus-vcan-master: the master side of the vcan integration test. Boots,
// configures and enables the given nodes over a real SocketCAN interface
// through DriveNetwork, runs a CSP ramp and checks that every drive followed
// it. Exit 0 on success, 1 with an explanation otherwise.
//   fieldbus-vcan-master IFACE CYCLE_US RAMP_CYCLES NODE...
#include <time.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fieldbus/can/socketcan_bus.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

using namespace canmotion;

namespace {
std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
void sleep_until(std::int64_t t) {
  timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: fieldbus-vcan-master IFACE CYCLE_US RAMP_CYCLES NODE...\n");
    return 1;
  }
  const std::string iface = argv[1];
  const std::int64_t cycle = std::atoll(argv[2]) * 1000;
  const long ramp_cycles = std::atol(argv[3]);
  std::vector<std::uint8_t> nodes;
  for (int i = 4; i < argc; ++i) nodes.push_back(static_cast<std::uint8_t>(std::atoi(argv[i])));

  cia402::DriveNetwork net;
  for (auto n : nodes) {
    cia402::DriveConfig d;
    d.node = n;
    d.cycle_ns = cycle;
    d.reset_node_first = true;  // the emulator booted before us
    // The VM is slow and its timing meaningless: generous timeouts.
    d.producer_heartbeat_ms = 100;
    d.consumer_heartbeat_ms = 3000;
    d.heartbeat_timeout_ns = 3'000'000'000;
    d.boot_timeout_ns = 10'000'000'000;
    d.sdo_timeout_ns = 2'000'000'000;
    d.start_timeout_ns = 10'000'000'000;
    d.transition_timeout_ns = 5'000'000'000;
    net.add_drive(d);
  }
  // Only the frames the master needs (kernel filters from the network).
  const auto filters = net.receive_filters();
  std::error_code ec;
  std::string detail;
  auto bus = can::SocketCanBus::open(iface, filters, ec, &detail);
  if (!bus) {
    std::fprintf(stderr, "fieldbus-vcan-master: %s\n", detail.c_str());
    return 1;
  }
  canopen::TransportSink sink(*bus);
  std::array<can::TimedFrame, 64> buf;
  std::int64_t t = now_ns();
  auto cycle_once = [&] {
    t += cycle;
    sleep_until(t);
    const std::int64_t now = now_ns();
    if (now - t > 50 * cycle) t = now;  // after a long stall (VM), do not burst
    for (;;) {
      const std::size_t n = bus->receive(buf);
      for (std::size_t i = 0; i < n; ++i) net.on_frame(buf[i]);
      if (n < buf.size()) break;
    }
    net.cycle(now, sink);
  };
  auto fail = [&](const char* what) {
    std::fprintf(stderr, "fieldbus-vcan-master: %s\n", what);
    for (std::size_t i = 0; i < net.size(); ++i) {
      const auto& d = net.at(i);
      std::fprintf(stderr, "  node %u: %s, %s, statusword 0x%04X%s%s\n", d.node(),
                   std::string(cia402::phase_name(d.phase())).c_str(), std::string(cia402::state_name(d.state())).c_str(),
                   d.feedback().statusword, d.failed() ? ": " : "", d.failed() ? d.failure().to_string().c_str() : "");
    }
    return 1;
  };
  const std::int64_t t0 = now_ns();
  while (!net.all_operational()) {
    if (net.any_failed()) return fail("boot failed");
    if (now_ns() - t0 > 60'000'000'000) return fail("boot did not finish in 60 s");
    cycle_once();
  }
  std::printf("fieldbus-vcan-master: %zu node(s) configured and started after %.3f s\n", nodes.size(),
              static_cast<double>(now_ns() - t0) / 1e9);
  net.enable_all();
  const std::int64_t t1 = now_ns();
  while (!net.all_enabled()) {
    if (net.any_failed()) return fail("enable failed");
    if (now_ns() - t1 > 30'000'000'000) return fail("enable did not finish in 30 s");
    cycle_once();
  }
  std::printf("fieldbus-vcan-master: all enabled\n");
  std::vector<std::int64_t> start;
  for (std::size_t i = 0; i < net.size(); ++i) start.push_back(net.at(i).feedback().position);
  constexpr std::int32_t kStep = 100;  // counts per cycle
  for (long k = 1; k <= ramp_cycles; ++k) {
    for (std::size_t i = 0; i < net.size(); ++i)
      net.at(i).set_target_position(start[i] + static_cast<std::int64_t>(k) * kStep);
    cycle_once();
    if (net.any_failed()) return fail("failure during the ramp");
  }
  // Hold the final target until the drives caught up (lag + latency).
  for (int k = 0; k < 200; ++k) cycle_once();
  int rc = 0;
  for (std::size_t i = 0; i < net.size(); ++i) {
    const auto& d = net.at(i);
    const std::int64_t want = start[i] + static_cast<std::int64_t>(ramp_cycles) * kStep;
    const std::int64_t got = d.feedback().position;
    std::printf("fieldbus-vcan-master: node %u moved %lld -> %lld (target %lld), TPDOs %llu, missed %llu\n", d.node(),
                static_cast<long long>(start[i]), static_cast<long long>(got), static_cast<long long>(want), static_cast<unsigned long long>(d.feedback().tpdo_count),
                static_cast<unsigned long long>(d.feedback().tpdo_missed));
    if (std::abs(got - want) > 2) {
      std::fprintf(stderr, "fieldbus-vcan-master: node %u did not follow the ramp (at %lld, want %lld)\n", d.node(),
                   static_cast<long long>(got), static_cast<long long>(want));
      rc = 1;
    }
  }
  net.disable_all();
  for (int k = 0; k < 20; ++k) cycle_once();
  return rc;
}
