#include "rt/controller/sim_world.hpp"

#include <array>

#include "fieldbus/canopen/frame_sink.hpp"

namespace canmotion::rt {

can::Transport& SimWorld::add_bus(const std::string& name) {
  Bus b;
  b.bus = std::make_unique<can::SimBus>(name);
  b.controller = &b.bus->add_endpoint("controller");
  buses_.push_back(std::move(b));
  return *buses_.back().controller;
}

emulator::Emulator& SimWorld::add_drive(std::size_t bus, const emulator::EmulatorConfig& cfg) {
  Drive d;
  d.bus = bus;
  d.emu = std::make_unique<emulator::Emulator>(cfg);
  d.ep = &buses_.at(bus).bus->add_endpoint("node" + std::to_string(cfg.node));
  drives_.push_back(std::move(d));
  refresh_filter(drives_.back());
  return *drives_.back().emu;
}

void SimWorld::refresh_filter(Drive& d) noexcept {
  const std::uint64_t gen = d.emu->accept_generation();
  if (d.filtered && gen == d.accept_gen) return;
  can::SimBus::Endpoint::IdSet ids, openers;
  d.emu->accepted_ids(ids, openers);
  d.ep->set_accept(ids, openers);
  d.filtered = true;
  d.accept_gen = gen;
}

emulator::Emulator* SimWorld::find_drive(std::size_t bus, std::uint8_t node) noexcept {
  for (auto& d : drives_)
    if (d.bus == bus && d.emu->node() == node) return d.emu.get();
  return nullptr;
}

void SimWorld::power_on(std::int64_t now_ns) {
  begin_cycle(now_ns);
  for (auto& d : drives_) {
    canopen::TransportSink sink(*d.ep);
    d.emu->power_on(now_ns, sink);
    refresh_filter(d);
  }
}

void SimWorld::power_cycle(std::size_t drive, std::int64_t now_ns) {
  Drive& d = drives_.at(drive);
  d.connected = true;
  canopen::TransportSink sink(*d.ep);
  d.emu->power_on(now_ns, sink);
  refresh_filter(d);
}

void SimWorld::begin_cycle(std::int64_t now_ns) noexcept {
  for (auto& b : buses_) b.bus->set_time(now_ns);
  for (auto& d : drives_) refresh_filter(d);  // e.g. after a test wrote to a drive directly
}

void SimWorld::end_cycle(std::int64_t now_ns) noexcept {
  for (auto& d : drives_) {
    if (!d.connected) {  // a dead node: drop whatever reached it
      std::array<can::TimedFrame, 64> sink;
      while (d.ep->receive(sink) > 0) {
      }
      continue;
    }
    d.emu->service(*d.ep, now_ns);
    refresh_filter(d);  // before the next drive's frames reach this one
  }
}

}  // namespace canmotion::rt
