#pragma once
/// \file
/// Snapshot buffer: the RT thread publishes its latest status, non-RT threads
/// read the newest complete copy. Triple buffering: the writer never waits
/// and never sees a reader; a reader never sees a half-written value.

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <type_traits>

namespace canmotion::rt {

/// Triple buffer of a trivially copyable T.
///
/// Writer (one thread, the RT thread): publish() or write_slot()+commit();
/// wait-free, realtime-safe, one atomic exchange per publish.
/// Readers (any number of non-RT threads): read() copies the newest published
/// value. Readers serialise among themselves on a mutex that the writer never
/// touches, so a slow reader delays only other readers.
template <typename T>
class SnapshotBuffer {
  static_assert(std::is_trivially_copyable_v<T>, "snapshots must be trivially copyable");

 public:
  /// Writer only: copy v in and publish it. Realtime-safe.
  void publish(const T& v) noexcept {
    write_slot() = v;
    commit();
  }

  /// Writer only: the slot to fill in place (contents unspecified: an older
  /// value; overwrite every field), then call commit(). Realtime-safe.
  T& write_slot() noexcept { return slots_[write_].value; }

  /// Writer only: publish what write_slot() holds. Realtime-safe.
  void commit() noexcept {
    slots_[write_].seq = ++published_;
    const std::uint8_t previous = middle_.exchange(static_cast<std::uint8_t>(write_ | kFresh),
                                                   std::memory_order_acq_rel);
    write_ = previous & kIndexMask;
  }

  /// Any non-RT thread: copy the newest published value into out and return
  /// its sequence number (1 for the first publish, +1 per publish); returns 0
  /// and leaves out alone if nothing was published yet. Not realtime-safe
  /// (takes the readers' mutex).
  std::uint64_t read(T& out) {
    std::lock_guard lock(reader_mutex_);
    if ((middle_.load(std::memory_order_acquire) & kFresh) != 0) {
      const std::uint8_t previous = middle_.exchange(read_, std::memory_order_acq_rel);
      read_ = previous & kIndexMask;
    }
    const Slot& s = slots_[read_];
    if (s.seq != 0) {
      out = s.value;
    }
    return s.seq;
  }

  /// Number of publishes so far (writer-side count, readable by the writer).
  std::uint64_t published() const noexcept { return published_; }

 private:
  struct Slot {
    T value{};
    std::uint64_t seq = 0;  // 0 = never written
  };
  static constexpr std::uint8_t kIndexMask = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;  // middle holds a value the reader has not taken

  std::array<Slot, 3> slots_{};
  std::uint8_t write_ = 0;                  // writer-owned
  std::uint64_t published_ = 0;             // writer-owned
  alignas(64) std::atomic<std::uint8_t> middle_{1};
  alignas(64) std::uint8_t read_ = 2;       // reader-owned (under reader_mutex_)
  std::mutex reader_mutex_;
};

}  // namespace canmotion::rt
