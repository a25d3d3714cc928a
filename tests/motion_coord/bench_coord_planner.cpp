// Google Benchmark: the coordinated instructions through the planner (issue
// 14 phase 2): Planner::update per cycle with a 3-D coordinate system of
// three virtual axes cruising on a line / an arc (the path step, the three
// member slots, the CS tag), against the same planner with the axes idle;
// and the cost of executing an MCLM / MCCM (operands, units, geometry,
// profile plan; each one merges into the running move, so every iteration
// plans from a moving state). Figures go to BENCHMARKS.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "motion/planner.hpp"
#include "motion/st_parser.hpp"

using namespace canmotion::motion;

namespace {

struct Bench {
  std::unique_ptr<Planner> p = std::make_unique<Planner>(0.001);
  Symbols sym;
  std::array<std::vector<double>, 3> arrays{std::vector<double>{1e6, 2e6, 3e6}, std::vector<double>{0, 0, 0},
                                            std::vector<double>{0, 0, 0}};
  std::array<AxisOutput, 3> out{};
  std::uint64_t cycle = 0;
  Bench() {
    AxisConfig a;
    a.max_speed = 1e9;
    a.max_accel = a.max_decel = 1e9;
    for (int i = 0; i < 3; ++i) {
      if (!p->configure_axis(static_cast<AxisId>(i), a)) throw std::runtime_error("axis");
      sym.axes["A" + std::to_string(i)] = static_cast<AxisId>(i);
    }
    CoordSystemConfig c;
    c.dim = 3;
    c.axes = {0, 1, 2};
    c.max_speed = 100;
    c.max_accel = c.max_decel = 1000;
    c.max_accel_jerk = c.max_decel_jerk = 1e5;
    if (!p->configure_coordinate_system(0, c)) throw std::runtime_error("cs");
    sym.coordinate_systems["cs"] = 0;
    const char* names[] = {"far", "via", "mid"};
    for (std::uint16_t i = 0; i < 3; ++i) {
      p->attach_real_array(i, std::span<double>(arrays[i]));
      sym.real_arrays[names[i]] = i;
    }
    for (int i = 0; i < 3; ++i) exec("MSO(A" + std::to_string(i) + ", so" + std::to_string(i) + ");");
    step();
  }
  Request req(const std::string& text) {
    const ParseResult r = parse_st_call(text);
    if (!r.ok()) throw std::runtime_error(r.error.message);
    for (std::size_t k = 0; k < r.call->operands.size(); ++k)
      if (signature(r.call->instr).operands[k].kind == OperandKind::Control)
        sym.controls.emplace(r.call->operands[k].text, static_cast<ControlId>(sym.controls.size()));
    Request q;
    if (auto e = bind_call(*r.call, sym, q)) throw std::runtime_error(*e);
    return q;
  }
  void exec(const std::string& text) {
    if (p->execute(req(text)) != Err::None) throw std::runtime_error("refused: " + text);
  }
  /// The coordinate system moves (MoveStatus): the state a benchmark measures.
  void require_moving() {
    const CoordSystemTag& t = p->coordinate_system(0);
    const auto p0 = t.command_position;
    step();
    const double d = std::hypot(t.command_position[0] - p0[0], t.command_position[1] - p0[1], t.command_position[2] - p0[2]);
    if (std::getenv("BENCH_SHOW") || !(d > 0.9 * t.speed * 0.001)) std::fprintf(stderr, "speed %g, moved %g in a cycle, at (%g, %g)\n", t.speed, d, t.command_position[0], t.command_position[1]);
    if (!(t.speed > 0) || !((t.motion_status >> coordinate_motion_status::MoveStatus) & 1u) || !(d > 0.9 * t.speed * 0.001))
      throw std::runtime_error("bench setup: the coordinate system does not move");
  }
  void step() {
    Input in{++cycle, {}, {}};
    Output o{std::span<AxisOutput>(out)};
    p->update(in, o);
  }
};

const std::string kLine =
    "MCLM(cs, m1, 0, far, 50, unitspersec, 1000, unitspersec2, 1000, unitspersec2, scurve, 1e5, 1e5, unitspersec3,"
    " nosettle, disabled, programmed, 0, 0, none, 0, 0);";
void BM_UpdateIdle3Axes(benchmark::State& st) {
  Bench b;
  for (auto _ : st) b.step();
}
BENCHMARK(BM_UpdateIdle3Axes);

void BM_UpdateLine3Axes(benchmark::State& st) {
  Bench b;
  b.exec(kLine);
  for (int i = 0; i < 2000; ++i) b.step();  // cruising
  b.require_moving();
  for (auto _ : st) b.step();
}
BENCHMARK(BM_UpdateLine3Axes);

void BM_UpdateArc3Axes(benchmark::State& st) {
  Bench b;
  b.arrays[1] = {0, 1000, 0};  // center 1000 from the start (incremental): a full circle of 6283 at 50/s
  b.arrays[2] = {1000, 1000, 0};  // a second point on the circle (incremental)
  b.exec("MCCM(cs, c1, 1, mid, center, via, clockwisefull, 50, unitspersec, 1000, unitspersec2, 1000, unitspersec2,"
         " scurve, 1e5, 1e5, unitspersec3, nosettle, disabled, programmed, 0, 0, none, 0, 0);");
  for (int i = 0; i < 2000; ++i) b.step();
  b.require_moving();
  for (auto _ : st) b.step();
}
BENCHMARK(BM_UpdateArc3Axes);

void BM_ExecuteMclmMerge(benchmark::State& st) {
  Bench b;
  b.exec(kLine);
  for (int i = 0; i < 2000; ++i) b.step();
  const Request r = b.req(
      "MCLM(cs, m2, 0, far, 50, unitspersec, 1000, unitspersec2, 1000, unitspersec2, scurve, 1e5, 1e5, unitspersec3,"
      " nosettle, coordinatedmotion, current, 0, 0, none, 0, 0);");
  for (auto _ : st) benchmark::DoNotOptimize(b.p->execute(r));
}
BENCHMARK(BM_ExecuteMclmMerge);

void BM_ExecuteMccmMerge(benchmark::State& st) {
  Bench b;
  b.arrays[1] = {0, 1000, 0};
  b.arrays[2] = {1000, 1000, 0};  // a second point on the circle (incremental)
  b.exec(kLine);
  for (int i = 0; i < 2000; ++i) b.step();
  const Request r = b.req(
      "MCCM(cs, c2, 1, mid, center, via, clockwisefull, 50, unitspersec, 1000, unitspersec2, 1000, unitspersec2, scurve,"
      " 1e5, 1e5, unitspersec3, nosettle, coordinatedmotion, current, 0, 0, none, 0, 0);");
  for (auto _ : st) benchmark::DoNotOptimize(b.p->execute(r));
}
BENCHMARK(BM_ExecuteMccmMerge);

}  // namespace

BENCHMARK_MAIN();
