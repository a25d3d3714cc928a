// describe_axis_fault(): the log text of an axis exception latched as a
// fault (Event::Kind::kAxisFault). Not RT: canmotiond's housekeeping thread.
#include <fmt/format.h>

#include <cstdlib>

#include "rt/controller/controller.hpp"

namespace canmotion::rt {

namespace {

/// What the action did to the axis and what clears it (seed 002's exception
/// actions; MASR is MAFR plus leaving Shutdown).
std::string_view effect(motion::ExceptionAction a) {
  using A = motion::ExceptionAction;
  switch (a) {
    case A::FaultStatusOnly: return "the fault is shown, motion goes on; MAFR clears it";
    case A::StopPlanner: return "motion stopped, the servo stays on; MAFR clears it";
    case A::StopDrive: return "motion stopped, servo off (drive disabled); MAFR clears it, then MSO";
    case A::Shutdown: return "motion stopped, servo off, the axis in Shutdown; MASR clears it, then MSO";
    case A::Ignore:
    case A::Alarm: break;  // never latched as a fault
  }
  return "";
}

/// `v` with 6 significant digits, or as many more as it takes to show it
/// beyond `limit` (above it when `above`), so a value just past the limit
/// never reads as the limit itself.
std::string beyond(double v, double limit, bool above) {
  std::string t;
  for (int digits = 6; digits <= 17; ++digits) {
    t = fmt::format("{:.{}g}", v, digits);
    const double shown = std::strtod(t.c_str(), nullptr);
    if (above ? shown > limit : shown < limit) break;
  }
  return t;
}

}  // namespace

std::string describe_axis_fault(const Event& e, const AxisSpec& axis, std::size_t index) {
  using K = motion::ExceptionKind;
  const motion::AxisConfig& c = axis.config;
  if (e.value >= static_cast<std::uint64_t>(K::Count)) return fmt::format("exception {} latched", e.value);
  const auto kind = static_cast<K>(e.value);
  const std::string key = fmt::format("axes[{}]", index);
  const std::string_view u = c.units_name;
  std::string what;
  switch (kind) {
    case K::PositionError:
      what = fmt::format("position error {} {} beyond its tolerance {:.6g} {} ({}.position_error_tolerance)",
                         beyond(e.detail, c.position_error_tolerance, true), u, c.position_error_tolerance, u, key);
      break;
    case K::SoftOvertravelPos:
      what = fmt::format("command position {} {} beyond the positive soft limit {:.6g} {} ({}.soft_limits.positive)",
                         beyond(e.detail, c.soft_limit_pos, true), u, c.soft_limit_pos, u, key);
      break;
    case K::SoftOvertravelNeg:
      what = fmt::format("command position {} {} beyond the negative soft limit {:.6g} {} ({}.soft_limits.negative)",
                         beyond(e.detail, c.soft_limit_neg, false), u, c.soft_limit_neg, u, key);
      break;
    case K::DriveFault: what = "drive fault (its cause is logged for the drive)"; break;
    case K::NodeLost: what = "node lost (heartbeat lost, or the node left NMT operational)"; break;
    case K::BusOff: what = "its bus is off"; break;
    case K::Count: break;
  }
  const motion::ExceptionAction act = c.action(kind);
  return fmt::format("{}: {} ({}.exception_actions.{}): {}", what, motion::exception_action_name(act), key,
                     motion::exception_key(kind), effect(act));
}

}  // namespace canmotion::rt
