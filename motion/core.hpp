#pragma once
/// \file motion/core.hpp
/// The planner's state and the operations every instruction family shares.
/// Internal to motion/: the runtime uses motion/planner.hpp. Every function
/// here is noexcept and allocation-free; all but configure_axis() are
/// realtime-safe.
///
/// Where things are:
///   core.cpp          shared operations: fold, set_slot, stops, servo off, shutdown, checks
///   cycle.cpp         one cycle: feedback, exceptions, step every axis in order, outputs, status
///   generator.hpp     the generators in the slots and their interface (step, on_fold)
///   hooks.hpp         the other events of an axis the families answer (drive feedback, servo off, ...)
///   instr/<family>    one file per instruction family: params, start, generator steps, hooks
///   planner.cpp       the public API, execute(): checks, decode, one std::visit to start()
///
/// The core knows no family: it reaches them only through the generator
/// interface and the hooks (instr/hooks.cpp answers those); the families
/// include the core, never the other way.

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "motion/axis.hpp"
#include "motion/control_tag.hpp"
#include "motion/cam/cam_motion.hpp"
#include "motion/coord_system.hpp"
#include "motion/generator.hpp"
#include "motion/io.hpp"
#include "motion/types.hpp"

namespace canmotion::motion {

/// Capacity of the CAM_PROFILE registry (config: one entry per CAM_PROFILE array tag).
inline constexpr std::size_t kMaxCamProfiles = 64;
/// Capacity of the CAM array registry (config `arrays:` entries of type CAM,
/// the operands of MCCP). Bound: like CAM_PROFILE arrays, one per cam table.
inline constexpr std::size_t kMaxCamArrays = 64;
/// Capacity of the REAL array registry (config `arrays:` entries of type
/// REAL: MAM EventDistance / CalculatedData). Bound: one pair per axis that
/// reports events.
inline constexpr std::size_t kMaxRealArrays = 64;

/// Servo loop and fault state of an axis (MSO, MSF, MASD, MASR, MAFR, MGSD,
/// MGSR, exceptions).
struct ServoState {
  bool on = false;            ///< servo loop active (ServoActionStatus)
  bool enable_req = false;    ///< drive enable requested
  bool shutdown = false;      ///< Logix Shutdown state
  bool faulted = false;       ///< StopDrive/Shutdown fault latched: ERR 20 until MAFR/MASR
  bool fault_reset_pulse = false;  ///< send a CiA 402 fault reset this cycle
  /// MAFR/MASR/MGSR on a CIP drive: DN when the drive has left Fault and is
  /// connected, ER on a transition timeout or the drive timeout. While it
  /// waits, the drive fault and lost node conditions are not latched again.
  OwnerRef reset{};
  std::uint64_t reset_deadline = 0;
  std::uint64_t reset_since = 0;   ///< cycle the waiting fault reset started
  Instr reset_instr = Instr::MAFR; ///< the instruction that waits (MAFR, MASR, MGSR)
};

/// Instructions waiting for the drive (AXIS_CIP_DRIVE): the MSO/MSF enable
/// handshakes and MAH drive homing (CiA 402 mode 6).
struct Handshakes {
  OwnerRef mso{}, msf{};       ///< MSO waiting for Operation Enabled, MSF for its end
  std::uint64_t deadline = 0;  ///< cycle at which MSO/MSF/MDS stop waiting (ERR 12)
  std::uint64_t since = 0;     ///< cycle the waiting MSO/MSF/MDS started
  OwnerRef mah{};              ///< MAH homing on the drive
  bool homing = false;         ///< drive homing (mode 6) in progress
  bool homing_started = false; ///< the homing request was sent
  bool homing_clear = false;   ///< since the start, the feedback showed homing not attained (a stale bit is not completion)
  bool homed = false;          ///< AxisHomedStatus
  bool resync = false;         ///< a drive homing was cancelled: the command takes the next actual position
};

/// MDS direct velocity/torque control of an axis.
struct DirectControl {
  bool status = false;   ///< AxisStatus.DirectControlStatus (cleared only by MSO, shutdown, servo off)
  bool active = false;   ///< DirectVelocity/TorqueControlStatus: the direct command is applied
  double cmd = 0.0;      ///< velocity (units/s) or torque command
  double vel_cmd = 0.0;  ///< torque mode: velocity command for SLAT (units/s)
  OwnerRef mds{};        ///< the MDS in control
  bool waiting = false;  ///< MDS waits for the drive enable (STATE 1)
  OwnerRef stop{};       ///< MAS stopping direct motion (PC at standstill)
};

/// A pending MATC waiting for the end of the current pass (or for an immediate cam).
struct PendingCam {
  cam::CamProfile* profile = nullptr;
  cam::CamMotionConfig cfg{};
  OwnerRef owner{};
  bool master_driven = false;  ///< its InstructionMode: must match the cam it follows [seed 004]
  constexpr bool valid() const noexcept { return profile != nullptr; }
};

/// A pending MAPC waiting for the end of the current pass (or for a non-pending cam).
struct PendingPosCam {
  cam::CamProfile* profile = nullptr;
  cam::CamMotionConfig cfg{};
  AxisId master = kNoAxis;
  bool use_actual = false;
  std::uint8_t master_dir = 0;
  OwnerRef owner{};
  constexpr bool valid() const noexcept { return profile != nullptr; }
};

/// Cams waiting to take over (pending MATC / MAPC) and the last cam directions.
struct PendingCams {
  PendingCam time{};          ///< TimeCamPendingStatus
  int time_dir = 0;           ///< last time-cam direction (+1/-1, 0 never cammed)
  PendingPosCam position{};   ///< PositionCamPendingStatus (MAPC)
  int position_dir = 0;       ///< last position-cam direction (+1/-1, 0 never cammed)
};

/// One MDAC link of a slave (per motion type).
struct MdacLink {
  AxisId master = kNoAxis;
  bool use_actual = false;
  bool all = false;            ///< set by MDAC MotionType All
  OwnerRef owner{};            ///< the MDAC execution
  constexpr bool valid() const noexcept { return master != kNoAxis; }
};

/// Index of a motion type's link in MdacLinks (AxisRt::links).
namespace link {
inline constexpr std::size_t Move = 0, Jog = 1, TimeCam = 2, MasterOffsetMove = 3, Count = 4;
}

/// MDAC links of a slave per motion type (index: link::Move, Jog, TimeCam,
/// MasterOffsetMove) and the queued masters.
struct MdacLinks {
  std::array<MdacLink, link::Count> active{}, pending{};
};

/// One axis in the planner.
struct AxisRt {
  AxisConfig cfg{};
  AxisTag tag{};
  bool present = false;
  double base = 0.0;          ///< drive-frame position with all finished motion folded in
  double frame_offset = 0.0;  ///< user = drive + frame_offset (MRP, homing)
  Kin cmd{};                  ///< total command (drive frame)
  /// The command position one cycle older than `cmd` (set by step_axis(),
  /// and to `cmd` when the feedback step takes the command from the actual):
  /// with Core::command_lag the command the feedback is compared with.
  double prev_cmd_p = 0.0;
  double fb_pos = 0.0, fb_vel = 0.0;
  AxisFeedback fb{};
  std::array<Generator, kSlots> gen{};
  /// Bit per Slot: the slot holds a generator (not std::monostate). Kept by
  /// Core::set_slot() and Core::fold(), the only writers of `gen`, so that
  /// the cycle reads no empty slot; Core::check_incremental_state() verifies it.
  std::uint8_t live = 0;
  double last_speed = 0.0;    ///< last non-zero programmed speed (zero-speed S-curve rule)
  int gear_dir = 0;           ///< last gearing direction (+1 same, -1 opposite, 0 never geared)
  ServoState servo{};
  Handshakes hs{};
  DirectControl direct{};
  PendingCams cams{};
  MdacLinks links{};
};

/// An MGS in progress: PC when every ramp it owns ended.
struct GroupOp {
  OwnerRef owner{};
  std::uint8_t group = 0;
  bool active = false;
};

/// The planner's state (fixed arrays, sized at construction) and the shared
/// operations of the instruction families.
struct Core {
  /// cycle_period in seconds (> 0; anything else gives 1 ms).
  explicit Core(double cycle_period) noexcept;

  double T;                   ///< cycle period, seconds
  std::uint64_t cycle = 0;    ///< the cycle being run; time = cycle * T
  bool started = false;
  std::size_t axis_count = 0;
  std::array<AxisRt, kMaxAxes> axes{};
  std::array<ControlTag, kMaxControlTags> controls{};
  std::array<GroupOp, kMaxGroups> groups{};
  std::array<cam::CamProfile*, kMaxCamProfiles> cam_profiles{};
  std::array<std::span<cam::CamPoint>, kMaxCamArrays> cam_arrays{};
  std::array<std::span<double>, kMaxRealArrays> real_arrays{};
  std::array<CoordSystemRt, kMaxCoordSystems> systems{};  ///< coordinate systems (motion/coord_system.hpp)
  std::array<AxisId, kMaxAxes> order{};  ///< step order: masters before slaves
  std::size_t order_n = 0;
  bool order_dirty = true;  ///< a slot or an axis changed since `order` was computed
  ControllerMode mode = ControllerMode::Run;  ///< Program: no instruction starts motion (ERR 24)
  /// Cycles between a command and the feedback that shows it applied,
  /// beyond the usual one (Planner::set_command_lag): 0 or 1.
  std::uint8_t command_lag = 0;

  /// Configure (or reconfigure) an axis. Not realtime.
  bool configure_axis(AxisId id, const AxisConfig& cfg) noexcept;

  // ---- the cycle (cycle.cpp), in this order around the requests (Planner::update)
  /// 1. Feedback (CIP axes) and the handshakes waiting for it, exceptions.
  void read_feedback(const Input& in) noexcept;
  /// 3. Step every axis, masters before slaves: outputs and axis tags.
  void step(std::uint64_t new_cycle, Output& out) noexcept;
  /// Recompute the axis tag (status bits, positions in the user frame).
  void update_status(AxisRt& a) noexcept;
  /// Step order: every axis after the masters it follows (only when order_dirty).
  void compute_order() noexcept;
  bool check_incremental_state() noexcept;

  // ---- shared operations (core.cpp)
  /// The control tag `o` names, or null when a newer execution reused it.
  ControlTag* tag(OwnerRef o) noexcept {
    if (o.id >= kMaxControlTags) return nullptr;
    ControlTag& c = controls[o.id];
    return c.generation == o.gen ? &c : nullptr;  // the tag was re-executed: not ours any more
  }
  /// An active MGS owns `o`: its ramps end without PC (the MGS gets PC when
  /// its whole group stopped, stop::finish_group_stops).
  bool group_owns(OwnerRef o) const noexcept {
    for (const GroupOp& g : groups)
      if (g.active && g.owner == o) return true;
    return false;
  }
  /// End the generator in slot `s`: its on_fold(), its offset into the base
  /// (a master offset move's into the position cam), its owner's IP, ACCEL,
  /// DECEL, TrackingMaster, AC cleared (if `clear_owner_ip`); the slot empty.
  void fold(AxisRt& a, Slot s, bool clear_owner_ip) noexcept;
  /// Put generator g into slot s: every write of a slot goes through here or
  /// fold(), keeping AxisRt::live and the step order (order_dirty) current.
  template <class G>
  G& set_slot(AxisRt& a, Slot s, const G& g) noexcept {
    a.gen[index(s)] = g;
    a.live = static_cast<std::uint8_t>(a.live | slot_bit(s));
    order_dirty = true;
    return *std::get_if<G>(&a.gen[index(s)]);
  }
  /// Cancel every generator at once (no ramp).
  void abort_all(AxisRt& a) noexcept;
  /// Replace the generators of the slots in `mask` by stop ramps (decel d,
  /// jerk jd, owned by `owner`; all slots: one ramp in Slot::StopAll).
  /// False when nothing moved.
  bool stop_slots(AxisRt& a, std::uint32_t slot_mask, double d, double jd, ControlId owner,
                  std::uint8_t post_stop) noexcept;
  /// Stop all motion at the axis' maximum deceleration (S-curve with the
  /// maximum decel jerk if any running motion is S-curve): Stop Planner
  /// exceptions, MGS. False when nothing moved.
  bool stop_all(AxisRt& a, ControlId owner, std::uint8_t post_stop) noexcept;
  /// Servo off: motion aborted, pending cams and direct control dropped, homing cancelled.
  void servo_off(AxisRt& a) noexcept;
  /// Logix Shutdown: servo off, the MDAC links of the axis (as slave and master) broken.
  void do_shutdown(AxisRt& a) noexcept;
  /// The checks most instructions start with: ERR 11, 53, 7, 20, and with
  /// `need_servo` 5, 87.
  Err common_checks(const AxisRt& a, bool need_servo) const noexcept;
  Kin slot_kin(const AxisRt& a, Slot s) const noexcept;
  double user_command(const AxisRt& a) const noexcept { return a.cmd.p + a.frame_offset; }
  /// The command position a CIP axis's actual position is compared with
  /// (position error, its exception, a coordinate system's following error):
  /// the command the drive applied when it measured that actual, in the
  /// drive frame: `cmd.p` before this cycle's step, or one cycle older with
  /// command_lag. Realtime-safe.
  double compared_command(const AxisRt& a) const noexcept { return command_lag != 0 ? a.prev_cmd_p : a.cmd.p; }
  /// A stop ramp runs (StoppingStatus; MAM/MAJ/MAPC refused, ERR 78).
  bool any_stopping(const AxisRt& a) const noexcept {
    for (unsigned m = a.live; m != 0; m &= m - 1)  // live slots only
      if (auto* p = std::get_if<ProfileGen>(&a.gen[std::countr_zero(m)]); p && p->role == GenRole::Stop) return true;
    return false;
  }
  /// An S-curve profile runs (a merge continues its acceleration).
  bool any_scurve(const AxisRt& a) const noexcept {
    for (unsigned m = a.live; m != 0; m &= m - 1)  // live slots only
      if (auto* p = std::get_if<ProfileGen>(&a.gen[std::countr_zero(m)]); p && p->scurve) return true;
    return false;
  }
  /// The cycle at which a handshake with `a`'s drive (MSO, MSF, MDS, a
  /// fault reset) started now times out (AxisConfig::drive_wait_limit).
  std::uint64_t drive_deadline(const AxisRt& a) const noexcept;
  /// Why an enable handshake (MSO, MDS) waiting on `a`'s drive fails now, if
  /// it does: the axis faulted (Stop Drive) or shut down meanwhile, the drive in Fault (unless `fault_waits_for_reset` and a fault
  /// reset waits for it), a failed link, a transition timeout, the deadline
  /// Handshakes::deadline.
  std::optional<DriveWaitCause> enable_failed(const AxisRt& a, bool fault_waits_for_reset) const noexcept;
  /// End an instruction that waited on `a`'s drive with an error: `t` (may
  /// be null: a stale tag) rejected with `e`/`exerr`, and the end recorded
  /// in the axis tag for the log (AxisTag::last_drive_wait).
  void end_drive_wait(AxisRt& a, ControlTag* t, ControlId id, Instr instr, DriveWaitCause cause, std::uint64_t since,
                      Err e = Err::ServoMessageFailure, std::int8_t exerr = 16) noexcept;
  AxisId id_of(const AxisRt& a) const noexcept { return static_cast<AxisId>(&a - axes.data()); }

 private:
  void step_axis(AxisRt& a, AxisOutput* out) noexcept;
  void handle_feedback(AxisRt& a, const AxisFeedback* fb) noexcept;
  void handle_exceptions(AxisRt& a) noexcept;
};

}  // namespace canmotion::motion
