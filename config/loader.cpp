// YAML loading and validation of the canmotion configuration.
//
// The loader walks the document once, section by section (load_*.cpp, over
// the Reader of yaml_reader.hpp), collecting every problem as a Diagnostic
// (file, line, column, dotted key, message with what would be valid) instead
// of stopping at the first, then runs the cross-checks (cross_check.cpp:
// names, node ids, COB-IDs, 0x60C2, bus budget) and the drives' EDS files
// (eds_check.cpp). Only a configuration without errors is returned.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

#include "config/config.hpp"
#include "config/eds_check.hpp"
#include "config/load_sections.hpp"

namespace canmotion::config {

namespace {

using Severity = Diagnostic::Severity;

/// The top-level list `key` when present, each entry read by `entry(node,
/// "key[i]")` into `out`; `what` says what the list holds.
template <class T, class Entry>
void list(load::Reader& r, const YAML::Node& root, const char* key, std::string_view what, std::vector<T>& out,
          Entry entry) {
  const YAML::Node l = root[key];
  if (!l) return;
  if (!l.IsSequence()) {
    r.error(l, key, fmt::format("must be a list of {}", what));
    return;
  }
  for (std::size_t i = 0; i < l.size(); ++i) out.push_back(entry(l[i], fmt::format("{}[{}]", key, i)));
}

/// The document's sections, in order; `drives:` gives the axes' drive defaults.
Config document(load::Reader& r, const YAML::Node& root) {
  Config cfg;
  cfg.path = r.file();
  if (!root || root.IsNull()) {
    r.error_at({1, 1}, "", "the file is empty; it needs at least `axes:`");
    return cfg;
  }
  if (!r.check_map(root, "", {"controller", "buses", "drives", "axes", "cams", "arrays", "coordinate_systems"})) return cfg;
  if (root["controller"]) cfg.controller = load::controller(r, root["controller"]);
  using Node = const YAML::Node&;
  list(r, root, "buses", "buses", cfg.buses, [&](Node n, const std::string& k) { return load::bus(r, n, k); });
  DriveSettings defaults;
  if (root["drives"]) load::drive(r, root["drives"], "drives", defaults);
  if (!root["axes"]) r.error(root, "axes", "missing: a configuration needs at least one axis");
  list(r, root, "axes", "axes", cfg.axes, [&](Node n, const std::string& k) { return load::axis(r, n, k, defaults); });
  list(r, root, "cams", "cams", cfg.cams, [&](Node n, const std::string& k) { return load::cam(r, n, k); });
  list(r, root, "arrays", "{name, type, size, values}", cfg.arrays,
       [&](Node n, const std::string& k) { return load::array(r, n, k); });
  list(r, root, "coordinate_systems", "{name, axes, max_speed, max_accel, max_decel, ...}", cfg.coordinate_systems,
       [&](Node n, const std::string& k) { return load::coordinate_system(r, n, k); });
  return cfg;
}

Config finish(load::Reader& r, Config cfg) {
  load::cross_check(r, cfg);
  // The drives' EDS files, once the configuration itself is valid (the check
  // builds each drive's boot configuration from it).
  if (std::none_of(r.diags.begin(), r.diags.end(), [](const Diagnostic& d) { return d.severity == Severity::kError; }))
    check_drive_descriptions(cfg, r.diags);
  std::vector<Diagnostic> errors;
  for (auto& d : r.diags) {
    if (d.severity == Severity::kError) errors.push_back(d);
    else cfg.warnings.push_back(d);
  }
  if (!errors.empty()) {
    std::stable_sort(errors.begin(), errors.end(),
                     [](const Diagnostic& a, const Diagnostic& b) { return a.where.line < b.where.line; });
    throw ConfigError(std::move(errors));
  }
  return cfg;
}

}  // namespace

Config load_string(std::string_view yaml, const std::string& name) {
  load::Reader r(name);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    throw ConfigError({Diagnostic{Severity::kError, name, {e.mark.line + 1, e.mark.column + 1}, "",
                                  "YAML syntax: " + e.msg}});
  }
  Config cfg = document(r, root);
  return finish(r, std::move(cfg));
}

Config load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::system_error(errno, std::generic_category(), "cannot read configuration file '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return load_string(ss.str(), path);
}

}  // namespace canmotion::config
