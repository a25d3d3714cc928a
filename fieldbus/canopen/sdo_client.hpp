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
  enum class Phase : std::uint8_t { kIdle, kInitDownload, kDownloadSegment, kInitUpload, kUploadSegment };
  struct Request {
    std::uint32_t tag;
    std::int64_t timeout_ns;  // 0: the client's
    std::uint16_t index;
    std::uint8_t sub;
    bool upload;
    std::uint8_t len;
    std::array<std::uint8_t, kSdoMaxDownload> data;
  };
  void start(const Request& r, std::int64_t now_ns) noexcept;
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
  std::uint64_t completed_ = 0;
  std::uint64_t failed_ = 0;
};

}  // namespace canmotion::canopen
