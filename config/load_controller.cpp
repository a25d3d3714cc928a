// The loader's `controller:` and `buses:` sections.
#include "config/load_sections.hpp"

namespace canmotion::config::load {

ControllerSettings controller(Reader& r, const YAML::Node& n) {
  ControllerSettings c;
  c.where = r.loc(n);
  if (!r.check_map(n, "controller", {"period_ms", "priority", "cpu", "lock_memory", "cpu_dma_latency_us", "sync_first"}))
    return c;
  double ms = c.period_ms();
  if (r.scalar(n, "controller", "period_ms", ms, 0.25, 100.0, "ms")) c.period_s = period_s_from_ms(ms);
  r.scalar(n, "controller", "priority", c.priority, 0, 99);
  r.scalar(n, "controller", "cpu", c.cpu, -1, 1023);
  r.scalar(n, "controller", "lock_memory", c.lock_memory, false, true);
  // -1 = leave the CPU idle states alone; the top is the kernel's "no constraint" (rt/pm_qos.hpp).
  r.scalar(n, "controller", "cpu_dma_latency_us", c.cpu_dma_latency_us, std::int32_t{-1}, std::int32_t{2'000'000'000}, "us");
  r.scalar(n, "controller", "sync_first", c.sync_first, false, true);
  return c;
}

BusSettings bus(Reader& r, const YAML::Node& n, const std::string& path) {
  BusSettings b;
  b.where = r.loc(n);
  if (!r.check_map(n, path, {"name", "interface", "bitrate", "master_node", "master_heartbeat_ms", "sync_counter_overflow"}))
    return b;
  if (r.required(n, path, "name", "every bus needs a name")) r.string(n, path, "name", b.name);
  if (r.string(n, path, "interface", b.interface) && b.interface.size() >= 16)
    r.error(n["interface"], path + ".interface", "an interface name has at most 15 characters");
  r.scalar(n, path, "bitrate", b.bitrate, 10'000u, 1'000'000u, "bit/s");
  r.scalar(n, path, "master_node", b.master_node, std::uint8_t{1}, std::uint8_t{127});
  r.scalar(n, path, "master_heartbeat_ms", b.master_heartbeat_ms, std::uint16_t{0}, std::uint16_t{65535}, "ms");
  std::uint8_t sc = b.sync_counter_overflow;
  if (r.scalar(n, path, "sync_counter_overflow", sc, std::uint8_t{0}, std::uint8_t{240})) {
    if (sc == 1) r.error(n["sync_counter_overflow"], path + ".sync_counter_overflow",
                         "must be 0 (no counter) or 2 .. 240 (CiA 301 0x1019), got 1");
    else b.sync_counter_overflow = sc;
  }
  return b;
}

}  // namespace canmotion::config::load
