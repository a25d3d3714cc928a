// The loader's YAML reader (yaml_reader.hpp): diagnostics, unknown keys,
// required keys, strings, finite numbers.
#include "config/yaml_reader.hpp"

#include <algorithm>
#include <cctype>

namespace canmotion::config::load {

std::string sub(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string lower_compact(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != ' ' && c != '_' && c != '-') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

Location Reader::loc(const YAML::Node& n) const {
  const YAML::Mark m = n.Mark();
  if (m.line < 0) return {};
  return {m.line + 1, m.column + 1};
}

void Reader::error(const YAML::Node& n, const std::string& key, std::string msg) {
  diags.push_back({Severity::kError, file_, loc(n), key, std::move(msg)});
}

void Reader::error_at(Location l, const std::string& key, std::string msg) {
  diags.push_back({Severity::kError, file_, l, key, std::move(msg)});
}

void Reader::warning_at(Location l, const std::string& key, std::string msg) {
  diags.push_back({Severity::kWarning, file_, l, key, std::move(msg)});
}

bool Reader::check_map(const YAML::Node& map, const std::string& path, const std::vector<std::string_view>& allowed) {
  if (!map.IsMap()) {
    error(map, path, "must be a mapping (key: value lines)");
    return false;
  }
  for (auto it = map.begin(); it != map.end(); ++it) {
    const std::string k = it->first.Scalar();
    if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
    std::string msg = fmt::format("unknown key '{}'", k);
    if (auto s = nearest(k, allowed)) msg += fmt::format("; did you mean '{}'?", *s);
    else msg += fmt::format("; valid keys: {}", fmt::join(allowed, ", "));
    error(it->first, path.empty() ? k : path + "." + k, msg);
  }
  return true;
}

bool Reader::required(const YAML::Node& parent, const std::string& path, std::string_view key, std::string_view what) {
  if (parent[std::string(key)]) return true;
  error(parent, sub(path, key), fmt::format("missing: {}", what));
  return false;
}

bool Reader::string(const YAML::Node& parent, const std::string& path, std::string_view key, std::string& out) {
  const YAML::Node n = parent[std::string(key)];
  if (!n) return false;
  if (!n.IsScalar() || n.Scalar().empty()) {
    error(n, sub(path, key), "must be a non-empty string");
    return false;
  }
  out = n.Scalar();
  return true;
}

bool Reader::finite_number(const YAML::Node& e, const std::string& key, std::string_view what, double& out) {
  if (e.IsScalar() && YAML::convert<double>::decode(e, out) && std::isfinite(out)) return true;
  error(e, key, fmt::format("{}must be a finite number, got '{}'", what, e.IsScalar() ? e.Scalar() : "<non-scalar>"));
  return false;
}

}  // namespace canmotion::config::load
