#pragma once
// Internal to config/: the YAML reader the loader's sections share. It reads
// typed values (ranges, units, enumerations by name or number, unknown keys
// with the nearest valid one) and collects every problem as a Diagnostic
// (file, line, column, dotted key, what would be valid) instead of stopping
// at the first. Not realtime: start-up only.

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "config/config.hpp"

namespace canmotion::config::load {

/// `path.key`, or `key` at the top level.
[[nodiscard]] std::string sub(const std::string& path, std::string_view key);

/// Lower case without spaces, '_' and '-': how names are compared ("Switch
/// Marker" == "switch_marker").
[[nodiscard]] std::string lower_compact(std::string_view s);

/// Reads one document's values, collecting diagnostics.
class Reader {
 public:
  using Severity = Diagnostic::Severity;

  explicit Reader(std::string file) : file_(std::move(file)) {}

  std::vector<Diagnostic> diags;

  /// The file named in messages (and the folder relative paths start from).
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  /// Where `n` is in the file (1-based; 0 when unknown).
  [[nodiscard]] Location loc(const YAML::Node& n) const;

  void error(const YAML::Node& n, const std::string& key, std::string msg);
  void error_at(Location l, const std::string& key, std::string msg);
  void warning_at(Location l, const std::string& key, std::string msg);

  /// Reject keys of `map` not in `allowed`, suggesting the nearest.
  bool check_map(const YAML::Node& map, const std::string& path, const std::vector<std::string_view>& allowed);

  /// `parent[key]` as a T in lo .. hi (bool: true/false, yes/no, on/off,
  /// 1/0; integers: decimal or 0x hex); false when absent or reported.
  template <class T>
  bool scalar(const YAML::Node& parent, const std::string& path, std::string_view key, T& out, T lo, T hi,
              std::string_view unit = {}) {
    const YAML::Node n = parent[std::string(key)];
    if (!n) return false;
    const std::string p = sub(path, key);
    if (!n.IsScalar()) {
      error(n, p, "must be a single value");
      return false;
    }
    T v{};
    bool ok = true;
    if constexpr (std::is_same_v<T, bool>) {
      const std::string s = lower_compact(n.Scalar());
      if (s == "true" || s == "yes" || s == "on" || s == "1") v = true;
      else if (s == "false" || s == "no" || s == "off" || s == "0") v = false;
      else ok = false;
      if (!ok) {
        error(n, p, fmt::format("must be true or false, got '{}'", n.Scalar()));
        return false;
      }
      out = v;
      return true;
    } else if constexpr (std::is_floating_point_v<T>) {
      ok = YAML::convert<double>::decode(n, v) && std::isfinite(v);
    } else {
      // Integers: decimal or 0x hex, no fraction.
      const std::string& s = n.Scalar();
      errno = 0;
      char* end = nullptr;
      const long long ll = std::strtoll(s.c_str(), &end, 0);
      ok = !s.empty() && end != nullptr && *end == '\0' && errno == 0;
      v = static_cast<T>(ll);
      if (ok && (ll < static_cast<long long>(lo) || ll > static_cast<long long>(hi))) {
        error(n, p, fmt::format("must be {} .. {}{}{}, got {}", lo, hi, unit.empty() ? "" : " ", unit, s));
        return false;
      }
    }
    if (!ok) {
      error(n, p, fmt::format("must be a {} number{}{}, got '{}'", std::is_floating_point_v<T> ? "real" : "whole",
                              unit.empty() ? "" : " in ", unit, n.Scalar()));
      return false;
    }
    if (v < lo || v > hi) {
      error(n, p, fmt::format("must be {} .. {}{}{}, got {}", lo, hi, unit.empty() ? "" : " ", unit, n.Scalar()));
      return false;
    }
    out = v;
    return true;
  }

  /// A required key: true when present, else `missing: <what>` at the parent
  /// (a present but bad value is reported by whoever reads it, once).
  bool required(const YAML::Node& parent, const std::string& path, std::string_view key, std::string_view what);

  /// A non-empty string.
  bool string(const YAML::Node& parent, const std::string& path, std::string_view key, std::string& out);

  /// Enumeration by text (case, spaces and underscores ignored) or number.
  template <class E>
  bool enumeration(const YAML::Node& parent, const std::string& path, std::string_view key, E& out,
                   const std::vector<std::pair<std::string_view, E>>& table) {
    const YAML::Node n = parent[std::string(key)];
    if (!n) return false;
    const std::string p = sub(path, key);
    if (n.IsScalar()) {
      const std::string s = lower_compact(n.Scalar());
      for (const auto& [name, val] : table) {
        if (lower_compact(name) == s || std::to_string(static_cast<int>(val)) == s) {
          out = val;
          return true;
        }
      }
    }
    std::vector<std::string> names;
    for (const auto& [name, val] : table) names.push_back(fmt::format("{} ({})", name, static_cast<int>(val)));
    error(n, p, fmt::format("'{}' is not one of: {}", n.IsScalar() ? n.Scalar() : std::string("<non-scalar>"),
                            fmt::join(names, ", ")));
    return false;
  }

  /// A list element that must be a finite real number (cam point coordinates,
  /// REAL array values); `what` names it in the message ("master ", or "").
  bool finite_number(const YAML::Node& e, const std::string& key, std::string_view what, double& out);

 private:
  std::string file_;
};

}  // namespace canmotion::config::load
