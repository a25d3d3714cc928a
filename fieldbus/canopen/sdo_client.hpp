#pragma once
/// \file
/// Non-blocking SDO client (CiA 301 §7.2.4): expedited and segmented upload
/// and download, toggle bit checked, every abort reported with its code, a
/// per-node timeout (a transfer may have its own), short replies taken as
/// lely takes them, transfers queued and run one at a time. It is stepped
/// each cycle: on_frame() feeds the server's responses, step() sends what is
/// due and checks the timeout, poll() hands out finished transfers.
/// All member functions except the constructor are realtime-safe.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>
#include <vector>

#include "fieldbus/can/frame.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"

namespace canmotion::canopen {

/// Largest value a queued download may carry (configuration values are 1-4
/// bytes; 64 leaves room for short strings/domains).
inline constexpr std::size_t kSdoMaxDownload = 64;
/// Largest value an upload may return (0x1008 device names, short strings).
inline constexpr std::size_t kSdoMaxUpload = 256;
/// Segments per sub-block the client asks for in a block upload (CiA 301
/// allows 1..127; 127 is what python-canopen and CANopenNode ask for).
inline constexpr std::uint8_t kSdoBlockSize = 127;

/// How a transfer goes on the wire. kAuto: block for data longer than
/// kSdoMaxDownload bytes (block upload for upload_into()), else expedited or
/// segmented. A server that refuses a block initiate with 0x05040001 gets the
/// same transfer segmented (a drive may lack block transfer).
enum class Transfer : std::uint8_t { kAuto, kSegmented, kBlock };

/// CRC-16 of CiA 301 §7.2.4.3.16 (CCITT polynomial 0x1021, initial value 0,
/// no reflection: CRC-16/XMODEM; check value of "123456789" is 0x31C3),
/// continuing from `crc`. Realtime-safe.
[[nodiscard]] constexpr std::uint16_t sdo_crc16(std::span<const std::uint8_t> data, std::uint16_t crc = 0) noexcept {
  for (const std::uint8_t b : data) {
    crc = static_cast<std::uint16_t>(crc ^ (static_cast<std::uint16_t>(b) << 8));
    for (int i = 0; i < 8; ++i)
      crc = static_cast<std::uint16_t>((crc & 0x8000u) != 0 ? (crc << 1) ^ 0x1021u : crc << 1);
  }
  return crc;
}

/// A finished transfer.
struct SdoResult {
  std::uint32_t tag = 0;     ///< caller's tag from download()/upload()
  std::uint8_t node = 0;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  bool upload = false;
  SdoAbort abort = SdoAbort::kNone;  ///< kNone = success
  bool aborted_by_server = false;    ///< true: the server sent the abort; false: the client aborted (timeout, protocol)
  std::uint16_t abort_index = 0;     ///< aborted_by_server: the index/sub the abort frame named (may differ from index/sub)
  std::uint8_t abort_sub = 0;
  bool segmented = false;
  bool block = false;        ///< the transfer went as a block transfer
  bool fell_back = false;    ///< a block initiate was refused (0x05040001) and the transfer went segmented
  bool retried = false;      ///< the first try timed out and the transfer was started once more
  std::uint32_t bytes = 0;   ///< bytes transferred (download_ref(): sent; upload_into(): written to the destination)
  std::int64_t started_ns = 0;
  std::int64_t finished_ns = 0;
  std::uint16_t size = 0;  ///< bytes in `data` (uploads)
  std::array<std::uint8_t, kSdoMaxUpload> data{};

  [[nodiscard]] bool ok() const noexcept { return abort == SdoAbort::kNone; }
  /// The first up to 4 bytes as a little-endian unsigned value.
  [[nodiscard]] std::uint32_t u32() const noexcept {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < size && i < 4; ++i) v |= static_cast<std::uint32_t>(data[i]) << (8 * i);
    return v;
  }
};

class SdoClient {
 public:
  /// Transfers waiting to run: a drive's boot configuration is ~30 writes.
  static constexpr std::size_t kQueueCapacity = 64;
  /// Finished transfers not yet taken with poll().
  static constexpr std::size_t kResultCapacity = 64;

  /// Set-up (allocates the queues). `timeout_ns` is the per-response timeout.
  explicit SdoClient(std::uint8_t node = 1, std::int64_t timeout_ns = 500'000'000);

  void set_node(std::uint8_t node) noexcept { node_ = node; }
  [[nodiscard]] std::uint8_t node() const noexcept { return node_; }
  void set_timeout(std::int64_t ns) noexcept { timeout_ns_ = ns; }
  [[nodiscard]] std::int64_t timeout() const noexcept { return timeout_ns_; }

  /// Queue a write of `data` (1..kSdoMaxDownload bytes; <= 4 bytes go
  /// expedited, longer ones segmented). `timeout_ns` > 0 is this transfer's
  /// per-response timeout instead of the client's (a store to 0x1010 takes
  /// seconds). False if the queue is full or the data too long.
  bool download(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data, std::uint32_t tag = 0,
                std::int64_t timeout_ns = 0) noexcept;
  /// Queue a write of an integer value in its natural size.
  template <typename T>
    requires std::is_integral_v<T>
  bool download_value(std::uint16_t index, std::uint8_t sub, T value, std::uint32_t tag = 0) noexcept {
    std::array<std::uint8_t, sizeof(T)> b{};
    using U = std::make_unsigned_t<T>;
    const auto u = static_cast<U>(value);
    for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<std::uint8_t>((u >> (8 * i)) & 0xFFu);
    return download(index, sub, b, tag);
  }
  /// Queue a read (`timeout_ns` as for download()). False if the queue is full.
  bool upload(std::uint16_t index, std::uint8_t sub, std::uint32_t tag = 0, std::int64_t timeout_ns = 0) noexcept;

  /// Queue a write of `data` of any length (firmware, parameter blocks,
  /// DOMAIN values) that the caller keeps alive and unchanged until the
  /// transfer's result is polled: nothing is copied, nothing allocated.
  /// `mode` as Transfer says. False if the queue is full or `data` is empty.
  bool download_ref(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data, std::uint32_t tag = 0,
                    std::int64_t timeout_ns = 0, Transfer mode = Transfer::kAuto) noexcept;
  /// Queue a read into `dest` (kept alive by the caller until the result is
  /// polled; SdoResult::bytes says how much was written, SdoResult::data is
  /// not used). A value longer than `dest` aborts with 0x05040005. kAuto goes
  /// as a block upload. False if the queue is full or `dest` is empty.
  bool upload_into(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> dest, std::uint32_t tag = 0,
                   std::int64_t timeout_ns = 0, Transfer mode = Transfer::kAuto) noexcept;

  /// Feed a frame from the server (ID 0x580 + node; other frames are ignored).
  /// An initiate answer naming another object than the running transfer's
  /// (a late answer to one that timed out or was cancelled) is ignored too.
  /// A reply shorter than 8 bytes is taken with the bytes it lacks as 0 (as
  /// lely's client does) when it holds the data it announces (else the
  /// transfer aborts with 0x06070013); an abort without its code counts as
  /// 0x08000000.
  void on_frame(const can::Frame& f, std::int64_t now_ns) noexcept;
  /// Start the next transfer, send pending segments, check the timeout.
  void step(std::int64_t now_ns, FrameSink& out) noexcept;
  /// Take the oldest finished transfer; false if none.
  bool poll(SdoResult& out) noexcept;
  /// Take the oldest finished transfer with `tag`, leaving the others in
  /// order; false if none. Lets several users share one client.
  bool poll_tag(std::uint32_t tag, SdoResult& out) noexcept;

  /// Drop all queued transfers; a running one is aborted (abort code
  /// kGeneral sent to the server) at the next step().
  void cancel_all() noexcept;

  /// True when nothing is running or queued.
  [[nodiscard]] bool idle() const noexcept { return phase_ == Phase::kIdle && queue_count_ == 0 && !tx_pending_; }
  [[nodiscard]] std::size_t queued() const noexcept { return queue_count_; }
  /// Finished transfers waiting for poll()/poll_tag().
  [[nodiscard]] std::size_t results() const noexcept { return result_count_; }
  [[nodiscard]] std::uint64_t completed() const noexcept { return completed_; }
  [[nodiscard]] std::uint64_t failed() const noexcept { return failed_; }

 private:
  enum class Phase : std::uint8_t {
    kIdle, kInitDownload, kDownloadSegment, kInitUpload, kUploadSegment,
    kBlockDownInit, kBlockDownSub, kBlockDownAck, kBlockDownEnd,  // block download (CiA 301 §7.2.4.3.9-.12)
    kBlockUpInit, kBlockUpSub, kBlockUpEnd,                       // block upload (§7.2.4.3.13-.16)
    kRetry,  // timed out once: the abort goes out, then the transfer starts again
  };
  struct Request {
    std::uint32_t tag;
    std::int64_t timeout_ns;  // 0: the client's
    std::uint16_t index;
    std::uint8_t sub;
    bool upload;
    bool block;  // go as a block transfer
    std::uint8_t len;
    std::array<std::uint8_t, kSdoMaxDownload> data;
    const std::uint8_t* ref = nullptr;  // download_ref(): caller's data; upload_into(): caller's destination
    std::uint8_t* dest = nullptr;
    std::uint32_t ref_len = 0;  // bytes at ref / room at dest
  };
  [[nodiscard]] const std::uint8_t* src() const noexcept { return cur_.ref != nullptr ? cur_.ref : cur_.data.data(); }
  [[nodiscard]] std::size_t src_len() const noexcept { return cur_.ref != nullptr ? cur_.ref_len : cur_.len; }
  [[nodiscard]] std::uint8_t* dst() noexcept { return cur_.dest != nullptr ? cur_.dest : res_.data.data(); }
  [[nodiscard]] std::size_t dst_cap() const noexcept { return cur_.dest != nullptr ? cur_.ref_len : kSdoMaxUpload; }
  /// The next free queue slot with the fields every request has set (the
  /// rest cleared), counted as queued; nullptr when the queue is full.
  Request* enqueue(std::uint16_t index, std::uint8_t sub, bool upload, std::uint32_t tag, std::int64_t timeout_ns) noexcept;
  void start(const Request& r, std::int64_t now_ns) noexcept;
  void start_block(std::int64_t now_ns) noexcept;
  bool on_block_frame(const can::Frame& f, std::int64_t now_ns) noexcept;
  void on_block_upload_segment(const can::Frame& f, std::int64_t now_ns) noexcept;
  void send_block_segments(std::int64_t now_ns, FrameSink& out) noexcept;
  void fall_back_to_segmented(std::int64_t now_ns) noexcept;
  void finish(SdoAbort abort, bool by_server, std::int64_t now_ns) noexcept;
  void abort_transfer(SdoAbort abort, std::int64_t now_ns) noexcept;
  void queue_tx(const can::Frame& f) noexcept {
    tx_ = f;
    tx_pending_ = true;
    tx_refused_since_ns_ = -1;
  }
  void send_next_download_segment() noexcept;
  [[nodiscard]] std::int64_t timeout_of(const Request& r) const noexcept {
    return r.timeout_ns > 0 ? r.timeout_ns : timeout_ns_;
  }

  std::uint8_t node_;
  std::int64_t timeout_ns_;
  std::vector<Request> queue_;
  std::size_t queue_head_ = 0;
  std::size_t queue_count_ = 0;
  std::vector<SdoResult> results_;
  std::size_t result_head_ = 0;
  std::size_t result_count_ = 0;

  Phase phase_ = Phase::kIdle;
  Request cur_{};
  SdoResult res_{};
  bool toggle_ = false;
  std::size_t offset_ = 0;     // bytes already sent (download) / received (upload)
  std::uint32_t expected_ = 0; // announced upload size (0 = not indicated)
  bool size_known_ = false;
  std::int64_t last_tx_ns_ = 0;
  bool tx_pending_ = false;
  std::int64_t tx_refused_since_ns_ = -1;  // the pending frame's first refused send (-1: none)
  bool cancel_pending_ = false;
  can::Frame tx_{};
  // Block transfer state.
  bool block_refused_ = false;    // the server refused a block initiate once: later transfers go segmented
  bool server_crc_ = false;       // the server supports the CRC (both sides must for it to be used)
  std::uint8_t blksize_ = 0;      // segments in the current sub-block
  std::uint8_t seqno_ = 0;        // download: last segment sent; upload: last in-order segment received
  std::size_t sub_start_ = 0;     // download: data offset of the current sub-block's first segment
  bool last_sent_ = false;        // download: the segment with the c bit is in this sub-block
  bool got_last_ = false;         // upload: the segment with the c bit arrived in order
  std::array<std::uint8_t, 7> last_seg_{};  // upload: that segment's bytes until the end frame says how many count
  std::uint64_t completed_ = 0;
  std::uint64_t failed_ = 0;
};

}  // namespace canmotion::canopen
