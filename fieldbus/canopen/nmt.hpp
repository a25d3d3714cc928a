#pragma once
/// \file
/// NMT command specifiers and NMT states (CiA 301 §7.2.8), with frame builders.
/// Everything here is constexpr and realtime-safe.

#include <cstdint>
#include <optional>
#include <string_view>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/cob_id.hpp"

namespace canmotion::canopen {

/// NMT command specifier, byte 0 of an NMT frame (ID 0x000, DLC 2: [cs, node]).
enum class NmtCommand : std::uint8_t {
  kStart = 0x01,                ///< start remote node -> Operational
  kStop = 0x02,                 ///< stop remote node -> Stopped
  kEnterPreOperational = 0x80,  ///< -> Pre-operational
  kResetNode = 0x81,            ///< reset application + communication
  kResetCommunication = 0x82,   ///< reset communication
};

/// NMT state as sent in byte 0 of a heartbeat (ID 0x700 + node, DLC 1).
enum class NmtState : std::uint8_t {
  kBootUp = 0x00,
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
  kUnknown = 0xFF,  ///< not a spec value: nothing heard yet / not a valid state byte
};

[[nodiscard]] constexpr std::string_view nmt_command_name(NmtCommand c) noexcept {
  switch (c) {
    case NmtCommand::kStart: return "start";
    case NmtCommand::kStop: return "stop";
    case NmtCommand::kEnterPreOperational: return "enter pre-operational";
    case NmtCommand::kResetNode: return "reset node";
    case NmtCommand::kResetCommunication: return "reset communication";
  }
  return "unknown";
}

/// Name of an NMT command byte, "unknown" if it is not a command specifier.
[[nodiscard]] constexpr std::string_view nmt_command_name(std::uint8_t cs) noexcept {
  switch (cs) {
    case 0x01: case 0x02: case 0x80: case 0x81: case 0x82:
      return nmt_command_name(static_cast<NmtCommand>(cs));
    default: return "unknown";
  }
}

[[nodiscard]] constexpr std::string_view nmt_state_name(NmtState s) noexcept {
  switch (s) {
    case NmtState::kBootUp: return "boot-up";
    case NmtState::kStopped: return "stopped";
    case NmtState::kOperational: return "operational";
    case NmtState::kPreOperational: return "pre-operational";
    case NmtState::kUnknown: break;
  }
  return "unknown";
}

/// Decode a heartbeat state byte (bit 7, the node-guarding toggle, is ignored).
[[nodiscard]] constexpr NmtState nmt_state_from_byte(std::uint8_t b) noexcept {
  switch (b & 0x7Fu) {
    case 0x00: return NmtState::kBootUp;
    case 0x04: return NmtState::kStopped;
    case 0x05: return NmtState::kOperational;
    case 0x7F: return NmtState::kPreOperational;
    default: return NmtState::kUnknown;
  }
}

/// NMT command frame: ID 0x000, [cs, node] (node 0 = all nodes).
[[nodiscard]] constexpr can::Frame make_nmt_frame(NmtCommand cs, std::uint8_t node) noexcept {
  can::Frame f;
  f.id = cob::kNmt;
  f.len = 2;
  f.data[0] = static_cast<std::uint8_t>(cs);
  f.data[1] = node;
  return f;
}

/// Heartbeat / boot-up frame: ID 0x700 + node, [state].
[[nodiscard]] constexpr can::Frame make_heartbeat_frame(std::uint8_t node, NmtState s) noexcept {
  can::Frame f;
  f.id = cob::heartbeat(node);
  f.len = 1;
  f.data[0] = static_cast<std::uint8_t>(s);
  return f;
}

/// A decoded NMT command frame.
struct NmtFrame {
  std::uint8_t command = 0;  ///< raw command specifier (see NmtCommand)
  std::uint8_t node = 0;     ///< 0 = all nodes
};

/// Decode an NMT command frame (ID 0x000, DLC 2); nullopt if it is not one.
[[nodiscard]] constexpr std::optional<NmtFrame> decode_nmt(const can::Frame& f) noexcept {
  if (f.id != cob::kNmt || f.extended() || f.remote() || f.len != 2) return std::nullopt;
  return NmtFrame{f.data[0], f.data[1]};
}

/// Node-guarding request (CiA 301 §7.2.8.3.2.1): a remote frame (RTR) on
/// ID 0x700 + node with DLC 1 and no data, sent by the master every guard time.
[[nodiscard]] constexpr can::Frame make_guard_request(std::uint8_t node) noexcept {
  can::Frame f;
  f.id = cob::heartbeat(node);
  f.len = 1;
  f.flags = can::kRemote;
  return f;
}

/// Node-guarding response: ID 0x700 + node, DLC 1, bit 7 the toggle bit, bits
/// 6..0 the NMT state. The toggle starts at 0 after boot-up / reset communication
/// and alternates with each response.
[[nodiscard]] constexpr can::Frame make_guard_response(std::uint8_t node, NmtState s, bool toggle) noexcept {
  can::Frame f = make_heartbeat_frame(node, s);
  if (toggle) f.data[0] = static_cast<std::uint8_t>(f.data[0] | 0x80U);
  return f;
}

/// What a node-guarding response says against the toggle the master expects.
enum class GuardAnswer : std::uint8_t {
  kOk,           ///< toggle as expected, a valid NMT state
  kToggleError,  ///< the toggle did not alternate (a lost or repeated answer)
  kBadState,     ///< bits 6..0 are not an NMT state (or boot-up: the node reset)
  kNotAnswer,    ///< not a guarding response (wrong ID, RTR, DLC != 1)
};

/// The master's side of one guarded node: expected toggle, last state.
/// Realtime-safe: plain value type, no allocation.
class GuardChecker {
 public:
  /// After boot-up / reset communication the node's next toggle is 0.
  constexpr void reset() noexcept { expect_toggle_ = false; state_ = NmtState::kUnknown; }

  /// Check one frame received on 0x700 + node as the answer to a guarding request.
  [[nodiscard]] constexpr GuardAnswer check(const can::Frame& f, std::uint8_t node) noexcept {
    if (f.id != cob::heartbeat(node) || f.extended() || f.remote() || f.len != 1) return GuardAnswer::kNotAnswer;
    const bool toggle = (f.data[0] & 0x80U) != 0;
    const NmtState s = nmt_state_from_byte(f.data[0]);
    if (s == NmtState::kUnknown || s == NmtState::kBootUp) return GuardAnswer::kBadState;
    if (toggle != expect_toggle_) return GuardAnswer::kToggleError;
    expect_toggle_ = !expect_toggle_;
    state_ = s;
    return GuardAnswer::kOk;
  }

  [[nodiscard]] constexpr NmtState state() const noexcept { return state_; }
  [[nodiscard]] constexpr bool expected_toggle() const noexcept { return expect_toggle_; }

 private:
  bool expect_toggle_ = false;
  NmtState state_ = NmtState::kUnknown;
};

}  // namespace canmotion::canopen
