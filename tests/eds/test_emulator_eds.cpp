// cia402-emu --eds (issue 17): the emulated drive serves exactly the object
// set of an EDS: absent objects abort 0x06020000 (0x06090011 for a missing
// sub-index), defaults ($NODEID resolved), access and PDO mapping flags from
// the file, PDOs the file lacks never valid.
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <utility>

#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/eds/eds.hpp"
#include "fieldbus/emulator/eds_dictionary.hpp"
#include "fieldbus/emulator/emulator.hpp"

using namespace canmotion;

namespace {

const std::string kDir = CANMOTION_EXAMPLES_DIR;

emulator::EmulatorConfig described(const eds::Eds& e, std::uint8_t node) {
  emulator::EmulatorConfig c;
  c.node = node;
  c.served = emulator::served_objects(e, node);
  return c;
}

canopen::SdoAbort write_u32(emulator::Emulator& emu, std::uint16_t index, std::uint8_t sub, std::uint32_t v) {
  const std::array<std::uint8_t, 4> b{static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
                                      static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)};
  return emu.sdo_write(index, sub, b);
}

canopen::SdoAbort read(emulator::Emulator& emu, std::uint16_t index, std::uint8_t sub, std::uint64_t* value = nullptr) {
  std::array<std::uint8_t, 8> b{};
  std::size_t len = 0;
  const canopen::SdoAbort a = emu.sdo_read(index, sub, b, len);
  if (value != nullptr) {
    *value = 0;
    for (std::size_t i = 0; i < len; ++i) *value |= static_cast<std::uint64_t>(b[i]) << (8 * i);
  }
  return a;
}

TEST(EmulatorEds, ServesExactlyTheMinimalDrivesObjects) {
  const eds::Eds e = eds::load(kDir + "/minimal-drive.eds");
  emulator::Emulator emu(described(e, 5));
  std::set<std::pair<int, int>> want, got;
  for (const eds::Object& o : e.objects)
    for (const eds::SubObject& s : o.subs) want.insert({o.index, s.sub});
  for (const auto& d : emu.dictionary()) got.insert({d.index, d.sub});
  EXPECT_EQ(got, want);
  // Absent objects and sub-indices abort as on a drive without them.
  EXPECT_EQ(read(emu, 0x1016, 1), canopen::SdoAbort::kNoObject);
  EXPECT_EQ(write_u32(emu, 0x1016, 1, (127u << 16) | 300), canopen::SdoAbort::kNoObject);
  EXPECT_EQ(write_u32(emu, 0x1402, 1, 0x80000000u | 0x405), canopen::SdoAbort::kNoObject);
  EXPECT_EQ(read(emu, 0x606C, 0), canopen::SdoAbort::kNoObject);
  EXPECT_EQ(read(emu, 0x1018, 5), canopen::SdoAbort::kNoSubindex);
  // Present ones answer, with the file's defaults ($NODEID+0x200 for node 5).
  std::uint64_t v = 0;
  EXPECT_EQ(read(emu, 0x1400, 1, &v), canopen::SdoAbort::kNone);
  EXPECT_EQ(v, 0x205u);
  EXPECT_EQ(read(emu, 0x6502, 0, &v), canopen::SdoAbort::kNone);
  EXPECT_EQ(v, e.find(0x6502, 0)->default_value->bits);
}

TEST(EmulatorEds, MappingFollowsTheFile) {
  const eds::Eds e = eds::load(kDir + "/minimal-drive.eds");
  emulator::Emulator emu(described(e, 2));
  // TPDO2 invalid, then map: 0x6064 (in the file, mappable) is accepted, 0x606C (not in the file) is not.
  ASSERT_EQ(write_u32(emu, 0x1801, 1, 0x80000000u | 0x282), canopen::SdoAbort::kNone);
  const std::array<std::uint8_t, 1> zero{0};
  ASSERT_EQ(emu.sdo_write(0x1A01, 0, zero), canopen::SdoAbort::kNone);
  EXPECT_EQ(write_u32(emu, 0x1A01, 1, 0x60640020u), canopen::SdoAbort::kNone);
  EXPECT_EQ(write_u32(emu, 0x1A01, 2, 0x606C0020u), canopen::SdoAbort::kNoObject);
  // 0x6040 is mappable into RPDOs only in the file: not into a TPDO.
  EXPECT_EQ(write_u32(emu, 0x1A01, 2, 0x60400010u), canopen::SdoAbort::kNotMappable);
}

TEST(EmulatorEds, TheEmulatorsOwnEdsChangesNothing) {
  // cia402-emu.eds describes the permissive dictionary (every object; the
  // strict profile hides the optional ones and adds 0x1029).
  const eds::Eds e = eds::load(kDir + "/cia402-emu.eds");
  emulator::EmulatorConfig permissive;
  permissive.behaviour = emulator::EmulatorBehaviour::permissive();
  emulator::Emulator own(permissive);
  emulator::EmulatorConfig from_file = described(e, permissive.node);
  from_file.behaviour = emulator::EmulatorBehaviour::permissive();
  emulator::Emulator desc(from_file);
  const auto a = own.dictionary();
  const auto b = desc.dictionary();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].index, b[i].index);
    EXPECT_EQ(a[i].sub, b[i].sub);
    EXPECT_EQ(a[i].access, b[i].access) << std::hex << a[i].index << ":" << int(a[i].sub);
    EXPECT_EQ(a[i].pdo, b[i].pdo) << std::hex << a[i].index << ":" << int(a[i].sub);
    EXPECT_EQ(a[i].default_value, b[i].default_value) << std::hex << a[i].index << ":" << int(a[i].sub);
  }
}

}  // namespace
