#pragma once
// Helpers for the cam tests: seeded random generation with the seed and the
// case count taken from the environment, and random cam tables.
//
//   CANMOTION_SEED=<u64>        seed of every property test (default fixed;
//                               CANMOTION_TEST_SEED is accepted too)
//   CANMOTION_PROP_COUNT=<n>    number of random cases per property test
//                               (CANMOTION_TEST_COUNT is accepted too)
// The names match tests/motion (prop_util.hpp).
#include <cstdint>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "motion/cam/cam_profile.hpp"

namespace cam_test {

inline std::uint64_t env_u64(const char* name, std::uint64_t fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  return std::strtoull(v, nullptr, 0);
}

/// Seed for property tests: $CANMOTION_SEED, else a fixed default.
inline std::uint64_t seed() {
  return env_u64("CANMOTION_SEED", env_u64("CANMOTION_TEST_SEED", 0x5eed'ca11ULL));
}
/// Case count for property tests: $CANMOTION_PROP_COUNT, else `fallback`.
inline int count(int fallback) {
  const auto f = static_cast<std::uint64_t>(fallback);
  return static_cast<int>(env_u64("CANMOTION_PROP_COUNT", env_u64("CANMOTION_TEST_COUNT", f)));
}

/// Text for SCOPED_TRACE so every failure prints how to reproduce it (the
/// base seed; each test derives its generator from base seed + a fixed offset).
inline std::string repro(int c) {
  const auto s = seed();
  return "seed=" + std::to_string(s) + " case=" + std::to_string(c) +
         " (reproduce: CANMOTION_SEED=" + std::to_string(s) + " CANMOTION_PROP_COUNT=" + std::to_string(c + 1) +
         ")";
}

enum class Mix { AllCubic, AllLinear, Mixed };

/// Random cam table: n points, master gaps in [0.01, 5], slaves in [-50, 50].
inline std::vector<canmotion::motion::cam::CamPoint> random_cam(std::mt19937_64& rng, std::size_t n, Mix mix) {
  using namespace canmotion::motion::cam;
  std::uniform_real_distribution<double> gap(0.01, 5.0);
  std::uniform_real_distribution<double> val(-50.0, 50.0);
  std::uniform_real_distribution<double> start(-100.0, 100.0);
  std::bernoulli_distribution coin(0.5);
  std::vector<CamPoint> cam(n);
  double m = start(rng);
  for (auto& p : cam) {
    p.master = m;
    p.slave = val(rng);
    p.segment_type = mix == Mix::AllCubic    ? kSegmentCubic
                     : mix == Mix::AllLinear ? kSegmentLinear
                                             : (coin(rng) ? kSegmentCubic : kSegmentLinear);
    m += gap(rng);
  }
  return cam;
}

}  // namespace cam_test
