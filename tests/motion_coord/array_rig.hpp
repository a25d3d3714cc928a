#pragma once
// A planner test rig (tests/motion/rig.hpp) with REAL array tags, as the
// coordinated instructions take their Position, Via/Center and
// EventDistance/CalculatedData operands.
#include <span>
#include <string>
#include <vector>

#include "tests/motion/rig.hpp"

namespace canmotion::motion::test {

struct ArrayRig : Rig {
  std::vector<std::vector<double>> arrays;
  ArrayRig() { arrays.reserve(kMaxArrays); }
  /// A REAL[n] tag `name`, zeroed. Bound: the vectors are never reallocated.
  void add_array(const std::string& name, std::size_t n) {
    EXPECT_LT(arrays.size(), kMaxArrays);
    arrays.emplace_back(n, 0.0);
    const auto id = static_cast<std::uint16_t>(arrays.size() - 1);
    EXPECT_TRUE(p->attach_real_array(id, std::span<double>(arrays.back())));
    sym.real_arrays[name] = id;
  }
  static constexpr std::size_t kMaxArrays = 16;
};

}  // namespace canmotion::motion::test
