#pragma once
/// \file
/// What the trace decoder (decoder.hpp) makes of one frame: its kind, node,
/// protocol problem and the fields of its protocol (NMT, SYNC, EMCY,
/// heartbeat, SDO transfer, PDO fields, the CiA 402 values it carries), with
/// the capacities that bound the decoder's memory.

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"

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

}  // namespace canmotion::trace
