// YAML loading and validation of the canmotion configuration.
//
// The loader walks the document once, collecting every problem as a
// Diagnostic (file, line, column, dotted key, message with what would be
// valid) instead of stopping at the first, then runs the cross-checks (names,
// node ids, COB-IDs, 0x60C2, bus budget). Only a configuration without errors
// is returned.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

#include "config/config.hpp"
#include "config/eds_check.hpp"
#include "fieldbus/canopen/bus_budget.hpp"
#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "motion/planner.hpp"
#include "rt/controller/controller.hpp"
#include "rt/controller/tags.hpp"

namespace canmotion::config {

namespace {

using Severity = Diagnostic::Severity;

std::string lower_compact(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != ' ' && c != '_' && c != '-') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Walks one document, collecting diagnostics.
class Loader {
 public:
  explicit Loader(std::string file) : file_(std::move(file)) {}

  std::vector<Diagnostic> diags;

  Location loc(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    if (m.line < 0) return {};
    return {m.line + 1, m.column + 1};
  }

  void error(const YAML::Node& n, const std::string& key, std::string msg) {
    diags.push_back({Severity::kError, file_, loc(n), key, std::move(msg)});
  }
  void error_at(Location l, const std::string& key, std::string msg) {
    diags.push_back({Severity::kError, file_, l, key, std::move(msg)});
  }
  void warning_at(Location l, const std::string& key, std::string msg) {
    diags.push_back({Severity::kWarning, file_, l, key, std::move(msg)});
  }

  /// Reject keys of `map` not in `allowed`, suggesting the nearest.
  bool check_map(const YAML::Node& map, const std::string& path, const std::vector<std::string_view>& allowed) {
    if (!map.IsMap()) {
      error(map, path, "must be a mapping (key: value lines)");
      return false;
    }
    for (auto it = map.begin(); it != map.end(); ++it) {
      const std::string k = it->first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
      std::string msg = fmt::format("unknown key '{}'", k);
      if (auto s = nearest(k, allowed)) msg += fmt::format("; did you mean '{}'?", *s);
      else msg += fmt::format("; valid keys: {}", fmt::join(allowed, ", "));
      error(it->first, path.empty() ? k : path + "." + k, msg);
    }
    return true;
  }

  static std::string sub(const std::string& path, std::string_view key) {
    return path.empty() ? std::string(key) : path + "." + std::string(key);
  }

  template <class T>
  bool scalar(const YAML::Node& parent, const std::string& path, std::string_view key, T& out, T lo, T hi,
              std::string_view unit = {}) {
    const YAML::Node n = parent[std::string(key)];
    if (!n) return false;
    const std::string p = sub(path, key);
    if (!n.IsScalar()) {
      error(n, p, "must be a single value");
      return false;
    }
    T v{};
    bool ok = true;
    if constexpr (std::is_same_v<T, bool>) {
      const std::string s = lower_compact(n.Scalar());
      if (s == "true" || s == "yes" || s == "on" || s == "1") v = true;
      else if (s == "false" || s == "no" || s == "off" || s == "0") v = false;
      else ok = false;
      if (!ok) {
        error(n, p, fmt::format("must be true or false, got '{}'", n.Scalar()));
        return false;
      }
      out = v;
      return true;
    } else if constexpr (std::is_floating_point_v<T>) {
      ok = YAML::convert<double>::decode(n, v) && std::isfinite(v);
    } else {
      // Integers: decimal or 0x hex, no fraction.
      const std::string& s = n.Scalar();
      errno = 0;
      char* end = nullptr;
      const long long ll = std::strtoll(s.c_str(), &end, 0);
      ok = !s.empty() && end != nullptr && *end == '\0' && errno == 0;
      v = static_cast<T>(ll);
      if (ok && (ll < static_cast<long long>(lo) || ll > static_cast<long long>(hi))) {
        error(n, p, fmt::format("must be {} .. {}{}{}, got {}", lo, hi, unit.empty() ? "" : " ", unit, s));
        return false;
      }
    }
    if (!ok) {
      error(n, p, fmt::format("must be a {} number{}{}, got '{}'", std::is_floating_point_v<T> ? "real" : "whole",
                              unit.empty() ? "" : " in ", unit, n.Scalar()));
      return false;
    }
    if (v < lo || v > hi) {
      error(n, p, fmt::format("must be {} .. {}{}{}, got {}", lo, hi, unit.empty() ? "" : " ", unit, n.Scalar()));
      return false;
    }
    out = v;
    return true;
  }

  /// A required key: true when present, else `missing: <what>` at the parent
  /// (a present but bad value is reported by whoever reads it, once).
  bool required(const YAML::Node& parent, const std::string& path, std::string_view key, std::string_view what) {
    if (parent[std::string(key)]) return true;
    error(parent, sub(path, key), fmt::format("missing: {}", what));
    return false;
  }

  bool string(const YAML::Node& parent, const std::string& path, std::string_view key, std::string& out) {
    const YAML::Node n = parent[std::string(key)];
    if (!n) return false;
    if (!n.IsScalar() || n.Scalar().empty()) {
      error(n, sub(path, key), "must be a non-empty string");
      return false;
    }
    out = n.Scalar();
    return true;
  }

  /// Enumeration by text (case, spaces and underscores ignored) or number.
  template <class E>
  bool enumeration(const YAML::Node& parent, const std::string& path, std::string_view key, E& out,
                   const std::vector<std::pair<std::string_view, E>>& table) {
    const YAML::Node n = parent[std::string(key)];
    if (!n) return false;
    const std::string p = sub(path, key);
    if (n.IsScalar()) {
      const std::string s = lower_compact(n.Scalar());
      for (const auto& [name, val] : table) {
        if (lower_compact(name) == s || std::to_string(static_cast<int>(val)) == s) {
          out = val;
          return true;
        }
      }
    }
    std::vector<std::string> names;
    for (const auto& [name, val] : table) names.push_back(fmt::format("{} ({})", name, static_cast<int>(val)));
    error(n, p, fmt::format("'{}' is not one of: {}", n.IsScalar() ? n.Scalar() : std::string("<non-scalar>"),
                            fmt::join(names, ", ")));
    return false;
  }

  ControllerSettings controller(const YAML::Node& n) {
    ControllerSettings c;
    c.where = loc(n);
    if (!check_map(n, "controller", {"period_ms", "priority", "cpu", "lock_memory", "cpu_dma_latency_us"})) return c;
    double ms = c.period_ms();
    if (scalar(n, "controller", "period_ms", ms, 0.25, 100.0, "ms")) c.period_s = period_s_from_ms(ms);
    scalar(n, "controller", "priority", c.priority, 0, 99);
    scalar(n, "controller", "cpu", c.cpu, -1, 1023);
    scalar(n, "controller", "lock_memory", c.lock_memory, false, true);
    // -1 = leave the CPU idle states alone; the top is the kernel's "no constraint" (rt/pm_qos.hpp).
    scalar(n, "controller", "cpu_dma_latency_us", c.cpu_dma_latency_us, std::int32_t{-1}, std::int32_t{2'000'000'000}, "us");
    return c;
  }

  BusSettings bus(const YAML::Node& n, const std::string& path) {
    BusSettings b;
    b.where = loc(n);
    if (!check_map(n, path, {"name", "interface", "bitrate", "master_node", "master_heartbeat_ms", "sync_counter_overflow"}))
      return b;
    if (required(n, path, "name", "every bus needs a name")) string(n, path, "name", b.name);
    if (string(n, path, "interface", b.interface) && b.interface.size() >= 16)
      error(n["interface"], path + ".interface", "an interface name has at most 15 characters");
    scalar(n, path, "bitrate", b.bitrate, 10'000u, 1'000'000u, "bit/s");
    scalar(n, path, "master_node", b.master_node, std::uint8_t{1}, std::uint8_t{127});
    scalar(n, path, "master_heartbeat_ms", b.master_heartbeat_ms, std::uint16_t{0}, std::uint16_t{65535}, "ms");
    std::uint8_t sc = b.sync_counter_overflow;
    if (scalar(n, path, "sync_counter_overflow", sc, std::uint8_t{0}, std::uint8_t{240})) {
      if (sc == 1) error(n["sync_counter_overflow"], path + ".sync_counter_overflow",
                         "must be 0 (no counter) or 2 .. 240 (CiA 301 0x1019), got 1");
      else b.sync_counter_overflow = sc;
    }
    return b;
  }

  void timeouts(const YAML::Node& n, const std::string& path, DriveTimeouts& t) {
    if (!check_map(n, path, {"sdo_ms", "boot_ms", "transition_ms", "mode_switch_ms", "homing_ms", "wait_ms"})) return;
    scalar(n, path, "sdo_ms", t.sdo_ms, 1u, 60'000u, "ms");
    scalar(n, path, "boot_ms", t.boot_ms, 10u, 600'000u, "ms");
    scalar(n, path, "transition_ms", t.transition_ms, 1u, 60'000u, "ms");
    scalar(n, path, "mode_switch_ms", t.mode_switch_ms, 1u, 60'000u, "ms");
    scalar(n, path, "homing_ms", t.homing_ms, 0u, 3'600'000u, "ms (0 = no limit)");
    scalar(n, path, "wait_ms", t.wait_ms, 0u, 3'600'000u,
           "ms (0 = 3 x boot_ms + mode_switch_ms + 4 x transition_ms)");
  }

  void drive(const YAML::Node& n, const std::string& path, DriveSettings& d) {
    if (!check_map(n, path, {"timeouts", "pdo", "heartbeat_ms", "master_heartbeat_timeout_ms",
                             "following_error_window", "sdo_writes", "identity", "quick_stop_option", "eds", "sync_watch",
                             "mds_objects"}))
      return;
    if (std::int16_t q = 0; scalar(n, path, "quick_stop_option", q, std::int16_t{-32768}, std::int16_t{8},
                                   "(0x605A: 0 coast, 1/2 ramp then Switch on disabled, 5/6 ramp and stay in Quick stop "
                                   "active, ...; < 0 manufacturer-specific)"))
      d.quick_stop_option = q;
    if (const YAML::Node id = n["identity"]) {
      const std::string p = path + ".identity";
      if (check_map(id, p, {"device_type", "vendor_id", "product_code", "revision"})) {
        auto u32 = [&](std::string_view key, std::optional<std::uint32_t>& out) {
          std::uint32_t v = 0;
          if (id[std::string(key)] && scalar(id, p, key, v, 0u, 0xFFFFFFFFu)) out = v;
        };
        u32("device_type", d.identity.device_type);
        u32("vendor_id", d.identity.vendor_id);
        u32("product_code", d.identity.product_code);
        u32("revision", d.identity.revision);
      }
    }
    if (n["master_heartbeat_timeout_ms"]) d.master_heartbeat_timeout_set = true;
    if (n["eds"] && string(n, path, "eds", d.eds)) {
      // Relative to the YAML file's folder, like a vendor's EDS shipped beside the configuration.
      const std::filesystem::path e(d.eds);
      d.eds_path = e.is_absolute() ? e.string() : (std::filesystem::path(file_).parent_path() / e).lexically_normal().string();
      d.eds_key = path + ".eds";
      d.eds_where = loc(n["eds"]);
    }
    if (n["timeouts"]) timeouts(n["timeouts"], path + ".timeouts", d.timeouts);
    enumeration(n, path, "pdo", d.pdo,
                {{"csp", cia402::PdoProfile::kCsp}, {"csp_csv_cst", cia402::PdoProfile::kCspCsvCst}});
    scalar(n, path, "heartbeat_ms", d.heartbeat_ms, std::uint16_t{0}, std::uint16_t{65535}, "ms");
    scalar(n, path, "master_heartbeat_timeout_ms", d.master_heartbeat_timeout_ms, std::uint16_t{0},
           std::uint16_t{65535}, "ms");
    scalar(n, path, "following_error_window", d.following_error_window, std::uint16_t{0}, std::uint16_t{65535},
           "counts");
    scalar(n, path, "sync_watch", d.sync_watch, false, true);
    if (const YAML::Node m = n["mds_objects"]) mds_objects(m, path + ".mds_objects", d);
    if (const YAML::Node w = n["sdo_writes"]) {
      if (!w.IsSequence()) {
        error(w, path + ".sdo_writes", "must be a list of {index, sub, size, value}");
      } else {
        d.sdo_writes.clear();
        for (std::size_t i = 0; i < w.size(); ++i) {
          const std::string p = fmt::format("{}.sdo_writes[{}]", path, i);
          const YAML::Node e = w[i];
          SdoWrite s;
          s.where = loc(e);
          if (!check_map(e, p, {"index", "sub", "size", "value"})) continue;
          if (!e["index"] || !e["value"]) {
            error(e, p, "needs at least index and value");
            continue;
          }
          scalar(e, p, "index", s.index, std::uint16_t{0x1000}, std::uint16_t{0xFFFF});
          scalar(e, p, "sub", s.sub, std::uint8_t{0}, std::uint8_t{254});
          // An object of the one object table (canopen::known_objects()) has
          // its size from there: `size:` may be left out, and must match.
          const canopen::ObjectInfo* known = canopen::object_info(s.index, s.sub);
          const std::size_t known_size = known != nullptr ? canopen::data_type_size(known->type) : 0;
          if (known != nullptr && (known->access == canopen::Access::kRo || known->access == canopen::Access::kConst))
            error(e["index"], p + ".index",
                  fmt::format("0x{:04X}:{:02X} ({}) is read-only", s.index, s.sub, known->name));
          if (known_size == 1 || known_size == 2 || known_size == 4) s.size = static_cast<std::uint8_t>(known_size);
          if (const YAML::Node sz = e["size"]) {
            std::uint8_t given = 0;
            if (scalar(e, p, "size", given, std::uint8_t{1}, std::uint8_t{4})) {
              if (given == 3)
                error(sz, p + ".size", "must be 1, 2 or 4 bytes, got 3");
              else if (known_size != 0 && given != known_size)
                error(sz, p + ".size",
                      fmt::format("0x{:04X}:{:02X} ({}) is {} byte{}, got {}", s.index, s.sub, known->name, known_size,
                                  known_size == 1 ? "" : "s", given));
              else
                s.size = given;
            }
          }
          if (scalar(e, p, "value", s.value, std::int64_t{-2147483648LL}, std::int64_t{4294967295LL})) {
            // The object's own type when known (INTEGERn signed, UNSIGNEDn
            // unsigned); otherwise either reading of `size` bytes.
            const int bits = 8 * s.size;
            const bool is_signed = known_size != 0 && canopen::data_type_signed(known->type);
            const bool is_unsigned = known_size != 0 && !is_signed;
            const std::int64_t lo = is_unsigned ? 0 : -(std::int64_t{1} << (bits - 1));
            const std::int64_t hi = is_signed ? (std::int64_t{1} << (bits - 1)) - 1 : (std::int64_t{1} << bits) - 1;
            if (s.value < lo || s.value > hi)
              error(e["value"], p + ".value",
                    fmt::format("{} does not fit in {} byte{} ({} .. {})", s.value, s.size, s.size == 1 ? "" : "s", lo, hi));
          }
          d.sdo_writes.push_back(s);
        }
      }
    }
  }

  /// `mds_objects:` {ramp_velocity_positive: "0x3000:1", ...}: each an
  /// INDEX:SUB in the manufacturer-specific or device-profile area. Clashes
  /// are checked per axis, once `drives:` and the axis's own are merged
  /// (mds_object_checks).
  void mds_objects(const YAML::Node& m, const std::string& path, DriveSettings& d) {
    std::vector<std::string_view> keys;
    for (const cia402::MdsObjectInfo& i : cia402::kMdsObjectInfo) keys.push_back(i.key);
    if (!check_map(m, path, keys)) return;
    for (std::size_t i = 0; i < cia402::kMdsObjectCount; ++i) {
      const cia402::MdsObjectInfo& info = cia402::kMdsObjectInfo[i];
      const YAML::Node v = m[std::string(info.key)];
      if (!v) continue;
      const std::string k = sub(path, info.key);
      const std::optional<cia402::ObjectAddress> a = v.IsScalar() ? cia402::parse_object_address(v.Scalar()) : std::nullopt;
      if (!a) {
        error(v, k, fmt::format("'{}' is not an object INDEX:SUB (e.g. \"0x{:04X}:{}\", or \"0x2011\" for sub-index 0; "
                                "sub-index 0 .. 254)",
                                v.IsScalar() ? v.Scalar() : std::string("<non-scalar>"), info.standard.index,
                                info.standard.sub));
        continue;
      }
      if (a->index < 0x2000 || a->index > 0x9FFF) {
        error(v, k, fmt::format("0x{:04X}:{} is outside the manufacturer-specific (0x2000 .. 0x5FFF) and device profile "
                                "(0x6000 .. 0x9FFF) areas where a drive keeps such objects",
                                a->index, a->sub));
        continue;
      }
      d.mds_objects.at[i] = *a;
      d.mds_object_keys[i] = k;
      d.mds_object_where[i] = loc(v);
    }
  }

  void homing(const YAML::Node& n, const std::string& path, motion::HomingConfig& h) {
    if (!check_map(n, path, {"mode", "sequence", "position", "method", "speed_search", "speed_zero", "accel", "offset"}))
      return;
    using M = motion::HomingConfig::Mode;
    using S = motion::HomingConfig::Sequence;
    enumeration(n, path, "mode", h.mode, {{"Passive", M::Passive}, {"Active", M::Active}, {"Absolute", M::Absolute}});
    enumeration(n, path, "sequence", h.sequence,
                {{"Immediate", S::Immediate}, {"Switch", S::Switch}, {"Marker", S::Marker},
                 {"Switch Marker", S::SwitchMarker}, {"Torque Level", S::TorqueLevel},
                 {"Torque Level Marker", S::TorqueLevelMarker}});
    scalar(n, path, "position", h.home_position, -1e12, 1e12, "units");
    scalar(n, path, "method", h.cia_method, std::int8_t{-128}, std::int8_t{127});
    scalar(n, path, "speed_search", h.speed_search, 0.0, 1e12, "units/s");
    scalar(n, path, "speed_zero", h.speed_zero, 0.0, 1e12, "units/s");
    scalar(n, path, "accel", h.accel, 0.0, 1e15, "units/s^2");
    // 0x607C is written only when configured (a drive keeps its own otherwise).
    if (n["offset"] && scalar(n, path, "offset", h.offset, -1e12, 1e12, "units")) h.write_offset = true;
  }

  /// `direct_control:` of a CIP axis (MDS): direct command kind, drive ramps, SLAT.
  void direct_control(const YAML::Node& n, const std::string& path, AxisSettings& a) {
    DirectControlSettings& d = a.direct;
    motion::AxisConfig& c = a.axis;
    d.present = true;
    d.where = loc(n);
    c.direct_control = true;  // MDS is validated (the drive's ramp attributes are configured) [seed 002]
    if (!check_map(n, path, {"mode", "max_torque", "velocity_command", "ramp", "slat"})) return;
    using DM = motion::AxisConfig::DirectMode;
    enumeration(n, path, "mode", c.direct_mode, {{"velocity", DM::Velocity}, {"torque", DM::Torque}});
    scalar(n, path, "max_torque", c.max_torque, 1.0, 32767.0, "per mille of rated torque");
    scalar(n, path, "velocity_command", c.direct_velocity_command, -1e12, 1e12, "units/s");
    const double conv = c.conversion_constant;
    // A value in user units that the drive gets in counts as UNSIGNED32.
    auto counts = [&](const YAML::Node& m, const std::string& p, std::string_view key, std::optional<double>& out,
                      std::string_view unit, std::string_view object) {
      double v = 0;
      if (!scalar(m, p, key, v, 1e-12, 1e15, unit)) return;
      const double cnt = std::round(v * conv);
      if (cnt < 1 || cnt > 4294967295.0) {
        error(m[std::string(key)], sub(p, key),
              fmt::format("{} {} x conversion_constant {} = {} counts does not fit {} (UNSIGNED32, 1 .. 4294967295)", v,
                          unit, conv, cnt, object));
        return;
      }
      out = v;
    };
    if (const YAML::Node r = n["ramp"]) {
      const std::string p = path + ".ramp";
      if (check_map(r, p, {"acceleration", "deceleration", "velocity_positive", "velocity_negative", "jerk_control"})) {
        counts(r, p, "acceleration", d.ramp_acceleration, "units/s^2", "0x6083 profile acceleration");
        counts(r, p, "deceleration", d.ramp_deceleration, "units/s^2", "0x6084 profile deceleration");
        counts(r, p, "velocity_positive", d.ramp_velocity_positive, "units/s", "0x2010:1 ramp velocity - positive");
        counts(r, p, "velocity_negative", d.ramp_velocity_negative, "units/s", "0x2010:2 ramp velocity - negative");
        std::uint8_t j = 0;
        if (scalar(r, p, "jerk_control", j, std::uint8_t{0}, std::uint8_t{100}, "% of the ramp time")) d.ramp_jerk_control = j;
      }
    }
    if (const YAML::Node s = n["slat"]) {
      const std::string p = path + ".slat";
      d.slat_set = true;  // asked for: a drive without 0x2020..0x2022 then fails its boot, naming the key
      if (check_map(s, p, {"configuration", "set_point", "time_delay_ms"})) {
        enumeration(s, p, "configuration", d.slat_configuration,
                    {{"SLAT disabled", std::uint8_t{0}}, {"SLAT Min Speed/Torque", std::uint8_t{1}},
                     {"SLAT Max Speed/Torque", std::uint8_t{2}}});
        if (scalar(s, p, "set_point", d.slat_set_point, 0.0, 1e12, "units/s") &&
            std::round(d.slat_set_point * conv) > 4294967295.0)
          error(s["set_point"], p + ".set_point",
                fmt::format("{} units/s x conversion_constant {} does not fit 0x2021 (UNSIGNED32 counts/s)",
                            d.slat_set_point, conv));
        scalar(s, p, "time_delay_ms", d.slat_time_delay_ms, std::uint16_t{0}, std::uint16_t{65535}, "ms");
        c.direct_slat = d.slat_configuration != 0;  // MDS's Speed is then the SLAT speed (velocity command)
        if (d.slat_configuration != 0 && c.direct_mode != DM::Torque)
          error(s["configuration"] ? s["configuration"] : s, p + ".configuration",
                fmt::format("SLAT {} needs the direct command in torque: set {}.mode: torque (SLAT acts in CST)",
                            d.slat_configuration, path));
      }
    }
  }

  void exception_actions(const YAML::Node& n, const std::string& path, motion::AxisConfig& a) {
    using K = motion::ExceptionKind;
    using A = motion::ExceptionAction;
    std::vector<std::string_view> keys;
    for (unsigned k = 0; k < static_cast<unsigned>(K::Count); ++k) keys.push_back(motion::exception_key(static_cast<K>(k)));
    if (!check_map(n, path, keys)) return;
    std::vector<std::pair<std::string_view, A>> actions;
    for (A act : {A::Ignore, A::Alarm, A::FaultStatusOnly, A::StopPlanner, A::StopDrive, A::Shutdown})
      actions.emplace_back(motion::exception_action_name(act), act);
    for (unsigned k = 0; k < static_cast<unsigned>(K::Count); ++k)
      enumeration(n, path, keys[k], a.exception_actions[k], actions);
  }

  AxisSettings axis(const YAML::Node& n, const std::string& path, const DriveSettings& defaults) {
    AxisSettings a;
    a.where = loc(n);
    a.drive = defaults;
    if (!check_map(n, path, {"name", "type", "bus", "node", "units", "conversion_constant", "rotary", "unwind",
                             "max_speed", "max_accel", "max_decel", "max_accel_jerk", "max_decel_jerk",
                             "soft_limits", "position_error_tolerance", "homing", "exception_actions", "drive",
                             "direct_control"}))
      return a;
    if (required(n, path, "name", "every axis needs a name")) string(n, path, "name", a.name);
    auto& c = a.axis;
    if (required(n, path, "type", "AXIS_VIRTUAL or AXIS_CIP_DRIVE"))
      enumeration(n, path, "type", c.type,
                  {{"AXIS_VIRTUAL", motion::AxisType::Virtual}, {"AXIS_CIP_DRIVE", motion::AxisType::CipDrive}});
    std::string units;
    if (string(n, path, "units", units)) {
      if (units.size() >= sizeof c.units_name) error(n["units"], path + ".units", "at most 15 characters");
      else std::copy(units.c_str(), units.c_str() + units.size() + 1, c.units_name);
    }
    scalar(n, path, "conversion_constant", c.conversion_constant, 1e-9, 1e12, "counts/unit");
    scalar(n, path, "rotary", c.rotary, false, true);
    scalar(n, path, "unwind", c.unwind, 1e-9, 1e12, "units/rev");
    scalar(n, path, "max_speed", c.max_speed, 1e-12, 1e12, "units/s");
    scalar(n, path, "max_accel", c.max_accel, 1e-12, 1e15, "units/s^2");
    scalar(n, path, "max_decel", c.max_decel, 1e-12, 1e15, "units/s^2");
    scalar(n, path, "max_accel_jerk", c.max_accel_jerk, 1e-12, 1e18, "units/s^3");
    scalar(n, path, "max_decel_jerk", c.max_decel_jerk, 1e-12, 1e18, "units/s^3");
    scalar(n, path, "position_error_tolerance", c.position_error_tolerance, 0.0, 1e12, "units");
    if (const YAML::Node s = n["soft_limits"]) {
      const std::string p = path + ".soft_limits";
      if (check_map(s, p, {"enabled", "positive", "negative"})) {
        scalar(s, p, "enabled", c.soft_limits_enabled, false, true);
        scalar(s, p, "positive", c.soft_limit_pos, -1e12, 1e12, "units");
        scalar(s, p, "negative", c.soft_limit_neg, -1e12, 1e12, "units");
        if (c.soft_limits_enabled && c.soft_limit_neg >= c.soft_limit_pos)
          error(s, p, fmt::format("negative limit {} must be below positive limit {}", c.soft_limit_neg,
                                  c.soft_limit_pos));
      }
    }
    if (n["homing"]) homing(n["homing"], path + ".homing", c.homing);
    if (n["exception_actions"]) exception_actions(n["exception_actions"], path + ".exception_actions", c);
    const bool cip = c.type == motion::AxisType::CipDrive;
    if (cip) {
      if (required(n, path, "bus", "an AXIS_CIP_DRIVE axis needs the bus of its drive")) string(n, path, "bus", a.bus);
      if (required(n, path, "node", "an AXIS_CIP_DRIVE axis needs its drive's node id (1 .. 127)"))
        scalar(n, path, "node", a.node, std::uint8_t{1}, std::uint8_t{127});
      if (n["drive"]) drive(n["drive"], path + ".drive", a.drive);
      if (n["direct_control"]) {
        direct_control(n["direct_control"], path + ".direct_control", a);
        if (a.drive.pdo != cia402::PdoProfile::kCspCsvCst)
          error(n["direct_control"], path + ".direct_control",
                "MDS sends 0x60FF/0x6071 and switches 0x6060 cyclically: set drive.pdo: csp_csv_cst (here or under "
                "`drives:`)");
      }
    } else {
      for (std::string_view k : {"bus", "node", "drive", "direct_control"})
        if (n[std::string(k)]) error(n[std::string(k)], sub(path, k), "only an AXIS_CIP_DRIVE axis has a drive; this axis is AXIS_VIRTUAL");
    }
    if (c.rotary && c.homing.home_position >= c.unwind)
      error(n["homing"] ? n["homing"] : n, path + ".homing.position",
            fmt::format("on a rotary axis the home position must be in [0, unwind={})", c.unwind));
    return a;
  }

  /// A list element that must be a finite real number (cam point coordinates,
  /// REAL array values); `what` names it in the message ("master ", or "").
  bool finite_number(const YAML::Node& e, const std::string& key, std::string_view what, double& out) {
    if (e.IsScalar() && YAML::convert<double>::decode(e, out) && std::isfinite(out)) return true;
    error(e, key, fmt::format("{}must be a finite number, got '{}'", what, e.IsScalar() ? e.Scalar() : "<non-scalar>"));
    return false;
  }

  /// One cam point, `[master, slave]` or `[master, slave, linear|cubic]` (a
  /// Logix CAM element: Master, Slave, SegmentType). The one parser of both
  /// `cams[].points[]` and a CAM array's `values[]`: the same rules and the same
  /// messages, reported at the offending element. nullopt once reported.
  std::optional<CamPoint> cam_point(const YAML::Node& p, const std::string& key) {
    if (!p.IsSequence() || (p.size() != 2 && p.size() != 3)) {
      const std::string got = p.IsSequence() ? fmt::format("{} value{}", p.size(), p.size() == 1 ? "" : "s")
                              : p.IsScalar() ? fmt::format("'{}'", p.Scalar())
                              : p.IsMap()    ? std::string("a mapping")
                                             : std::string("nothing");
      error(p, key, fmt::format("must be [master, slave] or [master, slave, linear|cubic], got {}", got));
      return std::nullopt;
    }
    CamPoint cp;
    bool ok = finite_number(p[0], key, "master ", cp.master);
    ok = finite_number(p[1], key, "slave ", cp.slave) && ok;
    if (p.size() == 3) {
      const std::string t = p[2].IsScalar() ? lower_compact(p[2].Scalar()) : std::string();
      if (t == "cubic" || t == "1") cp.cubic = true;
      else if (t != "linear" && t != "0") {
        error(p[2], key, fmt::format("segment type must be linear (0) or cubic (1), got '{}'",
                                     p[2].IsScalar() ? p[2].Scalar() : "<non-scalar>"));
        ok = false;
      }
    }
    if (!ok) return std::nullopt;
    return cp;
  }

  /// A list of cam points (see cam_point): a `cams:` entry's `points`, or a CAM
  /// array's `values`. `increasing`: master values must strictly increase (a
  /// `cams:` entry is one cam, computed by MCCP at load). A CAM array's values
  /// are not checked for order: one array may hold several cams, each given to
  /// MCCP from its own start element, and MCCP checks the points it is given
  /// (ERR 29). Every bad point is reported; returns the good ones.
  std::vector<CamPoint> cam_points(const YAML::Node& list, const YAML::Node& parent, const std::string& key,
                                   bool increasing) {
    std::vector<CamPoint> out;
    if (!list || !list.IsSequence()) {
      error(list ? list : parent, key, "must be a list of [master, slave] or [master, slave, linear|cubic]");
      return out;
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string k = fmt::format("{}[{}]", key, i);
      const std::optional<CamPoint> cp = cam_point(list[i], k);
      if (!cp) continue;
      if (increasing && !out.empty() && cp->master <= out.back().master)
        error(list[i], k, fmt::format("master values must increase: {} follows {}", cp->master, out.back().master));
      out.push_back(*cp);
    }
    return out;
  }

  CamSettings cam(const YAML::Node& n, const std::string& path) {
    CamSettings c;
    c.where = loc(n);
    if (!check_map(n, path, {"name", "points", "start_slope", "end_slope"})) return c;
    if (required(n, path, "name", "every cam needs a name")) string(n, path, "name", c.name);
    scalar(n, path, "start_slope", c.start_slope, -1e12, 1e12);
    scalar(n, path, "end_slope", c.end_slope, -1e12, 1e12);
    const YAML::Node pts = n["points"];
    c.points = cam_points(pts, n, path + ".points", true);
    if (pts && pts.IsSequence() && c.points.size() < 2)
      error(pts, path + ".points", fmt::format("needs at least 2 points, got {}", c.points.size()));
    return c;
  }

  /// One `arrays:` entry: {name, type: CAM | CAM_PROFILE | REAL, size, values}.
  ArraySettings array(const YAML::Node& n, const std::string& path) {
    using T = ArraySettings::Type;
    ArraySettings a;
    a.where = loc(n);
    if (!check_map(n, path, {"name", "type", "size", "values"})) return a;
    if (required(n, path, "name", "every array needs a name")) string(n, path, "name", a.name);
    if (required(n, path, "type", "CAM, CAM_PROFILE or REAL"))
      enumeration(n, path, "type", a.type, {{"CAM", T::kCam}, {"CAM_PROFILE", T::kCamProfile}, {"REAL", T::kReal}});
    const std::size_t max = a.type == T::kReal ? rt::kMaxRealElements : ArraySettings::kMaxCamElements;
    if (required(n, path, "size", fmt::format("the number of elements, 1 .. {}", max)))
      scalar(n, path, "size", a.size, std::size_t{1}, max, "elements");
    const YAML::Node v = n["values"];
    if (!v) return a;
    const std::string vp = path + ".values";
    if (a.type == T::kCamProfile) {
      error(v, vp, "a CAM_PROFILE array has no initial values: MCCP calculates it");
      return a;
    }
    if (v.IsSequence() && a.size > 0 && v.size() > a.size)
      error(v, vp, fmt::format("{} values do not fit in size {}", v.size(), a.size));
    if (a.type == T::kCam) {
      a.cam_values = cam_points(v, n, vp, false);
      return a;
    }
    if (!v.IsSequence()) {
      error(v, vp, "must be a list of numbers");
      return a;
    }
    for (std::size_t i = 0; i < v.size(); ++i) {
      double x = 0;
      finite_number(v[i], fmt::format("{}[{}]", vp, i), "", x);
      a.real_values.push_back(x);
    }
    return a;
  }

  /// One `coordinate_systems:` entry.
  CoordinateSystemSettings coordinate_system(const YAML::Node& n, const std::string& path) {
    CoordinateSystemSettings c;
    c.where = loc(n);
    if (!check_map(n, path, {"name", "axes", "conversion_ratios", "coordination_modes", "units", "max_speed",
                             "max_accel", "max_decel", "max_accel_jerk", "max_decel_jerk",
                             "actual_position_tolerance", "command_position_tolerance"}))
      return c;
    if (required(n, path, "name", "every coordinate system needs a name")) string(n, path, "name", c.name);
    if (required(n, path, "axes", "the member axes in order, 1 to 3 axis names")) {
      const YAML::Node a = n["axes"];
      if (!a.IsSequence() || a.size() < 1 || a.size() > 3) {
        error(a, path + ".axes", "must be a list of 1 to 3 axis names");
      } else {
        for (std::size_t i = 0; i < a.size(); ++i) {
          if (!a[i].IsScalar() || a[i].Scalar().empty()) error(a[i], fmt::format("{}.axes[{}]", path, i), "must be an axis name");
          else {
            c.axes.push_back(a[i].Scalar());
            c.axes_where.push_back(loc(a[i]));
          }
        }
      }
    }
    if (const YAML::Node r = n["conversion_ratios"]) {
      if (!r.IsSequence() || r.size() != c.axes.size()) {
        error(r, path + ".conversion_ratios", fmt::format("must be a list of {} numbers > 0, one per member axis", c.axes.size()));
      } else {
        for (std::size_t i = 0; i < r.size(); ++i) {
          double x = 0;
          const std::string k = fmt::format("{}.conversion_ratios[{}]", path, i);
          if (finite_number(r[i], k, "", x) && !(x > 0)) error(r[i], k, fmt::format("must be > 0, got {}", x));
          c.conversion_ratios.push_back(x);
        }
      }
    }
    // Logix's per-member Coordination Mode: only Primary (every member is in
    // the vector length); Ancillary members are refused (README, "Coordinated motion")
    if (const YAML::Node m = n["coordination_modes"]) {
      if (!m.IsSequence() || m.size() != c.axes.size()) {
        error(m, path + ".coordination_modes", fmt::format("must be a list of {} modes (primary), one per member axis", c.axes.size()));
      } else {
        for (std::size_t i = 0; i < m.size(); ++i) {
          const std::string k = fmt::format("{}.coordination_modes[{}]", path, i);
          const std::string v = m[i].IsScalar() ? m[i].Scalar() : std::string{};
          if (v == "ancillary")
            error(m[i], k, "ancillary members are not supported: every member is primary (part of the vector length)");
          else if (v != "primary")
            error(m[i], k, fmt::format("must be primary, got '{}'", v));
        }
      }
    }
    string(n, path, "units", c.units);
    constexpr double kBig = 1e12;
    for (auto [key, out] : {std::pair<std::string_view, double*>{"max_speed", &c.max_speed}, {"max_accel", &c.max_accel},
                            {"max_decel", &c.max_decel}}) {
      if (required(n, path, key, "> 0, coordination units per second (squared)")) scalar(n, path, key, *out, 1e-12, kBig);
    }
    scalar(n, path, "max_accel_jerk", c.max_accel_jerk, 0.0, kBig);
    scalar(n, path, "max_decel_jerk", c.max_decel_jerk, 0.0, kBig);
    scalar(n, path, "actual_position_tolerance", c.actual_position_tolerance, 0.0, kBig);
    scalar(n, path, "command_position_tolerance", c.command_position_tolerance, 0.0, kBig);
    return c;
  }

  /// `coordinate_systems:` members name configured axes, once each; the
  /// capacity motion::kMaxCoordSystems.
  template <class Unique>
  void coordinate_system_checks(const Config& cfg, Unique& unique) {
    std::vector<std::string_view> axis_names;
    for (const auto& a : cfg.axes) axis_names.push_back(a.name);
    for (std::size_t i = 0; i < cfg.coordinate_systems.size(); ++i) {
      const CoordinateSystemSettings& c = cfg.coordinate_systems[i];
      const std::string key = fmt::format("coordinate_systems[{}]", i);
      unique(c.name, c.where, key + ".name", "tag");
      tag_name_check(c.name, c.where, key + ".name");
      if (i == motion::kMaxCoordSystems) error_at(c.where, key, fmt::format("at most {} coordinate systems", motion::kMaxCoordSystems));
      for (std::size_t k = 0; k < c.axes.size(); ++k) {
        const std::string ak = fmt::format("{}.axes[{}]", key, k);
        if (!cfg.find_axis(c.axes[k])) {
          std::string msg = fmt::format("no axis named '{}'", c.axes[k]);
          if (auto s = nearest(c.axes[k], axis_names)) msg += fmt::format("; did you mean '{}'?", *s);
          else msg += fmt::format("; axes: {}", fmt::join(axis_names, ", "));
          error_at(c.axes_where[k], ak, msg);
        }
        for (std::size_t j = 0; j < k; ++j)
          if (c.axes[j] == c.axes[k])
            error_at(c.axes_where[k], ak, fmt::format("axis '{}' is already member {}", c.axes[k], j));
      }
    }
  }

  Config document(const YAML::Node& root) {
    Config cfg;
    cfg.path = file_;
    if (!root || root.IsNull()) {
      error_at({1, 1}, "", "the file is empty; it needs at least `axes:`");
      return cfg;
    }
    if (!check_map(root, "", {"controller", "buses", "drives", "axes", "cams", "arrays", "coordinate_systems"})) return cfg;
    if (root["controller"]) cfg.controller = controller(root["controller"]);
    if (const YAML::Node b = root["buses"]) {
      if (!b.IsSequence()) error(b, "buses", "must be a list of buses");
      else
        for (std::size_t i = 0; i < b.size(); ++i) cfg.buses.push_back(bus(b[i], fmt::format("buses[{}]", i)));
    }
    DriveSettings defaults;
    if (root["drives"]) drive(root["drives"], "drives", defaults);
    if (const YAML::Node a = root["axes"]) {
      if (!a.IsSequence()) error(a, "axes", "must be a list of axes");
      else
        for (std::size_t i = 0; i < a.size(); ++i) cfg.axes.push_back(axis(a[i], fmt::format("axes[{}]", i), defaults));
    } else {
      error(root, "axes", "missing: a configuration needs at least one axis");
    }
    if (const YAML::Node c = root["cams"]) {
      if (!c.IsSequence()) error(c, "cams", "must be a list of cams");
      else
        for (std::size_t i = 0; i < c.size(); ++i) cfg.cams.push_back(cam(c[i], fmt::format("cams[{}]", i)));
    }
    if (const YAML::Node a = root["arrays"]) {
      if (!a.IsSequence()) error(a, "arrays", "must be a list of {name, type, size, values}");
      else
        for (std::size_t i = 0; i < a.size(); ++i) cfg.arrays.push_back(array(a[i], fmt::format("arrays[{}]", i)));
    }
    if (const YAML::Node c = root["coordinate_systems"]) {
      if (!c.IsSequence()) error(c, "coordinate_systems", "must be a list of {name, axes, max_speed, max_accel, max_decel, ...}");
      else
        for (std::size_t i = 0; i < c.size(); ++i)
          cfg.coordinate_systems.push_back(coordinate_system(c[i], fmt::format("coordinate_systems[{}]", i)));
    }
    return cfg;
  }

  // ---- cross-checks ---------------------------------------------------------
  /// A `cams:` or `arrays:` name is a tag (`cam1[0].Status`, `pts[2]`): the
  /// runtime's own tag-name rule.
  void tag_name_check(const std::string& name, Location where, const std::string& key) {
    if (!name.empty() && !rt::TagTable::is_user_tag_name(name))
      error_at(where, key, fmt::format("'{}' is not a tag name (a letter or '_', then letters, digits or '_')", name));
  }

  /// `arrays:` names (unique among cams, arrays and axes) and the registry
  /// capacities (motion::kMaxCamArrays, kMaxCamProfiles, kMaxRealArrays,
  /// rt::kMaxRealElements).
  template <class Unique>
  void array_checks(const Config& cfg, Unique& unique) {
    using T = ArraySettings::Type;
    std::size_t cams = 0, profiles = cfg.cams.size(), reals = 0, real_elems = 0;
    for (std::size_t i = 0; i < cfg.arrays.size(); ++i) {
      const ArraySettings& a = cfg.arrays[i];
      const std::string key = fmt::format("arrays[{}]", i);
      unique(a.name, a.where, key + ".name", "tag");
      tag_name_check(a.name, a.where, key + ".name");
      if (a.type == T::kCam && ++cams == motion::kMaxCamArrays + 1)
        error_at(a.where, key, fmt::format("at most {} CAM arrays", motion::kMaxCamArrays));
      if (a.type == T::kCamProfile && ++profiles == motion::kMaxCamProfiles + 1)
        error_at(a.where, key, fmt::format("at most {} CAM_PROFILE arrays, `cams:` entries included", motion::kMaxCamProfiles));
      if (a.type == T::kReal) {
        if (++reals == motion::kMaxRealArrays + 1) error_at(a.where, key, fmt::format("at most {} REAL arrays", motion::kMaxRealArrays));
        real_elems += a.size;
        if (real_elems > rt::kMaxRealElements && real_elems - a.size <= rt::kMaxRealElements)
          error_at(a.where, key + ".size",
                   fmt::format("REAL arrays may hold {} elements together; this one brings the total to {}",
                               rt::kMaxRealElements, real_elems));
      }
    }
  }

  /// An axis's MDS objects (drives: and its own merged): no two at one
  /// address, a record's sub-index 0 not taken while its other sub-indices
  /// are, none on a CiA 402 object the master writes, maps or reads, none of
  /// another size than the standard object there, and (with direct_control,
  /// when they are written) none written by drive.sdo_writes too. Each
  /// problem once, at the key that placed the object.
  void mds_object_checks(const Config& cfg, std::set<std::string>& said) {
    for (std::size_t ai = 0; ai < cfg.axes.size(); ++ai) {
      const AxisSettings& a = cfg.axes[ai];
      if (a.axis.type != motion::AxisType::CipDrive) continue;
      const DriveSettings& d = a.drive;
      auto report = [&](std::size_t i, const std::string& msg) {
        if (said.insert(d.mds_object_keys[i] + msg).second) error_at(d.mds_object_where[i], d.mds_object_keys[i], msg);
      };
      auto name_of = [&](std::size_t j) {
        return d.mds_object_keys[j].empty() ? fmt::format("{} (the default)", cia402::kMdsObjectInfo[j].key)
                                            : d.mds_object_keys[j];
      };
      for (std::size_t i = 0; i < cia402::kMdsObjectCount; ++i) {
        if (d.mds_object_keys[i].empty()) continue;  // the defaults do not clash among themselves
        const cia402::ObjectAddress at = d.mds_objects.at[i];
        const std::string where = fmt::format("0x{:04X}:{}", at.index, at.sub);
        for (std::size_t j = 0; j < cia402::kMdsObjectCount; ++j) {
          if (j == i) continue;
          const cia402::ObjectAddress other = d.mds_objects.at[j];
          if (other == at && (j < i || d.mds_object_keys[j].empty()))
            report(i, fmt::format("{} is also {}: each MDS object needs its own", where, name_of(j)));
          else if (other.index == at.index && at.sub == 0 && other.sub != 0)
            report(i, fmt::format("{} is sub-index 0 of a record whose sub-index {} is {} (sub-index 0 holds the "
                                  "record's highest sub-index)",
                                  where, other.sub, name_of(j)));
        }
        if (std::find(cia402::kMasterProfileObjects.begin(), cia402::kMasterProfileObjects.end(), at.index) !=
            cia402::kMasterProfileObjects.end()) {
          const std::string_view n = canopen::object_name(at.index, at.sub);
          report(i, fmt::format("{} is 0x{:04X} ({}), which the master itself writes, maps or reads; choose the "
                                "drive's own object",
                                where, at.index, n.empty() ? canopen::object_name(at.index, 0) : n));
          continue;
        }
        const std::uint8_t size = cia402::kMdsObjectInfo[i].size;
        if (const canopen::ObjectInfo* o = canopen::object_info(at.index, at.sub);
            o != nullptr && at.index >= 0x6000 && canopen::data_type_size(o->type) != size)
          report(i, fmt::format("{} is {} ({} byte{}), but {} is {} byte{}", where, o->name, canopen::data_type_size(o->type),
                                canopen::data_type_size(o->type) == 1 ? "" : "s", cia402::kMdsObjectInfo[i].key, size,
                                size == 1 ? "" : "s"));
        if (a.direct.present)
          for (std::size_t wi = 0; wi < d.sdo_writes.size(); ++wi)
            if (d.sdo_writes[wi].index == at.index && d.sdo_writes[wi].sub == at.sub)
              report(i, fmt::format("{} is also written by sdo_writes[{}] (line {}) of axis '{}', and its "
                                    "direct_control writes it: remove one",
                                    where, wi, d.sdo_writes[wi].where.line, a.name));
      }
    }
  }

  void cross_check(Config& cfg) {
    std::map<std::string, Location> names;
    auto unique = [&](const std::string& name, Location l, const std::string& key, const char* what) {
      if (name.empty()) return;
      auto [it, fresh] = names.emplace(name, l);
      if (!fresh)
        error_at(l, key, fmt::format("{} name '{}' is already used at line {}", what, name, it->second.line));
    };
    for (std::size_t i = 0; i < cfg.buses.size(); ++i) unique(cfg.buses[i].name, cfg.buses[i].where, fmt::format("buses[{}].name", i), "bus");
    names.clear();
    for (std::size_t i = 0; i < cfg.axes.size(); ++i) unique(cfg.axes[i].name, cfg.axes[i].where, fmt::format("axes[{}].name", i), "axis");
    for (std::size_t i = 0; i < cfg.cams.size(); ++i) {
      const CamSettings& c = cfg.cams[i];
      unique(c.name, c.where, fmt::format("cams[{}].name", i), "tag");
      tag_name_check(c.name, c.where, fmt::format("cams[{}].name", i));
    }
    array_checks(cfg, unique);
    coordinate_system_checks(cfg, unique);
    std::set<std::string> said;
    mds_object_checks(cfg, said);

    const auto ip = interpolation_period(cfg.controller.period_s);
    if (!ip)
      error_at(cfg.controller.where, "controller.period_ms",
               fmt::format("{} ms cannot be written to 0x60C2 (mantissa 1..255 x 10^exponent); use e.g. 0.5, 1, 2 or 4",
                           cfg.controller.period_ms()));

    // Per bus: axes on it, node ids, COB-ID clashes, 0x60C2 writes, budget.
    for (std::size_t bi = 0; bi < cfg.buses.size(); ++bi) {
      const BusSettings& bus = cfg.buses[bi];
      std::map<std::uint32_t, std::string> cob_owner;  // COB-ID -> who uses it
      auto claim = [&](std::uint32_t cob, const std::string& who, Location l, const std::string& key) {
        auto [it, fresh] = cob_owner.emplace(cob, who);
        if (!fresh) error_at(l, key, fmt::format("COB-ID 0x{:03X} of {} clashes with {}", cob, who, it->second));
      };
      if (bus.master_heartbeat_ms > 0)
        claim(canopen::cob::heartbeat(bus.master_node), fmt::format("the master's heartbeat (node {})", bus.master_node),
              bus.where, fmt::format("buses[{}].master_node", bi));
      std::vector<canopen::NodeTraffic> traffic;
      for (std::size_t ai = 0; ai < cfg.axes.size(); ++ai) {
        const AxisSettings& a = cfg.axes[ai];
        if (a.axis.type != motion::AxisType::CipDrive || a.bus != bus.name || a.node == 0) continue;
        const std::string key = fmt::format("axes[{}].node", ai);
        const std::string who = fmt::format("axis '{}' (node {})", a.name, a.node);
        const auto pdos = cia402::default_drive_pdos(a.drive.pdo, a.node);
        claim(canopen::cob::heartbeat(a.node), who + " heartbeat", a.where, key);
        claim(canopen::cob::sdo_tx(a.node), who + " SDO", a.where, key);
        claim(canopen::cob::emcy(a.node), who + " EMCY", a.where, key);
        canopen::NodeTraffic t;
        for (std::uint8_t i = 0; i < pdos.rpdo_count; ++i) {
          claim(pdos.rpdo[i].cob_id, fmt::format("{} RPDO{}", who, pdos.rpdo[i].number), a.where, key);
          t.rpdo_bytes[t.rpdo_count++] = pdos.rpdo[i].size_bytes;
        }
        for (std::uint8_t i = 0; i < pdos.tpdo_count; ++i) {
          claim(pdos.tpdo[i].cob_id, fmt::format("{} TPDO{}", who, pdos.tpdo[i].number), a.where, key);
          t.tpdo_bytes[t.tpdo_count++] = pdos.tpdo[i].size_bytes;
        }
        t.heartbeat_ms = a.drive.heartbeat_ms;
        traffic.push_back(t);
        if (a.drive.master_heartbeat_timeout_ms > 0 && bus.master_heartbeat_ms == 0)
          error_at(a.where, fmt::format("axes[{}].drive.master_heartbeat_timeout_ms", ai),
                   fmt::format("the drive watches the master's heartbeat but bus '{}' has master_heartbeat_ms: 0", bus.name));
        if (a.drive.master_heartbeat_timeout_ms > 0 && a.drive.master_heartbeat_timeout_ms <= bus.master_heartbeat_ms)
          error_at(a.where, fmt::format("axes[{}].drive.master_heartbeat_timeout_ms", ai),
                   fmt::format("{} ms must exceed the master's heartbeat period {} ms (CiA 301: consumer time > producer time)",
                               a.drive.master_heartbeat_timeout_ms, bus.master_heartbeat_ms));
        for (std::size_t wi = 0; wi < a.drive.sdo_writes.size(); ++wi) {
          const SdoWrite& w = a.drive.sdo_writes[wi];
          if (w.index != 0x60C2 || !ip) continue;
          const bool mant = w.sub == 1 && w.value != ip->mantissa;
          const bool expo = w.sub == 2 && w.value != ip->exponent;
          if (mant || expo)
            error_at(w.where, fmt::format("axes[{}].drive.sdo_writes[{}]", ai, wi),
                     fmt::format("0x60C2:{:02X} = {} contradicts the controller period {} ms (0x60C2 = {} x 10^{} s, "
                                 "written automatically; remove this write)",
                                 w.sub, w.value, cfg.controller.period_ms(), ip->mantissa, ip->exponent));
        }
      }
      canopen::BusBudgetInput in;
      in.cycle_ns = cfg.controller.period_ns();
      in.bitrate = bus.bitrate;
      in.sync_counter = bus.sync_counter_overflow != 0;
      in.master_heartbeat_ms = bus.master_heartbeat_ms;
      in.nodes = traffic;
      const canopen::BusBudget b = canopen::bus_budget(in);
      const std::string msg = fmt::format(
          "worst-case bus load {:.1f} % ({} frames, {:.0f} of {:.0f} bits per {} ms cycle at {} bit/s)", b.load_percent,
          b.frames_per_cycle, b.bits_per_cycle, b.capacity_bits, cfg.controller.period_ms(), bus.bitrate);
      if (b.load_percent > 100.0)
        error_at(bus.where, fmt::format("buses[{}]", bi),
                 msg + "; over 100 % cannot work: lengthen the period, raise the bitrate or move axes to another bus");
      else if (b.load_percent > 70.0)
        warning_at(bus.where, fmt::format("buses[{}]", bi), msg + "; over 70 % leaves little room for SDO and EMCY");
    }

    std::map<std::pair<std::string, int>, std::size_t> nodes;
    for (std::size_t ai = 0; ai < cfg.axes.size(); ++ai) {
      const AxisSettings& a = cfg.axes[ai];
      if (a.axis.type != motion::AxisType::CipDrive || a.bus.empty()) continue;
      if (!cfg.find_bus(a.bus)) {
        std::vector<std::string_view> bus_names;
        for (const auto& b : cfg.buses) bus_names.push_back(b.name);
        std::string msg = fmt::format("no bus named '{}'", a.bus);
        if (auto s = nearest(a.bus, bus_names)) msg += fmt::format("; did you mean '{}'?", *s);
        else if (bus_names.empty()) msg += "; the configuration has no `buses:` section";
        else msg += fmt::format("; buses: {}", fmt::join(bus_names, ", "));
        error_at(a.where, fmt::format("axes[{}].bus", ai), msg);
        continue;
      }
      auto [it, fresh] = nodes.emplace(std::make_pair(a.bus, static_cast<int>(a.node)), ai);
      if (!fresh)
        error_at(a.where, fmt::format("axes[{}].node", ai),
                 fmt::format("node {} on bus '{}' is already axis '{}'", a.node, a.bus, cfg.axes[it->second].name));
    }
  }

 private:
  std::string file_;
};

Config finish(Loader& l, Config cfg) {
  l.cross_check(cfg);
  // The drives' EDS files, once the configuration itself is valid (the check
  // builds each drive's boot configuration from it).
  if (std::none_of(l.diags.begin(), l.diags.end(), [](const Diagnostic& d) { return d.severity == Severity::kError; }))
    check_drive_descriptions(cfg, l.diags);
  std::vector<Diagnostic> errors;
  for (auto& d : l.diags) {
    if (d.severity == Severity::kError) errors.push_back(d);
    else cfg.warnings.push_back(d);
  }
  if (!errors.empty()) {
    std::stable_sort(errors.begin(), errors.end(),
                     [](const Diagnostic& a, const Diagnostic& b) { return a.where.line < b.where.line; });
    throw ConfigError(std::move(errors));
  }
  return cfg;
}

}  // namespace

Config load_string(std::string_view yaml, const std::string& name) {
  Loader l(name);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    throw ConfigError({Diagnostic{Severity::kError, name, {e.mark.line + 1, e.mark.column + 1}, "",
                                  "YAML syntax: " + e.msg}});
  }
  Config cfg = l.document(root);
  return finish(l, std::move(cfg));
}

Config load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::system_error(errno, std::generic_category(), "cannot read configuration file '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return load_string(ss.str(), path);
}

}  // namespace canmotion::config
