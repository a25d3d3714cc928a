#include "fieldbus/emulator/sim_rig.hpp"

#include <array>
#include <string>

#include "fieldbus/canopen/cob_id.hpp"

namespace canmotion::emulator {

SimRig::SimRig(const SimRigConfig& cfg)
    : cfg_(cfg),
      bus_("sim0"),
      net_(cia402::NetworkConfig{cfg.master, cfg.tx_queue_frames, cfg.sync_first}),
      master_ep_(&bus_.add_endpoint("master")) {
  for (std::uint8_t node : cfg_.nodes) {
    cia402::DriveConfig d = cfg_.drive;
    d.node = node;
    d.cycle_ns = cfg_.cycle_ns;
    net_.add_drive(d);
    EmulatorConfig e = cfg_.emulator;
    e.node = node;
    emus_.push_back(std::make_unique<Emulator>(e));
    emu_eps_.push_back(&bus_.add_endpoint("drive" + std::to_string(node)));
    connected_.push_back(true);
  }
}

Emulator& SimRig::emulator(std::uint8_t node) noexcept {
  for (auto& e : emus_)
    if (e->node() == node) return *e;
  return *emus_.front();
}

void SimRig::disconnect(std::uint8_t node) noexcept {
  for (std::size_t i = 0; i < emus_.size(); ++i)
    if (emus_[i]->node() == node) connected_[i] = false;
}

void SimRig::power_on() {
  for (std::size_t i = 0; i < emus_.size(); ++i) {
    canopen::TransportSink sink(*emu_eps_[i]);
    emus_[i]->power_on(now_ns_, sink);
  }
}

void SimRig::step() {
  now_ns_ = static_cast<std::int64_t>(cycles_) * cfg_.cycle_ns;
  bus_.set_time(now_ns_);
  // The master's interface queue (tx_queue_depth frames per cycle).
  struct Queue final : canopen::FrameSink {
    can::Transport& t;
    std::uint32_t depth;
    std::uint32_t used = 0;
    std::uint64_t& refused;
    std::uint64_t& syncs;
    Queue(can::Transport& tr, std::uint32_t d, std::uint64_t& r, std::uint64_t& s) : t(tr), depth(d), refused(r), syncs(s) {}
    bool send(const can::Frame& f) noexcept override {
      if (depth != 0 && used >= depth) {
        ++refused;
        if (f.id == canopen::cob::kSync) ++syncs;
        return false;
      }
      ++used;
      return t.send(f) == can::SendResult::kOk;
    }
  } sink(*master_ep_, cfg_.tx_queue_depth, tx_refused_, syncs_refused_);
  net_.sync(sink);  // sync_first only
  std::array<can::TimedFrame, 256> buf;
  for (;;) {
    const std::size_t n = master_ep_->receive(buf);
    for (std::size_t i = 0; i < n; ++i) net_.on_frame(buf[i]);
    if (n < buf.size()) break;
  }
  net_.cycle(now_ns_, sink);
  for (std::size_t i = 0; i < emus_.size(); ++i) {
    if (!connected_[i]) {
      // A dead node: drop whatever reached it.
      while (emu_eps_[i]->receive(buf) > 0) {
      }
      continue;
    }
    emus_[i]->service(*emu_eps_[i], now_ns_);
  }
  ++cycles_;
}

bool SimRig::run_until(const std::function<bool()>& done, std::uint64_t max_cycles) {
  for (std::uint64_t i = 0; i < max_cycles; ++i) {
    if (done()) return true;
    step();
  }
  return done();
}

}  // namespace canmotion::emulator
