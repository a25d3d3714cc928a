#pragma once
// Test rig: a Planner driven by ST text, with a virtual clock (cycle index).
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "motion/planner.hpp"
#include "motion/st_parser.hpp"

namespace canmotion::motion::test {

/// A virtual axis with the given maximum speed and acceleration = deceleration.
inline AxisConfig axis_cfg(double max_speed, double max_accel) {
  AxisConfig c;
  c.max_speed = max_speed;
  c.max_accel = c.max_decel = max_accel;
  return c;
}

/// An AXIS_CIP_DRIVE for MDS: 200 units/s and 1000 (per mille) at 100 %.
inline AxisConfig cip_direct(AxisConfig::DirectMode mode, double velocity_command = 0.0) {
  AxisConfig c;
  c.type = AxisType::CipDrive;
  c.max_speed = 200;
  c.max_torque = 1000;
  c.direct_mode = mode;
  c.direct_velocity_command = velocity_command;
  c.direct_control = true;  // the configuration has direct_control: (MDS allowed)
  return c;
}

struct Rig {
  std::unique_ptr<Planner> p = std::make_unique<Planner>(0.001);
  Symbols sym;
  std::uint64_t cycle = 0;
  std::array<AxisFeedback, kMaxAxes> fb{};
  std::array<AxisOutput, kMaxAxes> out{};
  std::vector<Request> queue;

  Rig() { sym.groups["g"] = 0; }

  AxisId add_axis(const std::string& name, AxisConfig cfg = {}) {
    const auto id = static_cast<AxisId>(sym.axes.size());
    EXPECT_TRUE(p->configure_axis(id, cfg));
    sym.axes[name] = id;
    return id;
  }
  ControlId ctl(const std::string& name) {
    auto it = sym.controls.find(name);
    if (it != sym.controls.end()) return it->second;
    const auto id = static_cast<ControlId>(sym.controls.size());
    sym.controls[name] = id;
    return id;
  }
  /// Parse + bind; the control tag named in the text is created on demand.
  Request req(const std::string& text) {
    const ParseResult r = parse_st_call(text);
    EXPECT_TRUE(r.ok()) << r.error.message;
    if (!r.ok()) return Request{};
    for (std::size_t k = 0; k < r.call->operands.size(); ++k)
      if (signature(r.call->instr).operands[k].kind == OperandKind::Control) ctl(r.call->operands[k].text);
    Request q;
    const auto e = bind_call(*r.call, sym, q);
    EXPECT_FALSE(e.has_value()) << *e;
    return q;
  }
  /// Execute now (as part of the next cycle's request phase is equivalent).
  Err exec(const std::string& text) { return p->execute(req(text)); }
  /// Queue for the next update().
  void submit(const std::string& text) { queue.push_back(req(text)); }
  void step(int n = 1) {
    for (int i = 0; i < n; ++i) {
      Input in{++cycle, std::span<const AxisFeedback>(fb.data(), p->axis_count()),
               std::span<const Request>(queue.data(), queue.size())};
      Output o{std::span<AxisOutput>(out.data(), p->axis_count())};
      ASSERT_EQ(p->update(in, o), Result::Ok);
      queue.clear();
    }
  }
  /// Step until pred() or the limit; returns cycles stepped.
  template <class F>
  int step_until(F pred, int limit = 1000000) {
    int n = 0;
    while (!pred() && n < limit) { step(); ++n; }
    return n;
  }
  const ControlTag& tag(const std::string& name) { return p->control(ctl(name)); }
  const AxisTag& axis(const std::string& name) { return p->axis(sym.axes.at(name)); }
};

/// A MAM with the common operands, trapezoidal, units/s.
inline std::string mam(const std::string& ax, const std::string& c, int type, double pos, double speed,
                       double acc = 1000, double dec = 1000, const std::string& profile = "trapezoidal",
                       double aj = 100, double dj = 100, const std::string& jerk_units = "%oftime",
                       const std::string& merge = "disabled") {
  return "MAM(" + ax + "," + c + "," + std::to_string(type) + "," + std::to_string(pos) + "," + std::to_string(speed) +
         ",unitspersec," + std::to_string(acc) + ",unitspersec2," + std::to_string(dec) + ",unitspersec2," + profile +
         "," + std::to_string(aj) + "," + std::to_string(dj) + "," + jerk_units + "," + merge + ",programmed,0,none,0,0);";
}
inline std::string maj(const std::string& ax, const std::string& c, int dir, double speed, double acc = 1000,
                       double dec = 1000, const std::string& profile = "trapezoidal", const std::string& merge = "disabled") {
  return "MAJ(" + ax + "," + c + "," + std::to_string(dir) + "," + std::to_string(speed) + ",unitspersec," +
         std::to_string(acc) + ",unitspersec2," + std::to_string(dec) + ",unitspersec2," + profile +
         ",100,100,%oftime," + merge + ",programmed,0,none);";
}

}  // namespace canmotion::motion::test
