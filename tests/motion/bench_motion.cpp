// Google Benchmark: planner step cost per axis per cycle, S-curve MAM start
// (planning) cost, and ST parse cost. Figures go to BENCHMARKS.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "motion/cam/cam_profile.hpp"
#include "motion/planner.hpp"
#include "motion/profile.hpp"
#include "motion/st_parser.hpp"

using namespace canmotion::motion;

namespace {

constexpr int kAxes = 32;

struct Bench {
  std::unique_ptr<Planner> p = std::make_unique<Planner>(0.001);
  Symbols sym;
  std::array<AxisFeedback, kMaxAxes> fb{};
  std::array<AxisOutput, kMaxAxes> out{};
  std::uint64_t cycle = 0;
  Bench() {
    AxisConfig c;
    c.max_speed = 1000;
    for (int i = 0; i < kAxes; ++i) {
      p->configure_axis(static_cast<AxisId>(i), c);
      sym.axes["a" + std::to_string(i)] = static_cast<AxisId>(i);
      sym.controls["mso" + std::to_string(i)] = static_cast<ControlId>(i);
      sym.controls["mv" + std::to_string(i)] = static_cast<ControlId>(100 + i);
    }
    for (int i = 0; i < kAxes; ++i) run("MSO(a" + std::to_string(i) + ", mso" + std::to_string(i) + ");");
  }
  void run(const std::string& t) {
    Request q;
    if (auto e = parse_and_bind(t, sym, q)) throw std::runtime_error(*e);
    p->execute(q);
  }
  void step() {
    Input in{++cycle, std::span<const AxisFeedback>(fb.data(), kAxes), {}};
    Output o{std::span<AxisOutput>(out.data(), kAxes)};
    p->update(in, o);
  }
};

std::string mam(int i, const char* profile) {
  return "MAM(a" + std::to_string(i) + ", mv" + std::to_string(i) +
         ", 1, 1e9, 100, unitspersec, 1000, unitspersec2, 1000, unitspersec2, " + profile +
         ", 60, 60, %oftime, disabled, programmed, 0, none, 0, 0);";
}

// step() of the whole planner divided by the number of moving axes
void step_bench(benchmark::State& st, const char* kind) {
  Bench b;
  for (int i = 0; i < kAxes; ++i) {
    if (std::string(kind) == "jog")
      b.run("MAJ(a" + std::to_string(i) + ", mv" + std::to_string(i) +
            ", 0, 100, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none);");
    else
      b.run(mam(i, kind));
  }
  b.step();
  for (auto _ : st) {
    b.step();
    benchmark::DoNotOptimize(b.out[0].position);
  }
  st.SetItemsProcessed(st.iterations() * kAxes);
  st.counters["ns_per_axis"] = benchmark::Counter(static_cast<double>(st.iterations() * kAxes),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_StepMoveTrapezoidal(benchmark::State& st) { step_bench(st, "trapezoidal"); }
void BM_StepMoveSCurve(benchmark::State& st) { step_bench(st, "scurve"); }
void BM_StepJog(benchmark::State& st) { step_bench(st, "jog"); }

// MAG: half the axes are virtual masters jogging, each other axis is geared to one
void gear_bench(benchmark::State& st, bool fractional) {
  Bench b;
  for (int i = 0; i < kAxes; i += 2) {
    const std::string m = "a" + std::to_string(i), s = "a" + std::to_string(i + 1);
    b.run("MAJ(" + m + ", mv" + std::to_string(i) +
          ", 0, 100, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none);");
    b.run("MAG(" + s + ", " + m + ", mv" + std::to_string(i + 1) + ", same, 0.5, 1, 3, command, " +
          (fractional ? "fraction_slave_master_counts" : "real") + ", disabled, 0, unitspersec2);");
  }
  b.step();
  for (auto _ : st) {
    b.step();
    benchmark::DoNotOptimize(b.out[1].position);
  }
  st.counters["ns_per_axis"] = benchmark::Counter(static_cast<double>(st.iterations() * kAxes),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_StepGearReal(benchmark::State& st) { gear_bench(st, false); }
void BM_StepGearFractional(benchmark::State& st) { gear_bench(st, true); }

// MAPC: half the axes are virtual masters jogging at 10 units/s (one cam
// segment per cycle), each other axis position-cams continuously on one with a
// 1000-point cubic profile (master 0..9.99, segment 0.01)
void BM_StepPositionCam1000Cubic(benchmark::State& st) {
  Bench b;
  cam::CamProfile prof(1000);
  std::vector<cam::CamPoint> pts(1000);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double x = 0.01 * static_cast<double>(i);
    pts[i] = cam::CamPoint{x, x + 0.5 * std::sin(x * 2 * 3.14159265358979 / 9.99), cam::kSegmentCubic};
  }
  if (!cam::mccp(cam::MccpRequest{pts, 0, 1000, 1.0, 1.0}, prof).ok()) throw std::runtime_error("mccp");
  b.p->attach_cam_profile(0, &prof);
  b.sym.cam_profiles["prof"] = 0;
  for (int i = 0; i < kAxes; i += 2) {
    const std::string m = "a" + std::to_string(i), s = "a" + std::to_string(i + 1);
    b.run("MAJ(" + m + ", mv" + std::to_string(i) +
          ", 0, 10, unitspersec, 1000, unitspersec2, 1000, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none);");
    b.run("MAPC(" + s + ", " + m + ", mv" + std::to_string(i + 1) +
          ", same, prof[0], 1, 1, continuous, immediate, 0, 0, command, bidirectional);");
    if (!b.p->control(static_cast<ControlId>(100 + i + 1)).ip()) throw std::runtime_error("MAPC refused");
  }
  b.step();
  for (auto _ : st) {
    b.step();
    benchmark::DoNotOptimize(b.out[1].position);
  }
  st.counters["ns_per_axis"] = benchmark::Counter(static_cast<double>(st.iterations() * kAxes),
                                                  benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["ns_per_cam_axis"] = benchmark::Counter(static_cast<double>(st.iterations() * kAxes / 2),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// MATC on a 1000-point cubic profile: half the axes are virtual masters
// jogging, each other axis runs the cam, master driven (through an MDAC Time
// Cam link, forward-only lock) or time driven for comparison. One pass is 10
// master units (0.1 s at 100 units/s), so every segment of the profile is
// visited many times. ns_per_cam = planner step / number of cam axes.
void cam_bench(benchmark::State& st, bool master_driven) {
  Bench b;
  constexpr int kPoints = 1000;
  std::vector<cam::CamPoint> pts(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    const double x = 0.01 * i;
    pts[static_cast<std::size_t>(i)] = cam::CamPoint{x, 5.0 * x - std::sin(6.283185307179586 * x / 10.0), 1};
  }
  auto prof = std::make_unique<cam::CamProfile>(kPoints);
  if (!cam::mccp(cam::MccpRequest{pts, 0, kPoints, 0.0, 0.0}, *prof).ok()) throw std::runtime_error("mccp");
  b.p->attach_cam_profile(0, prof.get());
  b.sym.cam_profiles["prof"] = 0;
  for (int i = 0; i < kAxes; i += 2) {
    const std::string m = "a" + std::to_string(i), s = "a" + std::to_string(i + 1);
    b.sym.controls["md" + std::to_string(i)] = static_cast<ControlId>(200 + i);
    b.run("MAJ(" + m + ", mv" + std::to_string(i) +
          ", 0, 100, unitspersec, 1e6, unitspersec2, 1e6, unitspersec2, trapezoidal, 0, 0, unitspersec3, disabled, programmed, 0, none);");
    if (master_driven) b.run("MDAC(" + s + ", " + m + ", md" + std::to_string(i) + ", timecam, command);");
    b.run("MATC(" + s + ", mv" + std::to_string(i + 1) + ", same, prof[0], 1, " + (master_driven ? "1" : "0.01") +
          ", continuous, immediate, 0, " + (master_driven ? "immediateforwardonly, masterdrivenmode);" : "none, timedrivenmode);"));
  }
  b.step();
  for (int i = 1; i < kAxes; i += 2)
    if (!b.p->axis(static_cast<AxisId>(i)).motion(motion_status::TimeCamStatus)) throw std::runtime_error("cam not running");
  for (auto _ : st) {
    b.step();
    benchmark::DoNotOptimize(b.out[1].position);
  }
  if (!(b.p->axis(1).command_velocity > 0)) throw std::runtime_error("cam not moving");
  st.counters["ns_per_cam"] = benchmark::Counter(static_cast<double>(st.iterations() * (kAxes / 2)),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_StepCamMasterDriven1000(benchmark::State& st) { cam_bench(st, true); }
void BM_StepCamTimeDriven1000(benchmark::State& st) { cam_bench(st, false); }

// plan_move for an S-curve from a moving state (a merge): the planning maths alone
void BM_PlanSCurveMoveFromMotion(benchmark::State& st) {
  Limits l{100, 1000, 800, 20000, 15000};
  Profile prof;
  double d = 3.0;
  for (auto _ : st) {
    plan_move(prof, Kin{0, 35, 400}, d, l);
    benchmark::DoNotOptimize(prof);
    d = d == 3.0 ? 250.0 : 3.0;  // alternate short (peak velocity solve) and long moves
  }
}
void BM_PlanSCurveMoveRestToRest(benchmark::State& st) {
  Limits l{100, 1000, 800, 20000, 15000};
  Profile prof;
  double d = 0.5;
  for (auto _ : st) {
    plan_move(prof, Kin{0, 0, 0}, d, l);
    benchmark::DoNotOptimize(prof);
    d = d == 0.5 ? 250.0 : 0.5;
  }
}

// Full MAM start through Planner::execute (validation + units + planning + tags)
void BM_StartSCurveMam(benchmark::State& st) {
  Bench b;
  Request q;
  parse_and_bind("MAM(a0, mv0, 0, 12.5, 100, unitspersec, 1000, unitspersec2, 800, unitspersec2, scurve, 60, 50, "
                 "%oftime, disabled, programmed, 0, none, 0, 0);",
                 b.sym, q);
  for (auto _ : st) {
    benchmark::DoNotOptimize(b.p->execute(q));
  }
}

void BM_ParseMam(benchmark::State& st) {
  const std::string text =
      "MAM(a0, mv0, 0, 100, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 100, 100, %oftime, "
      "disabled, 0, 0, 0, 0, 0);";
  for (auto _ : st) {
    auto r = parse_st_call(text);
    benchmark::DoNotOptimize(r);
  }
}
void BM_ParseAndBindMam(benchmark::State& st) {
  Bench b;
  const std::string text =
      "MAM(a0, mv0, 0, 100, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 100, 100, %oftime, "
      "disabled, 0, 0, 0, 0, 0);";
  Request q;
  for (auto _ : st) {
    auto e = parse_and_bind(text, b.sym, q);
    benchmark::DoNotOptimize(e);
  }
}

}  // namespace

BENCHMARK(BM_StepMoveTrapezoidal);
BENCHMARK(BM_StepMoveSCurve);
BENCHMARK(BM_StepJog);
BENCHMARK(BM_StepGearReal);
BENCHMARK(BM_StepGearFractional);
BENCHMARK(BM_StepPositionCam1000Cubic);
BENCHMARK(BM_StepCamMasterDriven1000);
BENCHMARK(BM_StepCamTimeDriven1000);
BENCHMARK(BM_PlanSCurveMoveFromMotion);
BENCHMARK(BM_PlanSCurveMoveRestToRest);
BENCHMARK(BM_StartSCurveMam);
BENCHMARK(BM_ParseMam);
BENCHMARK(BM_ParseAndBindMam);
BENCHMARK_MAIN();
