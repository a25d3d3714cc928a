#include "rt/histogram.hpp"

#include <algorithm>
#include <cmath>

namespace canmotion::rt {

void Histogram::record(std::int64_t value) noexcept {
  const std::int64_t v = value < 0 ? 0 : value;
  // Single writer: load + store (no read-modify-write instruction needed).
  auto& b = buckets_[bucket_of(static_cast<std::uint64_t>(v))];
  b.store(b.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  sum_.store(sum_.load(std::memory_order_relaxed) + v, std::memory_order_relaxed);
  if (v < min_.load(std::memory_order_relaxed)) {
    min_.store(v, std::memory_order_relaxed);
  }
  if (v > max_.load(std::memory_order_relaxed)) {
    max_.store(v, std::memory_order_relaxed);
  }
  count_.store(count_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

std::int64_t Histogram::min() const noexcept {
  return count() == 0 ? 0 : min_.load(std::memory_order_relaxed);
}

std::int64_t Histogram::max() const noexcept {
  return count() == 0 ? 0 : max_.load(std::memory_order_relaxed);
}

std::int64_t Histogram::mean() const noexcept {
  const std::uint64_t n = count();
  return n == 0 ? 0 : sum_.load(std::memory_order_relaxed) / static_cast<std::int64_t>(n);
}

std::int64_t Histogram::percentile(double q) const noexcept {
  // Use the buckets' own total so a concurrent record() cannot make the rank
  // unreachable.
  std::uint64_t total = 0;
  for (const auto& b : buckets_) {
    total += b.load(std::memory_order_relaxed);
  }
  if (total == 0) {
    return 0;
  }
  q = std::clamp(q, 0.0, 1.0);
  auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total)));
  rank = std::clamp<std::uint64_t>(rank, 1, total);
  std::uint64_t seen = 0;
  std::size_t i = 0;
  for (; i < kBuckets; ++i) {
    seen += buckets_[i].load(std::memory_order_relaxed);
    if (seen >= rank) {
      break;
    }
  }
  i = std::min(i, kBuckets - 1);
  const auto upper = static_cast<std::int64_t>(bucket_upper(i));
  return std::clamp(upper, min(), std::max(min(), max()));
}

std::string histogram_text(const Histogram& h) {
  std::string t = "# lower_ns upper_ns count\n";
  for (std::size_t i = 0; i < Histogram::kBuckets; ++i)
    if (const std::uint64_t n = h.bucket_count(i))
      t += std::to_string(Histogram::bucket_lower(i)) + ' ' + std::to_string(Histogram::bucket_upper(i)) + ' ' +
           std::to_string(n) + '\n';
  return t;
}

}  // namespace canmotion::rt
