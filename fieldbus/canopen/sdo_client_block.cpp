// SdoClient: block download and block upload (CiA 301 §7.2.4.3.9-.16), the
// CRC, resends after a lost segment, and the fallback to segmented transfer
// when the server refuses block transfer. Realtime-safe: no allocation, the
// data stays where the caller keeps it (download_ref(), upload_into()).
#include <algorithm>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/sdo_client.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"

namespace canmotion::canopen {

namespace {
// Command bytes (bits 7..5 specifier, low bits as CiA 301 numbers them).
constexpr std::uint8_t kCrcSupported = 0x04;         // cc / sc
constexpr std::uint8_t kBlockSizeIndicated = 0x02;   // s
constexpr std::uint8_t kDownInitiate = 0xC0;         // ccs 6, cs 0
constexpr std::uint8_t kDownEnd = 0xC1;              // ccs 6, cs 1; n in bits 4..2
constexpr std::uint8_t kUpInitiate = 0xA0;           // ccs 5, cs 0
constexpr std::uint8_t kUpStart = 0xA3;              // ccs 5, cs 3
constexpr std::uint8_t kUpAck = 0xA2;                // ccs 5, cs 2
constexpr std::uint8_t kUpEndResponse = 0xA1;        // ccs 5, cs 1
constexpr std::uint8_t kLastSeg = 0x80;              // c bit of a sub-block segment
constexpr std::size_t kSeg = 7;                      // data bytes per segment

[[nodiscard]] bool is(const can::Frame& f, std::uint8_t mask, std::uint8_t value) noexcept {
  return (f.data[0] & mask) == value;
}
}  // namespace

void SdoClient::start_block(std::int64_t now_ns) noexcept {
  res_.block = true;
  blksize_ = 0;
  seqno_ = 0;
  sub_start_ = 0;
  last_sent_ = false;
  got_last_ = false;
  server_crc_ = false;
  if (cur_.upload) {
    phase_ = Phase::kBlockUpInit;
    can::Frame f = sdo::initiate_frame(cob::sdo_rx(node_), kUpInitiate | kCrcSupported, cur_.index, cur_.sub);
    f.data[4] = kSdoBlockSize;
    f.data[5] = 0;  // pst 0: no switch to segmented by the server
    queue_tx(f);
  } else {
    phase_ = Phase::kBlockDownInit;
    queue_tx(sdo::initiate_frame(cob::sdo_rx(node_), kDownInitiate | kCrcSupported | kBlockSizeIndicated, cur_.index,
                                 cur_.sub, static_cast<std::uint32_t>(src_len())));
  }
  (void)now_ns;
}

void SdoClient::fall_back_to_segmented(std::int64_t now_ns) noexcept {
  block_refused_ = true;  // this server is not asked for block transfer again
  const std::int64_t started = res_.started_ns;
  const bool retried = res_.retried;
  start(cur_, now_ns);
  res_.started_ns = started;
  res_.retried = retried;
  res_.fell_back = true;
}

void SdoClient::send_block_segments(std::int64_t now_ns, FrameSink& out) noexcept {
  const std::size_t len = src_len();
  while (seqno_ < blksize_ && !last_sent_) {
    const std::size_t off = sub_start_ + static_cast<std::size_t>(seqno_) * kSeg;
    const std::size_t n = std::min(kSeg, len - off);
    const bool last = off + n >= len;
    can::Frame f;
    f.id = cob::sdo_rx(node_);
    f.len = 8;
    f.data[0] = static_cast<std::uint8_t>((last ? kLastSeg : 0) | (seqno_ + 1));
    std::copy_n(src() + off, n, f.data.begin() + 1);
    if (!out.send(f)) return;  // transmit queue full: the rest goes next step
    ++seqno_;
    last_tx_ns_ = now_ns;
    last_sent_ = last;
  }
  phase_ = Phase::kBlockDownAck;
}

void SdoClient::on_block_upload_segment(const can::Frame& f, std::int64_t now_ns) noexcept {
  const auto seq = static_cast<std::uint8_t>(f.data[0] & 0x7F);
  const bool c = (f.data[0] & kLastSeg) != 0;
  last_tx_ns_ = now_ns;  // the server is sending: the timeout counts from its latest segment
  if (seq == seqno_ + 1 && !got_last_) {  // in order; a lost one's successors are dropped until the resend
    if (c) {
      std::copy_n(f.data.begin() + 1, kSeg, last_seg_.begin());  // how many count: the end frame says
      got_last_ = true;
    } else {
      if (offset_ + kSeg > dst_cap()) return abort_transfer(SdoAbort::kOutOfMemory, now_ns);
      std::copy_n(f.data.begin() + 1, kSeg, dst() + offset_);
      offset_ += kSeg;
    }
    seqno_ = seq;
  }
  if (!c && seq < blksize_) return;
  // End of the sub-block: acknowledge the last segment received in order;
  // the server starts the next sub-block after it (a resend if one was lost).
  can::Frame ack = sdo::initiate_frame(cob::sdo_rx(node_), kUpAck, 0, 0);
  ack.data[1] = seqno_;
  ack.data[2] = kSdoBlockSize;
  queue_tx(ack);
  blksize_ = kSdoBlockSize;
  seqno_ = 0;
  if (got_last_) phase_ = Phase::kBlockUpEnd;
}

bool SdoClient::on_block_frame(const can::Frame& fin, std::int64_t now_ns) noexcept {
  can::Frame f = fin;  // a short reply: the bytes it lacks read as 0
  std::fill(f.data.begin() + f.len, f.data.begin() + 8, std::uint8_t{0});
  const auto mux_ok = [&] {
    return static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8)) == cur_.index && f.data[3] == cur_.sub;
  };
  switch (phase_) {
    case Phase::kBlockUpSub:
      if (f.data[0] == 0x80) return false;  // seqno 0 is no segment: an abort
      on_block_upload_segment(f, now_ns);
      return true;
    case Phase::kBlockDownInit:
      if (!is(f, 0xE3, 0xA0)) return false;  // scs 5, ss 0 (an abort or a stray frame: the common path)
      if (!mux_ok()) return true;            // a late answer to an earlier transfer
      server_crc_ = (f.data[0] & kCrcSupported) != 0;
      blksize_ = f.data[4];
      if (blksize_ == 0 || blksize_ > 127) return abort_transfer(SdoAbort::kBlockSize, now_ns), true;
      phase_ = Phase::kBlockDownSub;  // segments go out at step()
      return true;
    case Phase::kBlockDownAck: {
      if (!is(f, 0xE3, 0xA2)) return false;  // scs 5, ss 2: block ack
      const std::uint8_t ackseq = f.data[1];
      if (ackseq > seqno_) return abort_transfer(SdoAbort::kSequenceNumber, now_ns), true;
      if (last_sent_ && ackseq == seqno_) {
        const std::size_t len = src_len();
        const std::size_t in_last = len - (sub_start_ + (static_cast<std::size_t>(seqno_) - 1) * kSeg);
        const std::uint16_t crc = server_crc_ ? sdo_crc16(std::span<const std::uint8_t>(src(), len)) : 0;
        can::Frame e = sdo::initiate_frame(cob::sdo_rx(node_), static_cast<std::uint8_t>(kDownEnd | ((kSeg - in_last) << 2)), 0, 0);
        e.data[1] = static_cast<std::uint8_t>(crc & 0xFF);
        e.data[2] = static_cast<std::uint8_t>(crc >> 8);
        e.data[3] = 0;
        queue_tx(e);
        phase_ = Phase::kBlockDownEnd;
        return true;
      }
      // Next sub-block from the first segment not acknowledged (a resend
      // when the server lost one), with the block size it asks for now.
      sub_start_ += static_cast<std::size_t>(ackseq) * kSeg;
      last_sent_ = false;
      seqno_ = 0;
      blksize_ = f.data[2];
      if (blksize_ == 0 || blksize_ > 127) return abort_transfer(SdoAbort::kBlockSize, now_ns), true;
      phase_ = Phase::kBlockDownSub;
      return true;
    }
    case Phase::kBlockDownEnd:
      if (!is(f, 0xE3, 0xA1)) return false;  // scs 5, ss 1: end response
      finish(SdoAbort::kNone, false, now_ns);
      return true;
    case Phase::kBlockUpInit:
      if (!is(f, 0xE1, 0xC0)) return false;  // scs 6, ss 0
      if (!mux_ok()) return true;
      server_crc_ = (f.data[0] & kCrcSupported) != 0;
      size_known_ = (f.data[0] & kBlockSizeIndicated) != 0;
      expected_ = static_cast<std::uint32_t>(f.data[4] | (f.data[5] << 8) | (f.data[6] << 16)) |
                  (static_cast<std::uint32_t>(f.data[7]) << 24);
      if (size_known_ && expected_ > dst_cap()) return abort_transfer(SdoAbort::kOutOfMemory, now_ns), true;
      blksize_ = kSdoBlockSize;
      seqno_ = 0;
      queue_tx(sdo::initiate_frame(cob::sdo_rx(node_), kUpStart, 0, 0));
      phase_ = Phase::kBlockUpSub;
      return true;
    case Phase::kBlockUpEnd: {
      if (!is(f, 0xE3, 0xC1)) return false;  // scs 6, ss 1: end
      const std::size_t valid = kSeg - ((f.data[0] >> 2) & 7);
      if (offset_ + valid > dst_cap()) return abort_transfer(SdoAbort::kOutOfMemory, now_ns), true;
      std::copy_n(last_seg_.begin(), valid, dst() + offset_);
      offset_ += valid;
      if (size_known_ && offset_ != expected_) {
        return abort_transfer(offset_ > expected_ ? SdoAbort::kLengthTooHigh : SdoAbort::kLengthTooLow, now_ns), true;
      }
      const auto crc = static_cast<std::uint16_t>(f.data[1] | (f.data[2] << 8));
      if (server_crc_ && crc != sdo_crc16(std::span<const std::uint8_t>(dst(), offset_))) {
        return abort_transfer(SdoAbort::kCrc, now_ns), true;
      }
      res_.bytes = static_cast<std::uint32_t>(offset_);
      if (cur_.dest == nullptr) res_.size = static_cast<std::uint16_t>(offset_);
      queue_tx(sdo::initiate_frame(cob::sdo_rx(node_), kUpEndResponse, 0, 0));
      finish(SdoAbort::kNone, false, now_ns);
      return true;
    }
    default: return false;
  }
}

}  // namespace canmotion::canopen
