#include "fieldbus/canopen/sdo_server.hpp"

#include <algorithm>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"

namespace canmotion::canopen {

can::Frame SdoServer::response(std::uint8_t b0, std::uint16_t index, std::uint8_t sub) const noexcept {
  return sdo::initiate_frame(cob::sdo_tx(node_), b0, index, sub);
}

void SdoServer::send_abort(std::uint16_t index, std::uint8_t sub, SdoAbort code, FrameSink& out) noexcept {
  out.send(sdo::abort_frame(cob::sdo_tx(node_), index, sub, static_cast<std::uint32_t>(code)));
  ++aborts_sent_;
  phase_ = Phase::kIdle;
}

void SdoServer::step(std::int64_t now_ns, FrameSink& out) noexcept {
  if (phase_ != Phase::kIdle && now_ns - last_ns_ > timeout_ns_) send_abort(index_, sub_, SdoAbort::kTimeout, out);
}

void SdoServer::on_frame(const can::Frame& f, std::int64_t now_ns, FrameSink& out) noexcept {
  if (f.id != cob::sdo_rx(node_) || f.extended() || f.remote()) return;
  last_ns_ = now_ns;
  if (f.len != 8) {
    // CiA 301: SDO frames always have 8 bytes; answer with a protocol abort.
    send_abort(static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8)), f.data[3], SdoAbort::kCommandSpecifier, out);
    return;
  }
  if (phase_ == Phase::kBlockDown && f.data[0] != 0x80) return on_block_download_segment(f, out);
  const sdo::SdoFrame s = sdo::decode(f, false);
  switch (s.kind) {
    case sdo::SdoFrameKind::kAbort:
      phase_ = Phase::kIdle;  // the client gave up; no answer
      return;
    case sdo::SdoFrameKind::kInitiateDownloadRequest: {
      phase_ = Phase::kIdle;
      if (s.expedited) {
        const SdoAbort a = backend_.sdo_write(s.index, s.sub, std::span<const std::uint8_t>(s.data, s.data_len));
        if (a != SdoAbort::kNone) return send_abort(s.index, s.sub, a, out);
        out.send(response(0x60, s.index, s.sub));
        return;
      }
      if (s.size_indicated && s.size > kSdoServerBuffer) return send_abort(s.index, s.sub, SdoAbort::kOutOfMemory, out);
      phase_ = Phase::kDownload;
      index_ = s.index;
      sub_ = s.sub;
      toggle_ = false;
      offset_ = 0;
      size_indicated_ = s.size_indicated;
      size_ = s.size_indicated ? s.size : 0;
      out.send(response(0x60, s.index, s.sub));
      return;
    }
    case sdo::SdoFrameKind::kDownloadSegmentRequest: {
      if (phase_ != Phase::kDownload) return send_abort(index_, sub_, SdoAbort::kCommandSpecifier, out);
      if (s.toggle != toggle_) return send_abort(index_, sub_, SdoAbort::kToggleBit, out);
      if (offset_ + s.data_len > kSdoServerBuffer) return send_abort(index_, sub_, SdoAbort::kOutOfMemory, out);
      std::copy_n(s.data, s.data_len, buf_.begin() + offset_);
      offset_ += s.data_len;
      if (s.last) {
        if (size_indicated_ && offset_ != size_) {
          return send_abort(index_, sub_, offset_ > size_ ? SdoAbort::kLengthTooHigh : SdoAbort::kLengthTooLow, out);
        }
        const SdoAbort a = backend_.sdo_write(index_, sub_, std::span<const std::uint8_t>(buf_.data(), offset_));
        if (a != SdoAbort::kNone) return send_abort(index_, sub_, a, out);
        phase_ = Phase::kIdle;
      }
      can::Frame r = response(static_cast<std::uint8_t>(0x20 | (toggle_ ? sdo::kToggle : 0)), 0, 0);
      toggle_ = !toggle_;
      out.send(r);
      return;
    }
    case sdo::SdoFrameKind::kInitiateUploadRequest: {
      phase_ = Phase::kIdle;
      std::size_t len = 0;
      const SdoAbort a = backend_.sdo_read(s.index, s.sub, buf_, len);
      if (a != SdoAbort::kNone) return send_abort(s.index, s.sub, a, out);
      if (len <= 4) {
        const auto n = static_cast<std::uint8_t>(4 - len);
        can::Frame r = response(static_cast<std::uint8_t>(0x40 | (n << 2) | sdo::kExpedited | sdo::kSizeIndicated),
                                s.index, s.sub);
        std::copy_n(buf_.begin(), len, r.data.begin() + 4);
        out.send(r);
        return;
      }
      phase_ = Phase::kUpload;
      index_ = s.index;
      sub_ = s.sub;
      size_ = len;
      offset_ = 0;
      toggle_ = false;
      out.send(sdo::initiate_frame(cob::sdo_tx(node_), 0x41, s.index, s.sub, static_cast<std::uint32_t>(len)));
      return;
    }
    case sdo::SdoFrameKind::kUploadSegmentRequest: {
      if (phase_ != Phase::kUpload) return send_abort(index_, sub_, SdoAbort::kCommandSpecifier, out);
      if (s.toggle != toggle_) return send_abort(index_, sub_, SdoAbort::kToggleBit, out);
      const std::size_t n = std::min<std::size_t>(7, size_ - offset_);
      const bool last = offset_ + n == size_;
      const can::Frame r =
          sdo::segment_frame(cob::sdo_tx(node_), toggle_, std::span<const std::uint8_t>(buf_.data() + offset_, n), last);
      offset_ += n;
      toggle_ = !toggle_;
      if (last) phase_ = Phase::kIdle;
      out.send(r);
      return;
    }
    case sdo::SdoFrameKind::kBlock:
      if (block_) return on_block_frame(f, out);
      // A drive without block transfer; the abort names the initiate's object.
      return send_abort(static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8)), f.data[3], SdoAbort::kCommandSpecifier, out);
    default:  // unknown command specifiers
      return send_abort(s.index, s.sub, SdoAbort::kCommandSpecifier, out);
  }
}

}  // namespace canmotion::canopen
