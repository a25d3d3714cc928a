#pragma once
/// \file
/// A device's object dictionary as its description (an EDS or DCF, CiA 306)
/// lists it: which index/sub-index pairs exist, their names and data types.
///
/// The master asks it "does the drive have this object?" before optional
/// boot writes (cia402::DriveProxy: an optional write to an object the drive
/// lacks is left out) and for the vendor's names in messages and traces. A
/// default-constructed one stands for "no description given": has() answers
/// kUnknown, and the master then tries optional writes and tolerates abort
/// 0x06020000 / 0x06090011.
///
/// fieldbus/eds builds one from an EDS (eds::device_dictionary()). Built at
/// set-up (allocates); has(), find() and name() are realtime-safe (a binary
/// search, no allocation, no exception).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "fieldbus/canopen/object_names.hpp"

namespace canmotion::canopen {

/// Whether a device has an object, as far as the master knows.
enum class Presence : std::uint8_t {
  kUnknown,  ///< no description of the device
  kPresent,  ///< the description lists it
  kAbsent,   ///< the description does not list it
};

class DeviceDictionary {
 public:
  struct Entry {
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    DataType type = DataType::kUnsigned8;
    Access access = Access::kRo;
    std::string name;  ///< the description's ParameterName ("" when it has none)
  };

  /// No description: every query answers kUnknown.
  DeviceDictionary() = default;
  /// A description with these sub-objects (any order; a pair given twice
  /// keeps the first). `source` names it in messages ("drive.eds").
  DeviceDictionary(std::vector<Entry> entries, std::string source);

  /// True when built from a description.
  [[nodiscard]] bool described() const noexcept { return described_; }
  /// Does the device have index:sub? Realtime-safe.
  [[nodiscard]] Presence has(std::uint16_t index, std::uint8_t sub) const noexcept;
  /// Does the device have any sub-index of `index`? Realtime-safe.
  [[nodiscard]] Presence has(std::uint16_t index) const noexcept;
  /// The entry of index:sub, or nullptr (also without a description). Realtime-safe.
  [[nodiscard]] const Entry* find(std::uint16_t index, std::uint8_t sub) const noexcept;
  /// The description's name of index:sub (NUL-terminated), or nullptr when
  /// there is none. Realtime-safe.
  [[nodiscard]] const char* name(std::uint16_t index, std::uint8_t sub) const noexcept;
  /// The description's name, else canopen's object table's, else "".
  [[nodiscard]] std::string_view name_or_standard(std::uint16_t index, std::uint8_t sub) const noexcept;
  /// What the description came from ("" without one).
  [[nodiscard]] const std::string& source() const noexcept { return source_; }
  /// Every entry, ascending index and sub-index.
  [[nodiscard]] std::span<const Entry> entries() const noexcept { return entries_; }

 private:
  std::vector<Entry> entries_;
  std::string source_;
  bool described_ = false;
};

}  // namespace canmotion::canopen
