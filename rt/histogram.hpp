#pragma once
/// \file
/// Fixed-size log-linear histogram of non-negative nanosecond values, written
/// by ONE thread (the RT thread) and read by any number of others, lock-free.

#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>

namespace canmotion::rt {

/// Log-linear buckets (like HdrHistogram with 64 sub-buckets per octave):
/// values below 128 ns have one bucket per ns; above, every power-of-two range
/// is split into 64 equal buckets, so a bucket is at most 1/64 (1.6 %) of its
/// value wide. The whole uint63 range fits in kBuckets buckets: no overflow
/// bucket, no allocation, no configuration. Memory: kBuckets * 8 bytes (~29 KiB).
///
/// Concurrency: record() is called by a single writer thread; every field is
/// an atomic written with relaxed stores, so readers on other threads never
/// block it and see a (possibly slightly inconsistent across fields) recent
/// state. That is enough for statistics and is data-race free.
class Histogram {
 public:
  static constexpr unsigned kSubBits = 6;                         ///< 64 sub-buckets per octave
  static constexpr std::uint64_t kSub = 1ULL << kSubBits;
  static constexpr unsigned kMaxExponent = 62;                    ///< values < 2^63
  static constexpr std::size_t kBuckets = 2 * kSub + (kMaxExponent - kSubBits) * kSub;

  /// Bucket index of a value. Realtime-safe.
  static constexpr std::size_t bucket_of(std::uint64_t v) noexcept {
    if (v < 2 * kSub) {
      return static_cast<std::size_t>(v);
    }
    const unsigned e = static_cast<unsigned>(std::bit_width(v)) - 1;  // 2^e <= v < 2^(e+1), e >= 7
    const std::uint64_t mantissa = v >> (e - kSubBits);                // in [64, 128)
    return static_cast<std::size_t>(2 * kSub + (e - kSubBits - 1) * kSub + (mantissa - kSub));
  }
  /// Smallest value of bucket i.
  static constexpr std::uint64_t bucket_lower(std::size_t i) noexcept {
    if (i < 2 * kSub) {
      return i;
    }
    const std::size_t j = i - 2 * kSub;
    const unsigned e = static_cast<unsigned>(j / kSub) + kSubBits + 1;
    const std::uint64_t mantissa = kSub + j % kSub;
    return mantissa << (e - kSubBits);
  }
  /// Largest value of bucket i (inclusive).
  static constexpr std::uint64_t bucket_upper(std::size_t i) noexcept {
    return i + 1 < kBuckets ? bucket_lower(i + 1) - 1 : (1ULL << 63) - 1;
  }

  /// Add one value (negative values count as 0). Single writer; realtime-safe,
  /// wait-free, no allocation.
  void record(std::int64_t value) noexcept;

  /// Number of values recorded.
  std::uint64_t count() const noexcept { return count_.load(std::memory_order_relaxed); }
  /// Smallest / largest value recorded (exact); 0 when empty.
  std::int64_t min() const noexcept;
  std::int64_t max() const noexcept;
  /// Mean (exact sum / count); 0 when empty.
  std::int64_t mean() const noexcept;
  /// Value at or below which a fraction q (0..1] of the values lie: the upper
  /// edge of the bucket holding that rank, clamped to [min, max], so it is at
  /// most 1/64 above the exact order statistic. 0 when empty. O(kBuckets);
  /// meant for non-RT readers.
  std::int64_t percentile(double q) const noexcept;
  /// Count in bucket i (for printing a histogram).
  std::uint64_t bucket_count(std::size_t i) const noexcept {
    return buckets_[i].load(std::memory_order_relaxed);
  }

 private:
  std::array<std::atomic<std::uint64_t>, kBuckets> buckets_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<std::int64_t> sum_{0};
  std::atomic<std::int64_t> min_{INT64_MAX};
  std::atomic<std::int64_t> max_{0};
};

static_assert(Histogram::bucket_of((1ULL << 63) - 1) == Histogram::kBuckets - 1);

/// The non-empty buckets as text, one "lower_ns upper_ns count" line each
/// after a "# lower_ns upper_ns count" header (rt-latency and canmotiond
/// --histogram; tools/rt-latency/compare-cyclictest.sh pools them). Not RT.
std::string histogram_text(const Histogram& h);

}  // namespace canmotion::rt
