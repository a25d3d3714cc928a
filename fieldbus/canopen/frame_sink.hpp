#pragma once
/// \file
/// Where the sans-IO protocol core puts the frames it wants sent.

#include "fieldbus/can/frame.hpp"
#include "fieldbus/can/transport.hpp"

namespace canmotion::canopen {

/// Receives the frames the protocol core emits. Implementations must be
/// realtime-safe when used from the cyclic path.
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  /// Send one frame; returns false if the frame could not be queued.
  virtual bool send(const can::Frame& f) noexcept = 0;
};

/// FrameSink that forwards to a Transport (SocketCanBus or a SimBus
/// endpoint) and counts rejected frames. Realtime-safe.
class TransportSink final : public FrameSink {
 public:
  explicit TransportSink(can::Transport& t) noexcept : t_(t) {}
  bool send(const can::Frame& f) noexcept override {
    const bool ok = t_.send(f) == can::SendResult::kOk;
    if (!ok) ++rejected_;
    return ok;
  }
  [[nodiscard]] std::uint64_t rejected() const noexcept { return rejected_; }

 private:
  can::Transport& t_;
  std::uint64_t rejected_ = 0;
};

}  // namespace canmotion::canopen
