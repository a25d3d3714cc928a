#pragma once
// canmotiond's bus opener: the I/O half of building the runtime (the other,
// config::build_spec, describes the buses without opening them). Not realtime:
// runs at start-up, before the RT thread.

#include <memory>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "fieldbus/can/socketcan_bus.hpp"
#include "rt/controller/controller.hpp"

namespace canmotion::daemon {

/// The SocketCAN buses open_buses() opened, and what it did or found on the
/// host, one sentence each (a raised txqueuelen, restart-ms 0, a bitrate
/// other than the configuration's), for the daemon's log.
struct OpenedBuses {
  std::vector<std::unique_ptr<can::SocketCanBus>> sockets;
  std::vector<std::string> notes;
};

/// Opens every bus of `spec` without a transport (the SocketCAN buses of
/// config::build_spec; spec.buses[i] is cfg.buses[i]) with receive filters for
/// the COB-IDs its nodes use; raises the interface's txqueuelen to one cycle's
/// burst when it is shorter (canopen::check_tx_queue) and sets
/// network.tx_queue_frames; reads the CAN link settings over netlink (notes
/// only). Sets each opened bus's transport. Throws std::runtime_error naming
/// the file, bus, line and interface when a socket cannot be opened or the
/// txqueuelen cannot be raised (nothing has been sent on any bus then).
[[nodiscard]] OpenedBuses open_buses(const config::Config& cfg, rt::ControllerSpec& spec);

}  // namespace canmotion::daemon
