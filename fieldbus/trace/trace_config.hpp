#pragma once
/// \file
/// The part of a canmotion YAML configuration that cantrace uses: node ids,
/// axis names, position units and PDO layouts (`drives.pdo` / `axes[].drive.pdo`
/// profile, expanded by cia402::default_drive_pdos), the cycle period and the
/// bus bitrates. Deliberately lenient: unknown keys are ignored (the full
/// validation is canmotion::config's job); wrong types are errors.
/// Not realtime-safe.

#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/trace/decoder.hpp"

namespace canmotion::trace {

struct TraceConfig {
  struct Bus {
    std::string name;
    std::string interface;
    double bitrate = 0;
  };
  struct Node {
    std::string axis;       ///< axis name
    std::string interface;  ///< SocketCAN interface of its bus ("" if unknown)
    std::uint8_t node = 0;
    double counts_per_unit = 0;  ///< conversion_constant
    std::string unit;
    NodeLayouts layouts;
  };
  std::string path;
  std::int64_t period_ns = 0;  ///< controller.period_ms
  std::vector<Bus> buses;
  std::vector<Node> nodes;
};

/// Read `path`. Throws std::runtime_error with "file:line:column: key: message".
TraceConfig load_trace_config(const std::string& path);

/// Same, from YAML text (`name` stands for the file in messages).
TraceConfig parse_trace_config(const std::string& yaml, const std::string& name);

}  // namespace canmotion::trace
