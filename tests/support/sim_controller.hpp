#pragma once
/// \file
/// The standard in-process test controller: a virtual axis "Master" and a CIP
/// drive axis "X" (node 2, 1000 counts per unit) with an emulated CiA 402 drive
/// on one SimBus "sim0", and a cam profile "cam1" (a 1 s, 10-unit cubic
/// rise and return), stepped cycle by cycle on virtual time. Shared by the
/// controller, host and command-server tests. Header-only; link canmotion::rt.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "rt/controller/controller.hpp"
#include "rt/controller/host.hpp"
#include "rt/controller/sim_world.hpp"

namespace canmotion::test {

struct SimController {
  static constexpr std::int64_t kPeriod = 1'000'000;  ///< 1 ms
  static constexpr std::uint8_t kNode = 2;             ///< node of axis X

  rt::SimWorld world;
  std::unique_ptr<rt::Controller> ctl;
  std::int64_t now = 0;

  /// `tweak` may change axis X and its drive's emulator before the controller
  /// is built; `sync_first` is rt::ControllerSpec::sync_first.
  explicit SimController(const std::function<void(rt::AxisSpec&, emulator::EmulatorConfig&)>& tweak = {},
                         bool sync_first = false) {
    rt::ControllerSpec spec;
    spec.period_ns = kPeriod;
    spec.sync_first = sync_first;
    rt::BusSpec bus;
    bus.name = "sim0";
    bus.transport = &world.add_bus("sim0");
    spec.buses.push_back(bus);
    rt::AxisSpec master;
    master.name = "Master";
    master.config.type = motion::AxisType::Virtual;
    master.config.max_speed = 500;
    master.config.max_accel = 5000;
    master.config.max_decel = 5000;
    spec.axes.push_back(master);
    rt::AxisSpec x;
    x.name = "X";
    x.config.type = motion::AxisType::CipDrive;
    x.config.conversion_constant = 1000;  // counts per mm
    x.config.max_speed = 200;
    x.config.max_accel = 2000;
    x.config.max_decel = 2000;
    x.config.position_error_tolerance = 5;
    x.bus = 0;
    x.drive.node = kNode;
    emulator::EmulatorConfig ec;
    ec.node = kNode;
    ec.behaviour = emulator::EmulatorBehaviour::strict();
    if (tweak) tweak(x, ec);
    spec.axes.push_back(x);
    rt::CamSpec cam;
    cam.name = "cam1";
    cam.points = {{0.0, 0.0, 1}, {0.5, 10.0, 1}, {1.0, 0.0, 0}};
    spec.cams.push_back(cam);
    world.add_drive(0, ec);
    ctl = std::make_unique<rt::Controller>(spec);
    world.power_on(0);
  }
  virtual ~SimController() = default;

  /// One controller cycle with the emulated drive, then after_cycle().
  void step() {
    world.begin_cycle(now);
    ctl->cycle(now);
    world.end_cycle(now);
    now += kPeriod;
    after_cycle();
  }
  /// Hook for rigs that add non-RT work after each cycle (e.g. a socket server).
  virtual void after_cycle() {}
  [[nodiscard]] double now_s() const { return static_cast<double>(now) * 1e-9; }
  rt::Status status() const {
    rt::Status s;
    ctl->read_status(s);
    return s;
  }
  /// Step until done(status) or max_cycles; true if done.
  bool run_until(const std::function<bool(const rt::Status&)>& done, int max_cycles) {
    for (int i = 0; i < max_cycles; ++i) {
      step();
      if (done(status())) return true;
    }
    return false;
  }
  void cycles(int n) {
    for (int i = 0; i < n; ++i) step();
  }
};

/// SimController with a ControllerHost: tags and ST calls as a user gives them.
struct SimHost : SimController {
  using SimController::SimController;
  std::unique_ptr<rt::ControllerHost> host = std::make_unique<rt::ControllerHost>(*ctl);
  /// A tag's value (a failed read fails the test and gives -1).
  double read(const std::string& tag) {
    std::string e;
    auto v = host->read(tag, &e);
    EXPECT_TRUE(v) << tag << ": " << e;
    return v.value_or(-1);
  }
  /// Execute an ST call; `settle`: then run until the planner took it (at most 10 cycles).
  void exec(const std::string& call, bool settle = true) {
    std::string name;
    const auto err = host->execute(call, &name);
    ASSERT_FALSE(err) << call << ": " << *err;
    if (settle) {
      ASSERT_TRUE(run_until([&](const rt::Status&) { return host->settled(); }, 10)) << call;
    }
  }
};

}  // namespace canmotion::test
