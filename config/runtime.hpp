#pragma once
/// \file
/// From a validated Config to a running set of parts: the buses (SocketCAN
/// sockets, or in-process SimBuses with an emulated CiA 402 drive per
/// AXIS_CIP_DRIVE node), and the Controller. Not realtime.

#include <memory>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "fieldbus/can/socketcan_bus.hpp"
#include "rt/controller/controller.hpp"
#include "rt/controller/sim_world.hpp"

namespace canmotion::config {

/// Everything a run needs, owned together (the controller refers to the buses).
struct Runtime {
  std::vector<std::unique_ptr<can::SocketCanBus>> sockets;
  std::unique_ptr<rt::SimWorld> sim;  ///< set when any bus is simulated
  std::unique_ptr<rt::Controller> controller;
  /// Name used for each bus in traces: the SocketCAN interface, or the bus name for simulated buses.
  std::vector<std::string> trace_names;
  /// What build_runtime changed on the host, one sentence each (e.g. a
  /// raised txqueuelen), for the daemon to log.
  std::vector<std::string> notes;
};

/// Build the runtime. With `force_sim` every bus is simulated (`--sim`);
/// otherwise buses with `interface: sim` are simulated and the others are
/// SocketCAN interfaces, opened with receive filters for the COB-IDs in use.
/// Throws std::runtime_error naming the bus and interface when a socket
/// cannot be opened (nothing has been sent on any bus then), and when an
/// interface's txqueuelen is shorter than one cycle's burst and cannot be
/// raised (canopen::check_tx_queue: the message has the numbers and the
/// command to run).
[[nodiscard]] Runtime build_runtime(const Config& cfg, bool force_sim);

/// The master-side drive configuration of a CIP axis (timeouts in ns, extra
/// SDO writes, heartbeats, PDO profile), for the controller's period. The
/// write hints name the YAML keys behind each boot write (`axes[axis_index]...`),
/// for the message when the drive refuses one.
[[nodiscard]] cia402::DriveConfig drive_config(const AxisSettings& a, const BusSettings& bus, double period_s,
                                               std::size_t axis_index = 0);

/// The SDO writes of an axis's `direct_control:` (ramps 0x6083, 0x6084 and
/// the MDS objects where `drive.mds_objects` puts them, by default 0x2010:1/2,
/// 0x2011, SLAT 0x2020..0x2022) in drive units; empty without one.
[[nodiscard]] std::vector<cia402::SdoWrite> direct_control_writes(const AxisSettings& a);

/// The emulated drive standing in for a CIP axis in a simulated bus: its
/// limits are set so that it can follow the axis's configured maxima.
[[nodiscard]] emulator::EmulatorConfig emulator_config(const AxisSettings& a);

}  // namespace canmotion::config
