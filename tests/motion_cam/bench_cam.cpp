// Cam benchmarks (Google Benchmark; figures go to BENCHMARKS.md, never a test).
//
//   BM_CamStep/<type>/<n>      one cycle of a running time cam (CamMotion::step
//                              at t = cycle * 1 ms, continuous mode, cursor
//                              lookup): the per-axis per-cycle cost. Goal <= 150 ns.
//   BM_CamEvalRandom/<type>/<n> evaluate at random master values (binary
//                              search every time): the O(log n) worst case.
//   BM_Mccp/<type>/<n>         MCCP compute time.
// type: 0 linear, 1 cubic. n: 10, 100, 1000, 10000 points.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "motion/cam/cam_motion.hpp"

namespace {

using namespace canmotion::motion::cam;

std::vector<CamPoint> make_cam(std::size_t n, std::int32_t type) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> gap(0.5, 1.5), val(-10.0, 10.0);
  std::vector<CamPoint> cam(n);
  double m = 0;
  for (auto& p : cam) {
    p = {m, val(rng), type};
    m += gap(rng);
  }
  return cam;
}

void compute(const std::vector<CamPoint>& cam, CamProfile& p) {
  const auto r = mccp({cam, 0, static_cast<std::int64_t>(cam.size()), 0.0, 0.0}, p);
  if (!r.ok()) std::abort();
}

void BM_CamStep(benchmark::State& state) {
  const auto type = static_cast<std::int32_t>(state.range(0));
  const auto n = static_cast<std::size_t>(state.range(1));
  const auto cam = make_cam(n, type);
  CamProfile p(n);
  compute(cam, p);
  CamMotion cm;
  // Time scaling so one pass of the profile lasts ~n * 10 cycles of 1 ms:
  // every cycle advances by ~0.1 segment, as a real time cam does.
  const double scale = 0.01 / (p.master_span() / static_cast<double>(n));
  if (cm.start(p, {ExecutionMode::Continuous, {1.5, scale}}) != CamError::None) std::abort();
  std::int64_t cycle = 0;
  for (auto _ : state) {
    const auto out = cm.step(static_cast<double>(cycle) * 1e-3);
    benchmark::DoNotOptimize(out);
    ++cycle;
  }
  state.SetLabel(type == 0 ? "linear" : "cubic");
}

void BM_CamEvalRandom(benchmark::State& state) {
  const auto type = static_cast<std::int32_t>(state.range(0));
  const auto n = static_cast<std::size_t>(state.range(1));
  const auto cam = make_cam(n, type);
  CamProfile p(n);
  compute(cam, p);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> x(p.master_start(), p.master_end());
  std::vector<double> xs(4096);
  for (auto& v : xs) v = x(rng);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(p.evaluate(xs[i]));
    i = (i + 1) & 4095;
  }
  state.SetLabel(type == 0 ? "linear" : "cubic");
}

void BM_Mccp(benchmark::State& state) {
  const auto type = static_cast<std::int32_t>(state.range(0));
  const auto n = static_cast<std::size_t>(state.range(1));
  const auto cam = make_cam(n, type);
  CamProfile p(n);
  for (auto _ : state) {
    compute(cam, p);
    benchmark::ClobberMemory();
  }
  state.SetLabel(type == 0 ? "linear" : "cubic");
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}

void args(benchmark::internal::Benchmark* b) {
  for (int type : {0, 1})
    for (int n : {10, 100, 1000, 10000}) b->Args({type, n});
  b->ArgNames({"type", "points"});
}

BENCHMARK(BM_CamStep)->Apply(args);
BENCHMARK(BM_CamEvalRandom)->Apply(args);
BENCHMARK(BM_Mccp)->Apply(args);

}  // namespace

BENCHMARK_MAIN();
