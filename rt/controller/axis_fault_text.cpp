// describe_axis_fault(): the log text of an axis exception latched as a
// fault (Event::Kind::kAxisFault); describe_drive_wait(): of an instruction
// that waited on the drive and ended with an error (Event::Kind::kDriveWait);
// describe_drive_status_bit(): a statusword bit's rising edge
// (Event::Kind::kDriveStatusBit). Not RT: canmotiond's housekeeping thread.
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
    case K::BusOff: what = "its bus is off (bus-off, or its interface down)"; break;
    case K::HardOvertravelPos: what = "PositiveOvertravelFault: the positive limit switch is active (0x60FD bit 1)"; break;
    case K::HardOvertravelNeg: what = "NegativeOvertravelFault: the negative limit switch is active (0x60FD bit 0)"; break;
    case K::Count: break;
  }
  const motion::ExceptionAction act = c.action(kind);
  return fmt::format("{}: {} ({}.exception_actions.{}): {}", what, motion::exception_action_name(act), key,
                     motion::exception_key(kind), effect(act));
}

std::string describe_drive_wait(const Event& e, const AxisSpec& axis, std::size_t index, std::string_view control,
                                double period_s) {
  using C = motion::DriveWaitCause;
  const std::string key = fmt::format("axes[{}].drive.timeouts", index);
  const motion::DriveWaitEnd& w = e.wait;
  std::string why;
  switch (w.cause) {
    case C::Limit:
      why = fmt::format("the drive did not get there within the wait limit {:.6g} s ({}.wait_ms; 0 or unset: "
                        "3 x boot_ms + mode_switch_ms + 4 x transition_ms)",
                        axis.config.drive_wait_limit, key);
      break;
    case C::LinkFailed: why = "the drive's boot failed"; break;
    case C::TransitionTimeout:
      why = fmt::format("the drive did not make a state transition within {:.6g} ms ({}.transition_ms)",
                        static_cast<double>(axis.drive.transition_timeout_ns) / 1e6, key);
      break;
    case C::DriveFault: why = "the drive went to Fault"; break;
    case C::AxisFaulted:
      why = "the axis latched a fault or went to Shutdown meanwhile (its exception action; MAFR or MASR, then MSO)";
      break;
  }
  std::string drive;
  if (axis.config.type == motion::AxisType::CipDrive) {
    const auto phase = cia402::phase_name(e.drive.phase);
    const auto state = cia402::state_name(e.drive.state);
    drive = fmt::format("; drive node {}: {}, {} (statusword 0x{:04X})", e.drive.node, phase, state, e.drive.statusword);
    if (e.failure.kind != cia402::FailureKind::kNone) drive += "; " + e.failure.to_string();
  }
  const std::string_view name = motion::signature(w.instr).name;
  return fmt::format("{}{}{} ended with ERR {} EXERR {} after {:.3f} s: {}{}", name, control.empty() ? "" : " ", control,
                     w.err, w.exerr, static_cast<double>(w.waited_cycles) * period_s, why, drive);
}

std::string describe_drive_status_bit(const Event& e, const AxisSpec& axis, std::size_t index) {
  std::string_view what, why;
  switch (e.value) {
    case 7:
      what = "bit 7 (warning)";
      why = "the drive reports a condition short of a fault (its EMCY or 0x603F says which, where it sends one); "
            "motion goes on";
      break;
    case 11:
      what = "bit 11 (internal limit active)";
      why = "the drive limits its own motion (a position, speed, torque or current limit of its own): the axis "
            "may not follow the command while it lasts";
      break;
    default:
      what = "bit 13 (following error)";
      why = "the drive's own following error window 0x6065 is exceeded (it faults when 0x6066 expires, if its "
            "following error option says so)";
      break;
  }
  const std::string_view mode = cia402::mode_name(static_cast<cia402::Mode>(e.mode_display));
  std::string guard;
  if (e.value == 13 && axis.config.position_error_tolerance <= 0)
    guard = fmt::format("; axes[{}].position_error_tolerance is not set: the drive's window is the axis's only guard",
                        index);
  return fmt::format("drive node {} set statusword {} in {} (0x6061 = {}), statusword 0x{:04X}: {}{}", e.drive.node,
                     what, mode, e.mode_display, e.drive.statusword, why, guard);
}

}  // namespace canmotion::rt
