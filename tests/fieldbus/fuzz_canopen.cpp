// libFuzzer target: arbitrary frames into an emulated drive and a master
// (DriveNetwork) that talk to each other. Looks for crashes, UB and broken
// invariants in the SDO server/client, NMT, PDO and state machine handling.
// Input: records of [id lo, id hi (3 bits) | flags, len, data...].
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/emulator.hpp"

using namespace canmotion;

namespace {
struct VecSink final : canopen::FrameSink {
  std::vector<can::Frame> frames;
  bool send(const can::Frame& f) noexcept override {
    frames.push_back(f);
    return true;
  }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  emulator::EmulatorConfig ec;
  ec.node = 2;
  emulator::Emulator emu(ec);
  cia402::DriveNetwork net;
  cia402::DriveConfig dc;
  dc.node = 2;
  dc.pdo_profile = (size > 0 && (data[0] & 1)) ? cia402::PdoProfile::kCspCsvCst : cia402::PdoProfile::kCsp;
  auto& d = net.add_drive(dc);
  d.enable();
  VecSink to_master, to_drive;
  std::int64_t t = 0;
  emu.power_on(t, to_master);
  std::size_t i = 1;
  while (i + 3 <= size) {
    can::Frame f;
    f.id = static_cast<std::uint32_t>(data[i] | ((data[i + 1] & 0x07) << 8));
    f.flags = static_cast<std::uint8_t>((data[i + 1] >> 3) & can::kRemote);
    f.len = static_cast<std::uint8_t>(data[i + 2] % 9);
    i += 3;
    for (std::size_t k = 0; k < f.len; ++k) f.data[k] = i < size ? data[i++] : 0;
    t += 1'000'000;
    // The fuzzed frame reaches both sides, then one cycle of real exchange.
    emu.set_time(t);
    emu.on_frame(can::TimedFrame{f, t}, to_master);
    net.on_frame(can::TimedFrame{f, t});
    for (const auto& m : to_master.frames) net.on_frame(can::TimedFrame{m, t});
    to_master.frames.clear();
    net.cycle(t, to_drive);
    for (const auto& m : to_drive.frames) emu.on_frame(can::TimedFrame{m, t}, to_master);
    to_drive.frames.clear();
    emu.step(t, to_master);
    if (static_cast<unsigned>(emu.state()) > 8 || static_cast<unsigned>(d.state()) > 8) std::abort();
    if (d.feedback().tpdo_missed > d.feedback().tpdo_count + static_cast<std::uint64_t>(t / 1'000'000)) std::abort();
  }
  return 0;
}
