// Google Benchmark: MCCP as a planner instruction (issue #5), i.e. what one
// cycle pays when a program runs MCCP: Planner::execute of a parsed MCCP
// request on an attached CAM array and CAM_PROFILE array, for 100 .. 4096
// points (the configured maximum, config ArraySettings::kMaxCamElements),
// linear and cubic, and 10000 for comparison. And MAM with 16 EventDistance / CalculatedData events.
// Figures go to the lead (BENCHMARKS.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <vector>

#include "motion/cam/cam_profile.hpp"
#include "motion/planner.hpp"
#include "motion/st_parser.hpp"

using namespace canmotion::motion;

namespace {

struct MccpBench {
  std::unique_ptr<Planner> p = std::make_unique<Planner>(0.001);
  std::vector<cam::CamPoint> pts;
  std::unique_ptr<cam::CamProfile> prof;
  Request req{};
  MccpBench(std::size_t n, bool cubic) : pts(n), prof(std::make_unique<cam::CamProfile>(n)) {
    for (std::size_t i = 0; i < n; ++i)
      pts[i] = {0.01 * static_cast<double>(i), std::sin(0.05 * static_cast<double>(i)), cubic ? 1 : 0};
    p->attach_cam_array(0, pts);
    p->attach_cam_profile(0, prof.get());
    Symbols sym;
    sym.controls["mc"] = 0;
    sym.cams["pts"] = 0;
    sym.cam_profiles["prof"] = 0;
    if (auto e = parse_and_bind("MCCP(mc, pts[0], " + std::to_string(n) + ", 0, 0, prof[0]);", sym, req))
      throw std::runtime_error(*e);
  }
};

void BM_MccpInstruction(benchmark::State& st) {
  MccpBench b(static_cast<std::size_t>(st.range(0)), st.range(1) != 0);
  for (auto _ : st) {
    const Err e = b.p->execute(b.req);
    if (e != Err::None) st.SkipWithError("MCCP failed");
    benchmark::DoNotOptimize(b.prof->elements().data());
  }
  st.SetItemsProcessed(st.iterations() * st.range(0));
  st.counters["points"] = static_cast<double>(st.range(0));
}
BENCHMARK(BM_MccpInstruction)
    ->ArgNames({"points", "cubic"})
    ->Args({100, 1})
    ->Args({1000, 0})
    ->Args({1000, 1})
    ->Args({4096, 1})
    ->Args({10000, 1})
    ->Unit(benchmark::kMicrosecond);

void BM_MamWithEvents(benchmark::State& st) {
  Planner p(0.001);
  AxisConfig c;
  c.max_speed = 1000;
  p.configure_axis(0, c);
  std::vector<double> ed(16), cd(16);
  for (std::size_t i = 0; i < ed.size(); ++i) ed[i] = 5.0 * static_cast<double>(i);
  p.attach_real_array(0, ed);
  p.attach_real_array(1, cd);
  Symbols sym;
  sym.axes["X"] = 0;
  sym.controls["on"] = 0;
  sym.controls["m"] = 1;
  sym.real_arrays["ed"] = 0;
  sym.real_arrays["cd"] = 1;
  Request on, mam;
  (void)parse_and_bind("MSO(X, on);", sym, on);
  const bool events = st.range(0) != 0;
  const std::string ops = events ? "ed, cd" : "0, 0";
  if (auto e = parse_and_bind("MAM(X, m, 1, 100, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, scurve, 50, 50, "
                              "%oftime, disabled, programmed, 0, none, " + ops + ");",
                              sym, mam))
    throw std::runtime_error(*e);
  p.execute(on);
  for (auto _ : st) {
    if (p.execute(mam) != Err::None) st.SkipWithError("MAM failed");
    benchmark::DoNotOptimize(cd.data());
  }
}
BENCHMARK(BM_MamWithEvents)->ArgName("events16")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
