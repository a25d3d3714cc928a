#pragma once
/// \file
/// Tag names as users write them in scripts and canmotionctl, resolved
/// against a Controller and read from its status snapshot:
///
///   X.ActualPosition  X.CommandPosition  X.ActualVelocity  X.CommandVelocity
///   X.PositionError   X.MotionStatus     X.AxisStatus      X.AxisFault
///   X.AxisState       X.<status bit>     (every MotionStatus / AxisStatus /
///                                          AxisFault bit by its Logix name,
///                                          e.g. X.GearingLockStatus)
///   X.DriveState  X.Statusword  X.Controlword  X.LastEmcy  X.TpdoMissed  (CIP drive axes)
///   X.DirectCommandVelocity  X.DirectCommandTorque  (writable: the MDS command, live;
///                                                    read back as the last value written)
///   mag1.EN .DN .ER .PC .IP .AC .ACCEL .DECEL .TrackingMaster .ERR .EXERR .STATE .SEGMENT .STATUS
///   cam1[0].Status    (CAM_PROFILE status: 0 not calculated, 2 calculated, n in use by n-2 cams)
///   pts[i].Master  pts[i].Slave  pts[i].SegmentType   (CAM arrays of `arrays:`, read/write)
///   ed[i]             (REAL arrays of `arrays:`, read/write; MAM EventDistance / CalculatedData)
///   CS.CoordinateSystemStatus  CS.CoordinateMotionStatus  CS.<status bit> (each bit of
///   both words by name, e.g. CS.MoveStatus, CS.ReadyStatus)  CS.ActualPosition[i]
///   CS.CommandPosition[i]  CS.Speed   (COORDINATE_SYSTEM tags of `coordinate_systems:`)
///   Controller.Cycle  Controller.Time  and the statistics the owner registers
///   user numeric tags (created by `tag := value;`)
///
/// Names are case-insensitive, as in Logix. Resolution is not realtime;
/// reading a resolved tag from a Status is cheap.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rt/controller/controller.hpp"

namespace canmotion::rt {

/// A resolved tag.
struct TagRef {
  enum class Kind : std::uint8_t { kAxis, kMotionBit, kAxisStatusBit, kAxisFaultBit, kControl, kControlFlag, kController, kUser, kCamStatus,
                                   kCamPoint, kRealElement, kCoordSystem, kCoordMotionBit, kCoordSystemBit };
  Kind kind = Kind::kAxis;
  std::uint16_t index = 0;  ///< axis id, control id, or statistic/user slot
  std::uint8_t member = 0;  ///< attribute number, bit number or member number
  bool writable = false;
  /// kCamPoint: element index (index = CAM array id, member 0 Master / 1 Slave /
  /// 2 SegmentType); kRealElement: position in Status::real_values;
  /// kCoordSystem ActualPosition[i] / CommandPosition[i]: i.
  std::uint32_t element = 0;
};

/// Resolves names and reads values. One per Controller, used from non-RT
/// threads (not thread-safe itself: give each thread its own or lock).
class TagTable {
 public:
  explicit TagTable(Controller& c);

  /// Resolve `name`; on failure sets `error` to a sentence with what would be valid.
  std::optional<TagRef> resolve(std::string_view name, std::string* error);
  /// Read a resolved tag from a status snapshot.
  [[nodiscard]] double read(const Status& s, const TagRef& t) const;
  /// Resolve and read in one go.
  std::optional<double> read(const Status& s, std::string_view name, std::string* error);
  /// Write a writable tag: a user tag (created when `create` is true), an
  /// axis's DirectCommandVelocity / DirectCommandTorque (queued for the RT
  /// thread; acts on an active MDS, see cmd::DirectCommand), or an
  /// array element (queued to the RT thread; see last_write_seq()).
  std::optional<std::string> write(std::string_view name, double value, bool create);
  /// True when `name` can be a user numeric tag: a letter or '_' followed by
  /// letters, digits and '_' (no member '.', no array index '[i]').
  static bool is_user_tag_name(std::string_view name) noexcept;
  /// Command sequence number of the last array element write (0 = none):
  /// the write is applied once Status::done_seq reaches it.
  [[nodiscard]] std::uint64_t last_write_seq() const noexcept { return last_write_seq_; }

  /// Extra read-only controller statistics (e.g. `Controller.LatencyMaxUs`),
  /// evaluated when read.
  void add_statistic(const std::string& name, std::function<double()> get);

  /// User numeric tags (for binding operands like `MAM(X, m, 0, Dist, ...)`).
  [[nodiscard]] const std::map<std::string, double, std::less<>>& user_tags() const noexcept { return user_; }

  /// All attribute and bit names of an axis (for help texts and `status`).
  static std::vector<std::string_view> axis_members();

 private:
  std::optional<TagRef> resolve_coordinate_system(motion::CoordSystemId cs, std::string_view base,
                                                  std::string_view member, std::string* error) const;

  Controller& c_;
  std::map<std::string, double, std::less<>> user_;  // lower-case name -> value
  std::vector<std::pair<std::string, std::function<double()>>> stats_;
  std::map<std::uint32_t, double> direct_;  // (axis << 8 | attribute) -> last DirectCommand* written
  std::uint64_t last_write_seq_ = 0;
};

}  // namespace canmotion::rt
