#include "fieldbus/trace/sdo_transfer.hpp"

#include <algorithm>

#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::trace::detail {
namespace {

namespace sdo = canmotion::canopen::sdo;

/// The CiA 402 value of an expedited transfer's object (sub 0 only).
void set_cia402_from_value(Decoded& d, std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> v) noexcept {
  if (sub != 0 || v.empty()) return;
  const std::uint32_t x = le32(v);
  set_cia402(d, index, x, static_cast<std::int32_t>(x));
}

/// An expedited transfer's value: the frame's own bytes.
void expedited_value(Decoded& d) noexcept {
  d.sdo_has_value = true;
  d.sdo_total = d.sdo.data_len;
  d.value = std::span<const std::uint8_t>(d.sdo.data, d.sdo.data_len);
}

}  // namespace

std::uint32_t le32(std::span<const std::uint8_t> v) noexcept {
  std::uint32_t x = 0;
  for (std::size_t i = 0; i < v.size() && i < 4; ++i) x |= static_cast<std::uint32_t>(v[i]) << (8 * i);
  return x;
}

void set_cia402(Decoded& d, std::uint16_t index, std::uint64_t raw, std::int64_t value) noexcept {
  switch (index) {
    case cia402::obj::kControlword:
      d.has_controlword = true;
      d.controlword = static_cast<std::uint16_t>(raw);
      break;
    case cia402::obj::kStatusword:
      d.has_statusword = true;
      d.statusword = static_cast<std::uint16_t>(raw);
      break;
    case cia402::obj::kTargetPosition:
      d.has_target = true;
      d.target_position = value;
      break;
    case cia402::obj::kPositionActualValue:
      d.has_actual = true;
      d.actual_position = value;
      break;
    case cia402::obj::kModesOfOperation:
    case cia402::obj::kModesOfOperationDisplay:
      d.has_mode = true;
      d.mode = static_cast<std::int8_t>(raw & 0xFFU);
      break;
    default:
      break;
  }
}

std::optional<ConfirmedWrite> SdoTransfer::step(Decoded& d) noexcept {
  d.sdo = sdo::decode(d.tf.frame, d.sdo_response);
  switch (d.sdo.kind) {
    case sdo::SdoFrameKind::kInitiateDownloadRequest: initiate_download(d); break;
    case sdo::SdoFrameKind::kInitiateDownloadResponse: return download_confirmed(d);
    case sdo::SdoFrameKind::kDownloadSegmentRequest: download_segment(d); break;
    case sdo::SdoFrameKind::kDownloadSegmentResponse: return download_segment_confirmed(d);
    case sdo::SdoFrameKind::kInitiateUploadRequest: initiate_upload(d); break;
    case sdo::SdoFrameKind::kInitiateUploadResponse: upload_response(d); break;
    case sdo::SdoFrameKind::kUploadSegmentRequest: upload_segment_request(d); break;
    case sdo::SdoFrameKind::kUploadSegmentResponse: upload_segment(d); break;
    case sdo::SdoFrameKind::kAbort: abort(d); break;
    case sdo::SdoFrameKind::kBlock: d.problem = "SDO block transfer (not decoded)"; break;
    case sdo::SdoFrameKind::kInvalid:
      d.problem = d.tf.frame.len != 8 ? "SDO frame is not 8 bytes long" : "invalid SDO command specifier";
      break;
  }
  return std::nullopt;
}

void SdoTransfer::describe(Decoded& d) const noexcept {
  d.sdo_index = t_.index;
  d.sdo_sub = t_.sub;
  d.sdo_dir = t_.dir;
}

bool SdoTransfer::segment_of(SdoDir dir, Decoded& d) const noexcept {
  if (t_.dir != dir || !t_.segmented) {
    d.sdo_orphan = true;
    return false;
  }
  describe(d);
  return true;
}

void SdoTransfer::append(const Decoded& d) noexcept {
  for (std::uint8_t i = 0; i < d.sdo.data_len; ++i) {
    if (t_.received < kSdoValueCapacity) t_.buf[t_.received] = d.sdo.data[i];
    ++t_.received;
  }
}

void SdoTransfer::finish_segmented(Decoded& d) const noexcept {
  d.sdo_has_value = true;
  d.sdo_segmented = true;
  d.sdo_total = t_.received;
  d.value = std::span<const std::uint8_t>(t_.buf.data(), std::min<std::size_t>(t_.received, kSdoValueCapacity));
}

// ---- download (write) ------------------------------------------------------

void SdoTransfer::initiate_download(Decoded& d) noexcept {
  const sdo::SdoFrame& s = d.sdo;
  t_ = State{};
  t_.dir = SdoDir::kDownload;
  t_.index = s.index;
  t_.sub = s.sub;
  describe(d);
  if (s.expedited) {
    expedited_value(d);
    t_.write_pending = true;
    t_.write_value = le32(d.value);
    set_cia402_from_value(d, s.index, s.sub, d.value);
  } else {
    t_.segmented = true;
    t_.announced = s.size_indicated ? s.size : 0;
    d.sdo_total = t_.announced;
  }
}

std::optional<ConfirmedWrite> SdoTransfer::download_confirmed(Decoded& d) noexcept {
  const sdo::SdoFrame& s = d.sdo;
  d.sdo_index = s.index;
  d.sdo_sub = s.sub;
  d.sdo_dir = SdoDir::kDownload;
  if (t_.dir != SdoDir::kDownload || t_.index != s.index || t_.sub != s.sub || !t_.write_pending) return std::nullopt;
  const ConfirmedWrite w{s.index, s.sub, t_.write_value};
  d.sdo_complete = true;
  t_ = State{};
  return w;
}

void SdoTransfer::download_segment(Decoded& d) noexcept {
  if (!segment_of(SdoDir::kDownload, d)) return;
  t_.toggle = d.sdo.toggle;
  append(d);
  if (d.sdo.last) finish_segmented(d);
}

std::optional<ConfirmedWrite> SdoTransfer::download_segment_confirmed(Decoded& d) noexcept {
  if (!segment_of(SdoDir::kDownload, d)) return std::nullopt;
  if (d.sdo.toggle != t_.toggle) d.problem = "toggle bit does not match the request";
  // A response to the last segment completes the write.
  if (t_.announced == 0 || t_.received < t_.announced) return std::nullopt;
  d.sdo_complete = true;
  d.sdo_total = t_.received;
  std::optional<ConfirmedWrite> w;
  if (t_.received <= 4) w = ConfirmedWrite{t_.index, t_.sub, le32(std::span(t_.buf.data(), t_.received))};
  t_ = State{};
  return w;
}

// ---- upload (read) ---------------------------------------------------------

void SdoTransfer::initiate_upload(Decoded& d) noexcept {
  t_ = State{};
  t_.dir = SdoDir::kUpload;
  t_.index = d.sdo.index;
  t_.sub = d.sdo.sub;
  describe(d);
}

void SdoTransfer::upload_response(Decoded& d) noexcept {
  const sdo::SdoFrame& s = d.sdo;
  d.sdo_index = s.index;
  d.sdo_sub = s.sub;
  d.sdo_dir = SdoDir::kUpload;
  t_ = State{};
  if (s.expedited) {
    expedited_value(d);
    d.sdo_complete = true;
    set_cia402_from_value(d, s.index, s.sub, d.value);
    return;
  }
  t_.dir = SdoDir::kUpload;
  t_.index = s.index;
  t_.sub = s.sub;
  t_.segmented = true;
  t_.announced = s.size_indicated ? s.size : 0;
  d.sdo_total = t_.announced;
}

void SdoTransfer::upload_segment_request(Decoded& d) noexcept {
  if (!segment_of(SdoDir::kUpload, d)) return;
  t_.toggle = d.sdo.toggle;
}

void SdoTransfer::upload_segment(Decoded& d) noexcept {
  if (!segment_of(SdoDir::kUpload, d)) return;
  if (d.sdo.toggle != t_.toggle) d.problem = "toggle bit does not match the request";
  append(d);
  if (!d.sdo.last) return;
  finish_segmented(d);
  d.sdo_complete = true;
  if (t_.announced != 0 && t_.announced != t_.received) d.problem = "segmented upload size differs from the announced size";
  t_.dir = SdoDir::kNone;  // the buffer stays valid for this Decoded
  t_.segmented = false;
}

void SdoTransfer::abort(Decoded& d) noexcept {
  d.sdo_index = d.sdo.index;
  d.sdo_sub = d.sdo.sub;
  d.sdo_dir = t_.dir;
  t_ = State{};
}

}  // namespace canmotion::trace::detail
