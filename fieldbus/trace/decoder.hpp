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
#include <span>
#include <string_view>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::trace {

/// Highest CANopen node-ID; per-node tables are indexed 0..kMaxNode.
inline constexpr std::size_t kMaxNode = 127;
/// PDOs per direction tracked per node: the pre-defined connection set has 4.
inline constexpr std::size_t kPdosPerDirection = 4;
/// Mapping entries per PDO: 8 bytes of classical CAN with byte-granular
/// objects allow at most 8 (bit-sized entries beyond that are shown as raw).
inline constexpr std::size_t kMaxPdoEntries = 8;
/// Bytes of a segmented SDO value kept for display; longer values are
/// reported with their full size and the first kSdoValueCapacity bytes.
inline constexpr std::size_t kSdoValueCapacity = 256;

/// What a frame is.
enum class EventKind : std::uint8_t {
  kNmt,
  kSync,
  kTime,
  kEmcy,
  kBootUp,
  kHeartbeat,
  kNodeGuardRequest,  ///< RTR on 0x700 + node
  kSdo,
  kPdo,
  kLss,
  kErrorFrame,
  kUnknown,  ///< an id outside the pre-defined connection set, or an extended id
};

/// Where a PDO's layout came from.
enum class LayoutSource : std::uint8_t { kNone, kConfig, kTrace, kDefault };

/// Text for a layout source ("config", "trace", "default", "none").
std::string_view layout_source_name(LayoutSource s) noexcept;

/// One PDO mapping entry (CiA 301 `(index << 16) | (sub << 8) | bits`).
struct MapEntry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
  /// Decode a raw mapping entry value.
  static constexpr MapEntry from_raw(std::uint32_t raw) noexcept {
    return MapEntry{static_cast<std::uint16_t>(raw >> 16), static_cast<std::uint8_t>((raw >> 8) & 0xFFU),
                    static_cast<std::uint8_t>(raw & 0xFFU)};
  }
};

/// A PDO layout: up to kMaxPdoEntries entries.
struct PdoLayout {
  std::array<MapEntry, kMaxPdoEntries> entries{};
  std::uint8_t count = 0;
};

/// One decoded field of a PDO.
struct PdoField {
  std::string_view name;  ///< object name ("Statusword"); empty when unknown
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
  bool is_signed = false;
  bool present = false;  ///< false when the frame was too short for this field
  std::int64_t value = 0;  ///< sign-extended for signed types, else zero-extended
};

/// Direction of an SDO transfer.
enum class SdoDir : std::uint8_t { kNone, kDownload /*write*/, kUpload /*read*/ };

/// The result of decoding one frame. Views (value, fields) are valid until
/// the next decode() call.
struct Decoded {
  can::TimedFrame tf{};
  EventKind kind = EventKind::kUnknown;
  std::uint8_t node = 0;
  /// Static text describing a protocol problem in this frame (wrong length,
  /// unknown command, ...), nullptr when the frame is well formed.
  const char* problem = nullptr;

  // NMT command
  std::uint8_t nmt_command = 0;
  std::uint8_t nmt_target = 0;  ///< 0 = all nodes
  // SYNC
  bool sync_has_counter = false;
  std::uint8_t sync_counter = 0;
  // EMCY
  std::uint16_t emcy_code = 0;
  std::uint8_t emcy_register = 0;
  std::array<std::uint8_t, 5> emcy_vendor{};
  // Heartbeat / boot-up
  canopen::NmtState nmt_state = canopen::NmtState::kUnknown;
  bool guard_toggle = false;  ///< bit 7 of a node-guarding response

  // SDO
  canopen::sdo::SdoFrame sdo{};
  bool sdo_response = false;  ///< true = server -> client (0x580 + node)
  SdoDir sdo_dir = SdoDir::kNone;
  std::uint16_t sdo_index = 0;  ///< index/sub of the transfer (also for segments)
  std::uint8_t sdo_sub = 0;
  bool sdo_has_value = false;   ///< `value` holds a value (expedited or reassembled segmented transfer)
  bool sdo_complete = false;    ///< the frame completes a transfer (success)
  bool sdo_segmented = false;   ///< `value` was reassembled from segments
  std::uint32_t sdo_total = 0;  ///< bytes of the value (may exceed value.size() when truncated)
  std::span<const std::uint8_t> value;
  bool sdo_orphan = false;      ///< a segment without a preceding initiate frame in the trace

  // PDO
  bool pdo_tx = false;  ///< TPDO (drive -> master) if true, RPDO otherwise
  std::uint8_t pdo_number = 0;
  LayoutSource layout = LayoutSource::kNone;
  std::uint8_t field_count = 0;
  std::array<PdoField, kMaxPdoEntries> fields{};
  bool pdo_length_mismatch = false;  ///< frame length differs from the mapped length
  std::uint16_t pdo_mapped_bits = 0;  ///< total bits of the layout

  // CiA 402 values carried by this frame (PDO or expedited SDO)
  bool has_controlword = false;
  std::uint16_t controlword = 0;
  bool has_statusword = false;
  std::uint16_t statusword = 0;
  bool has_target = false;
  std::int64_t target_position = 0;
  bool has_actual = false;
  std::int64_t actual_position = 0;
  bool has_mode = false;
  std::int8_t mode = 0;
};

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
  struct Transfer {
    SdoDir dir = SdoDir::kNone;
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    bool segmented = false;
    bool toggle = false;
    std::uint32_t announced = 0;
    std::uint32_t received = 0;
    std::array<std::uint8_t, kSdoValueCapacity> buf{};
    // pending expedited write, applied when the server confirms it
    bool write_pending = false;
    std::uint32_t write_value = 0;
    std::uint8_t write_len = 0;
  };
  struct Node {
    std::array<Pdo, kPdosPerDirection> rpdo{};
    std::array<Pdo, kPdosPerDirection> tpdo{};
    Transfer sdo{};
  };
  // Route of an 11-bit id: what it carries. Built from the pre-defined
  // connection set and updated by COB-ID writes to 0x1400../0x1800.. sub 1.
  struct Route {
    EventKind kind = EventKind::kUnknown;
    std::uint8_t node = 0;
    std::uint8_t pdo = 0;   // 1..4
    bool tx = false;        // TPDO / SDO response
  };

  void decode_sdo(Node& n, Decoded& d) noexcept;
  void decode_pdo(Decoded& d) noexcept;
  void apply_write(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                   std::uint8_t len) noexcept;
  void set_cia402_from_object(Decoded& d, std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> v) noexcept;
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
