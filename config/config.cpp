// The configuration's data model (config.hpp): diagnostics, look-ups, the
// period's unit conversions and its 0x60C2 form.
#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

#include "config/config.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::config {

std::int64_t period_ns(double period_s) noexcept { return static_cast<std::int64_t>(std::llround(period_s * 1e9)); }

double period_ms(double period_s) noexcept { return period_s * 1e3; }

double period_s_from_ms(double ms) noexcept { return ms / 1e3; }

std::string Diagnostic::str() const {
  return fmt::format("{}:{}:{}: {}: {}{}{}", file, where.line, where.column,
                     severity == Severity::kError ? "error" : "warning", key, key.empty() ? "" : ": ", message);
}

namespace {

std::string join_errors(const std::vector<Diagnostic>& d) {
  std::string s;
  for (const auto& x : d) {
    if (!s.empty()) s += '\n';
    s += x.str();
  }
  return s;
}

}  // namespace

ConfigError::ConfigError(std::vector<Diagnostic> diags) : std::runtime_error(join_errors(diags)), diags_(std::move(diags)) {}

const BusSettings* Config::find_bus(std::string_view name) const noexcept {
  for (const auto& b : buses)
    if (b.name == name) return &b;
  return nullptr;
}

const AxisSettings* Config::find_axis(std::string_view name) const noexcept {
  for (const auto& a : axes)
    if (a.name == name) return &a;
  return nullptr;
}

std::optional<std::string> nearest(std::string_view word, const std::vector<std::string_view>& candidates) {
  std::size_t best = std::string_view::npos;
  std::string_view best_word;
  for (std::string_view c : candidates) {
    // Levenshtein distance, two rows.
    std::vector<std::size_t> prev(c.size() + 1), cur(c.size() + 1);
    for (std::size_t j = 0; j <= c.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= word.size(); ++i) {
      cur[0] = i;
      for (std::size_t j = 1; j <= c.size(); ++j) {
        const bool same = std::tolower(static_cast<unsigned char>(word[i - 1])) ==
                          std::tolower(static_cast<unsigned char>(c[j - 1]));
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
      }
      std::swap(prev, cur);
    }
    if (prev[c.size()] < best) {
      best = prev[c.size()];
      best_word = c;
    }
  }
  const std::size_t limit = std::max<std::size_t>(2, word.size() / 3);
  if (best_word.empty() || best > limit) return std::nullopt;
  return std::string(best_word);
}

std::optional<InterpolationPeriod> interpolation_period(double period_s) noexcept {
  // The drive proxy's own encoder (cia402.hpp), on the period in ns as the
  // runtime uses it: what is checked here is what is written. 255 s is the
  // longest period 0x60C2 can hold (255 x 10^0).
  if (!(period_s > 0) || period_s > 255.0) return std::nullopt;
  const auto ip = cia402::encode_interpolation_period(period_ns(period_s));
  if (!ip) return std::nullopt;
  return InterpolationPeriod{ip->value, ip->index};
}

}  // namespace canmotion::config
