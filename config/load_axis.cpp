// The loader's `axes:` section: planner settings, soft limits, homing,
// exception actions, the drive and `direct_control:` (MDS) of a CIP axis.
#include "config/load_sections.hpp"
#include "motion/axis.hpp"

namespace canmotion::config::load {

namespace {

void homing(Reader& r, const YAML::Node& n, const std::string& path, motion::HomingConfig& h, double conv) {
  if (!r.check_map(n, path, {"mode", "sequence", "position", "method", "speed_search", "speed_zero", "accel", "offset"}))
    return;
  using M = motion::HomingConfig::Mode;
  using S = motion::HomingConfig::Sequence;
  r.enumeration(n, path, "mode", h.mode, {{"Passive", M::Passive}, {"Active", M::Active}, {"Absolute", M::Absolute}});
  r.enumeration(n, path, "sequence", h.sequence,
                {{"Immediate", S::Immediate}, {"Switch", S::Switch}, {"Marker", S::Marker},
                 {"Switch Marker", S::SwitchMarker}, {"Torque Level", S::TorqueLevel},
                 {"Torque Level Marker", S::TorqueLevelMarker}});
  r.scalar(n, path, "position", h.home_position, -1e12, 1e12, "units");
  r.scalar(n, path, "method", h.cia_method, std::int8_t{-128}, std::int8_t{127});
  r.scalar(n, path, "speed_search", h.speed_search, 0.0, 1e12, "units/s");
  r.scalar(n, path, "speed_zero", h.speed_zero, 0.0, 1e12, "units/s");
  r.scalar(n, path, "accel", h.accel, 0.0, 1e15, "units/s^2");
  // 0x607C is written only when configured (a drive keeps its own otherwise).
  if (n["offset"] && r.scalar(n, path, "offset", h.offset, -1e12, 1e12, "units")) {
    // 0x607C is INTEGER32 (the drive re-references 0x6064 to it): never clamped.
    const double cnt = std::round(h.offset * conv);
    if (cnt < -2147483648.0 || cnt > 2147483647.0)
      r.error(n["offset"], sub(path, "offset"),
              fmt::format("{} units x conversion_constant {} = {} counts does not fit 0x607C home offset (INTEGER32, "
                          "-2147483648 .. 2147483647)",
                          h.offset, conv, cnt));
    else
      h.write_offset = true;
  }
}

/// `direct_control:` of a CIP axis (MDS): direct command kind, drive ramps, SLAT.
void direct_control(Reader& r, const YAML::Node& n, const std::string& path, AxisSettings& a) {
  DirectControlSettings& d = a.direct;
  motion::AxisConfig& c = a.axis;
  d.present = true;
  d.where = r.loc(n);
  c.direct_control = true;  // MDS is validated (the drive's ramp attributes are configured) [seed 002]
  if (!r.check_map(n, path, {"mode", "max_torque", "velocity_command", "ramp", "slat"})) return;
  using DM = motion::AxisConfig::DirectMode;
  r.enumeration(n, path, "mode", c.direct_mode, {{"velocity", DM::Velocity}, {"torque", DM::Torque}});
  r.scalar(n, path, "max_torque", c.max_torque, 1.0, 32767.0, "per mille of rated torque");
  r.scalar(n, path, "velocity_command", c.direct_velocity_command, -1e12, 1e12, "units/s");
  const double conv = c.conversion_constant;
  // A value in user units that the drive gets in counts as UNSIGNED32.
  auto counts = [&](const YAML::Node& m, const std::string& p, std::string_view key, std::optional<double>& out,
                    std::string_view unit, std::string_view object) {
    double v = 0;
    if (!r.scalar(m, p, key, v, 1e-12, 1e15, unit)) return;
    const double cnt = std::round(v * conv);
    if (cnt < 1 || cnt > 4294967295.0) {
      r.error(m[std::string(key)], sub(p, key),
              fmt::format("{} {} x conversion_constant {} = {} counts does not fit {} (UNSIGNED32, 1 .. 4294967295)", v,
                          unit, conv, cnt, object));
      return;
    }
    out = v;
  };
  if (const YAML::Node ramp = n["ramp"]) {
    const std::string p = path + ".ramp";
    if (r.check_map(ramp, p, {"acceleration", "deceleration", "velocity_positive", "velocity_negative", "jerk_control"})) {
      counts(ramp, p, "acceleration", d.ramp_acceleration, "units/s^2", "0x6083 profile acceleration");
      counts(ramp, p, "deceleration", d.ramp_deceleration, "units/s^2", "0x6084 profile deceleration");
      counts(ramp, p, "velocity_positive", d.ramp_velocity_positive, "units/s", "0x2010:1 ramp velocity - positive");
      counts(ramp, p, "velocity_negative", d.ramp_velocity_negative, "units/s", "0x2010:2 ramp velocity - negative");
      std::uint8_t j = 0;
      if (r.scalar(ramp, p, "jerk_control", j, std::uint8_t{0}, std::uint8_t{100}, "% of the ramp time")) d.ramp_jerk_control = j;
    }
  }
  if (const YAML::Node s = n["slat"]) {
    const std::string p = path + ".slat";
    d.slat_set = true;  // asked for: a drive without 0x2020..0x2022 then fails its boot, naming the key
    if (r.check_map(s, p, {"configuration", "set_point", "time_delay_ms"})) {
      r.enumeration(s, p, "configuration", d.slat_configuration,
                    {{"SLAT disabled", std::uint8_t{0}}, {"SLAT Min Speed/Torque", std::uint8_t{1}},
                     {"SLAT Max Speed/Torque", std::uint8_t{2}}});
      if (r.scalar(s, p, "set_point", d.slat_set_point, 0.0, 1e12, "units/s") &&
          std::round(d.slat_set_point * conv) > 4294967295.0)
        r.error(s["set_point"], p + ".set_point",
                fmt::format("{} units/s x conversion_constant {} does not fit 0x2021 (UNSIGNED32 counts/s)",
                            d.slat_set_point, conv));
      r.scalar(s, p, "time_delay_ms", d.slat_time_delay_ms, std::uint16_t{0}, std::uint16_t{65535}, "ms");
      c.direct_slat = d.slat_configuration != 0;  // MDS's Speed is then the SLAT speed (velocity command)
      if (d.slat_configuration != 0 && c.direct_mode != DM::Torque)
        r.error(s["configuration"] ? s["configuration"] : s, p + ".configuration",
                fmt::format("SLAT {} needs the direct command in torque: set {}.mode: torque (SLAT acts in CST)",
                            d.slat_configuration, path));
    }
  }
}

void exception_actions(Reader& r, const YAML::Node& n, const std::string& path, motion::AxisConfig& a) {
  using K = motion::ExceptionKind;
  using A = motion::ExceptionAction;
  std::vector<std::string_view> keys;
  for (unsigned k = 0; k < static_cast<unsigned>(K::Count); ++k) keys.push_back(motion::exception_key(static_cast<K>(k)));
  if (!r.check_map(n, path, keys)) return;
  std::vector<std::pair<std::string_view, A>> actions;
  for (A act : {A::Ignore, A::Alarm, A::FaultStatusOnly, A::StopPlanner, A::StopDrive, A::Shutdown})
    actions.emplace_back(motion::exception_action_name(act), act);
  for (unsigned k = 0; k < static_cast<unsigned>(K::Count); ++k)
    r.enumeration(n, path, keys[k], a.exception_actions[k], actions);
}

}  // namespace

AxisSettings axis(Reader& r, const YAML::Node& n, const std::string& path, const DriveSettings& defaults) {
  AxisSettings a;
  a.where = r.loc(n);
  a.drive = defaults;
  if (!r.check_map(n, path, {"name", "type", "bus", "node", "units", "conversion_constant", "rotary", "unwind",
                             "max_speed", "max_accel", "max_decel", "max_accel_jerk", "max_decel_jerk",
                             "soft_limits", "position_error_tolerance", "homing", "exception_actions", "drive",
                             "direct_control"}))
    return a;
  if (r.required(n, path, "name", "every axis needs a name")) r.string(n, path, "name", a.name);
  auto& c = a.axis;
  if (r.required(n, path, "type", "AXIS_VIRTUAL or AXIS_CIP_DRIVE"))
    r.enumeration(n, path, "type", c.type,
                  {{"AXIS_VIRTUAL", motion::AxisType::Virtual}, {"AXIS_CIP_DRIVE", motion::AxisType::CipDrive}});
  std::string units;
  if (r.string(n, path, "units", units)) {
    if (units.size() >= sizeof c.units_name) r.error(n["units"], path + ".units", "at most 15 characters");
    else std::copy(units.c_str(), units.c_str() + units.size() + 1, c.units_name);
  }
  r.scalar(n, path, "conversion_constant", c.conversion_constant, 1e-9, 1e12, "counts/unit");
  r.scalar(n, path, "rotary", c.rotary, false, true);
  r.scalar(n, path, "unwind", c.unwind, 1e-9, 1e12, "units/rev");
  r.scalar(n, path, "max_speed", c.max_speed, 1e-12, 1e12, "units/s");
  r.scalar(n, path, "max_accel", c.max_accel, 1e-12, 1e15, "units/s^2");
  r.scalar(n, path, "max_decel", c.max_decel, 1e-12, 1e15, "units/s^2");
  r.scalar(n, path, "max_accel_jerk", c.max_accel_jerk, 1e-12, 1e18, "units/s^3");
  r.scalar(n, path, "max_decel_jerk", c.max_decel_jerk, 1e-12, 1e18, "units/s^3");
  r.scalar(n, path, "position_error_tolerance", c.position_error_tolerance, 0.0, 1e12, "units");
  if (const YAML::Node s = n["soft_limits"]) {
    const std::string p = path + ".soft_limits";
    if (r.check_map(s, p, {"enabled", "positive", "negative"})) {
      r.scalar(s, p, "enabled", c.soft_limits_enabled, false, true);
      r.scalar(s, p, "positive", c.soft_limit_pos, -1e12, 1e12, "units");
      r.scalar(s, p, "negative", c.soft_limit_neg, -1e12, 1e12, "units");
      if (c.soft_limits_enabled && c.soft_limit_neg >= c.soft_limit_pos)
        r.error(s, p, fmt::format("negative limit {} must be below positive limit {}", c.soft_limit_neg,
                                  c.soft_limit_pos));
    }
  }
  if (n["homing"]) homing(r, n["homing"], path + ".homing", c.homing, c.conversion_constant);
  if (n["exception_actions"]) exception_actions(r, n["exception_actions"], path + ".exception_actions", c);
  const bool cip = c.type == motion::AxisType::CipDrive;
  if (cip) {
    if (r.required(n, path, "bus", "an AXIS_CIP_DRIVE axis needs the bus of its drive")) r.string(n, path, "bus", a.bus);
    if (r.required(n, path, "node", "an AXIS_CIP_DRIVE axis needs its drive's node id (1 .. 127)"))
      r.scalar(n, path, "node", a.node, std::uint8_t{1}, std::uint8_t{127});
    if (n["drive"]) drive(r, n["drive"], path + ".drive", a.drive);
    if (n["direct_control"]) {
      direct_control(r, n["direct_control"], path + ".direct_control", a);
      if (a.drive.pdo != cia402::PdoProfile::kCspCsvCst)
        r.error(n["direct_control"], path + ".direct_control",
                "MDS sends 0x60FF/0x6071 and switches 0x6060 cyclically: set drive.pdo: csp_csv_cst (here or under "
                "`drives:`)");
    }
  } else {
    for (std::string_view k : {"bus", "node", "drive", "direct_control"})
      if (n[std::string(k)]) r.error(n[std::string(k)], sub(path, k), "only an AXIS_CIP_DRIVE axis has a drive; this axis is AXIS_VIRTUAL");
  }
  if (c.rotary && c.homing.home_position >= c.unwind)
    r.error(n["homing"] ? n["homing"] : n, path + ".homing.position",
            fmt::format("on a rotary axis the home position must be in [0, unwind={})", c.unwind));
  return a;
}

}  // namespace canmotion::config::load
