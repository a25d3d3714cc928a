// The allocation counter itself: it sees allocations on counting threads
// (so it CAN fail a test), ignores other threads, and counts every form.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/allocation_counter.hpp"

using namespace canmotion::test;

namespace {
struct alignas(64) Aligned {
  char c[64];
};
// Opaque to the optimiser so `new` is not elided.
template <typename T>
void escape(T* p) {
  asm volatile("" : : "g"(p) : "memory");
}
}  // namespace

TEST(RtAllocCounter, SeesAllocationsOnTheCountingThread) {
  reset_allocation_count();
  {
    CountAllocationsInScope scope;
    auto* p = new int(5);
    escape(p);
    delete p;
    auto* a = new int[10];
    escape(a);
    delete[] a;
    auto* al = new Aligned;
    escape(al);
    delete al;
    auto* nt = new (std::nothrow) double(1.0);
    escape(nt);
    delete nt;
    std::vector<int> v;
    v.push_back(1);
    escape(v.data());
  }
  EXPECT_EQ(counted_allocations(), 5u);
  EXPECT_GE(counted_bytes(), sizeof(int) * 11 + 64 + sizeof(double));
}

TEST(RtAllocCounter, IgnoresThreadsThatDoNotCount) {
  reset_allocation_count();
  std::thread other([] {
    for (int i = 0; i < 100; ++i) {
      auto s = std::make_unique<std::string>(200, 'x');
      escape(s.get());
    }
  });
  other.join();
  auto* p = new int(1);  // main thread, not counting
  escape(p);
  delete p;
  EXPECT_EQ(counted_allocations(), 0u);
}

TEST(RtAllocCounter, CountsOnAnotherThreadThatEnablesIt) {
  reset_allocation_count();
  std::thread rt([] {
    count_allocations_on_this_thread(true);
    auto* p = new int(1);
    escape(p);
    delete p;
    count_allocations_on_this_thread(false);
    auto* q = new int(2);  // after disabling: not counted
    escape(q);
    delete q;
  });
  rt.join();
  EXPECT_EQ(counted_allocations(), 1u);
  EXPECT_FALSE(counting_on_this_thread());
}
