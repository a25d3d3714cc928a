#pragma once
/// \file
/// Internal to the trace decoder: one node's SDO transfer as a trace shows
/// it (CiA 301 §7.2.4.3, expedited and segmented, both directions), frame by
/// frame, and the CiA 402 values an object's value carries. Never allocates,
/// never throws; the state is bounded (kSdoValueCapacity bytes of a value).

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "fieldbus/trace/decoded.hpp"

namespace canmotion::trace::detail {

/// An SDO write the server confirmed: the decoder applies it to its model of
/// the node (PDO mapping and communication objects, the SYNC period).
struct ConfirmedWrite {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint32_t value = 0;  ///< little-endian, writes of 1..4 bytes only
};

/// The transfer in progress on one node's SDO channel.
class SdoTransfer {
 public:
  /// Decode `d.tf.frame` (an SDO frame of this node; `d.sdo_response` says
  /// which direction) into d's SDO fields and follow the transfer. Returns
  /// the write this frame completes, if any. d.value may view this object's
  /// buffer: valid until the next step().
  std::optional<ConfirmedWrite> step(Decoded& d) noexcept;

 private:
  // One step per kind of SDO frame (sdo::SdoFrameKind).
  void initiate_download(Decoded& d) noexcept;
  std::optional<ConfirmedWrite> download_confirmed(Decoded& d) noexcept;
  void download_segment(Decoded& d) noexcept;
  std::optional<ConfirmedWrite> download_segment_confirmed(Decoded& d) noexcept;
  void initiate_upload(Decoded& d) noexcept;
  void upload_response(Decoded& d) noexcept;
  void upload_segment_request(Decoded& d) noexcept;
  void upload_segment(Decoded& d) noexcept;
  void abort(Decoded& d) noexcept;

  /// The transfer's object and direction into d.
  void describe(Decoded& d) const noexcept;
  /// A segment (or its request or response) of a segmented transfer in
  /// direction `dir`: describe() it; false (an orphan) when no such transfer
  /// was initiated in the trace.
  bool segment_of(SdoDir dir, Decoded& d) const noexcept;
  /// A segment's bytes into the buffer (beyond its capacity only counted).
  void append(const Decoded& d) noexcept;
  /// The reassembled value into d.
  void finish_segmented(Decoded& d) const noexcept;

  struct State {
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
  };
  State t_{};
};

/// Little-endian value of up to the first 4 bytes of `v`.
std::uint32_t le32(std::span<const std::uint8_t> v) noexcept;

/// Set d's CiA 402 value of object `index` sub 0 (controlword, statusword,
/// target position, position actual value, mode): `raw` is its bits,
/// `value` the number as its type reads (sign-extended for signed types).
void set_cia402(Decoded& d, std::uint16_t index, std::uint64_t raw, std::int64_t value) noexcept;

}  // namespace canmotion::trace::detail
