#pragma once
/// \file
/// Seed and iteration count for randomised property tests, overridable from
/// the environment so a failure can be replayed:
///   CANMOTION_SEED=1234 CANMOTION_COUNT=100000 ./rt_stats_test
/// Print the seed in every failure message, e.g. `<< seed_note(seed)`.

#include <cstdint>
#include <cstdlib>
#include <string>

namespace canmotion::test {

/// $CANMOTION_SEED if set, else `fallback`.
inline std::uint64_t test_seed(std::uint64_t fallback) {
  const char* s = std::getenv("CANMOTION_SEED");
  return s != nullptr && *s != '\0' ? std::strtoull(s, nullptr, 0) : fallback;
}

/// $CANMOTION_COUNT if set, else `fallback`.
inline std::uint64_t test_count(std::uint64_t fallback) {
  const char* s = std::getenv("CANMOTION_COUNT");
  return s != nullptr && *s != '\0' ? std::strtoull(s, nullptr, 0) : fallback;
}

/// " (replay with CANMOTION_SEED=<seed>)".
inline std::string seed_note(std::uint64_t seed) {
  return " (replay with CANMOTION_SEED=" + std::to_string(seed) + ")";
}

}  // namespace canmotion::test
