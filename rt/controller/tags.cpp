#include "rt/controller/tags.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <unistd.h>

#include <fmt/format.h>

namespace canmotion::rt {
namespace {

std::string lower(std::string_view s) {
  std::string o(s);
  for (char& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// Axis attributes (TagRef::member numbers).
enum Attr : std::uint8_t {
  kActualPosition, kCommandPosition, kActualVelocity, kCommandVelocity, kCommandAcceleration, kPositionError,
  kMotionStatus, kAxisStatus, kAxisFault, kAxisState, kDriveState, kStatusword, kControlword, kLastEmcy,
  kTpdoMissed, kMaxPositionError, kDirectCommandVelocity, kDirectCommandTorque,
  kDriveWarning, kInternalLimitActive, kDriveFollowsCommand, kDriveFollowingError, kActualCounts, kTargetCounts,
};
struct Named {
  std::string_view name;
  std::uint8_t value;
};
constexpr std::array kAttrs{
    Named{"ActualPosition", kActualPosition},   Named{"CommandPosition", kCommandPosition},
    Named{"ActualVelocity", kActualVelocity},   Named{"CommandVelocity", kCommandVelocity},
    Named{"CommandAcceleration", kCommandAcceleration}, Named{"PositionError", kPositionError},
    Named{"MotionStatus", kMotionStatus},       Named{"AxisStatus", kAxisStatus},
    Named{"AxisFault", kAxisFault},             Named{"AxisState", kAxisState},
    Named{"DriveState", kDriveState},           Named{"Statusword", kStatusword},
    Named{"Controlword", kControlword},         Named{"LastEmcy", kLastEmcy},
    Named{"TpdoMissed", kTpdoMissed},           Named{"MaxPositionError", kMaxPositionError},
    // MDS live commands (writable; read back as the last value written here)
    Named{"DirectCommandVelocity", kDirectCommandVelocity}, Named{"DirectCommandTorque", kDirectCommandTorque},
    // Statusword bits 7, 11, 12, 13 as the drive's mode gives them meaning (cia402::decode_status_bits)
    Named{"DriveWarning", kDriveWarning},       Named{"InternalLimitActive", kInternalLimitActive},
    Named{"DriveFollowsCommand", kDriveFollowsCommand}, Named{"DriveFollowingError", kDriveFollowingError},
    // The drive frame in 64-bit counts: 0x6064 unwrapped, 0x607A before its low 32 bits are sent
    Named{"ActualCounts", kActualCounts},       Named{"TargetCounts", kTargetCounts},
};
namespace ms = motion::motion_status;
constexpr std::array kMotionBits{
    Named{"AccelStatus", ms::AccelStatus},
    Named{"DecelStatus", ms::DecelStatus},
    Named{"MoveStatus", ms::MoveStatus},
    Named{"JogStatus", ms::JogStatus},
    Named{"GearingStatus", ms::GearingStatus},
    Named{"HomingStatus", ms::HomingStatus},
    Named{"StoppingStatus", ms::StoppingStatus},
    Named{"AxisHomedStatus", ms::AxisHomedStatus},
    Named{"PositionCamStatus", ms::PositionCamStatus},
    Named{"TimeCamStatus", ms::TimeCamStatus},
    Named{"PositionCamPendingStatus", ms::PositionCamPendingStatus},
    Named{"TimeCamPendingStatus", ms::TimeCamPendingStatus},
    Named{"GearingLockStatus", ms::GearingLockStatus},
    Named{"PositionCamLockStatus", ms::PositionCamLockStatus},
    Named{"TimeCamLockStatus", ms::TimeCamLockStatus},
    Named{"MasterOffsetMoveStatus", ms::MasterOffsetMoveStatus},
    Named{"CoordinatedMotionStatus", ms::CoordinatedMotionStatus},
    Named{"TransformStateStatus", ms::TransformStateStatus},
    Named{"ControlledByTransformStatus", ms::ControlledByTransformStatus},
    Named{"DirectVelocityControlStatus", ms::DirectVelocityControlStatus},
    Named{"DirectTorqueControlStatus", ms::DirectTorqueControlStatus},
    Named{"MoveLockStatus", ms::MoveLockStatus},
    Named{"JogLockStatus", ms::JogLockStatus},
    Named{"MasterOffsetMoveLockStatus", ms::MasterOffsetMoveLockStatus},
    Named{"MaximumSpeedExceeded", ms::MaximumSpeedExceeded},
};
namespace as = motion::axis_status;
constexpr std::array kStatusBits{
    Named{"ServoActionStatus", as::ServoActionStatus},   Named{"DriveEnableStatus", as::DriveEnableStatus},
    Named{"ShutdownStatus", as::ShutdownStatus},         Named{"ConfigUpdateInProcess", as::ConfigUpdateInProcess},
    Named{"InhibitStatus", as::InhibitStatus},           Named{"DirectControlStatus", as::DirectControlStatus},
    Named{"AxisUpdateStatus", as::AxisUpdateStatus},
};
namespace af = motion::axis_fault;
constexpr std::array kFaultBits{
    Named{"PhysicalAxisFault", af::PhysicalAxisFault}, Named{"ModuleFault", af::ModuleFault},
    Named{"ConfigFault", af::ConfigFault},             Named{"GroupFault", af::GroupFault},
    Named{"MotionFault", af::MotionFault},             Named{"GuardFault", af::GuardFault},
    Named{"InitializationFault", af::InitializationFault}, Named{"APRFault", af::APRFault},
    Named{"SafetyFault", af::SafetyFault},
};
// MOTION_INSTRUCTION members.
enum Member : std::uint8_t { kErr, kExerr, kState, kSegment, kStatusMember };
constexpr std::array kControlFlags{
    Named{"EN", motion::flag::EN}, Named{"DN", motion::flag::DN}, Named{"ER", motion::flag::ER},
    Named{"PC", motion::flag::PC}, Named{"IP", motion::flag::IP}, Named{"AC", motion::flag::AC},
    Named{"ACCEL", motion::flag::ACCEL}, Named{"DECEL", motion::flag::DECEL},
    Named{"TrackingMaster", motion::flag::TrackingMaster},
};
constexpr std::array kControlMembers{
    Named{"ERR", kErr}, Named{"EXERR", kExerr}, Named{"STATE", kState}, Named{"SEGMENT", kSegment},
    Named{"STATUS", kStatusMember},
};

// COORDINATE_SYSTEM members and status bits (motion/types.hpp).
enum CsAttr : std::uint8_t { kCsSystemStatus, kCsMotionStatus, kCsActualPosition, kCsCommandPosition, kCsSpeed };
constexpr std::array kCsAttrs{
    Named{"CoordinateSystemStatus", kCsSystemStatus}, Named{"CoordinateMotionStatus", kCsMotionStatus},
    Named{"ActualPosition", kCsActualPosition},       Named{"CommandPosition", kCsCommandPosition},
    Named{"Speed", kCsSpeed},
};
namespace cms = motion::coordinate_motion_status;
constexpr std::array kCsMotionBits{
    Named{"AccelStatus", cms::AccelStatus},
    Named{"DecelStatus", cms::DecelStatus},
    Named{"ActualPosToleranceStatus", cms::ActualPosToleranceStatus},
    Named{"CommandPosToleranceStatus", cms::CommandPosToleranceStatus},
    Named{"StoppingStatus", cms::StoppingStatus},
    Named{"MoveStatus", cms::MoveStatus},
    Named{"MoveTransitionStatus", cms::MoveTransitionStatus},
    Named{"MovePendingStatus", cms::MovePendingStatus},
    Named{"MovePendingQueueFullStatus", cms::MovePendingQueueFullStatus},
    Named{"CoordinateSystemLockStatus", cms::CoordinateSystemLockStatus},
};
namespace css = motion::coordinate_system_status;
constexpr std::array kCsSystemBits{
    Named{"ShutdownStatus", css::ShutdownStatus}, Named{"ReadyStatus", css::ReadyStatus},
    Named{"MotionStatus", css::MotionStatus},     Named{"AxisInhibitStatus", css::AxisInhibitStatus},
};

constexpr std::array kCamMembers{Named{"Master", 0}, Named{"Slave", 1}, Named{"SegmentType", 2}};

/// `name[index]` -> name and index; nullopt when `base` is not of that form.
std::optional<std::pair<std::string_view, std::uint32_t>> split_index(std::string_view base) {
  const std::size_t br = base.find('[');
  if (br == std::string_view::npos || br == 0 || base.back() != ']' || base.size() < br + 3) return std::nullopt;
  std::uint32_t idx = 0;
  for (std::size_t i = br + 1; i + 1 < base.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(base[i])) || idx > 100'000'000u) return std::nullopt;
    idx = idx * 10 + static_cast<std::uint32_t>(base[i] - '0');
  }
  return std::make_pair(base.substr(0, br), idx);
}

template <std::size_t N>
const Named* find(const std::array<Named, N>& a, std::string_view name) {
  for (const Named& n : a)
    if (iequals(n.name, name)) return &n;
  return nullptr;
}

/// The process's resident set in KiB (/proc/self/statm), 0 when unreadable.
/// Read on the thread that reads the tag (the script's or the socket's, never
/// the cycle's).
double resident_kib() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long size = 0, resident = 0;
  const int n = std::fscanf(f, "%lu %lu", &size, &resident);
  std::fclose(f);
  if (n != 2) return 0;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1024.0;
}

}  // namespace

TagTable::TagTable(Controller& c) : c_(c) {
  add_statistic("Cycle", [&c] { return static_cast<double>(c.cycles()); });
  add_statistic("Time", [&c] { return static_cast<double>(c.cycles()) * c.period_s(); });
  add_statistic("RssKiB", [] { return resident_kib(); });
}

void TagTable::add_statistic(const std::string& name, std::function<double()> get) {
  stats_.emplace_back(name, std::move(get));
}

std::vector<std::string_view> TagTable::axis_members() {
  std::vector<std::string_view> v;
  for (const auto& n : kAttrs) v.push_back(n.name);
  for (const auto& n : kMotionBits) v.push_back(n.name);
  for (const auto& n : kStatusBits) v.push_back(n.name);
  for (const auto& n : kFaultBits) v.push_back(n.name);
  return v;
}

std::optional<TagRef> TagTable::resolve(std::string_view name, std::string* error) {
  // Array tags of `arrays:`: pts[i].Master / .Slave / .SegmentType, ed[i].
  {
    const std::size_t d = name.find('.');
    const std::string_view base = name.substr(0, d);
    const std::string_view member = d == std::string_view::npos ? std::string_view{} : name.substr(d + 1);
    if (const auto si = split_index(base)) {
      if (const auto a = c_.find_array(si->first); a && a->type != ArraySpec::Type::kCamProfile) {
        const bool cam = a->type == ArraySpec::Type::kCam;
        if (si->second >= a->size) {
          if (error)
            *error = fmt::format("{}[{}]: array '{}' has {} elements ([0] .. [{}])", si->first, si->second, si->first,
                                 a->size, a->size - 1);
          return std::nullopt;
        }
        if (!cam) {
          if (d == std::string_view::npos) return TagRef{TagRef::Kind::kRealElement, a->id, 0, true, a->offset + si->second};
          if (error) *error = fmt::format("'{}' is a REAL array: write {}[{}] without a member", si->first, si->first, si->second);
          return std::nullopt;
        }
        if (const Named* n = find(kCamMembers, member)) return TagRef{TagRef::Kind::kCamPoint, a->id, n->value, true, si->second};
        if (error)
          *error = fmt::format("'{}' is a CAM array; its elements have the members Master, Slave and SegmentType, "
                               "e.g. {}[{}].Master",
                               si->first, si->first, si->second);
        return std::nullopt;
      }
    }
  }
  const std::size_t dot = name.find('.');
  if (dot == std::string_view::npos) {
    if (auto it = user_.find(lower(name)); it != user_.end())
      return TagRef{TagRef::Kind::kUser, 0, 0, true};
    if (error)
      *error = fmt::format("no tag named '{}': write Axis.Attribute (X.ActualPosition), control.MEMBER (mam1.DN), "
                           "Controller.<statistic>, or a numeric tag created by '{} := value;'",
                           name, name);
    return std::nullopt;
  }
  const std::string_view base = name.substr(0, dot);
  const std::string_view member = name.substr(dot + 1);
  if (iequals(base, "Controller")) {
    for (std::size_t i = 0; i < stats_.size(); ++i)
      if (iequals(stats_[i].first, member)) return TagRef{TagRef::Kind::kController, static_cast<std::uint16_t>(i), 0, false};
    std::vector<std::string_view> names;
    for (const auto& s : stats_) names.push_back(s.first);
    if (error) *error = fmt::format("Controller has no member '{}'; members: {}", member, fmt::join(names, ", "));
    return std::nullopt;
  }
  if (const std::size_t br = base.find('['); br != std::string_view::npos) {
    const auto cam = c_.cam_id(base.substr(0, br));
    if (cam && base.substr(br) == "[0]" && iequals(member, "Status"))
      return TagRef{TagRef::Kind::kCamStatus, *cam, 0, false};
    if (error)
      *error = cam ? fmt::format("a CAM_PROFILE tag has one member, {}[0].Status", base.substr(0, br))
                   : fmt::format("no cam profile named '{}'", base.substr(0, br));
    return std::nullopt;
  }
  if (const auto cs = c_.coordinate_system_id(base)) return resolve_coordinate_system(*cs, base, member, error);
  for (std::size_t a = 0; a < c_.axis_count(); ++a) {
    if (!iequals(c_.axis_name(static_cast<motion::AxisId>(a)), base)) continue;
    const auto id = static_cast<std::uint16_t>(a);
    if (const Named* n = find(kAttrs, member))
      return TagRef{TagRef::Kind::kAxis, id, n->value,
                    n->value == kDirectCommandVelocity || n->value == kDirectCommandTorque};
    if (const Named* n = find(kMotionBits, member)) return TagRef{TagRef::Kind::kMotionBit, id, n->value, false};
    if (const Named* n = find(kStatusBits, member)) return TagRef{TagRef::Kind::kAxisStatusBit, id, n->value, false};
    if (const Named* n = find(kFaultBits, member)) return TagRef{TagRef::Kind::kAxisFaultBit, id, n->value, false};
    if (error) {
      std::vector<std::string_view> attrs;
      for (const Named& n : kAttrs) attrs.push_back(n.name);
      *error = fmt::format("axis '{}' has no attribute '{}'; attributes: {}, and every MotionStatus, AxisStatus "
                           "and AxisFault bit by name (e.g. GearingLockStatus)",
                           base, member, fmt::join(attrs, ", "));
    }
    return std::nullopt;
  }
  if (const auto ctl = c_.find_control(lower(base))) {
    if (const Named* n = find(kControlFlags, member)) return TagRef{TagRef::Kind::kControlFlag, *ctl, n->value, false};
    if (const Named* n = find(kControlMembers, member)) return TagRef{TagRef::Kind::kControl, *ctl, n->value, false};
    if (error)
      *error = fmt::format("'{}' is a MOTION_INSTRUCTION; members: EN DN ER PC IP AC ACCEL DECEL TrackingMaster ERR EXERR STATE "
                           "SEGMENT STATUS, not '{}'",
                           base, member);
    return std::nullopt;
  }
  if (error) {
    std::vector<std::string> axes;
    for (std::size_t a = 0; a < c_.axis_count(); ++a) axes.push_back(c_.axis_name(static_cast<motion::AxisId>(a)));
    *error = fmt::format("'{}' is neither an axis ({}), a control tag used by an instruction so far, nor Controller",
                         base, fmt::join(axes, ", "));
  }
  return std::nullopt;
}

std::optional<TagRef> TagTable::resolve_coordinate_system(motion::CoordSystemId cs, std::string_view base,
                                                         std::string_view member, std::string* error) const {
  const int dim = c_.spec().coordinate_systems.at(cs).config.dim;
  if (const auto si = split_index(member)) {
    const Named* n = find(kCsAttrs, si->first);
    if (n && (n->value == kCsActualPosition || n->value == kCsCommandPosition)) {
      if (si->second < static_cast<std::uint32_t>(dim)) return TagRef{TagRef::Kind::kCoordSystem, cs, n->value, false, si->second};
      if (error) *error = fmt::format("{}.{}: coordinate system '{}' has {} axes ([0] .. [{}])", base, member, base, dim, dim - 1);
      return std::nullopt;
    }
  } else if (const Named* n = find(kCsAttrs, member); n && n->value != kCsActualPosition && n->value != kCsCommandPosition) {
    return TagRef{TagRef::Kind::kCoordSystem, cs, n->value, false};
  }
  if (const Named* n = find(kCsMotionBits, member)) return TagRef{TagRef::Kind::kCoordMotionBit, cs, n->value, false};
  if (const Named* n = find(kCsSystemBits, member)) return TagRef{TagRef::Kind::kCoordSystemBit, cs, n->value, false};
  if (error)
    *error = fmt::format("coordinate system '{}' has no member '{}'; members: CoordinateSystemStatus, "
                         "CoordinateMotionStatus, ActualPosition[i], CommandPosition[i], Speed, and each status bit "
                         "by name (e.g. MoveStatus, MovePendingStatus, ReadyStatus)",
                         base, member);
  return std::nullopt;
}

double TagTable::read(const Status& s, const TagRef& t) const {
  switch (t.kind) {
    case TagRef::Kind::kCoordMotionBit: return (s.systems[t.index].motion_status >> t.member) & 1u;
    case TagRef::Kind::kCoordSystemBit: return (s.systems[t.index].system_status >> t.member) & 1u;
    case TagRef::Kind::kCoordSystem: {
      const motion::CoordSystemTag& c = s.systems[t.index];
      switch (t.member) {
        case kCsSystemStatus: return c.system_status;
        case kCsMotionStatus: return c.motion_status;
        case kCsActualPosition: return c.actual_position[t.element];
        case kCsCommandPosition: return c.command_position[t.element];
        default: return c.speed;
      }
    }
    case TagRef::Kind::kUser: return 0.0;  // read through the name (see read(s, name))
    case TagRef::Kind::kCamStatus: return s.cam_status[t.index];
    case TagRef::Kind::kCamPoint: {
      ArrayRef a;
      a.type = ArraySpec::Type::kCam;
      a.id = t.index;
      return c_.read_cam_point(a, t.element, t.member);
    }
    case TagRef::Kind::kRealElement: return t.element < s.real_values.size() ? s.real_values[t.element] : 0.0;
    case TagRef::Kind::kController: return stats_.at(t.index).second();
    case TagRef::Kind::kControlFlag: return s.controls[t.index].get(t.member) ? 1.0 : 0.0;
    case TagRef::Kind::kControl: {
      const motion::ControlTag& c = s.controls[t.index];
      switch (t.member) {
        case kErr: return c.err;
        case kExerr: return c.exerr;
        case kState: return c.state;
        case kSegment: return c.segment;
        default: return c.status;
      }
    }
    case TagRef::Kind::kMotionBit: return (s.axes[t.index].tag.motion_status >> t.member) & 1u;
    case TagRef::Kind::kAxisStatusBit: return (s.axes[t.index].tag.axis_status >> t.member) & 1u;
    case TagRef::Kind::kAxisFaultBit: return (s.axes[t.index].tag.axis_fault >> t.member) & 1u;
    case TagRef::Kind::kAxis: {
      const AxisSnapshot& a = s.axes[t.index];
      switch (t.member) {
        case kActualPosition: return a.tag.actual_position;
        case kCommandPosition: return a.tag.command_position;
        case kActualVelocity: return a.tag.actual_velocity;
        case kCommandVelocity: return a.tag.command_velocity;
        case kCommandAcceleration: return a.tag.command_acceleration;
        case kPositionError: return a.tag.position_error;
        case kMotionStatus: return a.tag.motion_status;
        case kAxisStatus: return a.tag.axis_status;
        case kAxisFault: return a.tag.axis_fault;
        case kAxisState: return static_cast<double>(a.tag.state);
        case kDriveState: return static_cast<double>(a.drive_state);
        case kStatusword: return a.statusword;
        case kControlword: return a.controlword;
        case kLastEmcy: return a.last_emcy;
        case kTpdoMissed: return static_cast<double>(a.tpdo_missed);
        case kDirectCommandVelocity:
        case kDirectCommandTorque: {
          const auto it = direct_.find((static_cast<std::uint32_t>(t.index) << 8) | t.member);
          return it == direct_.end() ? 0.0 : it->second;
        }
        case kActualCounts: return static_cast<double>(a.actual_counts);
        case kTargetCounts: return static_cast<double>(a.target_counts);
        case kDriveWarning:
        case kInternalLimitActive:
        case kDriveFollowsCommand:
        case kDriveFollowingError: {
          const cia402::StatusBits b =
              cia402::decode_status_bits(a.statusword, static_cast<cia402::Mode>(a.mode_display));
          const bool on = t.member == kDriveWarning          ? b.warning
                          : t.member == kInternalLimitActive ? b.internal_limit
                          : t.member == kDriveFollowsCommand ? b.follows_command
                                                             : b.following_error;
          return on ? 1.0 : 0.0;
        }
        default: return a.max_abs_position_error;
      }
    }
  }
  return 0.0;
}

std::optional<double> TagTable::read(const Status& s, std::string_view name, std::string* error) {
  const auto t = resolve(name, error);
  if (!t) return std::nullopt;
  if (t->kind == TagRef::Kind::kUser) return user_.find(lower(name))->second;
  return read(s, *t);
}

bool TagTable::is_user_tag_name(std::string_view name) noexcept {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
}

std::optional<std::string> TagTable::write(std::string_view name, double value, bool create) {
  std::string e;
  const auto t = resolve(name, &e);
  if (t && !t->writable) return fmt::format("tag '{}' is read-only", name);
  if (t && t->kind == TagRef::Kind::kAxis) {  // MDS live command (DirectCommandVelocity / DirectCommandTorque)
    if (!std::isfinite(value)) return fmt::format("tag '{}' needs a finite number", name);
    const cmd::DirectCommand c{t->index, t->member == kDirectCommandTorque, value};
    if (c_.submit(c) == 0) return std::string("the controller's command queue is full; try again");
    direct_[(static_cast<std::uint32_t>(t->index) << 8) | t->member] = value;
    return std::nullopt;
  }
  if (t && (t->kind == TagRef::Kind::kCamPoint || t->kind == TagRef::Kind::kRealElement)) {
    if (!std::isfinite(value)) return fmt::format("{}: {} is not a finite number", name, value);
    if (t->kind == TagRef::Kind::kCamPoint && t->member == 2 &&
        (value != std::trunc(value) || std::abs(value) > 2147483647.0))
      return fmt::format("{}: SegmentType is a DINT (0 linear, 1 cubic), got {}", name, value);
    const auto si = split_index(name.substr(0, name.find('.')));
    const auto a = c_.find_array(si->first);
    const std::uint32_t element = t->kind == TagRef::Kind::kCamPoint ? t->element : t->element - a->offset;
    const std::uint64_t seq = c_.write_array(*a, element, t->member, value);
    if (seq == 0) return std::string("the command queue to the RT thread is full; try again");
    last_write_seq_ = seq;
    return std::nullopt;
  }
  if (!t) {
    if (!create || !is_user_tag_name(name)) return e;
    if (c_.axis_id(name) || c_.find_control(lower(name))) return fmt::format("'{}' is an axis or control tag, not a number", name);
  }
  user_[lower(name)] = value;
  return std::nullopt;
}

}  // namespace canmotion::rt
