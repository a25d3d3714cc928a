#pragma once
/// \file motion/planner.hpp
/// The motion planner: fixed-capacity axes, control tags and generators, the
/// Logix instruction model, and the one-call-per-cycle API for the runtime:
///
///     Planner p(cycle_period);                 // non-RT: construct, configure
///     p.configure_axis(0, cfg);
///     ... every cycle (RT):
///     Input in{cycle_index, feedback, requests};
///     p.update(in, out);                       // noexcept, no allocation
///
/// See motion/README.md for the full contract. The state and the instruction
/// families behind this API: motion/core.hpp, motion/instr/.

#include <cstdint>
#include <span>

#include "motion/axis.hpp"
#include "motion/cam/cam_profile.hpp"
#include "motion/control_tag.hpp"
#include "motion/core.hpp"
#include "motion/io.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// The planner. All state is inside (fixed arrays); update() is noexcept,
/// allocation-free and realtime-safe. Configuration calls are not RT.
class Planner {
 public:
  /// cycle_period in seconds (> 0), e.g. 0.001.
  explicit Planner(double cycle_period) noexcept : c_(cycle_period) {}

  /// Configure (or reconfigure) an axis. Not realtime (call before the
  /// cyclic loop). Returns false if the id is out of range or the config is
  /// invalid (non-positive conversion constant, unwind, negative limits).
  bool configure_axis(AxisId id, const AxisConfig& cfg) noexcept { return c_.configure_axis(id, cfg); }
  /// Number of configured axes (ids 0..axis_count()-1).
  std::size_t axis_count() const noexcept { return c_.axis_count; }

  /// Run one cycle: feedback, exceptions, requests (in order), generators,
  /// outputs (motion/README.md, "What update() does"). Realtime-safe.
  Result update(const Input& in, Output& out) noexcept;

  /// Execute one request right now (as part of the current cycle). update()
  /// calls this for every input request; exposed for tests. Returns the ERR
  /// (Err::None on success), also written to the control tag. Realtime-safe.
  Err execute(const Request& r) noexcept;

  /// MDS live command: write the direct velocity (units/s) or torque command
  /// of an axis in direct control, as a program writing the command tag.
  /// Returns false if the axis is not under an active MDS. Realtime-safe.
  bool set_direct_command(AxisId id, double value) noexcept;
  /// MDS torque mode: write the DirectVelocityControl Command (units/s) sent
  /// with the torque command (the drive's SLAT speed reference). False if the
  /// axis is not under an active MDS in torque mode. Realtime-safe.
  bool set_direct_velocity_command(AxisId id, double value) noexcept;

  /// Configure the COORDINATE_SYSTEM `id` (the binder's coordinate_systems
  /// id) after its member axes. Not realtime. False for an invalid
  /// configuration (dimension 1..3, members configured and distinct,
  /// ratios > 0, max speed/accel/decel > 0).
  bool configure_coordinate_system(CoordSystemId id, const CoordSystemConfig& cfg) noexcept;
  /// The tag of coordinate system `id` (CS.* status words and positions). Realtime-safe.
  const CoordSystemTag& coordinate_system(CoordSystemId id) const noexcept { return c_.systems[id].tag; }

  /// Controller mode change (Logix Run <-> Program, e.g. `canmotionctl mode
  /// program`): any change breaks every MDAC link [seed 000]; into Program
  /// every axis stops by its Programmed Stop Mode (moves, jogs, gears and cams
  /// [seed 004]; pending cams dropped). In Program mode the program does not
  /// run: instructions that would start motion (MAM MAJ MAG MATC MAPC MCD MDAC
  /// MDS MAH and the coordinated ones) answer ERR 24 Illegal Controller Mode;
  /// stops, servo on/off, shutdowns, resets, MRP and MCCP run. Setting the
  /// present mode does nothing. Realtime-safe.
  void set_controller_mode(ControllerMode m) noexcept;
  ControllerMode controller_mode() const noexcept { return c_.mode; }

  /// Cycles between a command and the feedback that shows it applied, beyond
  /// the usual one: 0 when the feedback read in cycle k shows the command of
  /// cycle k-1 (the drives apply a cycle's targets at that cycle's SYNC), 1
  /// when it shows the command of cycle k-2 (the SYNC goes out first, before
  /// the RPDOs: controller.sync_first). The position error, its exception
  /// and a coordinate system's following error then compare the actual
  /// position with that older command, so that they read the same as with 0
  /// (motion/README.md, Exceptions). False (nothing changed) for other
  /// values. Not realtime (configuration).
  bool set_command_lag(unsigned extra_cycles) noexcept {
    if (extra_cycles > 1) return false;
    c_.command_lag = static_cast<std::uint8_t>(extra_cycles);
    return true;
  }
  unsigned command_lag() const noexcept { return c_.command_lag; }

  /// Register the CAM_PROFILE array tag `id` (the binder's cam_profiles id).
  /// The profile must outlive the planner. Not realtime (configuration).
  bool attach_cam_profile(std::uint16_t id, cam::CamProfile* profile) noexcept;
  /// Register the CAM array tag `id` (the binder's cams id): MCCP reads its
  /// points. The storage must outlive the planner and is written only by the
  /// thread running update() (MCCP, motion/instr/mccp.cpp). Not realtime.
  bool attach_cam_array(std::uint16_t id, std::span<cam::CamPoint> points) noexcept;
  /// Register the REAL array tag `id` (the binder's real_arrays id): MAM
  /// reads EventDistance from it and writes CalculatedData into it. Same
  /// ownership rules as attach_cam_array. Not realtime.
  bool attach_real_array(std::uint16_t id, std::span<double> values) noexcept;

  /// Axis tag (status) of an axis. Realtime-safe.
  const AxisTag& axis(AxisId id) const noexcept { return c_.axes[id].tag; }
  const AxisConfig& config(AxisId id) const noexcept { return c_.axes[id].cfg; }
  /// Control tag. Realtime-safe.
  const ControlTag& control(ControlId id) const noexcept { return c_.controls[id]; }
  /// Clear a control tag (prescan). Realtime-safe.
  void reset_control(ControlId id) noexcept { c_.controls[id] = ControlTag{}; }
  double period() const noexcept { return c_.T; }
  std::uint64_t cycle() const noexcept { return c_.cycle; }

  /// Test hook: true when the state kept incrementally for speed agrees with
  /// what it summarises: every axis's live-slot mask (AxisRt::live) with its
  /// slots, and the cached step order with one computed afresh. Not realtime
  /// critical but allocation-free.
  bool check_incremental_state() noexcept { return c_.check_incremental_state(); }

 private:
  Core c_;
};

}  // namespace canmotion::motion
