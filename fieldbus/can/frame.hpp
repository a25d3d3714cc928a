#pragma once
/// \file
/// The CAN frame type shared by every layer (transports, protocol core,
/// emulator, trace tools). Fixed size, trivially copyable, no allocation.
///
/// CAN FD: `kMaxPayload` is the only capacity; FD adds the FDF/BRS/ESI flags
/// below and raises the capacity to 64 with `len` already a byte count, so the
/// codec and transports need no structural change.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace canmotion::can {

/// Classic CAN payload capacity in bytes.
inline constexpr std::size_t kMaxPayload = 8;

/// Flag bits of Frame::flags.
enum FrameFlag : std::uint8_t {
  kExtended = 0x01,  ///< 29-bit identifier (EFF)
  kRemote = 0x02,    ///< remote transmission request (RTR)
  kError = 0x04,     ///< error frame reported by the controller (id holds CAN_ERR_* class bits)
  kFd = 0x08,        ///< reserved: CAN FD frame (FDF)
  kBitRateSwitch = 0x10,  ///< reserved: CAN FD BRS
};

/// One CAN frame. `id` is the 11- or 29-bit identifier without flag bits.
/// Realtime-safe: plain value type.
struct Frame {
  std::uint32_t id = 0;
  std::uint8_t len = 0;    ///< payload length in bytes (0..kMaxPayload)
  std::uint8_t flags = 0;  ///< FrameFlag bits
  std::array<std::uint8_t, kMaxPayload> data{};

  constexpr Frame() = default;
  constexpr Frame(std::uint32_t id_, std::initializer_list<std::uint8_t> bytes) : id(id_) {
    len = static_cast<std::uint8_t>(std::min(bytes.size(), kMaxPayload));
    std::copy_n(bytes.begin(), len, data.begin());
  }

  [[nodiscard]] constexpr std::span<const std::uint8_t> payload() const { return {data.data(), len}; }
  [[nodiscard]] constexpr bool extended() const { return (flags & kExtended) != 0; }
  [[nodiscard]] constexpr bool remote() const { return (flags & kRemote) != 0; }
  [[nodiscard]] constexpr bool error() const { return (flags & kError) != 0; }

  friend constexpr bool operator==(const Frame& a, const Frame& b) {
    return a.id == b.id && a.len == b.len && a.flags == b.flags &&
           std::equal(a.data.begin(), a.data.begin() + a.len, b.data.begin());
  }
};

/// A received frame with the time it was received, in nanoseconds, on the
/// clock the cycle runs on: the kernel's stamp converted to CLOCK_MONOTONIC on
/// SocketCAN (SocketCanBus::RxClock), the virtual time on the SimBus. Sent
/// frames recorded for traces carry the cycle's time.
struct TimedFrame {
  Frame frame;
  std::int64_t t_ns = 0;
};

}  // namespace canmotion::can
