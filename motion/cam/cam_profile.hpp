#pragma once
/// \file
/// Logix CAM points, the CAM_PROFILE array, MCCP (Motion Calculate Cam
/// Profile) and profile evaluation. Pure code: no I/O, no clocks, no
/// allocation after a CamProfile is constructed. See motion/cam/README.md.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "motion/cam/cam_error.hpp"

namespace canmotion::motion::cam {

/// CAM.SegmentType values (Logix DINT): interpolation from a point to the next.
inline constexpr std::int32_t kSegmentLinear = 0;
/// Cubic spline segment.
inline constexpr std::int32_t kSegmentCubic = 1;

/// One Logix CAM element {Master, Slave, SegmentType} [RM002H p.627].
/// Logix stores Master/Slave as REAL; they are kept as double here (a REAL
/// converts exactly). segment_type is the raw DINT so that an illegal value
/// (ERR 28) can be represented and reported.
struct CamPoint {
  double master = 0.0;                       ///< x: master position, or time for MATC
  double slave = 0.0;                        ///< y: slave position
  std::int32_t segment_type = kSegmentLinear;  ///< 0 linear, 1 cubic (to the next point)
};

/// CAM_PROFILE[0].Status values [RM002H p.159, p.627; seed 004 "Cam Profile
/// Array Checks"]. A value n > 2 means "calculated, in use by n - 2 cams".
namespace profile_status {
inline constexpr std::int32_t kNotCalculated = 0;  ///< never calculated, or invalidated
inline constexpr std::int32_t kCalculating = 1;    ///< MCCP running
inline constexpr std::int32_t kCalculated = 2;     ///< calculated, not in use
}  // namespace profile_status

/// One CAM_PROFILE element. Layout follows the hidden members of Logix'
/// CAM_PROFILE (ICS cam_profile.cs: Status, Type, Master, Slave, A0..A3).
/// Element i describes the segment from cam point i to point i + 1:
///   slave(x) = a0 + a1*u + a2*u^2 + a3*u^3 with u = x - master.
/// The last element (i = point_count - 1) holds the end point, with
/// a0 = slave and a1..a3 = 0. Only element [0]'s status is meaningful.
struct CamProfileElement {
  std::int32_t status = profile_status::kNotCalculated;  ///< only [0] is used
  std::int32_t type = kSegmentLinear;  ///< segment type from this point to the next
  double master = 0.0;                 ///< knot master value M_i
  double slave = 0.0;                  ///< knot slave value S_i
  double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;  ///< polynomial in u = x - master
};

/// Slave position and its first and second derivative with respect to the
/// profile's master coordinate.
struct CamSample {
  double position = 0.0;      ///< slave(x)
  double velocity = 0.0;      ///< d slave / d x
  double acceleration = 0.0;  ///< d^2 slave / d x^2
};

/// Behaviour outside [master_start, master_end].
enum class EndBehaviour : std::uint8_t {
  /// Hold the end value, derivatives 0 (a Once cam that has finished: the
  /// axis motion stops). The default.
  Clamp = 0,
  /// Continue along the tangent of the first/last segment (derivative equal
  /// to the end slope, second derivative 0).
  Extrapolate = 1,
};

/// Segment hint for repeated lookups (one per user, e.g. per camming axis).
/// With monotonic master motion a lookup costs O(1) amortised; a jump falls
/// back to binary search, O(log n). A default-constructed cursor is valid.
struct CamCursor {
  std::size_t segment = 0;  ///< last segment found
};

/// Outcome of an MCCP calculation: .ERR, .EXERR and a static explanation.
struct MccpResult {
  CamError err = CamError::None;  ///< Logix .ERR (0 on success)
  /// Logix .EXERR: for ERR 13 the zero-based MCCP operand index
  /// (0 MotionControl, 1 Cam, 2 Length, 3 StartSlope, 4 EndSlope, 5 CamProfile);
  /// 0 otherwise.
  std::int32_t exerr = 0;
  /// Index in the CAM array of the offending point (ERR 13 on a point or on
  /// the Cam index, 28, 29); -1 when the error is not about one element.
  std::int64_t cam_index = -1;
  /// For ERR 26/27: the Length operand that was refused; 0 otherwise.
  std::int64_t length = 0;
  /// Static, human-readable reason (never allocated).
  const char* reason = "";
  /// True when the profile was calculated.
  [[nodiscard]] bool ok() const noexcept { return err == CamError::None; }
};

/// Zero-based MCCP operand indices (ST order = faceplate order), for EXERR.
namespace mccp_operand {
inline constexpr std::int32_t kMotionControl = 0;
inline constexpr std::int32_t kCam = 1;
inline constexpr std::int32_t kLength = 2;
inline constexpr std::int32_t kStartSlope = 3;
inline constexpr std::int32_t kEndSlope = 4;
inline constexpr std::int32_t kCamProfile = 5;
}  // namespace mccp_operand

/// The operands of `MCCP(MotionControl, Cam, Length, StartSlope, EndSlope, CamProfile)`
/// that carry data (MotionControl belongs to the caller; CamProfile is the
/// CamProfile object passed alongside).
struct MccpRequest {
  std::span<const CamPoint> cam;  ///< the whole CAM array tag
  std::int64_t start_index = 0;   ///< index of the Cam operand element (first point used)
  std::int64_t length = 0;        ///< Length operand: number of points used
  double start_slope = 0.0;       ///< used only when the first segment is cubic
  double end_slope = 0.0;         ///< used only when the last segment is cubic
};

/// A Logix CAM_PROFILE array with a fixed number of elements.
///
/// Capacity: the declared array dimension, chosen when the profile is created
/// (configuration load or tag creation, non-RT). Nothing allocates afterwards:
/// the element array and the spline solver's scratch vectors are sized once
/// in the constructor. A profile can hold a cam of up to capacity() points.
///
/// Threading: a profile is owned by one thread at a time (the RT thread once
/// the controller runs; the config loader before). Status is a plain int.
class CamProfile {
 public:
  /// Hard upper bound on the capacity of one profile (16 Mi points, ~1.9 GiB
  /// with scratch): a guard against absurd configuration values, not a
  /// Logix limit. Size profiles to the largest cam they will receive.
  static constexpr std::size_t kMaxCapacity = std::size_t{1} << 24;

  /// Creates an uncalculated profile of `capacity` elements (>= 1).
  /// Not realtime-safe (allocates). Throws std::invalid_argument when
  /// capacity is 0 or above kMaxCapacity.
  explicit CamProfile(std::size_t capacity);

  /// Declared number of elements. Realtime-safe.
  [[nodiscard]] std::size_t capacity() const noexcept { return elems_.size(); }
  /// Number of cam points of the calculated profile (0 when not calculated).
  /// Realtime-safe.
  [[nodiscard]] std::size_t point_count() const noexcept { return calculated() ? count_ : 0; }
  /// Number of segments (point_count() - 1, or 0). Realtime-safe.
  [[nodiscard]] std::size_t segment_count() const noexcept { return point_count() > 0 ? count_ - 1 : 0; }
  /// CAM_PROFILE[0].Status. Realtime-safe.
  [[nodiscard]] std::int32_t status() const noexcept { return elems_[0].status; }
  /// Status >= 2: the profile may be used for camming. Realtime-safe.
  [[nodiscard]] bool calculated() const noexcept { return status() >= profile_status::kCalculated && count_ >= 2; }
  /// Number of cams using the profile (Status - 2, or 0). Realtime-safe.
  [[nodiscard]] std::int32_t users() const noexcept { return calculated() ? status() - profile_status::kCalculated : 0; }

  /// The calculated elements [0, point_count()). Empty when not calculated.
  /// Realtime-safe.
  [[nodiscard]] std::span<const CamProfileElement> elements() const noexcept {
    return {elems_.data(), point_count()};
  }

  /// First / last master value, first / last slave value, and the spans
  /// (end - start) of the calculated profile. 0 when not calculated.
  /// Realtime-safe.
  [[nodiscard]] double master_start() const noexcept { return calculated() ? elems_[0].master : 0.0; }
  [[nodiscard]] double master_end() const noexcept { return calculated() ? elems_[count_ - 1].master : 0.0; }
  [[nodiscard]] double slave_start() const noexcept { return calculated() ? elems_[0].slave : 0.0; }
  [[nodiscard]] double slave_end() const noexcept { return calculated() ? elems_[count_ - 1].slave : 0.0; }
  [[nodiscard]] double master_span() const noexcept { return master_end() - master_start(); }
  [[nodiscard]] double slave_span() const noexcept { return slave_end() - slave_start(); }

  /// Camming start check (MATC/MAPC): Status 0 or 1 gives
  /// CamProfileNotCalculated (32); otherwise Status is incremented ("in use
  /// by one more cam") and None is returned. Realtime-safe.
  [[nodiscard]] CamError acquire() noexcept;
  /// A cam using the profile completed or terminated: Status is decremented,
  /// never below 2. Realtime-safe.
  void release() noexcept;
  /// Marks the profile not calculated (Status 0), e.g. when a program writes
  /// 0 to CamProfile[0].Status. Refused (returns CamProfileBeingUsed) while in
  /// use. Realtime-safe.
  [[nodiscard]] CamError invalidate() noexcept;

  /// A program's write to the CamProfile[0].Status tag (Logix shows Status in
  /// the tag editor). Sets the raw value: 0 forces "not calculated", 1 marks a
  /// calculation in progress elsewhere (MCCP then answers 30). Writing 2 or
  /// more to a never-calculated profile does not make it calculated:
  /// point_count() stays 0 until an MCCP succeeds. Realtime-safe.
  void write_status(std::int32_t status) noexcept;

  /// Segment containing `master`: the i with M_i <= master < M_{i+1}
  /// (the last segment for master >= M_last, segment 0 for master < M_0).
  /// Binary search, O(log n). Precondition: calculated(). Realtime-safe.
  [[nodiscard]] std::size_t find_segment(double master) const noexcept;
  /// As find_segment(master), starting from the cursor's segment: O(1) when
  /// the master stays in or steps to a neighbouring segment, binary search
  /// otherwise. Updates the cursor. Precondition: calculated(). Realtime-safe.
  [[nodiscard]] std::size_t find_segment(double master, CamCursor& cursor) const noexcept;

  /// Slave position, velocity and acceleration at `master` (binary search).
  /// Outside the master range see EndBehaviour. Returns zeros when the profile
  /// is not calculated; a NaN master gives NaN. Realtime-safe.
  [[nodiscard]] CamSample evaluate(double master, EndBehaviour end = EndBehaviour::Clamp) const noexcept;
  /// As evaluate(master, end), with a segment hint. Realtime-safe.
  [[nodiscard]] CamSample evaluate(double master, CamCursor& cursor,
                                   EndBehaviour end = EndBehaviour::Clamp) const noexcept;

 private:
  friend MccpResult mccp(const MccpRequest& request, CamProfile& profile) noexcept;
  [[nodiscard]] CamSample eval_in_segment(std::size_t seg, double master) const noexcept;
  [[nodiscard]] CamSample eval_outside(double master, EndBehaviour end) const noexcept;

  std::vector<CamProfileElement> elems_;  // size == capacity, never resized
  // Copy of the knot masters (size == capacity): the binary search touches
  // 8 bytes per probe instead of a 56-byte element, so a 10000-point
  // profile's search array (80 KB) stays in L2.
  std::vector<double> masters_;
  std::size_t count_ = 0;                 // points of the last successful MCCP
  // Tridiagonal spline system scratch, 6 * capacity doubles: sub-, main and
  // super-diagonal, right-hand side / solution, 1/h and chord slope per
  // segment, seen by MCCP as Eigen::Map
  // vectors. Kept in a std::vector so every allocation goes through operator
  // new (the RT allocation test counts it).
  std::vector<double> scratch_;
};

/// MCCP: validates the request and computes `profile` from
/// cam[start_index .. start_index + length).
///
/// Checks, in this order (first failure wins; the profile is left unchanged
/// on failure, so a previously calculated profile stays valid):
///  1. profile Status == 1 -> 30; Status > 2 -> 31;
///  2. start_index outside the CAM array -> 13, EXERR 1;
///  3. length < 2, or start_index + length > CAM array size -> 26;
///  4. length > profile.capacity() -> 27;
///  5. StartSlope / EndSlope not finite -> 13, EXERR 3 / 4;
///  6. per point, in order: master or slave not finite -> 13, EXERR 1;
///     SegmentType of a point that starts a segment not 0/1 -> 28 (the last
///     point's SegmentType is not used and not checked);
///     master <= previous master -> 29.
/// On success Status goes 1 then 2 and point_count() == length.
/// The spline rule is documented in motion/cam/README.md ("Spline rule").
/// Realtime-safe: O(length), no allocation.
[[nodiscard]] MccpResult mccp(const MccpRequest& request, CamProfile& profile) noexcept;

/// One-line explanation of an MCCP result for logs and tool output, e.g.
/// "MCCP ERR 29 ILLEGAL_CAM_ORDER: master values must strictly increase (cam[7])".
/// Not realtime-safe (allocates).
[[nodiscard]] std::string describe(const MccpResult& result);

}  // namespace canmotion::motion::cam
