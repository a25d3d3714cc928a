// SdoServer: block download and block upload (CiA 301 §7.2.4.3.9-.16) with
// the CRC (canopen::sdo_crc16) and the sequence numbers checked: a segment
// out of order is dropped and the sub-block acknowledged up to the last one
// received in order, so the client resends from there. Realtime-safe.
#include <algorithm>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/sdo_client.hpp"  // sdo_crc16
#include "fieldbus/canopen/sdo_frame.hpp"
#include "fieldbus/canopen/sdo_server.hpp"

namespace canmotion::canopen {

namespace {
constexpr std::uint8_t kCrc = 0x04;     // cc / sc
constexpr std::uint8_t kSize = 0x02;    // s
constexpr std::uint8_t kLast = 0x80;    // c bit of a sub-block segment
constexpr std::size_t kSeg = 7;
}  // namespace

void SdoServer::on_block_download_segment(const can::Frame& f, FrameSink& out) noexcept {
  const auto seq = static_cast<std::uint8_t>(f.data[0] & 0x7F);
  const bool c = (f.data[0] & kLast) != 0;
  if (seq == seqno_ + 1 && !got_last_) {
    if (offset_ + kSeg > buf_.size()) return send_abort(index_, sub_, SdoAbort::kOutOfMemory, out);
    std::copy_n(f.data.begin() + 1, kSeg, buf_.begin() + offset_);
    offset_ += kSeg;
    seqno_ = seq;
    got_last_ = c;
  }
  if (!c && seq < blksize_) return;
  can::Frame ack = sdo::initiate_frame(cob::sdo_tx(node_), 0xA2, 0, 0);  // scs 5, ss 2
  ack.data[1] = seqno_;
  ack.data[2] = down_blksize_;
  ack.data[3] = 0;
  blksize_ = down_blksize_;
  seqno_ = 0;
  if (got_last_) phase_ = Phase::kBlockDownEnd;
  out.send(ack);
}

void SdoServer::send_sub_block(FrameSink& out) noexcept {
  sub_start_ = offset_;
  std::size_t off = offset_;
  for (std::uint8_t seq = 1; seq <= blksize_ && off < size_; ++seq) {
    const std::size_t n = std::min(kSeg, size_ - off);
    const bool last = off + n >= size_;
    can::Frame f;
    f.id = cob::sdo_tx(node_);
    f.len = 8;
    f.data[0] = static_cast<std::uint8_t>((last ? kLast : 0) | seq);
    std::copy_n(buf_.begin() + off, n, f.data.begin() + 1);
    out.send(f);
    off += n;
  }
  phase_ = Phase::kBlockUpAck;
}

void SdoServer::on_block_frame(const can::Frame& f, FrameSink& out) noexcept {
  const std::uint8_t b0 = f.data[0];
  const auto index = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
  const std::uint8_t sub = f.data[3];
  if ((b0 & 0xE1) == 0xC0) {  // ccs 6, cs 0: block download initiate
    const std::uint32_t size = static_cast<std::uint32_t>(f.data[4] | (f.data[5] << 8) | (f.data[6] << 16)) |
                               (static_cast<std::uint32_t>(f.data[7]) << 24);
    size_indicated_ = (b0 & kSize) != 0;
    if (size_indicated_ && size > kSdoServerBuffer) return send_abort(index, sub, SdoAbort::kOutOfMemory, out);
    if (down_blksize_ == 0 || down_blksize_ > 127) return send_abort(index, sub, SdoAbort::kBlockSize, out);
    phase_ = Phase::kBlockDown;
    index_ = index;
    sub_ = sub;
    size_ = size;
    offset_ = 0;
    seqno_ = 0;
    got_last_ = false;
    blksize_ = down_blksize_;
    crc_ = (b0 & kCrc) != 0;
    can::Frame r = response(0xA0 | kCrc, index, sub);  // scs 5, sc, ss 0
    r.data[4] = blksize_;
    out.send(r);
    return;
  }
  if ((b0 & 0xE3) == 0xC1) {  // ccs 6, cs 1: block download end
    if (phase_ != Phase::kBlockDownEnd) return send_abort(index_, sub_, SdoAbort::kCommandSpecifier, out);
    const std::size_t unused = (b0 >> 2) & 7;
    const std::size_t total = offset_ - unused;
    if (size_indicated_ && total != size_) {
      return send_abort(index_, sub_, total > size_ ? SdoAbort::kLengthTooHigh : SdoAbort::kLengthTooLow, out);
    }
    const auto crc = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
    if (crc_ && crc != sdo_crc16(std::span<const std::uint8_t>(buf_.data(), total))) {
      return send_abort(index_, sub_, SdoAbort::kCrc, out);
    }
    const SdoAbort a = backend_.sdo_write(index_, sub_, std::span<const std::uint8_t>(buf_.data(), total));
    if (a != SdoAbort::kNone) return send_abort(index_, sub_, a, out);
    phase_ = Phase::kIdle;
    out.send(response(0xA1, 0, 0));  // scs 5, ss 1
    return;
  }
  if ((b0 & 0xE3) == 0xA0) {  // ccs 5, cs 0: block upload initiate (pst ignored: always a block)
    phase_ = Phase::kIdle;
    blksize_ = f.data[4];
    if (blksize_ == 0 || blksize_ > 127) return send_abort(index, sub, SdoAbort::kBlockSize, out);
    std::size_t len = 0;
    const SdoAbort a = backend_.sdo_read(index, sub, std::span<std::uint8_t>(buf_.data(), kSdoServerBuffer), len);
    if (a != SdoAbort::kNone) return send_abort(index, sub, a, out);
    phase_ = Phase::kBlockUp;
    index_ = index;
    sub_ = sub;
    size_ = len;
    offset_ = 0;
    crc_ = (b0 & kCrc) != 0;
    out.send(sdo::initiate_frame(cob::sdo_tx(node_), 0xC0 | kCrc | kSize, index, sub, static_cast<std::uint32_t>(len)));
    return;
  }
  if (b0 == 0xA3) {  // start upload
    if (phase_ != Phase::kBlockUp) return send_abort(index_, sub_, SdoAbort::kCommandSpecifier, out);
    return send_sub_block(out);
  }
  if ((b0 & 0xE3) == 0xA2) {  // ack of a sub-block
    if (phase_ != Phase::kBlockUpAck) return send_abort(index_, sub_, SdoAbort::kCommandSpecifier, out);
    const std::uint8_t ackseq = f.data[1];
    const std::size_t sent = (size_ - sub_start_ + kSeg - 1) / kSeg;
    if (ackseq > std::min<std::size_t>(blksize_, sent)) return send_abort(index_, sub_, SdoAbort::kSequenceNumber, out);
    offset_ = std::min(size_, sub_start_ + static_cast<std::size_t>(ackseq) * kSeg);
    if (offset_ < size_) {
      blksize_ = f.data[2];
      if (blksize_ == 0 || blksize_ > 127) return send_abort(index_, sub_, SdoAbort::kBlockSize, out);
      return send_sub_block(out);
    }
    const std::size_t in_last = size_ == 0 ? 0 : size_ - ((size_ - 1) / kSeg) * kSeg;
    const std::uint16_t crc = crc_ ? sdo_crc16(std::span<const std::uint8_t>(buf_.data(), size_)) : 0;
    can::Frame e = response(static_cast<std::uint8_t>(0xC1 | ((kSeg - in_last) << 2)), 0, 0);
    e.data[1] = static_cast<std::uint8_t>(crc & 0xFF);
    e.data[2] = static_cast<std::uint8_t>(crc >> 8);
    phase_ = Phase::kBlockUpEnd;
    out.send(e);
    return;
  }
  if (b0 == 0xA1) {  // the client's end response
    if (phase_ != Phase::kBlockUpEnd) return send_abort(index_, sub_, SdoAbort::kCommandSpecifier, out);
    phase_ = Phase::kIdle;
    return;
  }
  send_abort(index, sub, SdoAbort::kCommandSpecifier, out);
}

}  // namespace canmotion::canopen
