#pragma once
/// \file
/// SimWorld: the in-process stand-in for the hardware in `--sim` runs and
/// loop tests. One SimBus per configured bus, with one endpoint for the
/// controller and one emulated CiA 402 drive (fieldbus/emulator) per
/// AXIS_CIP_DRIVE node. Time is virtual; the emulators advance only on SYNC.
///
/// Per cycle at time t (same order as emulator::SimRig):
///   begin_cycle(t)     the buses' clocks move to t (delayed frames are delivered)
///   Controller::cycle  drains, plans, sends RPDOs + SYNC on the controller endpoints
///   end_cycle(t)       each emulator handles its frames: RPDOs latch, SYNC moves
///                      the motor and sends TPDOs, which the controller reads next cycle
///
/// Set-up functions allocate; begin_cycle/end_cycle are realtime-safe.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fieldbus/can/sim_bus.hpp"
#include "fieldbus/emulator/emulator.hpp"

namespace canmotion::rt {

class SimWorld {
 public:
  /// Add a bus; returns the endpoint the controller uses (valid for the
  /// SimWorld's lifetime).
  can::Transport& add_bus(const std::string& name);
  /// Attach an emulated drive to bus `bus` (index in add order).
  emulator::Emulator& add_drive(std::size_t bus, const emulator::EmulatorConfig& cfg);
  /// Power every drive on (boot-up messages) at `now_ns`.
  void power_on(std::int64_t now_ns);

  /// Realtime-safe.
  void begin_cycle(std::int64_t now_ns) noexcept;
  /// Realtime-safe.
  void end_cycle(std::int64_t now_ns) noexcept;

  [[nodiscard]] std::size_t bus_count() const noexcept { return buses_.size(); }
  [[nodiscard]] can::SimBus& bus(std::size_t i) noexcept { return *buses_[i].bus; }
  [[nodiscard]] std::size_t drive_count() const noexcept { return drives_.size(); }
  [[nodiscard]] emulator::Emulator& drive(std::size_t i) noexcept { return *drives_[i].emu; }
  /// The bus (index in add order) drive `i` is attached to.
  [[nodiscard]] std::size_t drive_bus(std::size_t i) const noexcept { return drives_[i].bus; }
  /// The emulator of `node` on `bus`, or nullptr.
  [[nodiscard]] emulator::Emulator* find_drive(std::size_t bus, std::uint8_t node) noexcept;
  /// Detach a drive (a dead node: it neither receives nor sends any more).
  void disconnect(std::size_t drive) noexcept { drives_[drive].connected = false; }
  /// Reattach a detached drive and power it on again at `now_ns` (a drive
  /// killed and restarted, or power-cycled): dictionary defaults, boot-up
  /// message, NMT pre-operational. Not realtime (tests and tools).
  void power_cycle(std::size_t drive, std::int64_t now_ns);

 private:
  struct Bus {
    std::unique_ptr<can::SimBus> bus;
    can::SimBus::Endpoint* controller = nullptr;
  };
  struct Drive {
    std::size_t bus = 0;
    std::unique_ptr<emulator::Emulator> emu;
    can::SimBus::Endpoint* ep = nullptr;
    bool connected = true;
    bool filtered = false;         ///< ep's acceptance filter is set ...
    std::uint64_t accept_gen = 0;  ///< ... from this emu->accept_generation()
  };
  /// Set the drive endpoint's acceptance filter to the identifiers its
  /// emulator acts on, when they changed: the drive is not handed the other
  /// nodes' PDOs that it would only drop. Realtime-safe.
  static void refresh_filter(Drive& d) noexcept;
  std::vector<Bus> buses_;
  std::vector<Drive> drives_;
};

}  // namespace canmotion::rt
