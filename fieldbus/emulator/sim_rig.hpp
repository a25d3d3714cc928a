#pragma once
/// \file
/// SimRig: a master (DriveNetwork) and emulated CiA 402 drives on one SimBus
/// with a virtual clock. Deterministic: the same configuration gives the same
/// frames, bit for bit. Used by the loop tests and tools/fieldbus-demo; the
/// runtime's --sim mode can use the same pieces (SimBus endpoint + Emulator).
///
/// One step() is one cycle at t = cycle_index x period:
///   0. (SimRigConfig::sync_first) DriveNetwork::sync sends the SYNC;
///   1. the master endpoint drains its frames into DriveNetwork::on_frame;
///   2. DriveNetwork::cycle sends the RPDOs, then SYNC (not with sync_first),
///      then SDO and heartbeat;
///   3. each emulator handles what it received (RPDOs latch, SYNC applies
///      them, moves the motor and sends the TPDOs) and its timers.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "fieldbus/can/sim_bus.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/emulator.hpp"

namespace canmotion::emulator {

struct SimRigConfig {
  std::int64_t cycle_ns = 1'000'000;
  std::vector<std::uint8_t> nodes = {2, 3, 4};
  /// Template; `node` is set per drive. Behaviour: EmulatorBehaviour::strict()
  /// (the default); a test may choose permissive() or single flags.
  EmulatorConfig emulator{};
  cia402::DriveConfig drive{};    ///< template; `node` and `cycle_ns` are set per drive
  canopen::MasterConfig master{};
  /// The master's interface queues this many frames per cycle (txqueuelen,
  /// emptied between cycles); more are refused like ENOBUFS. 0 = no limit.
  std::uint32_t tx_queue_depth = 0;
  /// NetworkConfig::tx_queue_frames of the master (0 = no limit).
  std::uint32_t tx_queue_frames = 0;
  /// NetworkConfig::sync_first: step() sends the SYNC before it drains the
  /// master's frames, and cycle() the RPDOs after.
  bool sync_first = false;
};

class SimRig {
 public:
  explicit SimRig(const SimRigConfig& cfg);

  /// Power the emulated drives on (boot-up messages at the present time).
  void power_on();
  /// Advance one cycle (see the file comment).
  void step();
  /// Step until `done()` or `max_cycles`; returns true if done() became true.
  bool run_until(const std::function<bool()>& done, std::uint64_t max_cycles);

  [[nodiscard]] can::SimBus& bus() noexcept { return bus_; }
  [[nodiscard]] cia402::DriveNetwork& network() noexcept { return net_; }
  [[nodiscard]] cia402::DriveProxy& drive(std::uint8_t node) noexcept { return *net_.drive(node); }
  [[nodiscard]] Emulator& emulator(std::uint8_t node) noexcept;
  [[nodiscard]] std::vector<std::unique_ptr<Emulator>>& emulators() noexcept { return emus_; }
  [[nodiscard]] std::int64_t now_ns() const noexcept { return now_ns_; }
  [[nodiscard]] std::uint64_t cycles() const noexcept { return cycles_; }
  [[nodiscard]] can::Transport& master_endpoint() noexcept { return *master_ep_; }
  /// Frames the master's queue refused (SimRigConfig::tx_queue_depth), and SYNCs among them.
  [[nodiscard]] std::uint64_t tx_refused() const noexcept { return tx_refused_; }
  [[nodiscard]] std::uint64_t syncs_refused() const noexcept { return syncs_refused_; }
  /// Detach an emulator from the bus (simulates a dead node: it neither
  /// receives nor sends any more).
  void disconnect(std::uint8_t node) noexcept;
 private:
  std::uint64_t tx_refused_ = 0;
  std::uint64_t syncs_refused_ = 0;
 public:

 private:
  SimRigConfig cfg_;
  can::SimBus bus_;
  cia402::DriveNetwork net_;
  can::SimBus::Endpoint* master_ep_;
  std::vector<std::unique_ptr<Emulator>> emus_;
  std::vector<can::SimBus::Endpoint*> emu_eps_;
  std::vector<bool> connected_;
  std::int64_t now_ns_ = 0;
  std::uint64_t cycles_ = 0;
};

}  // namespace canmotion::emulator
