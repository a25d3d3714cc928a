#pragma once
/// \file
/// SDO frame layout (CiA 301 §7.2.4.3): command byte constants, the frame
/// builders and a decoder for single frames, shared by the SDO client, the
/// SDO server and the trace decoder. Realtime-safe, constexpr.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "fieldbus/can/frame.hpp"

namespace canmotion::canopen::sdo {

// Command specifiers, bits 7..5 of byte 0.
inline constexpr std::uint8_t kCcsDownloadSegment = 0;  ///< client: download segment
inline constexpr std::uint8_t kCcsInitiateDownload = 1;
inline constexpr std::uint8_t kCcsInitiateUpload = 2;
inline constexpr std::uint8_t kCcsUploadSegment = 3;
inline constexpr std::uint8_t kCsAbort = 4;            ///< either side
inline constexpr std::uint8_t kCcsBlockUpload = 5;
inline constexpr std::uint8_t kCcsBlockDownload = 6;
inline constexpr std::uint8_t kScsUploadSegment = 0;   ///< server: upload segment
inline constexpr std::uint8_t kScsDownloadSegment = 1;
inline constexpr std::uint8_t kScsInitiateUpload = 2;
inline constexpr std::uint8_t kScsInitiateDownload = 3;
inline constexpr std::uint8_t kScsBlockDownload = 5;
inline constexpr std::uint8_t kScsBlockUpload = 6;

inline constexpr std::uint8_t kToggle = 0x10;     ///< t, segment frames
inline constexpr std::uint8_t kExpedited = 0x02;  ///< e, initiate frames
inline constexpr std::uint8_t kSizeIndicated = 0x01;  ///< s, initiate frames
inline constexpr std::uint8_t kLastSegment = 0x01;    ///< c, segment frames

/// Command specifier (bits 7..5) of an SDO command byte.
[[nodiscard]] constexpr std::uint8_t command_specifier(std::uint8_t b0) noexcept {
  return static_cast<std::uint8_t>(b0 >> 5);
}

/// An 8-byte SDO frame on `cob_id` with command byte `b0`, the multiplexer
/// `index`/`sub` (bytes 1..3) and `value` in bytes 4..7 (little endian: an
/// expedited value's bytes, an announced size or an abort code).
[[nodiscard]] constexpr can::Frame initiate_frame(std::uint32_t cob_id, std::uint8_t b0, std::uint16_t index,
                                                  std::uint8_t sub, std::uint32_t value = 0) noexcept {
  can::Frame f;
  f.id = cob_id;
  f.len = 8;
  f.data[0] = b0;
  f.data[1] = static_cast<std::uint8_t>(index & 0xFF);
  f.data[2] = static_cast<std::uint8_t>(index >> 8);
  f.data[3] = sub;
  for (int i = 0; i < 4; ++i) f.data[static_cast<std::size_t>(4 + i)] = static_cast<std::uint8_t>(value >> (8 * i));
  return f;
}

/// An abort transfer frame (either side) for `index`/`sub` with `code`
/// (an SdoAbort value).
[[nodiscard]] constexpr can::Frame abort_frame(std::uint32_t cob_id, std::uint16_t index, std::uint8_t sub,
                                               std::uint32_t code) noexcept {
  return initiate_frame(cob_id, static_cast<std::uint8_t>(kCsAbort << 5), index, sub, code);
}

/// A segment frame (download segment request or upload segment response):
/// 1..7 bytes of `data` (more are cut), toggle bit `toggle`, `last` = c bit.
[[nodiscard]] constexpr can::Frame segment_frame(std::uint32_t cob_id, bool toggle, std::span<const std::uint8_t> data,
                                                 bool last) noexcept {
  const std::size_t n = std::min<std::size_t>(7, data.size());
  can::Frame f;
  f.id = cob_id;
  f.len = 8;
  f.data[0] = static_cast<std::uint8_t>((toggle ? kToggle : 0) | ((7 - n) << 1) | (last ? kLastSegment : 0));
  std::copy_n(data.begin(), n, f.data.begin() + 1);
  return f;
}

/// Kind of one SDO frame, direction resolved.
enum class SdoFrameKind : std::uint8_t {
  kInitiateDownloadRequest,   ///< client 0x2x
  kInitiateDownloadResponse,  ///< server 0x60
  kDownloadSegmentRequest,    ///< client 0x0x/0x1x
  kDownloadSegmentResponse,   ///< server 0x20/0x30
  kInitiateUploadRequest,     ///< client 0x40
  kInitiateUploadResponse,    ///< server 0x4x
  kUploadSegmentRequest,      ///< client 0x60/0x70
  kUploadSegmentResponse,     ///< server 0x0x/0x1x
  kAbort,                     ///< 0x80 either side
  kBlock,                     ///< block transfer frames (not used by canmotion)
  kInvalid,
};

/// A decoded SDO frame. For initiate frames `index`/`sub` are set; for
/// expedited transfers `data`/`data_len` hold the value; for segmented
/// initiate frames with s=1 `size` is the announced total size; for segments
/// `data`/`data_len` hold the segment bytes (1..7) and `toggle`/`last` the flags;
/// for aborts `abort_code` is set.
struct SdoFrame {
  SdoFrameKind kind = SdoFrameKind::kInvalid;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  bool expedited = false;
  bool size_indicated = false;
  bool toggle = false;
  bool last = false;
  std::uint32_t size = 0;
  std::uint32_t abort_code = 0;
  std::uint8_t data_len = 0;
  std::uint8_t data[7]{};
};

/// Decode one SDO frame; `from_server` = it came on 0x580+node (response).
/// A frame that is not 8 bytes long decodes as kInvalid. Realtime-safe.
[[nodiscard]] constexpr SdoFrame decode(const can::Frame& f, bool from_server) noexcept {
  SdoFrame s;
  if (f.len != 8) return s;
  const std::uint8_t b0 = f.data[0];
  const std::uint8_t cs = command_specifier(b0);
  auto set_mux = [&] {
    s.index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
    s.sub = f.data[3];
  };
  auto u32 = [&] {
    return static_cast<std::uint32_t>(f.data[4]) | (static_cast<std::uint32_t>(f.data[5]) << 8) |
           (static_cast<std::uint32_t>(f.data[6]) << 16) | (static_cast<std::uint32_t>(f.data[7]) << 24);
  };
  auto initiate = [&] {
    set_mux();
    s.expedited = (b0 & kExpedited) != 0;
    s.size_indicated = (b0 & kSizeIndicated) != 0;
    if (s.expedited) {
      s.data_len = s.size_indicated ? static_cast<std::uint8_t>(4 - ((b0 >> 2) & 3)) : 4;
      for (std::uint8_t i = 0; i < s.data_len; ++i) s.data[i] = f.data[4 + i];
      s.size = s.data_len;
    } else if (s.size_indicated) {
      s.size = u32();
    }
  };
  auto segment = [&] {
    s.toggle = (b0 & kToggle) != 0;
    s.last = (b0 & kLastSegment) != 0;
    s.data_len = static_cast<std::uint8_t>(7 - ((b0 >> 1) & 7));
    for (std::uint8_t i = 0; i < s.data_len; ++i) s.data[i] = f.data[1 + i];
  };
  if (cs == kCsAbort) {
    set_mux();
    s.kind = SdoFrameKind::kAbort;
    s.abort_code = u32();
    return s;
  }
  if (!from_server) {
    switch (cs) {
      case kCcsInitiateDownload: s.kind = SdoFrameKind::kInitiateDownloadRequest; initiate(); break;
      case kCcsDownloadSegment: s.kind = SdoFrameKind::kDownloadSegmentRequest; segment(); break;
      case kCcsInitiateUpload: s.kind = SdoFrameKind::kInitiateUploadRequest; set_mux(); break;
      case kCcsUploadSegment: s.kind = SdoFrameKind::kUploadSegmentRequest; s.toggle = (b0 & kToggle) != 0; break;
      case kCcsBlockUpload: case kCcsBlockDownload: s.kind = SdoFrameKind::kBlock; break;
      default: break;
    }
  } else {
    switch (cs) {
      case kScsInitiateDownload: s.kind = SdoFrameKind::kInitiateDownloadResponse; set_mux(); break;
      case kScsDownloadSegment: s.kind = SdoFrameKind::kDownloadSegmentResponse; s.toggle = (b0 & kToggle) != 0; break;
      case kScsInitiateUpload: s.kind = SdoFrameKind::kInitiateUploadResponse; initiate(); break;
      case kScsUploadSegment: s.kind = SdoFrameKind::kUploadSegmentResponse; segment(); break;
      case kScsBlockDownload: case kScsBlockUpload: s.kind = SdoFrameKind::kBlock; break;
      default: break;
    }
  }
  return s;
}

[[nodiscard]] constexpr std::string_view sdo_frame_kind_name(SdoFrameKind k) noexcept {
  switch (k) {
    case SdoFrameKind::kInitiateDownloadRequest: return "initiate download request";
    case SdoFrameKind::kInitiateDownloadResponse: return "initiate download response";
    case SdoFrameKind::kDownloadSegmentRequest: return "download segment request";
    case SdoFrameKind::kDownloadSegmentResponse: return "download segment response";
    case SdoFrameKind::kInitiateUploadRequest: return "initiate upload request";
    case SdoFrameKind::kInitiateUploadResponse: return "initiate upload response";
    case SdoFrameKind::kUploadSegmentRequest: return "upload segment request";
    case SdoFrameKind::kUploadSegmentResponse: return "upload segment response";
    case SdoFrameKind::kAbort: return "abort";
    case SdoFrameKind::kBlock: return "block transfer";
    case SdoFrameKind::kInvalid: break;
  }
  return "invalid";
}

}  // namespace canmotion::canopen::sdo
