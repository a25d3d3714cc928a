#pragma once
// Helpers shared by the fieldbus tests.
#include <cstdio>
#include <string>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/frame_sink.hpp"

namespace fbtest {

/// A FrameSink that records everything.
struct VecSink final : canmotion::canopen::FrameSink {
  std::vector<canmotion::can::Frame> frames;
  bool send(const canmotion::can::Frame& f) noexcept override {
    frames.push_back(f);
    return true;
  }
  void clear() { frames.clear(); }
};

/// "ID#HEX" in cansend notation (upper-case hex, 3-digit ID).
inline std::string hex(const canmotion::can::Frame& f) {
  char buf[64];
  int n = std::snprintf(buf, sizeof buf, "%03X#", f.id);
  for (std::size_t i = 0; i < f.len; ++i) n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "%02X", f.data[i]);
  return std::string(buf, static_cast<std::size_t>(n));
}

/// Parse "ID#HEX".
inline canmotion::can::Frame frame(const std::string& s) {
  canmotion::can::Frame f;
  const auto hash = s.find('#');
  f.id = static_cast<std::uint32_t>(std::stoul(s.substr(0, hash), nullptr, 16));
  const std::string d = s.substr(hash + 1);
  f.len = static_cast<std::uint8_t>(d.size() / 2);
  for (std::size_t i = 0; i < f.len; ++i) f.data[i] = static_cast<std::uint8_t>(std::stoul(d.substr(2 * i, 2), nullptr, 16));
  return f;
}

}  // namespace fbtest
