#include "fieldbus/trace/trace_config.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <stdexcept>

#include "fieldbus/cia402/drive_pdos.hpp"

namespace canmotion::trace {
namespace {

[[noreturn]] void fail(const std::string& file, const YAML::Node& n, const std::string& key, const std::string& msg) {
  const YAML::Mark m = n.Mark();
  throw std::runtime_error(fmt::format("{}:{}:{}: {}: {}", file, m.line + 1, m.column + 1, key, msg));
}

template <typename T>
bool get(const std::string& file, const YAML::Node& map, const char* key, const std::string& path, T& out) {
  const YAML::Node v = map[key];
  if (!v) return false;
  try {
    out = v.as<T>();
  } catch (const YAML::Exception&) {
    fail(file, v, path + "." + key, "has the wrong type");
  }
  return true;
}

void set_profile(const std::string& file, const YAML::Node& n, const std::string& path, cia402::PdoProfile& p) {
  std::string s;
  if (!get(file, n, "pdo", path, s)) return;
  if (s == "csp") {
    p = cia402::PdoProfile::kCsp;
  } else if (s == "csp_csv_cst") {
    p = cia402::PdoProfile::kCspCsvCst;
  } else {
    fail(file, n["pdo"], path + ".pdo", "unknown PDO profile '" + s + "' (valid: csp, csp_csv_cst)");
  }
}

NodeLayouts layouts_for(cia402::PdoProfile profile, std::uint8_t node) {
  NodeLayouts l;
  const cia402::DrivePdoSet set = cia402::default_drive_pdos(profile, node);
  auto copy = [](const canopen::PdoMap& m, PdoLayout& out) {
    out.count = static_cast<std::uint8_t>(std::min<std::size_t>(m.count, kMaxPdoEntries));
    for (std::size_t i = 0; i < out.count; ++i) out.entries[i] = MapEntry{m.entries[i].index, m.entries[i].sub, m.entries[i].bits};
  };
  for (std::size_t i = 0; i < set.rpdo_count; ++i) {
    const std::uint8_t n = set.rpdo[i].number;
    if (n < 1 || n > kPdosPerDirection) continue;
    copy(set.rpdo[i], l.rpdo[n - 1]);
    l.rpdo_set[n - 1] = true;
  }
  for (std::size_t i = 0; i < set.tpdo_count; ++i) {
    const std::uint8_t n = set.tpdo[i].number;
    if (n < 1 || n > kPdosPerDirection) continue;
    copy(set.tpdo[i], l.tpdo[n - 1]);
    l.tpdo_set[n - 1] = true;
  }
  return l;
}

}  // namespace

TraceConfig parse_trace_config(const std::string& yaml, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("{}:{}:{}: {}", file, e.mark.line + 1, e.mark.column + 1, e.msg));
  }
  TraceConfig c;
  c.path = file;
  if (!root.IsMap()) throw std::runtime_error(file + ": not a YAML mapping (expected keys controller, buses, axes, ...)");
  if (const YAML::Node ctl = root["controller"]; ctl && ctl.IsMap()) {
    double ms = 0;
    if (get(file, ctl, "period_ms", "controller", ms)) {
      if (ms <= 0) fail(file, ctl["period_ms"], "controller.period_ms", "must be > 0");
      c.period_ns = static_cast<std::int64_t>(ms * 1e6 + 0.5);
    }
  }
  if (const YAML::Node buses = root["buses"]; buses && buses.IsSequence()) {
    for (std::size_t i = 0; i < buses.size(); ++i) {
      const std::string p = fmt::format("buses[{}]", i);
      TraceConfig::Bus b;
      get(file, buses[i], "name", p, b.name);
      get(file, buses[i], "interface", p, b.interface);
      get(file, buses[i], "bitrate", p, b.bitrate);
      c.buses.push_back(b);
    }
  }
  cia402::PdoProfile default_profile = cia402::PdoProfile::kCsp;
  if (const YAML::Node d = root["drives"]; d && d.IsMap()) set_profile(file, d, "drives", default_profile);
  const YAML::Node axes = root["axes"];
  if (axes && !axes.IsSequence()) fail(file, axes, "axes", "must be a list of axes");
  if (axes) {
    for (std::size_t i = 0; i < axes.size(); ++i) {
      const YAML::Node a = axes[i];
      const std::string p = fmt::format("axes[{}]", i);
      if (!a.IsMap()) fail(file, a, p, "must be a mapping");
      int node = 0;
      if (!get(file, a, "node", p, node)) continue;  // AXIS_VIRTUAL: not on a bus
      if (node < 1 || node > static_cast<int>(kMaxNode)) fail(file, a["node"], p + ".node", "must be 1 .. 127");
      TraceConfig::Node n;
      n.node = static_cast<std::uint8_t>(node);
      get(file, a, "name", p, n.axis);
      get(file, a, "units", p, n.unit);
      get(file, a, "conversion_constant", p, n.counts_per_unit);
      std::string bus;
      if (get(file, a, "bus", p, bus)) {
        for (const auto& b : c.buses) {
          if (b.name == bus) n.interface = b.interface;
        }
      }
      cia402::PdoProfile profile = default_profile;
      if (const YAML::Node d = a["drive"]; d && d.IsMap()) set_profile(file, d, p + ".drive", profile);
      n.layouts = layouts_for(profile, n.node);
      c.nodes.push_back(std::move(n));
    }
  }
  return c;
}

TraceConfig load_trace_config(const std::string& path) {
  std::string text;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) throw std::runtime_error(path + ": cannot open configuration file");
  char buf[65536];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  std::fclose(f);
  return parse_trace_config(text, path);
}

}  // namespace canmotion::trace
