#include "fieldbus/canopen/device_dictionary.hpp"

#include <algorithm>

namespace canmotion::canopen {

namespace {
constexpr std::uint32_t key_of(std::uint16_t index, std::uint8_t sub) noexcept {
  return (static_cast<std::uint32_t>(index) << 8) | sub;
}
constexpr std::uint32_t key_of(const DeviceDictionary::Entry& e) noexcept { return key_of(e.index, e.sub); }
}  // namespace

DeviceDictionary::DeviceDictionary(std::vector<Entry> entries, std::string source)
    : entries_(std::move(entries)), source_(std::move(source)), described_(true) {
  std::stable_sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return key_of(a) < key_of(b); });
  entries_.erase(std::unique(entries_.begin(), entries_.end(),
                             [](const Entry& a, const Entry& b) { return key_of(a) == key_of(b); }),
                 entries_.end());
}

const DeviceDictionary::Entry* DeviceDictionary::find(std::uint16_t index, std::uint8_t sub) const noexcept {
  const std::uint32_t k = key_of(index, sub);
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), k,
                                   [](const Entry& e, std::uint32_t kk) { return key_of(e) < kk; });
  return it != entries_.end() && key_of(*it) == k ? &*it : nullptr;
}

Presence DeviceDictionary::has(std::uint16_t index, std::uint8_t sub) const noexcept {
  if (!described_) return Presence::kUnknown;
  return find(index, sub) != nullptr ? Presence::kPresent : Presence::kAbsent;
}

Presence DeviceDictionary::has(std::uint16_t index) const noexcept {
  if (!described_) return Presence::kUnknown;
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), key_of(index, 0),
                                   [](const Entry& e, std::uint32_t kk) { return key_of(e) < kk; });
  return it != entries_.end() && it->index == index ? Presence::kPresent : Presence::kAbsent;
}

const char* DeviceDictionary::name(std::uint16_t index, std::uint8_t sub) const noexcept {
  const Entry* e = find(index, sub);
  return e != nullptr && !e->name.empty() ? e->name.c_str() : nullptr;
}

std::string_view DeviceDictionary::name_or_standard(std::uint16_t index, std::uint8_t sub) const noexcept {
  if (const char* n = name(index, sub)) return n;
  return object_name(index, sub);
}

}  // namespace canmotion::canopen
