#pragma once
/// \file
/// Lock-free single-producer single-consumer ring of trivially copyable
/// values: commands in to the RT thread, events out of it.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace canmotion::rt {

/// Fixed-capacity SPSC ring. Exactly one thread calls try_push() and exactly
/// one (other) thread calls try_pop(); both are wait-free, never allocate,
/// never block, and are realtime-safe. A full ring refuses the push (the
/// producer decides what to do: the RT side counts it and drops, a non-RT
/// side may retry later); push_failures() counts refusals.
///
/// Capacity: a power of two >= 2, all slots usable. Choose it from the
/// producer's worst burst between two consumer passes (e.g. commands: the most
/// instructions a client may queue in one period; events: events per cycle x
/// cycles the non-RT reader may lag).
template <typename T, std::size_t Capacity>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing payloads must be trivially copyable");
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "Capacity must be a power of two");

 public:
  using value_type = T;
  static constexpr std::size_t capacity() noexcept { return Capacity; }

  /// Producer only. Copies v in; false if the ring is full. Realtime-safe.
  bool try_push(const T& v) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_cache_ >= Capacity) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head - tail_cache_ >= Capacity) {
        push_failures_.store(push_failures_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
        return false;
      }
    }
    slots_[head & (Capacity - 1)] = v;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only. Moves the oldest value into out; false if empty.
  /// Realtime-safe.
  bool try_pop(T& out) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_cache_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail == head_cache_) {
        return false;
      }
    }
    out = slots_[tail & (Capacity - 1)];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Number of values queued; exact when called by producer or consumer while
  /// the other side is idle, approximate otherwise. Realtime-safe.
  std::size_t size_approx() const noexcept {
    const std::size_t tail = tail_.load(std::memory_order_acquire);
    const std::size_t head = head_.load(std::memory_order_acquire);
    return head - tail;
  }
  /// True when size_approx() == 0.
  bool empty_approx() const noexcept { return size_approx() == 0; }
  /// Pushes refused because the ring was full (readable from any thread).
  std::uint64_t push_failures() const noexcept { return push_failures_.load(std::memory_order_relaxed); }

 private:
  // Producer and consumer indices live on their own cache lines (64 bytes on
  // x86-64 and most ARM64) so the two threads do not false-share.
  alignas(64) std::atomic<std::size_t> head_{0};   // next slot to write; written by producer
  std::size_t tail_cache_ = 0;                      // producer's copy of tail_
  std::atomic<std::uint64_t> push_failures_{0};     // written by producer
  alignas(64) std::atomic<std::size_t> tail_{0};   // next slot to read; written by consumer
  std::size_t head_cache_ = 0;                      // consumer's copy of head_
  alignas(64) std::array<T, Capacity> slots_{};
};

}  // namespace canmotion::rt
