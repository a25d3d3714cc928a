#pragma once
/// \file
/// Counts heap allocations made on chosen threads, to prove that the RT
/// thread allocates nothing. Linking canmotion_test_support replaces the
/// global operator new/delete (all forms) of the test binary; they forward to
/// malloc/free and, when the calling thread has counting enabled, add one to
/// a process-wide counter. Other threads are not counted, so a test can run a
/// busy non-RT side (gtest, logging, socket clients) and still assert 0 on the
/// RT thread.
///
/// Limits: only C++ operator new is counted (direct malloc() calls from C
/// libraries are not); the counter is global, so run one counted scenario at
/// a time.

#include <cstdint>

namespace canmotion::test {

/// Turn counting on/off for the calling thread. Realtime-safe (a
/// thread_local store); the RT thread may call it, e.g. from
/// ExecutiveConfig::on_loop_start.
void count_allocations_on_this_thread(bool enable) noexcept;
/// True if the calling thread counts.
bool counting_on_this_thread() noexcept;
/// Allocations counted (all counting threads) since the last reset.
std::uint64_t counted_allocations() noexcept;
/// Bytes requested by the counted allocations since the last reset.
std::uint64_t counted_bytes() noexcept;
/// Zero both counters.
void reset_allocation_count() noexcept;

/// RAII: count allocations on this thread while the object lives.
class CountAllocationsInScope {
 public:
  CountAllocationsInScope() noexcept : previous_(counting_on_this_thread()) {
    count_allocations_on_this_thread(true);
  }
  ~CountAllocationsInScope() { count_allocations_on_this_thread(previous_); }
  CountAllocationsInScope(const CountAllocationsInScope&) = delete;
  CountAllocationsInScope& operator=(const CountAllocationsInScope&) = delete;

 private:
  bool previous_;
};

}  // namespace canmotion::test
