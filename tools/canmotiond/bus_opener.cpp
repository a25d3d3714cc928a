// canmotiond's bus opener: SocketCAN sockets, txqueuelen, CAN link settings.
#include "tools/canmotiond/bus_opener.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "fieldbus/can/can_netlink.hpp"
#include "fieldbus/canopen/receive_filters.hpp"
#include "fieldbus/canopen/tx_queue.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"

namespace canmotion::daemon {

namespace {

/// The CIP axes of `cfg` on bus `b`.
std::vector<const config::AxisSettings*> axes_on(const config::Config& cfg, const config::BusSettings& b) {
  std::vector<const config::AxisSettings*> out;
  for (const config::AxisSettings& a : cfg.axes)
    if (a.axis.type == motion::AxisType::CipDrive && a.bus == b.name) out.push_back(&a);
  return out;
}

/// Opens `b`'s interface, receiving only what a CANopen master needs: the
/// nodes' EMCY, TPDOs, SDO responses and heartbeats (the list
/// DriveNetwork::receive_filters() gives).
std::unique_ptr<can::SocketCanBus> open_socket(const config::Config& cfg, const config::BusSettings& b) {
  std::vector<std::uint8_t> nodes;
  for (const config::AxisSettings* a : axes_on(cfg, b)) nodes.push_back(a->node);
  const std::vector<can::Filter> filters = canopen::master_receive_filters(nodes);
  std::error_code ec;
  std::string why;
  auto sock = can::SocketCanBus::open(b.interface, filters, ec, &why);
  if (!sock) throw std::runtime_error(fmt::format("{}: bus '{}' (line {}): {}", cfg.path, b.name, b.where.line, why));
  return sock;
}

/// The interface's transmit queue must hold one cycle's burst: raised when
/// shorter. Sets `bs.network.tx_queue_frames`; notes a raise.
void fit_tx_queue(const config::Config& cfg, const config::BusSettings& b, can::SocketCanBus& sock, rt::BusSpec& bs,
                  std::vector<std::string>& notes) {
  canopen::TxBurst burst;
  burst.master_heartbeat = b.master_heartbeat_ms > 0;
  for (const config::AxisSettings* a : axes_on(cfg, b)) {
    burst.rpdos += cia402::default_drive_pdos(a->drive.pdo, a->node).rpdo_count;
    ++burst.sdo_nodes;
  }
  const std::int64_t qlen = sock.tx_queue_len();
  if (qlen < 0) return;
  const canopen::TxQueueCheck chk = canopen::check_tx_queue(static_cast<std::uint32_t>(qlen), burst, true);
  if (chk.action == canopen::TxQueueCheck::Action::kRaise) {
    if (const int err = sock.set_tx_queue_len(chk.needed); err != 0)
      throw std::runtime_error(fmt::format("{}: bus '{}' (line {}): {} (raising it failed: {})", cfg.path, b.name,
                                           b.where.line, chk.message(b.interface), std::strerror(err)));
    notes.push_back(fmt::format("bus '{}': raised the txqueuelen of {} from {} to {} (one cycle's burst)", b.name,
                                b.interface, chk.current, chk.needed));
  }
  // The cycle keeps within the queue and a place for the SYNC.
  // (0: no queue, no limit)
  bs.network.tx_queue_frames =
      std::max(chk.current, chk.action == canopen::TxQueueCheck::Action::kRaise ? chk.needed : 0u);
}

/// restart-ms 0 (the kernel's default) keeps a bus-off controller off: say so
/// once, with the command (nothing for vcan: no CAN attributes); and a
/// bitrate other than the configuration's.
void note_link_settings(const config::BusSettings& b, std::vector<std::string>& notes) {
  std::string why;
  const auto link = can::query_can_link(b.interface, &why);
  if (!link) {
    notes.push_back(fmt::format("bus '{}': could not read the CAN settings: {}", b.name, why));
    return;
  }
  if (std::string w = can::restart_ms_warning(*link); !w.empty()) notes.push_back(fmt::format("bus '{}': {}", b.name, w));
  if (std::string w = can::bitrate_note(*link, b.bitrate); !w.empty())
    notes.push_back(fmt::format("bus '{}' (line {}): {}", b.name, b.where.line, w));
}

}  // namespace

OpenedBuses open_buses(const config::Config& cfg, rt::ControllerSpec& spec) {
  OpenedBuses out;
  for (std::size_t bi = 0; bi < spec.buses.size() && bi < cfg.buses.size(); ++bi) {
    rt::BusSpec& bs = spec.buses[bi];
    if (bs.transport != nullptr) continue;  // simulated
    const config::BusSettings& b = cfg.buses[bi];
    std::unique_ptr<can::SocketCanBus> sock = open_socket(cfg, b);
    fit_tx_queue(cfg, b, *sock, bs, out.notes);
    note_link_settings(b, out.notes);
    bs.transport = sock.get();
    out.sockets.push_back(std::move(sock));
  }
  return out;
}

}  // namespace canmotion::daemon
