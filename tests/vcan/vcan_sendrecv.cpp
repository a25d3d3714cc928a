// vcan_sendrecv: two-process SocketCAN check through the project's transport.
//
//   vcan_sendrecv send IFACE COUNT [GAP_US] send COUNT frames (id 0x100 + i%16,
//                                           payload = i as 4 LE bytes + 0xCA 0xFE),
//                                           GAP_US apart (default 0: back to back)
//   vcan_sendrecv recv IFACE COUNT TIMEOUT_MS READY_FILE
//                                           receive COUNT frames, print ID#DATA
//                                           lines, verify the sequence; touch
//                                           READY_FILE once the socket is bound.
// Exit 0 on success, 1 with a message on failure.
#include <poll.h>
#include <time.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "fieldbus/can/socketcan_bus.hpp"

using canmotion::can::Frame;
using canmotion::can::SendResult;
using canmotion::can::SocketCanBus;
using canmotion::can::TimedFrame;

namespace {

Frame expected_frame(std::uint32_t i) {
  Frame f;
  f.id = 0x100 + (i % 16);
  f.len = 6;
  f.data = {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8), static_cast<std::uint8_t>(i >> 16),
            static_cast<std::uint8_t>(i >> 24), 0xCA, 0xFE, 0, 0};
  return f;
}

std::unique_ptr<SocketCanBus> open_or_die(const char* ifname) {
  std::error_code ec;
  std::string why;
  // Only the ids this test uses: 0x100..0x10F.
  const std::array filters{canmotion::can::Filter{0x100, 0x7F0, false}};
  auto bus = SocketCanBus::open(ifname, filters, ec, &why);
  if (!bus) {
    std::fprintf(stderr, "vcan_sendrecv: %s\n", why.c_str());
    std::exit(1);
  }
  return bus;
}

int do_send(const char* ifname, std::uint32_t count, long gap_us) {
  auto bus = open_or_die(ifname);
  std::uint32_t queue_full = 0;
  for (std::uint32_t i = 0; i < count;) {
    const SendResult r = bus->send(expected_frame(i));
    if (r == SendResult::kOk) {
      ++i;
      if (gap_us > 0) {  // pace like a cyclic master instead of flooding the bus
        const timespec ts{0, gap_us * 1000};
        ::nanosleep(&ts, nullptr);
      }
    } else if (r == SendResult::kQueueFull) {
      ++queue_full;  // wait until the socket is writable again
      pollfd p{bus->fd(), POLLOUT, 0};
      ::poll(&p, 1, 100);
    } else {
      std::fprintf(stderr, "vcan_sendrecv: send %u failed (errno %d)\n", i, bus->last_errno());
      return 1;
    }
  }
  std::printf("sent %u frames on %s (%u transmit-queue-full retries, counted %llu)\n", count, ifname, queue_full,
              static_cast<unsigned long long>(bus->counters().tx_queue_full));
  return 0;
}

int do_recv(const char* ifname, std::uint32_t count, int timeout_ms, const char* ready_file) {
  auto bus = open_or_die(ifname);
  std::ofstream(ready_file) << "ready\n";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::array<TimedFrame, 32> buf{};
  std::uint32_t got = 0;
  std::int64_t last_t = 0;
  while (got < count) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      std::fprintf(stderr, "vcan_sendrecv: timeout: received %u of %u frames on %s\n", got, count, ifname);
      return 1;
    }
    pollfd p{bus->fd(), POLLIN, 0};
    ::poll(&p, 1, static_cast<int>(left.count()));
    const std::size_t n = bus->receive(buf);
    for (std::size_t k = 0; k < n; ++k, ++got) {
      const Frame& f = buf[k].frame;
      std::printf("%03X#", f.id);
      for (std::size_t b = 0; b < f.len; ++b) std::printf("%02X", f.data[b]);
      std::printf("\n");
      if (!(f == expected_frame(got))) {
        std::fprintf(stderr, "vcan_sendrecv: frame %u differs from what was sent (id %03X)\n", got, f.id);
        return 1;
      }
      if (buf[k].t_ns <= 0 || buf[k].t_ns < last_t) {
        std::fprintf(stderr, "vcan_sendrecv: frame %u has no or a decreasing kernel timestamp\n", got);
        return 1;
      }
      last_t = buf[k].t_ns;
    }
  }
  std::fprintf(stderr, "received %u frames on %s, kernel timestamps monotonic\n", got, ifname);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "send" && (argc == 4 || argc == 5))
    return do_send(argv[2], static_cast<std::uint32_t>(std::strtoul(argv[3], nullptr, 0)),
                   argc == 5 ? std::atol(argv[4]) : 0);
  if (mode == "recv" && argc == 6)
    return do_recv(argv[2], static_cast<std::uint32_t>(std::strtoul(argv[3], nullptr, 0)), std::atoi(argv[4]), argv[5]);
  std::fprintf(stderr,
               "Usage: vcan_sendrecv send IFACE COUNT [GAP_US]\n"
               "       vcan_sendrecv recv IFACE COUNT TIMEOUT_MS READY_FILE\n");
  return 1;
}
