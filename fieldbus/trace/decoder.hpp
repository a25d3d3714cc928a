#pragma once
/// \file
/// Stateful decoder of CANopen / CiA 402 traffic, frame by frame.
///
/// The decoder keeps bounded per-node state only (PDO layouts, one SDO
/// transfer, the last controlword/statusword): memory does not grow with the
/// length of the trace. decode() never allocates and never throws.
///
/// PDO layouts are taken, in this order:
///   1. from a canmotion configuration (set_config_layout());
///   2. from SDO writes to the PDO mapping / communication objects seen
///      earlier in the trace (0x1400.., 0x1600.., 0x1800.., 0x1A00..);
///   3. the default CiA 402 CSP mapping: RPDO1 = controlword (u16) + target
///      position (i32); TPDO1 = statusword (u16) + position actual value (i32).

#include <array>
#include <cstdint>

#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/trace/decoded.hpp"
#include "fieldbus/trace/sdo_transfer.hpp"

namespace canmotion::trace {

/// PDO layouts of one node as configured (e.g. from a canmotion YAML file).
struct NodeLayouts {
  std::array<PdoLayout, kPdosPerDirection> rpdo{};
  std::array<bool, kPdosPerDirection> rpdo_set{};
  std::array<PdoLayout, kPdosPerDirection> tpdo{};
  std::array<bool, kPdosPerDirection> tpdo_set{};
};

/// Frame-by-frame decoder with bounded per-node state.
class Decoder {
 public:
  Decoder() noexcept;

  /// Use `layout` for PDO `number` (1..4) of `node` (1..127), direction
  /// `tx` (TPDO) or RPDO; it overrides mappings seen in the trace. Returns
  /// false if an argument is out of range. Not for the cyclic path (cheap,
  /// but meant for start-up).
  bool set_config_layout(std::uint8_t node, bool tx, std::uint8_t number, const PdoLayout& layout) noexcept;

  /// Decode one frame and update the decoder state. Never allocates, never
  /// throws. The result's views stay valid until the next call.
  const Decoded& decode(const can::TimedFrame& tf) noexcept;

  /// Record an error frame reported by a transport as a BusEvent (live
  /// capture: SocketCanBus delivers error frames as events, not frames).
  const Decoded& decode_error(std::uint32_t err_class, std::int64_t t_ns) noexcept;

  /// The layout currently used for a PDO, and where it came from.
  [[nodiscard]] LayoutSource layout_of(std::uint8_t node, bool tx, std::uint8_t number, PdoLayout& out) const noexcept;

  /// TPDO transmission type from 0x1800+n sub 2 writes (255 if never written,
  /// which CiA 402 drives commonly default to synchronous 1 for TPDO1).
  [[nodiscard]] std::uint8_t tpdo_transmission_type(std::uint8_t node, std::uint8_t number) const noexcept;

  /// SYNC period in ns last written to 0x1006 (communication cycle period)
  /// other than 0 (0 turns the SYNC watch off), 0 if none seen.
  [[nodiscard]] std::int64_t sync_period_from_trace_ns() const noexcept { return sync_period_ns_; }

 private:
  // A layout with per-entry names and signedness resolved once (object_info
  // is a table scan; doing it per frame would cost more than the decode).
  struct Resolved {
    PdoLayout layout{};
    std::array<std::string_view, kMaxPdoEntries> names{};
    std::uint8_t signed_mask = 0;
  };
  struct Pdo {
    Resolved config{};
    bool has_config = false;
    Resolved trace{};
    bool has_trace = false;         // a complete mapping (sub0 = N) was written
    PdoLayout pending{};            // entries written before sub0 = N
    std::uint32_t cob_id = 0;       // current 11-bit COB-ID
    bool cob_valid = true;
    std::uint8_t transmission = 255;
  };
  struct Node {
    std::array<Pdo, kPdosPerDirection> rpdo{};
    std::array<Pdo, kPdosPerDirection> tpdo{};
    detail::SdoTransfer sdo{};
  };
  // Route of an 11-bit id: what it carries. Built from the pre-defined
  // connection set and updated by COB-ID writes to 0x1400../0x1800.. sub 1.
  struct Route {
    EventKind kind = EventKind::kUnknown;
    std::uint8_t node = 0;
    std::uint8_t pdo = 0;   // 1..4
    bool tx = false;        // TPDO / SDO response
  };

  void decode_pdo(Decoded& d) noexcept;
  /// A confirmed SDO write into the model: PDO mappings, COB-IDs and
  /// transmission types, the SYNC period (0x1006).
  void apply_write(std::uint8_t node, const detail::ConfirmedWrite& w) noexcept;
  void reroute(std::uint8_t node, bool tx, std::uint8_t number, std::uint32_t cob) noexcept;
  [[nodiscard]] const Resolved* active_layout(const Pdo& p, std::uint8_t number, bool tx, LayoutSource& src) const noexcept;
  static Resolved resolve(const PdoLayout& l) noexcept;
  Resolved default_rpdo_{};
  Resolved default_tpdo_{};

  std::array<Route, 2048> routes_{};
  std::array<Node, kMaxNode + 1> nodes_{};
  std::int64_t sync_period_ns_ = 0;
  Decoded out_{};
};

/// Default CiA 402 CSP layouts (RPDO1: 0x6040 u16 + 0x607A i32; TPDO1: 0x6041 u16 + 0x6064 i32).
PdoLayout default_rpdo1() noexcept;
PdoLayout default_tpdo1() noexcept;

}  // namespace canmotion::trace
