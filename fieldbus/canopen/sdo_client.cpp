#include "fieldbus/canopen/sdo_client.hpp"

#include <algorithm>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"

namespace canmotion::canopen {

namespace {
can::Frame sdo_frame(std::uint8_t node, std::uint8_t b0, std::uint16_t index, std::uint8_t sub,
                     std::uint32_t value = 0) noexcept {
  return sdo::initiate_frame(cob::sdo_rx(node), b0, index, sub, value);
}
}  // namespace

SdoClient::SdoClient(std::uint8_t node, std::int64_t timeout_ns)
    : node_(node), timeout_ns_(timeout_ns), queue_(kQueueCapacity), results_(kResultCapacity) {}

SdoClient::Request* SdoClient::enqueue(std::uint16_t index, std::uint8_t sub, bool upload, std::uint32_t tag,
                                      std::int64_t timeout_ns) noexcept {
  if (queue_count_ == kQueueCapacity) return nullptr;
  Request& r = queue_[(queue_head_ + queue_count_) % kQueueCapacity];
  r.tag = tag;
  r.timeout_ns = timeout_ns;
  r.index = index;
  r.sub = sub;
  r.upload = upload;
  r.block = false;
  r.len = 0;
  r.ref = nullptr;
  r.dest = nullptr;
  r.ref_len = 0;
  ++queue_count_;
  return &r;
}

bool SdoClient::download(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data, std::uint32_t tag,
                         std::int64_t timeout_ns) noexcept {
  if (data.empty() || data.size() > kSdoMaxDownload) return false;
  Request* r = enqueue(index, sub, false, tag, timeout_ns);
  if (r == nullptr) return false;
  r->len = static_cast<std::uint8_t>(data.size());
  std::copy(data.begin(), data.end(), r->data.begin());
  return true;
}

bool SdoClient::upload(std::uint16_t index, std::uint8_t sub, std::uint32_t tag, std::int64_t timeout_ns) noexcept {
  return enqueue(index, sub, true, tag, timeout_ns) != nullptr;
}

bool SdoClient::download_ref(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data,
                             std::uint32_t tag, std::int64_t timeout_ns, Transfer mode) noexcept {
  if (data.empty() || data.size() > 0xFFFFFFFFu) return false;
  Request* r = enqueue(index, sub, false, tag, timeout_ns);
  if (r == nullptr) return false;
  r->block = mode == Transfer::kBlock || (mode == Transfer::kAuto && data.size() > kSdoMaxDownload);
  r->ref = data.data();
  r->ref_len = static_cast<std::uint32_t>(data.size());
  return true;
}

bool SdoClient::upload_into(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> dest, std::uint32_t tag,
                            std::int64_t timeout_ns, Transfer mode) noexcept {
  if (dest.empty() || dest.size() > 0xFFFFFFFFu) return false;
  Request* r = enqueue(index, sub, true, tag, timeout_ns);
  if (r == nullptr) return false;
  r->block = mode != Transfer::kSegmented;
  r->dest = dest.data();
  r->ref_len = static_cast<std::uint32_t>(dest.size());
  return true;
}

void SdoClient::cancel_all() noexcept {
  queue_count_ = 0;
  if (phase_ != Phase::kIdle) cancel_pending_ = true;
}

void SdoClient::start(const Request& r, std::int64_t now_ns) noexcept {
  cur_ = r;
  res_.block = false;
  res_.fell_back = false;
  res_.retried = false;
  res_.bytes = 0;
  res_.tag = r.tag;
  res_.node = node_;
  res_.index = r.index;
  res_.sub = r.sub;
  res_.upload = r.upload;
  res_.abort = SdoAbort::kNone;
  res_.aborted_by_server = false;
  res_.abort_index = 0;
  res_.abort_sub = 0;
  res_.segmented = false;
  res_.started_ns = now_ns;
  res_.size = 0;
  toggle_ = false;
  offset_ = 0;
  expected_ = 0;
  size_known_ = false;
  if (r.block && !block_refused_) {
    start_block(now_ns);
  } else if (r.upload) {
    phase_ = Phase::kInitUpload;
    queue_tx(sdo_frame(node_, 0x40, r.index, r.sub));
  } else if (src_len() <= 4) {
    phase_ = Phase::kInitDownload;
    const auto n = static_cast<std::uint8_t>(4 - src_len());
    can::Frame f = sdo_frame(node_, static_cast<std::uint8_t>(0x20 | (n << 2) | sdo::kExpedited | sdo::kSizeIndicated),
                             r.index, r.sub);
    std::copy_n(src(), src_len(), f.data.begin() + 4);
    queue_tx(f);
  } else {
    phase_ = Phase::kInitDownload;
    res_.segmented = true;
    queue_tx(sdo_frame(node_, 0x21, r.index, r.sub, static_cast<std::uint32_t>(src_len())));  // size indicated
  }
}

void SdoClient::finish(SdoAbort abort, bool by_server, std::int64_t now_ns) noexcept {
  res_.abort = abort;
  res_.aborted_by_server = by_server;
  res_.finished_ns = now_ns;
  if (abort == SdoAbort::kNone && !cur_.upload) res_.bytes = static_cast<std::uint32_t>(src_len());  // a download sent it all
  if (abort == SdoAbort::kNone) {
    ++completed_;
  } else {
    ++failed_;
  }
  if (result_count_ == kResultCapacity) {  // overwrite the oldest: the caller stopped polling
    result_head_ = (result_head_ + 1) % kResultCapacity;
    --result_count_;
  }
  results_[(result_head_ + result_count_) % kResultCapacity] = res_;
  ++result_count_;
  phase_ = Phase::kIdle;
}

void SdoClient::abort_transfer(SdoAbort abort, std::int64_t now_ns) noexcept {
  queue_tx(sdo::abort_frame(cob::sdo_rx(node_), cur_.index, cur_.sub, static_cast<std::uint32_t>(abort)));
  finish(abort, false, now_ns);
}

void SdoClient::send_next_download_segment() noexcept {
  const std::size_t remaining = src_len() - offset_;
  const std::size_t n = std::min<std::size_t>(7, remaining);
  const bool last = n == remaining;
  queue_tx(sdo::segment_frame(cob::sdo_rx(node_), toggle_, std::span<const std::uint8_t>(src() + offset_, n), last));
  offset_ += n;
}

void SdoClient::on_frame(const can::Frame& f, std::int64_t now_ns) noexcept {
  if (f.id != cob::sdo_tx(node_) || f.extended() || f.remote()) return;
  if (phase_ == Phase::kIdle || phase_ == Phase::kRetry) return;  // late or unsolicited response
  if (f.len == 0 || f.len > 8) {
    abort_transfer(SdoAbort::kCommandSpecifier, now_ns);
    return;
  }
  if (on_block_frame(f, now_ns)) return;
  // A reply shorter than 8 bytes is taken as lely takes it: the bytes it
  // lacks read as 0, as long as it carries what its command needs (checked
  // below: the data an expedited or segment reply announces; an abort
  // without its code is a general error).
  can::Frame padded = f;
  std::fill(padded.data.begin() + f.len, padded.data.begin() + 8, std::uint8_t{0});
  padded.len = 8;
  const sdo::SdoFrame s = sdo::decode(padded, true);
  if (s.kind == sdo::SdoFrameKind::kAbort) {
    const SdoAbort code = f.len >= 8 ? static_cast<SdoAbort>(s.abort_code) : SdoAbort::kGeneral;
    if ((phase_ == Phase::kBlockDownInit || phase_ == Phase::kBlockUpInit) && code == SdoAbort::kCommandSpecifier) {
      return fall_back_to_segmented(now_ns);  // the server lacks block transfer
    }
    // One transfer at a time per server: an abort now is for it, whatever
    // index/sub it names (some servers name another or none). Its code is
    // the answer, not a timeout later; what it named is kept.
    res_.abort_index = s.index;
    res_.abort_sub = s.sub;
    finish(code, true, now_ns);
    return;
  }
  // An initiate answer naming another object while this transfer waits for
  // its own: a late answer to an earlier transfer that timed out or was
  // cancelled (cancel_all()) while the server's answer was on its way. Not
  // this one's: ignored, its answer (or its timeout) is still to come.
  const bool late = (phase_ == Phase::kInitDownload || phase_ == Phase::kInitUpload) &&
                    (s.kind == sdo::SdoFrameKind::kInitiateDownloadResponse ||
                     s.kind == sdo::SdoFrameKind::kInitiateUploadResponse) &&
                    f.len >= 4 && (s.index != cur_.index || s.sub != cur_.sub);  // (a shorter one names nothing)
  if (late) return;
  switch (phase_) {
    case Phase::kInitDownload:
      if (s.kind != sdo::SdoFrameKind::kInitiateDownloadResponse) return abort_transfer(SdoAbort::kCommandSpecifier, now_ns);
      if (src_len() <= 4) return finish(SdoAbort::kNone, false, now_ns);
      phase_ = Phase::kDownloadSegment;
      toggle_ = false;
      send_next_download_segment();
      return;
    case Phase::kDownloadSegment:
      if (s.kind != sdo::SdoFrameKind::kDownloadSegmentResponse) return abort_transfer(SdoAbort::kCommandSpecifier, now_ns);
      if (s.toggle != toggle_) return abort_transfer(SdoAbort::kToggleBit, now_ns);
      if (offset_ >= src_len()) return finish(SdoAbort::kNone, false, now_ns);
      toggle_ = !toggle_;
      send_next_download_segment();
      return;
    case Phase::kInitUpload:
      if (s.kind != sdo::SdoFrameKind::kInitiateUploadResponse) return abort_transfer(SdoAbort::kCommandSpecifier, now_ns);
      if (s.expedited) {
        // The bytes it announces must be there (without a size: up to 4, as many as it has).
        if (f.len < 4 + (s.size_indicated ? s.data_len : 1)) return abort_transfer(SdoAbort::kLengthTooLow, now_ns);
        const std::uint8_t n = s.size_indicated ? s.data_len : static_cast<std::uint8_t>(f.len - 4);
        if (n > dst_cap()) return abort_transfer(SdoAbort::kOutOfMemory, now_ns);
        std::copy_n(s.data, n, dst());
        res_.bytes = n;
        if (cur_.dest == nullptr) res_.size = n;
        return finish(SdoAbort::kNone, false, now_ns);
      }
      res_.segmented = true;
      size_known_ = s.size_indicated;
      expected_ = s.size;
      if (size_known_ && expected_ > dst_cap()) return abort_transfer(SdoAbort::kOutOfMemory, now_ns);
      phase_ = Phase::kUploadSegment;
      toggle_ = false;
      queue_tx(sdo_frame(node_, 0x60, 0, 0));
      tx_.data[1] = tx_.data[2] = tx_.data[3] = 0;
      return;
    case Phase::kUploadSegment: {
      if (s.kind != sdo::SdoFrameKind::kUploadSegmentResponse) return abort_transfer(SdoAbort::kCommandSpecifier, now_ns);
      if (s.toggle != toggle_) return abort_transfer(SdoAbort::kToggleBit, now_ns);
      if (f.len < 1 + s.data_len) return abort_transfer(SdoAbort::kLengthTooLow, now_ns);  // announced, not sent
      if (offset_ + s.data_len > dst_cap()) return abort_transfer(SdoAbort::kOutOfMemory, now_ns);
      std::copy_n(s.data, s.data_len, dst() + offset_);
      offset_ += s.data_len;
      res_.bytes = static_cast<std::uint32_t>(offset_);
      if (cur_.dest == nullptr) res_.size = static_cast<std::uint16_t>(offset_);
      if (s.last) {
        if (size_known_ && offset_ != expected_) {
          return abort_transfer(offset_ > expected_ ? SdoAbort::kLengthTooHigh : SdoAbort::kLengthTooLow, now_ns);
        }
        return finish(SdoAbort::kNone, false, now_ns);
      }
      toggle_ = !toggle_;
      queue_tx(sdo_frame(node_, static_cast<std::uint8_t>(0x60 | (toggle_ ? sdo::kToggle : 0)), 0, 0));
      return;
    }
    default: return;  // idle, retry; block phases are handled by on_block_frame()
  }
}

void SdoClient::step(std::int64_t now_ns, FrameSink& out) noexcept {
  if (cancel_pending_) {
    cancel_pending_ = false;
    if (phase_ != Phase::kIdle) abort_transfer(SdoAbort::kGeneral, now_ns);
  }
  if (phase_ != Phase::kIdle && phase_ != Phase::kRetry && !tx_pending_ && now_ns - last_tx_ns_ > timeout_of(cur_)) {
    if (res_.retried) {
      abort_transfer(SdoAbort::kTimeout, now_ns);
    } else {
      // One retry: abort the first try (0x05040000, so the server drops
      // it), then start the same transfer from its initiate next step.
      queue_tx(sdo::abort_frame(cob::sdo_rx(node_), cur_.index, cur_.sub, static_cast<std::uint32_t>(SdoAbort::kTimeout)));
      phase_ = Phase::kRetry;
    }
  } else if (phase_ == Phase::kRetry && !tx_pending_) {
    const SdoResult first = res_;
    start(cur_, now_ns);
    res_.started_ns = first.started_ns;
    res_.fell_back = first.fell_back;
    res_.retried = true;
  }
  if (phase_ == Phase::kIdle && !tx_pending_ && queue_count_ > 0) {
    const Request r = queue_[queue_head_];
    queue_head_ = (queue_head_ + 1) % kQueueCapacity;
    --queue_count_;
    start(r, now_ns);
  }
  if (tx_pending_) {
    // A frame the transmit queue refused (full) is tried again next cycle;
    // the transfer times out when it could not be sent for the SDO timeout.
    if (out.send(tx_)) {
      tx_pending_ = false;
      last_tx_ns_ = now_ns;
      tx_refused_since_ns_ = -1;
      if (phase_ == Phase::kBlockDownSub) send_block_segments(now_ns, out);
    } else if (tx_refused_since_ns_ < 0) {
      tx_refused_since_ns_ = now_ns;
    } else if (now_ns - tx_refused_since_ns_ > timeout_of(cur_) && phase_ != Phase::kIdle) {
      tx_pending_ = false;
      finish(SdoAbort::kTimeout, false, now_ns);  // (the server never got the request: no abort frame)
    } else if (now_ns - tx_refused_since_ns_ > timeout_ns_) {
      tx_pending_ = false;  // an abort frame of ours that cannot go out: dropped
    }
  } else if (phase_ == Phase::kBlockDownSub) {
    send_block_segments(now_ns, out);
  }
}

bool SdoClient::poll(SdoResult& out) noexcept {
  if (result_count_ == 0) return false;
  out = results_[result_head_];
  result_head_ = (result_head_ + 1) % kResultCapacity;
  --result_count_;
  return true;
}

bool SdoClient::poll_tag(std::uint32_t tag, SdoResult& out) noexcept {
  for (std::size_t i = 0; i < result_count_; ++i) {
    const std::size_t at = (result_head_ + i) % kResultCapacity;
    if (results_[at].tag != tag) continue;
    out = results_[at];
    // Close the gap: move the later results one place towards the head.
    for (std::size_t j = i; j + 1 < result_count_; ++j)
      results_[(result_head_ + j) % kResultCapacity] = results_[(result_head_ + j + 1) % kResultCapacity];
    --result_count_;
    return true;
  }
  return false;
}

}  // namespace canmotion::canopen
