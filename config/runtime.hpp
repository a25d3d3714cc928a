#pragma once
/// \file
/// From a validated Config to a running set of parts, without I/O: the
/// controller spec (build_spec: buses described, simulated ones as in-process
/// SimBuses with an emulated CiA 402 drive per AXIS_CIP_DRIVE node), then the
/// Controller over the buses' transports (build_runtime). Opening SocketCAN
/// buses is the daemon's (tools/canmotiond/bus_opener.hpp). Not realtime.

#include <memory>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "fieldbus/can/socketcan_bus.hpp"
#include "rt/controller/controller.hpp"
#include "rt/controller/sim_world.hpp"

namespace canmotion::config {

/// A configuration as the controller's spec, before any bus is opened
/// (build_spec): what it runs, and for simulated buses the in-process world
/// they run on.
struct RuntimeSpec {
  /// Period, buses, axes with their drive configurations, cams, arrays,
  /// coordinate systems. A simulated bus has its transport (a SimBus of
  /// `sim`); a SocketCAN bus has none (null) until its user opens it
  /// (canmotiond: tools/canmotiond/bus_opener.hpp).
  rt::ControllerSpec controller;
  std::unique_ptr<rt::SimWorld> sim;  ///< set when any bus is simulated, with an emulated drive per CIP axis on it
  /// Name used for each bus in traces: the SocketCAN interface, or the bus name for simulated buses.
  std::vector<std::string> trace_names;
};

/// The controller spec of a configuration: no socket, no netlink, no I/O
/// (building the simulated world does none either). With `force_sim` every
/// bus is simulated (`--sim`, `--check-args`, tests); otherwise buses with
/// `interface: sim` are simulated and the others are described, their
/// transport left null. The period is cfg.controller.period_ns(); each CIP
/// axis's drive configuration is drive_config(), its planner's wait limit
/// drive_wait_limit_s().
[[nodiscard]] RuntimeSpec build_spec(const Config& cfg, bool force_sim);

/// Everything a run needs, owned together (the controller refers to the buses).
struct Runtime {
  std::vector<std::unique_ptr<can::SocketCanBus>> sockets;
  std::unique_ptr<rt::SimWorld> sim;  ///< set when any bus is simulated
  std::unique_ptr<rt::Controller> controller;
  /// Name used for each bus in traces: the SocketCAN interface, or the bus name for simulated buses.
  std::vector<std::string> trace_names;
};

/// The runtime of a spec whose every bus has its transport: the controller
/// is built (the cams computed by MCCP) and owned with `sockets`, the opened
/// SocketCAN buses it refers to. Throws std::runtime_error naming the file
/// when the controller refuses the spec (e.g. a cam), std::logic_error when a
/// bus has no transport (a SocketCAN bus not opened). No I/O.
[[nodiscard]] Runtime build_runtime(const Config& cfg, RuntimeSpec spec,
                                    std::vector<std::unique_ptr<can::SocketCanBus>> sockets = {});

/// Every bus simulated (`--sim`, tests): build_runtime(cfg, build_spec(cfg, true)).
[[nodiscard]] Runtime simulated_runtime(const Config& cfg);

/// What a run should say once at start about how its axes are guarded: one
/// warning per AXIS_CIP_DRIVE axis without `position_error_tolerance`
/// (named, at its line in the file): the master then never checks the
/// position error, and the drive's own following error window 0x6065 is
/// the only guard. canmotiond prints them after the configuration's own
/// warnings. No I/O.
[[nodiscard]] std::vector<Diagnostic> startup_warnings(const Config& cfg);

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
