// Google Benchmark: the coordinated path generator (motion/coord). Per
// coordinate system per cycle (a line, an arc, while blending) and planning
// (submit of an MCLM / MCCM into an idle system, a queued move that re-plans
// a Follow Contour junction). Figures go to BENCHMARKS.md.
//
// Stepping: a generator is brought into the state to measure (cruising on a
// line, on an arc, inside the overlap of a TT2 blend) and copied; each
// benchmark iteration restores the copy (~3 KB) and steps kSteps cycles that
// all stay in that state. The "step" counter is the time per step.
#include <benchmark/benchmark.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "motion/coord/path_generator.hpp"

using namespace canmotion::motion;
using namespace canmotion::motion::coord;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kSteps = 200;

Vec3 v3(double x, double y = 0, double z = 0) { return Vec3{{x, y, z}}; }

MoveRequest line(std::uint32_t id, const Vec3& p, Termination tt = Termination::NoSettle) {
  MoveRequest r;
  r.id = id;
  r.path.position = p;
  r.limits = Limits{10, 50, 50, 500, 500};
  r.termination = tt;
  return r;
}

MoveRequest arc(std::uint32_t id, const Vec3& p, CircleType t, const Vec3& aux, CircleDirection d) {
  MoveRequest r = line(id, p);
  r.path.kind = PathKind::Circle;
  r.path.circle_type = t;
  r.path.aux = aux;
  r.path.direction = d;
  return r;
}

PathGenerator make(int dim, double ct = 0) {
  PathGenerator g;
  SystemConfig c;
  c.dim = dim;
  c.command_tolerance = ct;
  g.configure(c);
  return g;
}

void check(Err e) {
  if (e != Err::None) throw std::runtime_error("bench setup: submit failed");
}

void run_steps(benchmark::State& st, const PathGenerator& snapshot, std::uint32_t must_have_status_bit) {
  Present now;
  Output out;
  PathGenerator g = snapshot;
  g.step(now, out);
  if (!((out.motion_status >> must_have_status_bit) & 1u)) throw std::runtime_error("bench setup: wrong state");
  for (auto _ : st) {
    g = snapshot;
    for (int i = 0; i < kSteps; ++i) {
      g.step(now, out);
      benchmark::DoNotOptimize(out);
    }
  }
  if (!((out.motion_status >> must_have_status_bit) & 1u)) throw std::runtime_error("bench: left the state");
  st.counters["step"] = benchmark::Counter(kSteps, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void advance(PathGenerator& g, int cycles) {
  Present now;
  Output out;
  for (int i = 0; i < cycles; ++i) g.step(now, out);
}

// A 3-D S-curve line, cruising.
void BM_StepLine(benchmark::State& st) {
  PathGenerator g = make(3);
  Events ev;
  check(g.submit(line(1, v3(1000, 2000, 500)), Present{}, ev));
  advance(g, 1000);
  run_steps(st, g, coordinate_motion_status::MoveStatus);
}
BENCHMARK(BM_StepLine);

// A 3-D arc (center type), cruising.
void BM_StepArc(benchmark::State& st) {
  PathGenerator g = make(3);
  Events ev;
  check(g.submit(arc(1, v3(50, 0, 50), CircleType::Center, v3(50, 0, 0), CircleDirection::CounterClockwise), Present{},
                 ev));
  advance(g, 1000);
  run_steps(st, g, coordinate_motion_status::MoveStatus);
}
BENCHMARK(BM_StepArc);

// Inside the overlap of a TT2 blend: line (tail) into an arc (mirrored head).
void BM_StepBlend(benchmark::State& st) {
  PathGenerator g = make(3, 5.0);
  Events ev;
  check(g.submit(line(1, v3(20, 0, 0), Termination::CommandTolerance), Present{}, ev));
  check(g.submit(arc(2, v3(30, 10, 0), CircleType::Center, v3(20, 10, 0), CircleDirection::CounterClockwise), Present{},
                 ev));
  Present now;
  Output out;
  for (int i = 0; i < 10000; ++i) {  // to the start of the overlap
    g.step(now, out);
    if ((out.motion_status >> coordinate_motion_status::MoveTransitionStatus) & 1u) break;
  }
  run_steps(st, g, coordinate_motion_status::MoveTransitionStatus);
}
BENCHMARK(BM_StepBlend);

// Planning: submit into an idle system (geometry + profile), then clear.
void plan(benchmark::State& st, int dim, const MoveRequest& m) {
  PathGenerator g = make(dim);
  Events ev;
  for (auto _ : st) {
    benchmark::DoNotOptimize(g.submit(m, Present{}, ev));
    g.clear(ev);
  }
}
void BM_PlanLine(benchmark::State& st) { plan(st, 3, line(1, v3(100, 200, 50))); }
BENCHMARK(BM_PlanLine);
void BM_PlanArcVia(benchmark::State& st) {
  plan(st, 3, arc(1, v3(100, 0, 100), CircleType::Via, v3(40, 60, 20), CircleDirection::Clockwise));
}
BENCHMARK(BM_PlanArcVia);
void BM_PlanArcCenter(benchmark::State& st) {
  plan(st, 2, arc(1, v3(100, 0), CircleType::Center, v3(50, 0), CircleDirection::CounterClockwise));
}
BENCHMARK(BM_PlanArcCenter);

// Queue a move behind a running Follow Contour move: the geometry of the new
// move plus the junction speed and the re-plan of the active move.
void BM_PlanQueuedJunction(benchmark::State& st) {
  PathGenerator g = make(2);
  Events ev;
  check(g.submit(line(1, v3(100, 0), Termination::FollowContourVelocityConstrained), Present{}, ev));
  advance(g, 500);
  const PathGenerator snapshot = g;
  const MoveRequest m = arc(2, v3(110, 10), CircleType::Center, v3(100, 10), CircleDirection::CounterClockwise);
  for (auto _ : st) {
    g = snapshot;
    benchmark::DoNotOptimize(g.submit(m, Present{}, ev));
  }
}
BENCHMARK(BM_PlanQueuedJunction);

// The cost of the snapshot copy alone (subtract from BM_PlanQueuedJunction).
void BM_SnapshotCopy(benchmark::State& st) {
  PathGenerator g = make(2);
  Events ev;
  check(g.submit(line(1, v3(100, 0), Termination::FollowContourVelocityConstrained), Present{}, ev));
  const PathGenerator snapshot = g;
  for (auto _ : st) {
    g = snapshot;
    benchmark::DoNotOptimize(g);
  }
}
BENCHMARK(BM_SnapshotCopy);

}  // namespace

BENCHMARK_MAIN();
