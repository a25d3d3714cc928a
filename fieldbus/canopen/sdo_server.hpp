#pragma once
/// \file
/// SDO server (CiA 301 §7.2.4), used by the drive emulator: expedited,
/// segmented and block upload/download (with the CRC) with the toggle bit and
/// sequence numbers checked and the right abort codes. Block transfer can be
/// switched off (set_block_transfer(false): 0x05040001, as a drive without it). The object dictionary is behind SdoServerBackend.
/// Realtime-safe after construction.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"

namespace canmotion::canopen {

/// Largest object the server transfers (0x1008 and other strings).
inline constexpr std::size_t kSdoServerBuffer = 256;

/// Access to an object dictionary for the SDO server.
class SdoServerBackend {
 public:
  virtual ~SdoServerBackend() = default;
  /// Read index:sub into `out`; set `len`. Return kNone or the abort code
  /// (kNoObject, kNoSubindex, kWriteOnly, ...).
  virtual SdoAbort sdo_read(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> out,
                            std::size_t& len) noexcept = 0;
  /// Write `data` to index:sub. Return kNone or the abort code (kReadOnly,
  /// kTypeMismatch / kLengthTooHigh / kLengthTooLow, kInvalidValue,
  /// kNotMappable, kDeviceState, ...).
  virtual SdoAbort sdo_write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) noexcept = 0;
};

class SdoServer {
 public:
  SdoServer(std::uint8_t node, SdoServerBackend& backend) noexcept : node_(node), backend_(backend) {}
  void set_node(std::uint8_t node) noexcept { node_ = node; }

  /// Handle a request frame (ID 0x600 + node; others are ignored) and send
  /// the response. `now_ns` restarts the segmented-transfer timer.
  void on_frame(const can::Frame& f, std::int64_t now_ns, FrameSink& out) noexcept;
  /// Abort a segmented transfer the client left hanging for longer than
  /// `timeout_ns` (abort 0x05040000).
  void step(std::int64_t now_ns, FrameSink& out) noexcept;
  void set_timeout(std::int64_t ns) noexcept { timeout_ns_ = ns; }
  /// Serve block transfer (default) or refuse it with 0x05040001.
  void set_block_transfer(bool on) noexcept { block_ = on; }
  /// Segments per sub-block the server asks for in a block download (1..127).
  void set_block_size(std::uint8_t n) noexcept { down_blksize_ = n; }

  /// Back to idle without sending anything (NMT reset communication).
  void reset() noexcept { phase_ = Phase::kIdle; }
  [[nodiscard]] std::uint64_t aborts_sent() const noexcept { return aborts_sent_; }

 private:
  enum class Phase : std::uint8_t { kIdle, kDownload, kUpload, kBlockDown, kBlockDownEnd, kBlockUp, kBlockUpAck, kBlockUpEnd };
  void on_block_frame(const can::Frame& f, FrameSink& out) noexcept;
  void on_block_download_segment(const can::Frame& f, FrameSink& out) noexcept;
  void send_sub_block(FrameSink& out) noexcept;
  void send_abort(std::uint16_t index, std::uint8_t sub, SdoAbort code, FrameSink& out) noexcept;
  can::Frame response(std::uint8_t b0, std::uint16_t index, std::uint8_t sub) const noexcept;

  std::uint8_t node_;
  SdoServerBackend& backend_;
  Phase phase_ = Phase::kIdle;
  std::uint16_t index_ = 0;
  std::uint8_t sub_ = 0;
  bool toggle_ = false;
  std::size_t size_ = 0;       // total (upload) / announced (download, 0 = not indicated)
  bool size_indicated_ = false;
  std::size_t offset_ = 0;
  std::array<std::uint8_t, kSdoServerBuffer + 7> buf_{};  // + a block segment's padding
  bool block_ = true;
  bool crc_ = false;               // both sides support the CRC
  std::uint8_t down_blksize_ = 127;
  std::uint8_t blksize_ = 0;       // current sub-block size
  std::uint8_t seqno_ = 0;         // block download: last segment received in order
  bool got_last_ = false;
  std::size_t sub_start_ = 0;      // block upload: offset of the sub-block's first segment
  std::int64_t last_ns_ = 0;
  std::int64_t timeout_ns_ = 1'000'000'000;
  std::uint64_t aborts_sent_ = 0;
};

}  // namespace canmotion::canopen
