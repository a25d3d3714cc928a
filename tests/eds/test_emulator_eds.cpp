// cia402-emu --eds (issue 17): the emulated drive serves exactly the object
// set of an EDS: absent objects abort 0x06020000 (0x06090011 for a missing
// sub-index), defaults ($NODEID resolved), access and PDO mapping flags from
// the file, PDOs the file lacks never valid.
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <set>
#include <utility>
#include <vector>

#include "fieldbus/can/sim_bus.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/eds/eds.hpp"
#include "fieldbus/emulator/eds_dictionary.hpp"
#include "fieldbus/emulator/emulator.hpp"

using namespace canmotion;

namespace {

const std::string kDir = CANMOTION_EXAMPLES_DIR;
const std::string kPeersDir = CANMOTION_PEERS_DIR;

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

/// A master made of raw frames (CiA 301 layouts written out here) and one
/// emulated drive on a SimBus, 1 ms per tick of the virtual clock. Nothing
/// sends a SYNC unless a test does (as a master that sets the drive up
/// before it starts its SYNC producer, e.g. python-canopen).
struct EdsDriveOnBus {
  explicit EdsDriveOnBus(const emulator::EmulatorConfig& c)
      : emu(c), master(bus.add_endpoint("master")), drive(bus.add_endpoint("drive")) {
    canopen::TransportSink sink(drive);
    emu.power_on(t, sink);
  }
  std::uint8_t node() const { return emu.node(); }
  void send(std::uint32_t id, std::vector<std::uint8_t> data) {
    can::Frame f;
    f.id = id;
    f.len = static_cast<std::uint8_t>(data.size());
    std::copy(data.begin(), data.end(), f.data.begin());
    master.send(f);
  }
  /// One millisecond: the drive handles what it got, the master collects the replies.
  void tick() {
    t += 1'000'000;
    bus.set_time(t);
    emu.service(drive, t);
    std::array<can::TimedFrame, 64> buf{};
    for (std::size_t n = master.receive(buf); n > 0; n = master.receive(buf))
      for (std::size_t i = 0; i < n; ++i) {
        received.push_back(buf[i].frame);
        if (buf[i].frame.id == 0x80u + node()) ++emcys;
      }
  }
  /// An expedited SDO request; the abort code of the reply (0: done), the
  /// value read in `value`.
  std::uint32_t sdo(std::uint8_t cmd, std::uint16_t index, std::uint8_t sub, std::uint32_t v, std::uint32_t* value = nullptr) {
    received.clear();
    send(0x600u + node(), {cmd, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), sub,
                           static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v >> 16),
                           static_cast<std::uint8_t>(v >> 24)});
    for (int i = 0; i < 10; ++i) {
      tick();
      for (const can::Frame& f : received) {
        if (f.id != 0x580u + node()) continue;
        const auto data = static_cast<std::uint32_t>(f.data[4] | f.data[5] << 8 | f.data[6] << 16 | f.data[7] << 24);
        if (value != nullptr) *value = data;
        return f.data[0] == 0x80 ? data : 0;
      }
    }
    ADD_FAILURE() << "no SDO reply";
    return ~0u;
  }
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t v, std::uint8_t size) {
    return sdo(static_cast<std::uint8_t>(0x23 | ((4 - size) << 2)), index, sub, v);
  }
  std::uint32_t read(std::uint16_t index, std::uint8_t sub, std::uint32_t& v) { return sdo(0x40, index, sub, 0, &v); }
  /// The CiA 301 re-mapping procedure for PDO 1 (rx: RPDO1), transmission type 1.
  void map_pdo1(bool rx, std::uint32_t e1, std::uint32_t e2) {
    const std::uint16_t comm = rx ? 0x1400 : 0x1800;
    const std::uint32_t cob = (rx ? 0x200u : 0x180u) + node();
    EXPECT_EQ(write(comm, 1, cob | 0x80000000u, 4), 0u);
    EXPECT_EQ(write(comm + 0x200, 0, 0, 1), 0u);
    EXPECT_EQ(write(comm + 0x200, 1, e1, 4), 0u);
    EXPECT_EQ(write(comm + 0x200, 2, e2, 4), 0u);
    EXPECT_EQ(write(comm + 0x200, 0, 2, 1), 0u);
    EXPECT_EQ(write(comm, 2, 1, 1), 0u);
    EXPECT_EQ(write(comm, 1, cob, 4), 0u);
  }
  /// One CSP cycle: RPDO1 (controlword, target), SYNC; TPDO1's statusword and position.
  void cycle(std::uint16_t cw, std::int32_t target) {
    const auto tp = static_cast<std::uint32_t>(target);
    received.clear();
    send(0x200u + node(), {static_cast<std::uint8_t>(cw), static_cast<std::uint8_t>(cw >> 8), static_cast<std::uint8_t>(tp),
                           static_cast<std::uint8_t>(tp >> 8), static_cast<std::uint8_t>(tp >> 16),
                           static_cast<std::uint8_t>(tp >> 24)});
    send(0x080, {});
    tick();
    for (const can::Frame& f : received)
      if (f.id == 0x180u + node() && f.len == 6) {
        statusword = static_cast<std::uint16_t>(f.data[0] | f.data[1] << 8);
        position = static_cast<std::int32_t>(f.data[2] | f.data[3] << 8 | f.data[4] << 16 | static_cast<std::uint32_t>(f.data[5]) << 24);
      }
  }

  std::int64_t t = 0;
  can::SimBus bus;
  emulator::Emulator emu;
  can::SimBus::Endpoint& master;
  can::SimBus::Endpoint& drive;
  std::vector<can::Frame> received;
  int emcys = 0;
  std::uint16_t statusword = 0;
  std::int32_t position = 0;
};

// Issue 26 item 3: a CSP drive's EDS (0x6502 = 0x80, 0x6060 rw / 0x6061 ro,
// both 0 at power-on) served by the strict emulator. The master sets the
// mode over SDO in pre-operational before any SYNC and reads 0x6061 back (as
// python-canopen's op_mode does), then maps its PDOs, enables and moves. The
// old emulator showed a new mode in 0x6061 only at SYNCs, so 0x6061 read 0,
// and checked modes against its own list instead of the file's 0x6502.
TEST(EmulatorEds, ModeSetOverSdoIsShownAndCspFollowed) {
  const eds::Eds e = eds::load(kPeersDir + "/csp-drive.eds");
  EdsDriveOnBus d(described(e, 2));
  for (int i = 0; i < 150; ++i) d.tick();  // boot (strict: 100 ms in Not ready to switch on)
  std::uint32_t v = 0;
  ASSERT_EQ(d.read(0x6061, 0, v), 0u);
  EXPECT_EQ(v, 0u) << "no mode at power-on (the file's default)";
  ASSERT_EQ(d.write(0x6060, 0, 8, 1), 0u);
  ASSERT_EQ(d.read(0x6061, 0, v), 0u);
  EXPECT_EQ(v, 8u) << "0x6061 shows the mode written over SDO (no SYNC yet)";
  EXPECT_EQ(d.write(0x6060, 0, 9, 1), 0x06090030u) << "CSV is not in the file's 0x6502 (0x80)";
  ASSERT_EQ(d.read(0x6061, 0, v), 0u);
  EXPECT_EQ(v, 8u);
  d.map_pdo1(true, 0x60400010, 0x607A0020);
  d.map_pdo1(false, 0x60410010, 0x60640020);
  d.send(0x000, {0x01, d.node()});  // NMT start
  d.tick();
  int cycles = 0;
  for (; cycles < 20 && (d.statusword & 0x6F) != 0x21; ++cycles) d.cycle(0x0006, 0);  // 2: Ready to switch on
  for (; cycles < 40 && (d.statusword & 0x6F) != 0x27; ++cycles) d.cycle(0x000F, 0);  // 3, 4: Operation enabled
  ASSERT_EQ(d.statusword & 0x6F, 0x27) << "not enabled after " << cycles << " cycles";
  EXPECT_NE(d.statusword & 0x1000, 0) << "CSP: drive follows the command value (bit 12)";
  // A move of 40000 counts over 400 cycles, then 20 cycles at rest.
  int worst = 0;
  for (int k = 1; k <= 420; ++k) {
    const std::int32_t target = 100 * std::min(k, 400);
    d.cycle(0x000F, target);
    worst = std::max(worst, std::abs(target - d.position));
  }
  EXPECT_EQ(d.position, 40000);
  EXPECT_LE(worst, 1000) << "following error of more than 10 cycles' travel";
  EXPECT_EQ(d.statusword & 0x6F, 0x27);
  EXPECT_EQ(d.emcys, 0);
}

}  // namespace
