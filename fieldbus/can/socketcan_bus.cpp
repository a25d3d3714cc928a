#include "fieldbus/can/socketcan_bus.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

namespace canmotion::can {
namespace {

std::string call_failed(std::string_view ifname, const char* what, int err) {
  std::string s = "SocketCAN interface '";
  s += ifname;
  s += "': ";
  s += what;
  s += " failed: ";
  s += std::strerror(err);
  return s;
}

}  // namespace

bool SocketCanBus::kernel_has_can() noexcept {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

std::unique_ptr<SocketCanBus> SocketCanBus::open(std::string_view ifname, std::span<const Filter> filters,
                                                 std::error_code& ec, std::string* detail) {
  auto fail = [&](const char* what, int err, std::string extra = {}) -> std::unique_ptr<SocketCanBus> {
    ec = std::error_code(err, std::system_category());
    if (detail != nullptr) {
      *detail = call_failed(ifname, what, err);
      if (err == EAFNOSUPPORT) *detail += " (this kernel has no CAN support; run inside tools/vcan-vm)";
      if (err == ENODEV) *detail += " (no such interface; for a virtual bus: ip link add dev " + std::string(ifname) +
                                    " type vcan && ip link set " + std::string(ifname) + " up)";
      *detail += extra;
    }
    return nullptr;
  };
  if (ifname.empty() || ifname.size() >= IFNAMSIZ) return fail("interface name check", EINVAL);
  if (filters.size() > kMaxFilters) return fail("filter count check", E2BIG);

  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return fail("socket(PF_CAN)", errno);
  // From here on the bus owns fd, so early returns close it.
  std::unique_ptr<SocketCanBus> bus(new SocketCanBus(fd, std::string(ifname)));

  ifreq ifr{};
  std::memcpy(ifr.ifr_name, ifname.data(), ifname.size());
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) return fail("SIOCGIFINDEX", errno);

  if (!filters.empty()) {
    std::vector<can_filter> kf;
    kf.reserve(filters.size());
    for (const Filter& f : filters) {
      can_filter k{};
      k.can_id = f.extended ? (f.id | CAN_EFF_FLAG) : f.id;
      k.can_mask = (f.extended ? f.mask : (f.mask & CAN_SFF_MASK)) | CAN_EFF_FLAG | CAN_RTR_FLAG;
      kf.push_back(k);
    }
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, kf.data(),
                     static_cast<socklen_t>(kf.size() * sizeof(can_filter))) < 0)
      return fail("setsockopt(CAN_RAW_FILTER)", errno);
  }
  const can_err_mask_t err_mask = CAN_ERR_MASK;  // all error classes
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0)
    return fail("setsockopt(CAN_RAW_ERR_FILTER)", errno);
  const int one = 1;
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one) < 0)
    return fail("setsockopt(SO_TIMESTAMPNS)", errno);
  if (::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) < 0)
    return fail("setsockopt(SO_RXQ_OVFL)", errno);

  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) return fail("bind", errno);
  ec.clear();
  return bus;
}

std::int64_t SocketCanBus::tx_queue_len() const noexcept {
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, name_.data(), std::min(name_.size(), sizeof ifr.ifr_name - 1));
  if (::ioctl(fd_, SIOCGIFTXQLEN, &ifr) < 0) return -errno;
  return ifr.ifr_qlen;
}

int SocketCanBus::set_tx_queue_len(std::uint32_t frames) noexcept {
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, name_.data(), std::min(name_.size(), sizeof ifr.ifr_name - 1));
  ifr.ifr_qlen = static_cast<int>(frames);
  return ::ioctl(fd_, SIOCSIFTXQLEN, &ifr) < 0 ? errno : 0;
}

SocketCanBus::SocketCanBus(int fd, std::string name) noexcept : fd_(fd), name_(std::move(name)) {}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) ::close(fd_);
}

SendResult SocketCanBus::send(const Frame& frame) noexcept {
  if (state_ == BusState::kBusOff) {
    ++counters_.tx_errors;
    return SendResult::kBusOff;
  }
  can_frame kf{};
  kf.can_id = frame.extended() ? ((frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (frame.id & CAN_SFF_MASK);
  if (frame.remote()) kf.can_id |= CAN_RTR_FLAG;
  kf.len = frame.len > CAN_MAX_DLEN ? CAN_MAX_DLEN : frame.len;
  std::memcpy(kf.data, frame.data.data(), kf.len);
  const ssize_t n = ::write(fd_, &kf, sizeof kf);
  if (n == static_cast<ssize_t>(sizeof kf)) {
    ++counters_.tx_frames;
    if (link_down_) [[unlikely]] set_link_down(false, 0);
    return SendResult::kOk;
  }
  last_errno_ = n < 0 ? errno : EIO;
  if (last_errno_ == ENOBUFS || last_errno_ == EAGAIN) {
    ++counters_.tx_queue_full;
    push_event(BusEvent{BusEvent::Kind::kTxQueueFull, state_, 0, 0});
    return SendResult::kQueueFull;
  }
  // The interface is down (the kernel's can_send(), or the socket error it
  // left at NETDEV_DOWN): every send fails the same way until it is up.
  if (last_errno_ == ENETDOWN) set_link_down(true, ENETDOWN);
  ++counters_.tx_errors;
  return SendResult::kError;
}

void SocketCanBus::set_link_down(bool down, int err) noexcept {
  if (down == link_down_) return;
  link_down_ = down;
  push_event(BusEvent{down ? BusEvent::Kind::kLinkDown : BusEvent::Kind::kLinkUp, state_,
                      static_cast<std::uint32_t>(err), 0});
}

namespace {
std::int64_t clock_ns(clockid_t id) noexcept {
  timespec ts{};
  ::clock_gettime(id, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
}  // namespace

std::size_t SocketCanBus::receive(std::span<TimedFrame> out) noexcept {
  std::size_t got = 0;
  // Kernel stamps are CLOCK_REALTIME. For the monotonic scale, the offset
  // between the clocks is read once per call (two vDSO reads, only when a
  // frame came): a frame waits at most a cycle in the socket, so a clock step
  // or slew between its arrival and this call is all the error there is.
  bool have_offset = false;
  std::int64_t real_minus_mono = 0;
  auto to_rx_clock = [&](std::int64_t real_ns) noexcept {
    if (rx_clock_ == RxClock::kRealtime) return real_ns;
    if (!have_offset) {
      const std::int64_t m0 = clock_ns(CLOCK_MONOTONIC);
      const std::int64_t r = clock_ns(CLOCK_REALTIME);
      const std::int64_t m1 = clock_ns(CLOCK_MONOTONIC);
      real_minus_mono = r - (m0 + (m1 - m0) / 2);
      have_offset = true;
    }
    return real_ns - real_minus_mono;
  };
  while (got < out.size()) {
    can_frame kf{};
    iovec iov{&kf, sizeof kf};
    // Room for SO_TIMESTAMPNS (timespec) and SO_RXQ_OVFL (uint32).
    alignas(cmsghdr) char ctrl[CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = ctrl;
    msg.msg_controllen = sizeof ctrl;
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {  // EAGAIN: nothing more; other errors are retried next cycle
      // ENETDOWN: the interface went down (the socket's pending error, reported once).
      if (errno == ENETDOWN) set_link_down(true, ENETDOWN);
      break;
    }
    if (static_cast<std::size_t>(n) < sizeof kf) continue;  // CAN FD frame on an FD-enabled socket: not ours
    std::int64_t t_ns = -1;
    std::uint32_t drops = last_kernel_drops_;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SO_TIMESTAMPNS) {
        timespec ts{};
        std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
        t_ns = to_rx_clock(static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
      }
    }
    if (t_ns < 0)  // no stamp from the kernel: the time of reading
      t_ns = clock_ns(rx_clock_ == RxClock::kRealtime ? CLOCK_REALTIME : CLOCK_MONOTONIC);
    // Never earlier than the frame before: the realtime-to-monotonic offset
    // is read once per call, and a step or slew of CLOCK_REALTIME between two
    // calls (NTP, a VM's clock sync) would otherwise put a later frame before
    // an earlier one (seen in vcan.sendrecv in the VM).
    if (t_ns < last_rx_ns_) t_ns = last_rx_ns_;
    last_rx_ns_ = t_ns;
    if (drops != last_kernel_drops_) {
      counters_.rx_dropped += drops - last_kernel_drops_;
      push_event(BusEvent{BusEvent::Kind::kRxOverflow, state_, drops - last_kernel_drops_, t_ns});
      last_kernel_drops_ = drops;
    }
    if ((kf.can_id & CAN_ERR_FLAG) != 0) {
      ++counters_.error_frames;
      const std::uint8_t len = kf.len > CAN_MAX_DLEN ? CAN_MAX_DLEN : kf.len;
      handle_error_frame(kf.can_id & CAN_ERR_MASK, {kf.data, len}, t_ns);
      continue;
    }
    TimedFrame& tf = out[got++];
    tf.t_ns = t_ns;
    tf.frame = Frame{};
    const bool eff = (kf.can_id & CAN_EFF_FLAG) != 0;
    tf.frame.id = eff ? (kf.can_id & CAN_EFF_MASK) : (kf.can_id & CAN_SFF_MASK);
    tf.frame.flags = static_cast<std::uint8_t>((eff ? kExtended : 0) | ((kf.can_id & CAN_RTR_FLAG) ? kRemote : 0));
    tf.frame.len = kf.len > CAN_MAX_DLEN ? CAN_MAX_DLEN : kf.len;
    std::memcpy(tf.frame.data.data(), kf.data, tf.frame.len);
    ++counters_.rx_frames;
  }
  return got;
}

void SocketCanBus::handle_error_frame(std::uint32_t err_class, std::span<const std::uint8_t> data,
                                      std::int64_t t_ns) noexcept {
  const std::uint8_t ctrl = data.size() > 1 ? data[1] : 0;
  if ((err_class & CAN_ERR_BUSOFF) != 0) {
    set_state(BusState::kBusOff, t_ns);
  } else if ((err_class & CAN_ERR_RESTARTED) != 0) {
    push_event(BusEvent{BusEvent::Kind::kRestarted, BusState::kErrorActive, err_class, t_ns});
    set_state(BusState::kErrorActive, t_ns);
  } else if ((err_class & CAN_ERR_CRTL) != 0) {
    if ((ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
      set_state(BusState::kErrorPassive, t_ns);
    } else if ((ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
      set_state(BusState::kErrorWarning, t_ns);
    } else if ((ctrl & CAN_ERR_CRTL_ACTIVE) != 0) {
      set_state(BusState::kErrorActive, t_ns);
    }
    if ((ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0)
      push_event(BusEvent{BusEvent::Kind::kRxOverflow, state_, ctrl, t_ns});
  }
  const std::uint32_t other = err_class & ~static_cast<std::uint32_t>(CAN_ERR_BUSOFF | CAN_ERR_RESTARTED | CAN_ERR_CRTL);
  if (other != 0) push_event(BusEvent{BusEvent::Kind::kErrorFrame, state_, other, t_ns});
}

std::string SocketCanBus::error_classes_text(std::uint32_t err_class) {
  static constexpr struct {
    std::uint32_t bit;
    const char* text;
  } kClasses[] = {
      {CAN_ERR_TX_TIMEOUT, "TX timeout (by the netdevice driver)"},
      {CAN_ERR_LOSTARB, "lost arbitration"},
      {CAN_ERR_CRTL, "controller problem (error counters, overflow)"},
      {CAN_ERR_PROT, "protocol violation (bit, form, stuff or CRC error: wiring, termination or bitrate)"},
      {CAN_ERR_TRX, "transceiver problem (CAN_H/CAN_L open or short)"},
      {CAN_ERR_ACK, "no ACK (no other node acknowledged: all drives off or unplugged, or another bitrate)"},
      {CAN_ERR_BUSOFF, "bus-off"},
      {CAN_ERR_BUSERROR, "bus error"},
      {CAN_ERR_RESTARTED, "controller restarted"},
  };
  std::string s;
  for (const auto& c : kClasses) {
    if ((err_class & c.bit) == 0) continue;
    if (!s.empty()) s += "; ";
    s += c.text;
  }
  if (s.empty()) s = "unknown error class";
  return s;
}

std::string SocketCanBus::bus_off_advice(std::string_view ifname) {
  const std::string i(ifname);
  return "SocketCAN keeps " + i + " off until it is restarted: now `ip link set " + i +
         " type can restart`, or for an automatic restart (restart-ms is 0 by default) `ip link set " + i +
         " down && ip link set " + i + " type can restart-ms 100 && ip link set " + i +
         " up`; canmotiond re-boots the drives when the bus is back, then MASR and MSO";
}

void SocketCanBus::set_state(BusState s, std::int64_t t_ns) noexcept {
  if (s == state_) return;
  state_ = s;
  push_event(BusEvent{BusEvent::Kind::kStateChanged, s, 0, t_ns});
}

void SocketCanBus::push_event(const BusEvent& ev) noexcept {
  if (ev_count_ == kEventCapacity) {  // drop the oldest
    ev_head_ = (ev_head_ + 1) % kEventCapacity;
    --ev_count_;
    ++counters_.rx_dropped;
  }
  events_[(ev_head_ + ev_count_) % kEventCapacity] = ev;
  ++ev_count_;
}

std::size_t SocketCanBus::poll_events(std::span<BusEvent> out) noexcept {
  std::size_t n = 0;
  while (n < out.size() && ev_count_ > 0) {
    out[n++] = events_[ev_head_];
    ev_head_ = (ev_head_ + 1) % kEventCapacity;
    --ev_count_;
  }
  return n;
}

}  // namespace canmotion::can
