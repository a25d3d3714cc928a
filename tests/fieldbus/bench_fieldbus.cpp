// Fieldbus benchmarks: encode/decode cost per frame and the per-cycle master
// cost; the bus budget of the default mapping is computed and printed.
//   build-*/tests/fieldbus/fieldbus_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cstdio>

#include "fieldbus/canopen/bus_budget.hpp"
#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"
#include "fieldbus/emulator/sim_rig.hpp"

using namespace canmotion;

namespace {
struct NullSink final : canopen::FrameSink {
  std::uint64_t n = 0;
  bool send(const can::Frame& f) noexcept override {
    n += f.len;
    return true;
  }
};

void BM_RpdoEncode(benchmark::State& st) {
  const auto pdos = cia402::default_drive_pdos(cia402::PdoProfile::kCsp, 2);
  const canopen::PdoMap& m = pdos.rpdo[0];
  std::int32_t target = 0;
  for (auto _ : st) {
    can::Frame f;
    f.id = m.cob_id;
    f.len = m.size_bytes;
    std::span<std::uint8_t> p(f.data.data(), f.len);
    canopen::pack_bits(p, m.entries[0].bit_offset, 16, 0x000F);
    canopen::pack_bits(p, m.entries[1].bit_offset, 32, static_cast<std::uint32_t>(target++));
    benchmark::DoNotOptimize(f);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_RpdoEncode);

void BM_TpdoDecode(benchmark::State& st) {
  const auto pdos = cia402::default_drive_pdos(cia402::PdoProfile::kCsp, 2);
  const canopen::PdoMap& m = pdos.tpdo[0];
  can::Frame f{0x182, {0x37, 0x12, 0x78, 0x56, 0x34, 0x12}};
  for (auto _ : st) {
    benchmark::DoNotOptimize(f.data);
    const auto p = f.payload();
    const auto sw = static_cast<std::uint16_t>(canopen::unpack_bits(p, m.entries[0].bit_offset, 16));
    const auto pos = static_cast<std::int32_t>(canopen::sign_extend(canopen::unpack_bits(p, m.entries[1].bit_offset, 32), 32));
    benchmark::DoNotOptimize(cia402::decode_state(sw));
    benchmark::DoNotOptimize(pos);
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_TpdoDecode);

void BM_Classify(benchmark::State& st) {
  std::uint32_t id = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(canopen::classify(id));
    id = (id + 37) & 0x7FF;
  }
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_Classify);

void BM_SdoFrameDecode(benchmark::State& st) {
  const can::Frame f{0x582, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}};
  for (auto _ : st) benchmark::DoNotOptimize(canopen::sdo::decode(f, true));
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_SdoFrameDecode);

void BM_EmcyDecode(benchmark::State& st) {
  const can::Frame f{0x082, {0x11, 0x86, 0x21, 0, 0, 0, 0, 0}};
  for (auto _ : st) benchmark::DoNotOptimize(canopen::decode_emcy(f));
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_EmcyDecode);

/// The master's whole per-cycle work for N enabled CSP axes: on_frame of the
/// N TPDOs, then DriveNetwork::cycle (state machines, N RPDOs, SYNC).
void BM_MasterCycle(benchmark::State& st) {
  emulator::SimRigConfig cfg;
  cfg.nodes.clear();
  const auto n = static_cast<std::size_t>(st.range(0));
  for (std::size_t i = 0; i < n; ++i) cfg.nodes.push_back(static_cast<std::uint8_t>(2 + i));
  emulator::SimRig rig(cfg);
  rig.power_on();
  rig.run_until([&] { return rig.network().all_operational(); }, 5000);
  rig.network().enable_all();
  rig.run_until([&] { return rig.network().all_enabled(); }, 5000);
  if (!rig.network().all_enabled()) {
    st.SkipWithError("drives did not enable");
    return;
  }
  std::vector<can::TimedFrame> tpdos;
  for (std::size_t i = 0; i < n; ++i)
    tpdos.push_back(can::TimedFrame{can::Frame{static_cast<std::uint32_t>(0x182 + i), {0x37, 0x12, 0, 0, 0, 0}}, 0});
  NullSink sink;
  auto& net = rig.network();
  std::int64_t t = rig.now_ns();
  for (auto _ : st) {
    t += 1'000'000;
    for (const auto& f : tpdos) net.on_frame(f);
    for (std::size_t i = 0; i < n; ++i) net.at(i).set_target_position(static_cast<std::int32_t>(t / 1000));
    net.cycle(t, sink);
  }
  benchmark::DoNotOptimize(sink.n);
  st.SetItemsProcessed(st.iterations() * static_cast<std::int64_t>(n));
  st.counters["axes"] = static_cast<double>(n);
}
BENCHMARK(BM_MasterCycle)->Arg(1)->Arg(3)->Arg(8)->Arg(16);

/// Whole simulation step (master + emulated drives on the SimBus).
void BM_SimRigStep(benchmark::State& st) {
  emulator::SimRigConfig cfg;
  emulator::SimRig rig(cfg);
  rig.power_on();
  rig.run_until([&] { return rig.network().all_operational(); }, 5000);
  rig.network().enable_all();
  for (auto _ : st) rig.step();
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_SimRigStep);

void print_budget() {
  canopen::NodeTraffic csp;
  csp.rpdo_bytes[0] = 6;
  csp.rpdo_count = 1;
  csp.tpdo_bytes[0] = 6;
  csp.tpdo_count = 1;
  canopen::NodeTraffic full = csp;
  full.rpdo_bytes[1] = 7;
  full.rpdo_count = 2;
  full.tpdo_bytes[1] = 7;
  full.tpdo_count = 2;
  std::printf("Bus budget (classical CAN, 11-bit IDs, worst-case bit stuffing, 1 Mbit/s):\n");
  std::printf("  SYNC (0 bytes): %u bits; 6-byte PDO: %u bits; 7-byte PDO: %u bits\n", canopen::frame_bits_worst_case(0),
              canopen::frame_bits_worst_case(6), canopen::frame_bits_worst_case(7));
  for (const auto& [name, t] : {std::pair{"CSP default (RPDO1+TPDO1)", csp}, std::pair{"CSP/CSV/CST (+RPDO2+TPDO2)", full}}) {
    const canopen::NodeTraffic one[] = {t};
    canopen::BusBudgetInput in;
    in.nodes = one;
    const auto b = canopen::bus_budget(in);
    std::printf("  %-28s %u bits per axis per cycle;", name, b.cyclic_bits - canopen::frame_bits_worst_case(0));
    for (std::int64_t ms : {1, 2, 4})
      std::printf(" %lld ms: %u axes", static_cast<long long>(ms), canopen::max_axes(t, ms * 1'000'000, 1'000'000));
    std::printf(" (100%% load)\n");
  }
}
}  // namespace

int main(int argc, char** argv) {
  print_budget();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
