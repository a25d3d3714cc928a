#pragma once
// Shared by the config tests that run a loaded configuration: its Runtime
// (every bus simulated), stepped cycle by cycle on virtual time at the
// configured period, with a host for tags and instruction calls.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "config/runtime.hpp"
#include "rt/controller/host.hpp"

namespace canmotion::config::test {

struct RuntimeRig {
  Runtime rt;
  rt::ControllerHost host;
  std::int64_t now = 0;

  explicit RuntimeRig(const Config& cfg) : rt(simulated_runtime(cfg)), host(*rt.controller) {}
  virtual ~RuntimeRig() = default;
  RuntimeRig(const RuntimeRig&) = delete;
  RuntimeRig& operator=(const RuntimeRig&) = delete;

  rt::Controller& ctl() { return *rt.controller; }
  /// One controller cycle at `now`, the simulated buses (if any) around it, then after_cycle().
  void cycle() {
    if (rt.sim) rt.sim->begin_cycle(now);
    ctl().cycle(now);
    if (rt.sim) rt.sim->end_cycle(now);
    now += ctl().spec().period_ns;
    after_cycle();
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i) cycle();
  }
  /// Hook for rigs that collect something after each cycle (e.g. the trace).
  virtual void after_cycle() {}
  /// A tag's value from the last snapshot; a test failure (and -1) when it cannot be read.
  double read(const std::string& tag) {
    std::string e;
    const auto v = host.read(tag, &e);
    EXPECT_TRUE(v) << tag << ": " << e;
    return v.value_or(-1.0);
  }
  /// Queue an instruction call (taken at the next cycle); a test failure when refused.
  bool execute(const std::string& call) {
    std::string ctl_name;
    const auto err = host.execute(call, &ctl_name);
    EXPECT_FALSE(err) << call << ": " << *err;
    return !err;
  }
};

}  // namespace canmotion::config::test
