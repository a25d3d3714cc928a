// The loader's `coordinate_systems:` section.
#include "config/load_sections.hpp"

namespace canmotion::config::load {

/// One `coordinate_systems:` entry.
CoordinateSystemSettings coordinate_system(Reader& r, const YAML::Node& n, const std::string& path) {
  CoordinateSystemSettings c;
  c.where = r.loc(n);
  if (!r.check_map(n, path, {"name", "axes", "conversion_ratios", "coordination_modes", "units", "max_speed",
                             "max_accel", "max_decel", "max_accel_jerk", "max_decel_jerk",
                             "actual_position_tolerance", "command_position_tolerance"}))
    return c;
  if (r.required(n, path, "name", "every coordinate system needs a name")) r.string(n, path, "name", c.name);
  if (r.required(n, path, "axes", "the member axes in order, 1 to 3 axis names")) {
    const YAML::Node a = n["axes"];
    if (!a.IsSequence() || a.size() < 1 || a.size() > 3) {
      r.error(a, path + ".axes", "must be a list of 1 to 3 axis names");
    } else {
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (!a[i].IsScalar() || a[i].Scalar().empty()) r.error(a[i], fmt::format("{}.axes[{}]", path, i), "must be an axis name");
        else {
          c.axes.push_back(a[i].Scalar());
          c.axes_where.push_back(r.loc(a[i]));
        }
      }
    }
  }
  if (const YAML::Node ratios = n["conversion_ratios"]) {
    if (!ratios.IsSequence() || ratios.size() != c.axes.size()) {
      r.error(ratios, path + ".conversion_ratios", fmt::format("must be a list of {} numbers > 0, one per member axis", c.axes.size()));
    } else {
      for (std::size_t i = 0; i < ratios.size(); ++i) {
        double x = 0;
        const std::string k = fmt::format("{}.conversion_ratios[{}]", path, i);
        if (r.finite_number(ratios[i], k, "", x) && !(x > 0)) r.error(ratios[i], k, fmt::format("must be > 0, got {}", x));
        c.conversion_ratios.push_back(x);
      }
    }
  }
  // Logix's per-member Coordination Mode: only Primary (every member is in
  // the vector length); Ancillary members are refused (README, "Coordinated motion")
  if (const YAML::Node m = n["coordination_modes"]) {
    if (!m.IsSequence() || m.size() != c.axes.size()) {
      r.error(m, path + ".coordination_modes", fmt::format("must be a list of {} modes (primary), one per member axis", c.axes.size()));
    } else {
      for (std::size_t i = 0; i < m.size(); ++i) {
        const std::string k = fmt::format("{}.coordination_modes[{}]", path, i);
        const std::string v = m[i].IsScalar() ? m[i].Scalar() : std::string{};
        if (v == "ancillary")
          r.error(m[i], k, "ancillary members are not supported: every member is primary (part of the vector length)");
        else if (v != "primary")
          r.error(m[i], k, fmt::format("must be primary, got '{}'", v));
      }
    }
  }
  r.string(n, path, "units", c.units);
  constexpr double kBig = 1e12;
  for (auto [key, out] : {std::pair<std::string_view, double*>{"max_speed", &c.max_speed}, {"max_accel", &c.max_accel},
                          {"max_decel", &c.max_decel}}) {
    if (r.required(n, path, key, "> 0, coordination units per second (squared)")) r.scalar(n, path, key, *out, 1e-12, kBig);
  }
  r.scalar(n, path, "max_accel_jerk", c.max_accel_jerk, 0.0, kBig);
  r.scalar(n, path, "max_decel_jerk", c.max_decel_jerk, 0.0, kBig);
  r.scalar(n, path, "actual_position_tolerance", c.actual_position_tolerance, 0.0, kBig);
  r.scalar(n, path, "command_position_tolerance", c.command_position_tolerance, 0.0, kBig);
  return c;
}

}  // namespace canmotion::config::load
