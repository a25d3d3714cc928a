#pragma once
/// \file
/// PDO mapping (CiA 301 §7.2.2): a mapping with byte offsets computed once at
/// configuration, bit-exact little-endian packing/unpacking, the CiA 301
/// remapping procedure as a list of SDO writes, and the default mappings
/// canmotion uses for CiA 402 drives. Packing is realtime-safe.

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_client.hpp"

namespace canmotion::canopen {

/// Classic CAN: 8 bytes, so at most 8 (byte-granular) entries.
inline constexpr std::size_t kMaxPdoEntries = 8;
/// COB-ID bit 31: PDO not valid.
inline constexpr std::uint32_t kPdoInvalid = 0x80000000u;
/// COB-ID bit 30: no RTR allowed.
inline constexpr std::uint32_t kPdoNoRtr = 0x40000000u;
/// Transmission type 1: synchronous, every SYNC (canmotion's cyclic PDOs).
inline constexpr std::uint8_t kTransmissionSyncEvery = 1;

/// One mapped object with its position in the PDO payload.
struct PdoEntry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;        ///< 8, 16, 24, 32 (byte granular)
  std::uint8_t bit_offset = 0;  ///< computed by PdoMap::finalize()
  [[nodiscard]] constexpr std::uint32_t raw() const noexcept {
    return (static_cast<std::uint32_t>(index) << 16) | (static_cast<std::uint32_t>(sub) << 8) | bits;
  }
};

/// Direction of a PDO seen from the drive: RPDO = master -> drive.
enum class PdoDir : std::uint8_t { kRpdo, kTpdo };

/// A PDO's communication and mapping parameters.
struct PdoMap {
  PdoDir dir = PdoDir::kRpdo;
  std::uint8_t number = 1;          ///< 1..512 in CiA 301; canmotion uses 1..4
  std::uint32_t cob_id = 0;         ///< 11-bit CAN-ID (bit 31 = invalid)
  std::uint8_t transmission_type = kTransmissionSyncEvery;
  std::uint8_t count = 0;
  std::array<PdoEntry, kMaxPdoEntries> entries{};
  std::uint8_t size_bytes = 0;      ///< computed by finalize()

  /// Append an entry (set-up). False if full.
  constexpr bool add(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) noexcept {
    if (count == kMaxPdoEntries) return false;
    entries[count++] = PdoEntry{index, sub, bits, 0};
    return true;
  }
  /// Compute offsets and size; false when the mapping exceeds 64 bits.
  constexpr bool finalize() noexcept {
    unsigned off = 0;
    for (std::uint8_t i = 0; i < count; ++i) {
      entries[i].bit_offset = static_cast<std::uint8_t>(off);
      off += entries[i].bits;
    }
    if (off > 64) return false;
    size_bytes = static_cast<std::uint8_t>((off + 7) / 8);
    return true;
  }
  /// Index of the entry mapping index:sub, or -1.
  [[nodiscard]] constexpr int find(std::uint16_t index, std::uint8_t sub = 0) const noexcept {
    for (std::uint8_t i = 0; i < count; ++i)
      if (entries[i].index == index && entries[i].sub == sub) return i;
    return -1;
  }
  /// Communication parameter object (0x1400/0x1800 + number - 1).
  [[nodiscard]] constexpr std::uint16_t comm_index() const noexcept {
    return static_cast<std::uint16_t>((dir == PdoDir::kRpdo ? 0x1400 : 0x1800) + number - 1);
  }
  /// Mapping parameter object (0x1600/0x1A00 + number - 1).
  [[nodiscard]] constexpr std::uint16_t map_index() const noexcept {
    return static_cast<std::uint16_t>((dir == PdoDir::kRpdo ? 0x1600 : 0x1A00) + number - 1);
  }
};

/// Write `bits` of `value` little-endian at `bit_offset` (bit-exact, any
/// alignment). Realtime-safe.
constexpr void pack_bits(std::span<std::uint8_t> payload, unsigned bit_offset, unsigned bits, std::uint64_t value) noexcept {
  if ((bit_offset % 8) == 0 && (bits % 8) == 0) {  // byte-aligned fast path (all CiA 402 objects)
    for (unsigned i = 0; i < bits / 8 && bit_offset / 8 + i < payload.size(); ++i)
      payload[bit_offset / 8 + i] = static_cast<std::uint8_t>(value >> (8 * i));
    return;
  }
  for (unsigned i = 0; i < bits; ++i) {
    const unsigned b = bit_offset + i;
    if (b / 8 >= payload.size()) return;
    const auto mask = static_cast<std::uint8_t>(1u << (b % 8));
    if ((value >> i) & 1u) {
      payload[b / 8] = static_cast<std::uint8_t>(payload[b / 8] | mask);
    } else {
      payload[b / 8] = static_cast<std::uint8_t>(payload[b / 8] & ~mask);
    }
  }
}

/// Read `bits` little-endian at `bit_offset`, zero-extended. Realtime-safe.
[[nodiscard]] constexpr std::uint64_t unpack_bits(std::span<const std::uint8_t> payload, unsigned bit_offset,
                                                  unsigned bits) noexcept {
  if ((bit_offset % 8) == 0 && (bits % 8) == 0) {
    std::uint64_t v = 0;
    for (unsigned i = 0; i < bits / 8 && bit_offset / 8 + i < payload.size(); ++i)
      v |= static_cast<std::uint64_t>(payload[bit_offset / 8 + i]) << (8 * i);
    return v;
  }
  std::uint64_t v = 0;
  for (unsigned i = 0; i < bits; ++i) {
    const unsigned b = bit_offset + i;
    if (b / 8 >= payload.size()) break;
    if ((payload[b / 8] >> (b % 8)) & 1u) v |= std::uint64_t{1} << i;
  }
  return v;
}

/// Sign-extend a `bits`-wide value.
[[nodiscard]] constexpr std::int64_t sign_extend(std::uint64_t v, unsigned bits) noexcept {
  if (bits == 0 || bits >= 64) return static_cast<std::int64_t>(v);
  const std::uint64_t m = std::uint64_t{1} << (bits - 1);
  return static_cast<std::int64_t>((v ^ m) - m);
}

/// A PDO's packing plan, made once when its mapping is set (after
/// PdoMap::finalize()): a classic CAN PDO holds at most 64 bits, so its
/// payload is one little-endian 64-bit word and every entry a bit field of
/// it, `mask` wide at `shift`. Packing and unpacking are then a shift and a
/// mask per entry, whatever the alignment, and the frame's data is written
/// and read with one 8-byte store/load (payload_word / set_payload_word).
/// Same bytes as pack_bits/unpack_bits into/from a zeroed payload of
/// `size_bytes` (tests/fieldbus/test_pdo_plan.cpp checks it on random
/// mappings). One implementation serves the master's proxies (RPDO packing,
/// TPDO unpacking) and the emulated drives. Realtime-safe.
struct PdoPlan {
  std::uint8_t count = 0;
  std::uint8_t size_bytes = 0;
  std::array<std::uint8_t, kMaxPdoEntries> shift{};
  std::array<std::uint64_t, kMaxPdoEntries> mask{};  ///< 0 for a field outside the payload

  /// The plan of a finalized mapping: the bits of each entry that lie inside
  /// the `size_bytes` payload (as pack_bits/unpack_bits clip them).
  [[nodiscard]] static constexpr PdoPlan of(const PdoMap& m) noexcept {
    PdoPlan p;
    p.count = m.count;
    p.size_bytes = m.size_bytes;
    const unsigned limit = m.size_bytes >= 8 ? 64u : 8u * m.size_bytes;
    for (std::uint8_t i = 0; i < m.count; ++i) {
      const unsigned off = m.entries[i].bit_offset;
      if (off >= limit) continue;
      const unsigned width = m.entries[i].bits < limit - off ? m.entries[i].bits : limit - off;
      p.shift[i] = static_cast<std::uint8_t>(off);
      p.mask[i] = width >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << width) - 1;
    }
    return p;
  }
  /// Entry i of `word`, zero-extended.
  [[nodiscard]] constexpr std::uint64_t get(std::uint64_t word, std::size_t i) const noexcept {
    return (word >> shift[i]) & mask[i];
  }
  /// `word` with entry i (still zero in `word`) set to the low bits of `value`.
  [[nodiscard]] constexpr std::uint64_t put(std::uint64_t word, std::size_t i, std::uint64_t value) const noexcept {
    return word | ((value & mask[i]) << shift[i]);
  }
};

/// The 8 data bytes of `f` as a little-endian word (bytes past `len`
/// included: a plan's fields lie inside the mapped payload). Realtime-safe.
[[nodiscard]] inline std::uint64_t payload_word(const can::Frame& f) noexcept {
  static_assert(can::kMaxPayload == 8);
  std::uint64_t w;
  std::memcpy(&w, f.data.data(), sizeof w);
  if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
  return w;
}

/// Set all 8 data bytes of `f` from a little-endian word. Realtime-safe.
inline void set_payload_word(can::Frame& f, std::uint64_t w) noexcept {
  if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
  std::memcpy(f.data.data(), &w, sizeof w);
}

/// Queue the CiA 301 remapping procedure for `map` on `sdo` (set-up time):
/// COB-ID invalid (bit 31), mapping count 0, entries, count, transmission
/// type, COB-ID valid. Returns false if the SDO queue is full. `tag` is
/// given to every queued write.
bool queue_pdo_configuration(const PdoMap& map, SdoClient& sdo, std::uint32_t tag) noexcept;

/// Queue the writes that disable PDO `number` in direction `dir` (COB-ID
/// with bit 31 set) for the node of `sdo`.
bool queue_pdo_disable(PdoDir dir, std::uint8_t number, std::uint8_t node, SdoClient& sdo, std::uint32_t tag) noexcept;

}  // namespace canmotion::canopen
