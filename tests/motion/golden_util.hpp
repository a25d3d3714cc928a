#pragma once
// What the planner's golden tests share (tests/golden/planner_golden.cpp,
// tests/motion_coord/test_coord_golden.cpp): a fixed, portable random
// sequence (own SplitMix64 generator, no std distributions, so that it does
// not depend on the standard library's implementation), the hash of a run
// and the ST spelling of a number. Their recorded hashes depend on every
// line here.
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "motion/planner.hpp"
#include "motion/st_parser.hpp"

namespace canmotion::motion::golden {

/// SplitMix64: a fixed, portable sequence.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uni(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
  int pick(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }
  bool coin(double p = 0.5) { return uni(0, 1) < p; }
  template <std::size_t N>
  const char* of(const std::array<const char*, N>& a) { return a[static_cast<std::size_t>(pick(static_cast<int>(N)))]; }
};

/// FNV-1a, 64 bit.
struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void byte(std::uint8_t b) { h = (h ^ b) * 1099511628211ull; }
  void u64(std::uint64_t v) { for (int i = 0; i < 8; ++i) byte(static_cast<std::uint8_t>(v >> (8 * i))); }
  void f64(double d) { std::uint64_t v; std::memcpy(&v, &d, 8); u64(v); }
  void i(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
};

/// `v` as an ST literal, exactly (17 significant digits).
inline std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

/// MASR then MSO on one of `axes`, each with one of the `controls` control
/// tags c0, c1, ... (a run gets back to servo on: fewer refusals for servo
/// off and shutdown); their results hashed.
template <std::size_t N>
void servo_on_again(Rng& g, Hash& h, Planner& p, const Symbols& sym, const std::array<const char*, N>& axes,
                    int controls) {
  const std::string ax = g.of(axes);
  for (const char* ins : {"MASR", "MSO"}) {
    Request q;
    if (!parse_and_bind(std::string(ins) + "(" + ax + ",c" + std::to_string(g.pick(controls)) + ");", sym, q))
      h.i(static_cast<int>(p.execute(q)));
  }
}

}  // namespace canmotion::motion::golden
