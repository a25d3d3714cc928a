#pragma once
/// \file motion/coord/path_generator.hpp
/// The path generator of one coordinate system (MCLM / MCCM / MCS / MCCD
/// semantics, seed 001 and reference coordinated-motion.md): one active and
/// one pending move, a 1-D profile s(u) along each segment planned with the
/// project's own trapezoid / S-curve planner (motion/profile.hpp), the seven
/// termination types with their blends, merges, a stop along the path, a
/// re-plan of the dynamics, and master-driven stepping. The instruction layer
/// (phase 2) owns operands, units, control tags and member axes; this class
/// owns the path. README: motion/coord/README.md.
///
/// Realtime: every member function is noexcept and allocates nothing; `step`
/// is closed-form O(1) (no solve in the cycle). `submit`, `stop` and
/// `change_dynamics` plan (closed form plus bounded bisections, as
/// plan_move) and may run in the cycle that executes the instruction.

#include <array>
#include <cstdint>
#include <span>

#include "motion/coord/geometry.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace canmotion::motion::coord {

/// MCLM/MCCM TerminationType [RM002H p.500-506].
enum class Termination : std::uint8_t {
  ActualTolerance = 0,
  NoSettle = 1,
  CommandTolerance = 2,
  NoDecel = 3,
  FollowContourVelocityConstrained = 4,
  FollowContourVelocityUnconstrained = 5,
  CommandToleranceProgrammed = 6,
};

/// MCLM/MCCM Merge (reference 1.3: 0 disabled, 1 coordinated motion, 2 all motion).
enum class CoordMerge : std::uint8_t { Disabled = 0, CoordinatedMotion = 1, AllMotion = 2 };

/// MCCD Scope: the active move, or the active and the pending one.
enum class ChangeScope : std::uint8_t { ActiveMotion = 0, ActiveAndPendingMotion = 1 };

/// Configuration of one coordinate system (from the COORDINATE_SYSTEM tag).
struct SystemConfig {
  int dim = 2;                                     ///< 1..3 member axes
  std::array<double, kMaxDim> ratio{1.0, 1.0, 1.0};  ///< coordination units per axis unit, per member
  double period = 0.001;                           ///< cycle period, s (time-driven abscissa step)
  double actual_tolerance = 0.0;                   ///< Actual Position Tolerance (TT0), coordination units
  double command_tolerance = 0.0;                  ///< Command Position Tolerance (TT2), coordination units
};

/// One MCLM or MCCM, operands resolved by the instruction layer: units are
/// converted (the limits are per second or per master unit), the move id is
/// the caller's handle that comes back in the events.
struct MoveRequest {
  std::uint32_t id = 0;  ///< non-zero handle (e.g. control id and generation)
  PathSpec path;
  Limits limits;         ///< vector limits; limits.v = 0 starts paused (waits for MCCD)
  Termination termination = Termination::NoSettle;
  double command_tolerance = 0.0;  ///< the CommandTolerance operand (TT6 only)
  CoordMerge merge = CoordMerge::Disabled;
  MergeSpeed merge_speed = MergeSpeed::Programmed;
  bool master_driven = false;  ///< Speed in units per master unit: u = master travel
  LockDirection lock_direction = LockDirection::None;
  double lock_position = 0.0;  ///< master position (master-driven, Position locks)
};

/// The present state the instruction layer passes to submit/stop/step.
struct Present {
  /// The coordinate system's present total command position (coordination
  /// units; members' command positions x ratio, superposed motion included).
  /// A move that starts from rest with nothing else moving starts here (the
  /// Motion Start Point), moved by what the path itself travelled since its
  /// last output (position()): inside a step, where the path ended plus the
  /// superposed motion. Without it the path continues from its own end.
  bool has_total = false;
  Vec3 total;
  /// MDCC master this cycle (position and velocity, master units).
  bool has_master = false;
  double master_position = 0.0;
  double master_velocity = 0.0;
  /// |actual - command| of the members as a vector (coordination units), for TT0.
  double following_error = 0.0;
};

/// What happened to a move (or a stop): the instruction layer maps these to
/// AC / PC / IP of the control tags.
enum class EventKind : std::uint8_t {
  Activated,  ///< became the active move (AC set)
  Completed,  ///< reached its termination condition (PC; AC cleared)
  Cancelled,  ///< ended without PC: merged, stopped, cleared, a superseded stop (IP cleared)
  Failed,     ///< could not start when its turn came (a re-based arc, `err` = 44..49)
  StopDone,   ///< the stop with this id reached standstill (MCS PC)
};
struct Event {
  std::uint32_t id = 0;
  EventKind kind = EventKind::Activated;
  Err err = Err::None;
};
/// Events of one call. Bound: a call ends at most the active and the pending
/// move and a stop, activates one move, and one step can complete the
/// active move, activate the pending one and complete it (zero length): 8.
struct Events {
  static constexpr int kMax = 8;
  std::array<Event, kMax> e{};
  int n = 0;
  void push(std::uint32_t id, EventKind k, Err err = Err::None) noexcept {
    if (n < kMax && id != 0) e[static_cast<std::size_t>(n++)] = Event{id, k, err};
  }
};

/// MCCD: the fields to change (Change... = yes) and their values (converted).
struct DynamicsChange {
  bool change_speed = false, change_accel = false, change_decel = false;
  bool change_accel_jerk = false, change_decel_jerk = false;
  Limits values;               ///< v, a, d, ja, jd for the flagged fields
  bool master_driven = false;  ///< the units' mode (ERR 105 when it differs from the move's)
  ChangeScope scope = ChangeScope::ActiveMotion;
};

/// Outputs of one cycle.
struct Output {
  Vec3 position;      ///< path command position, coordination units (path frame)
  Vec3 velocity;      ///< per second
  Vec3 acceleration;  ///< per second^2
  /// position - origin: the continuous displacement the coordinated slot adds
  /// to the members (re-basing and fold() keep it continuous).
  Vec3 offset;
  std::array<double, kMaxDim> axis_offset{};        ///< offset / ratio, member axis units
  std::array<double, kMaxDim> axis_velocity{};      ///< velocity / ratio
  std::array<double, kMaxDim> axis_acceleration{};  ///< acceleration / ratio
  double speed = 0.0;                ///< |velocity|, the vector speed
  std::uint32_t motion_status = 0;   ///< CoordinateMotionStatus bits (types.hpp)
  bool tracking_master = false;      ///< master-driven active move locked at its programmed ratio
  Events events;
};

/// Path generator of one coordinate system. Plain data (copyable, ~3 KB); no heap.
class PathGenerator {
 public:
  /// Non-RT configuration. Resets the generator (idle at the origin).
  void configure(const SystemConfig& cfg) noexcept;

  /// Execute an MCLM/MCCM: start, queue behind the active move, or merge.
  /// Errors (nothing changes): 13 invalid limits or TT4/TT5 master-driven,
  /// 43 queue full, 44..49 geometry, 78 while stopping, 95 lock direction vs
  /// mode, 97 master-driven start while moving with the master idle.
  Err submit(const MoveRequest& rq, const Present& now, Events& ev) noexcept;

  /// MCS: clear the pending move, end the active one (Cancelled) and stop
  /// along the path at `decel` / `decel_jerk` (per s^2, s^3; +inf =
  /// trapezoidal), time-driven. StopDone(stop_id) at standstill (at once if
  /// nothing moves); a newer stop supersedes (Cancelled for the old id).
  void stop(std::uint32_t stop_id, double decel, double decel_jerk, Events& ev) noexcept;

  /// MCCD: re-plan the active move (and with Scope 1 the pending one) from
  /// the present state with Overshoot::StopAtTarget (MCD's policy): no
  /// position step. Speed 0 pauses. 105 if the units' mode differs, 13 for
  /// invalid values; nothing changes then. No effect while stopping or idle.
  Err change_dynamics(const DynamicsChange& ch, Events& ev) noexcept;

  /// MCSD / shutdown / faults: drop everything at once (Cancelled events);
  /// the position holds.
  void clear(Events& ev) noexcept;

  /// One cycle. Realtime-safe, O(1).
  void step(const Present& now, Output& out) noexcept;

  /// EventDistance / CalculatedData of the active move (call on Activated):
  /// cd[i] = abscissa (s, or master travel) from the move's start to where the
  /// distance to its completion point is ed[i] (0: the whole move). False if
  /// no move is active or cd is shorter than ed. Bounded bisections.
  bool calculated_data(std::span<const double> ed, std::span<double> cd) const noexcept;

  /// Fold: origin = position (the slot's offset becomes 0; the caller has
  /// moved it into the axes' base). Realtime-safe.
  void fold() noexcept { origin_ = pos_; }

  /// MDCC changed the master (seed 001): the next step takes the new
  /// master's position as its reference (no travel is counted for the
  /// switch). Realtime-safe.
  void master_changed() noexcept { have_mp_ = false; }

  bool idle() const noexcept { return !has_head_ && !has_tail_ && !has_pending_; }
  bool moving() const noexcept { return has_head_ || has_tail_; }
  bool stopping() const noexcept { return stopping_; }
  std::uint32_t active_id() const noexcept { return has_head_ && !head_.pc ? head_.rq.id : 0; }
  std::uint32_t pending_id() const noexcept { return has_pending_ ? pending_.rq.id : 0; }
  /// The id of the stop that runs (0: none).
  std::uint32_t stop_id() const noexcept { return stopping_ ? stop_id_ : 0; }
  /// The head (active move) runs on the master's travel.
  bool master_driven() const noexcept { return has_head_ && ht_.clock == Clock::Master; }
  const Vec3& position() const noexcept { return pos_; }
  double speed() const noexcept { return speed_; }
  const SystemConfig& config() const noexcept { return cfg_; }

 private:
  enum class Clock : std::uint8_t { Time, Master };

  /// A move's request and geometry (active or pending).
  struct Slot {
    MoveRequest rq;
    Path path;
    bool blended_into = false;  ///< started by a blend (CT rule 50 %)
    bool pc = false;            ///< Completed already sent
  };

  /// The motion of one segment along its path.
  struct Track {
    Path path;
    Profile prof;
    int hint = 0;
    Clock clock = Clock::Time;
    Limits lim;
    double u = 0.0;   ///< abscissa since the start (s, or master units)
    double u0 = 0.0;  ///< abscissa where `prof` starts
    Kin k;            ///< last sample: s, ds/du, d2s/du2
    double ve = 0.0;  ///< planned end speed (Follow Contour junction)
    double td = 0.0;  ///< abscissa where the final deceleration starts (TT3)
    bool paused = false;
    bool resume = false;  ///< `prof` is a stop short of the end; then on from rest (plan_head)
    // Mirror phase of a blended head [README "Blending"].
    bool mirror = false;
    double mk = 0.0;   ///< scale k
    double mvm = 0.0;  ///< tail speed where the mirror starts
    double msm = 0.0;  ///< tail position there
    double mu = 0.0;   ///< tail abscissa where the mirror starts
    Kin cont;          ///< state where the continuation profile starts
  };

  void sample_head() noexcept;
  bool transition(const Present& now, Events& ev) noexcept;
  bool pc_condition(const Present& now) const noexcept;
  double pc_abscissa() const noexcept;
  void activate_from_rest(const Present& now, double excess, bool chained, Events& ev) noexcept;
  void activate_junction(const Present& now, double v_end, double excess, Events& ev) noexcept;
  void activate_blend(Events& ev) noexcept;
  void start_track(const Slot& s, double u) noexcept;
  void plan_head(const Kin& from, double ve, double u0, Overshoot policy) noexcept;
  void plan_junction() noexcept;
  void fresh_lock(const MoveRequest& rq, const Present& now) noexcept;
  Kin to_time(const Track& t) const noexcept;
  double ct_eff(bool with_successor) const noexcept;
  double head_s_at(double u) const noexcept;
  void outputs(const Present& now, Output& out) noexcept;

  SystemConfig cfg_;
  Slot head_, pending_;
  Track ht_, tt_;  ///< head (active move or stop ramp) and tail (the finishing move of a blend)
  bool has_head_ = false, has_tail_ = false, has_pending_ = false;
  bool stopping_ = false;
  std::uint32_t stop_id_ = 0;
  double ub_ = 0.0;  ///< tail abscissa when the head's blend started
  double tb_ = 0.0;  ///< tail abscissa from which the next move may blend in
  double du_head_ = 0.0;  ///< the head's abscissa step this cycle
  Vec3 rest_;        ///< path position when nothing moves
  Vec3 origin_;
  Vec3 pos_;
  double speed_ = 0.0;
  // MDCC following (master_follow_step; one lock per coordinate system).
  LockDirection lock_ = LockDirection::None;
  double lock_pos_ = 0.0;
  bool locked_ = false, following_ = false, have_mp_ = false;
  double prev_mp_ = 0.0;
  double mdot_ = 0.0;  ///< master speed in the lock direction this cycle (0 when not following)
  bool last_master_ = false;  ///< the last active move was master-driven (its lock carries on)
};

}  // namespace canmotion::motion::coord
