#pragma once
// Seeded randomness for property tests: seed and count come from the
// environment (CANMOTION_SEED, CANMOTION_PROP_COUNT) and are printed on failure.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

namespace canmotion::motion::test {

inline std::uint64_t env_u64(const char* name, std::uint64_t dflt) {
  const char* s = std::getenv(name);
  if (!s || !*s) return dflt;
  return std::strtoull(s, nullptr, 0);
}

/// Seed: CANMOTION_SEED if set, else a fixed default (CI reproducible); set
/// CANMOTION_SEED=random for a fresh seed each run.
inline std::uint64_t prop_seed() {
  const char* s = std::getenv("CANMOTION_SEED");
  if (s && std::string(s) == "random") return std::random_device{}();
  return env_u64("CANMOTION_SEED", 20261121);
}
inline std::uint64_t prop_count(std::uint64_t dflt) { return env_u64("CANMOTION_PROP_COUNT", dflt); }

struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t seed) : g(seed) {}
  double uni(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g); }
  double logu(double lo, double hi) { return std::exp(uni(std::log(lo), std::log(hi))); }
  bool coin(double p = 0.5) { return uni(0, 1) < p; }
  int pick(int n) { return static_cast<int>(std::uniform_int_distribution<int>(0, n - 1)(g)); }
};

/// `v` as an ST literal with `precision` significant digits (17: the exact
/// double; std::to_string keeps 6 decimals only).
inline std::string num(double v, int precision = 17) {
  char b[40];
  std::snprintf(b, sizeof b, "%.*g", precision, v);
  return b;
}

}  // namespace canmotion::motion::test
