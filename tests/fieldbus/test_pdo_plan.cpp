// PdoPlan (fieldbus/canopen/pdo.hpp): the packing plan made once per PDO
// mapping must give exactly the bytes of pack_bits into a zeroed payload of
// the mapping's size, and read back what unpack_bits reads, for any mapping
// (byte-aligned CiA 402 objects and arbitrary bit fields). Seeded random
// mappings; the seed is printed on failure (CANMOTION_SEED /
// CANMOTION_COUNT override seed and count, tests/support/random_seed.hpp).
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"
#include "tests/support/random_seed.hpp"

using namespace canmotion;

namespace {
/// A random finalized mapping of 1..8 entries, 1..64 bits in all; with
/// `byte_aligned` only 8/16/24/32-bit entries (as the CiA 402 objects are).
canopen::PdoMap random_map(std::mt19937_64& rng, bool byte_aligned) {
  canopen::PdoMap m;
  const int n = std::uniform_int_distribution<int>(1, 8)(rng);
  unsigned total = 0;
  for (int i = 0; i < n; ++i) {
    unsigned bits = byte_aligned ? 8u * std::uniform_int_distribution<unsigned>(1, 4)(rng)
                                 : std::uniform_int_distribution<unsigned>(1, 32)(rng);
    if (total + bits > 64) bits = 64 - total;
    if (bits == 0) break;
    m.add(static_cast<std::uint16_t>(0x6000 + i), 0, static_cast<std::uint8_t>(bits));
    total += bits;
  }
  EXPECT_TRUE(m.finalize());
  return m;
}

/// The frame pack_bits builds (payload of size_bytes, zeroed first).
can::Frame reference_pack(const canopen::PdoMap& m, const std::array<std::uint64_t, 8>& v) {
  can::Frame f;
  f.len = m.size_bytes;
  for (std::uint8_t i = 0; i < m.count; ++i)
    canopen::pack_bits(std::span<std::uint8_t>(f.data.data(), f.len), m.entries[i].bit_offset, m.entries[i].bits, v[i]);
  return f;
}

can::Frame plan_pack(const canopen::PdoPlan& plan, const std::array<std::uint64_t, 8>& v) {
  can::Frame f;
  f.len = plan.size_bytes;
  std::uint64_t w = 0;
  for (std::uint8_t i = 0; i < plan.count; ++i) w = plan.put(w, i, v[i]);
  canopen::set_payload_word(f, w);
  return f;
}
}  // namespace

TEST(PdoPlan, GoldenBytesAgainstPackBitsOnRandomMappings) {
  const std::uint64_t seed = canmotion::test::test_seed(402);
  const std::uint64_t count = canmotion::test::test_count(20000);
  std::mt19937_64 rng(seed);
  for (std::uint64_t k = 0; k < count; ++k) {
    const bool aligned = (k & 1) == 0;
    const canopen::PdoMap m = random_map(rng, aligned);
    const canopen::PdoPlan plan = canopen::PdoPlan::of(m);
    std::array<std::uint64_t, 8> v{};
    for (auto& x : v) x = rng();  // wider than the fields: both must cut them to the entry width
    const can::Frame ref = reference_pack(m, v);
    const can::Frame got = plan_pack(plan, v);
    ASSERT_EQ(got.len, ref.len) << canmotion::test::seed_note(seed) << " k " << k;
    // All 8 data bytes: the plan writes zeros past the payload, as the zeroed frame has.
    ASSERT_EQ(got.data, ref.data) << canmotion::test::seed_note(seed) << " k " << k << " aligned " << aligned;
    // Unpacking: the plan reads what unpack_bits reads, from a frame whose
    // bytes past the payload hold garbage (a received frame may).
    can::Frame rx = ref;
    for (std::size_t b = rx.len; b < rx.data.size(); ++b) rx.data[b] = static_cast<std::uint8_t>(rng());
    const std::uint64_t w = canopen::payload_word(rx);
    for (std::uint8_t i = 0; i < m.count; ++i) {
      ASSERT_EQ(plan.get(w, i), canopen::unpack_bits(rx.payload(), m.entries[i].bit_offset, m.entries[i].bits))
          << canmotion::test::seed_note(seed) << " k " << k << " entry " << int{i};
    }
  }
}

TEST(PdoPlan, CiA402DefaultMappingsGoldenBytes) {
  // RPDO1 of the CSP profile: controlword 0x000F, target position -2 (0xFFFFFFFE).
  const cia402::DrivePdoSet s = cia402::default_drive_pdos(cia402::PdoProfile::kCspCsvCst, 2);
  const canopen::PdoPlan r1 = canopen::PdoPlan::of(s.rpdo[0]);
  ASSERT_EQ(r1.count, 2);
  std::array<std::uint64_t, 8> v{0x000F, 0xFFFFFFFEu};
  EXPECT_EQ(plan_pack(r1, v).data, (std::array<std::uint8_t, 8>{0x0F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF, 0, 0}));
  // RPDO2: target velocity 0x01020304, torque 0x0506, mode 9.
  const canopen::PdoPlan r2 = canopen::PdoPlan::of(s.rpdo[1]);
  ASSERT_EQ(r2.count, 3);
  v = {0x01020304u, 0x0506u, 9};
  EXPECT_EQ(plan_pack(r2, v).data, (std::array<std::uint8_t, 8>{0x04, 0x03, 0x02, 0x01, 0x06, 0x05, 0x09, 0}));
  EXPECT_EQ(r2.size_bytes, 7);
  // Reading TPDO1 back: statusword, position actual.
  const canopen::PdoPlan t1 = canopen::PdoPlan::of(s.tpdo[0]);
  can::Frame f{0x182, {0x37, 0x12, 0x78, 0x56, 0x34, 0x12}};
  const std::uint64_t w = canopen::payload_word(f);
  EXPECT_EQ(t1.get(w, 0), 0x1237u);
  EXPECT_EQ(t1.get(w, 1), 0x12345678u);
}

TEST(PdoPlan, FieldsOutsideThePayloadAreDropped) {
  // A mapping whose size_bytes is smaller than its entries (not finalized
  // again after an add): pack_bits stops at the payload's end, so does the plan.
  canopen::PdoMap m;
  m.add(0x6040, 0, 16);
  ASSERT_TRUE(m.finalize());
  m.add(0x607A, 0, 32);  // offset 0 (not finalized), size_bytes still 2
  m.entries[1].bit_offset = 8;
  const canopen::PdoPlan plan = canopen::PdoPlan::of(m);
  const std::array<std::uint64_t, 8> v{0, 0xAABBCCDDu};
  EXPECT_EQ(plan_pack(plan, v).data, reference_pack(m, v).data);
  EXPECT_EQ(plan_pack(plan, v).data, (std::array<std::uint8_t, 8>{0x00, 0xDD, 0, 0, 0, 0, 0, 0}));
}
