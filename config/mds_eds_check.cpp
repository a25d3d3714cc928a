// The MDS objects (`direct_control:`, seed 002) against the drive's EDS:
// CiA 402 has no ramp velocity limits, ramp jerk or SLAT objects, so the
// master writes them where drive.mds_objects says, by default the project's
// own 0x2010..0x2022 (cia402.hpp). On a vendor's drive those addresses
// usually hold something else (Ingenia's 0x2020 is "Enable alternative
// frequency PWM", UNSIGNED8 rw: same size, writable, and not SLAT). A write
// there must never go out; eds::check() compares access and size only, so
// the object's name and type are compared here, before it runs.
#include <algorithm>
#include <cctype>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "config/eds_check.hpp"

namespace canmotion::config {

namespace {

using cia402::MdsObject;
using Severity = Diagnostic::Severity;

/// `name` (an EDS ParameterName, lower-cased) names MDS object `o` as the
/// project's own EDS files do ("Ramp velocity - positive", "Ramp jerk -
/// control (% of ramp time)", "SLAT configuration" ...).
bool names_mds_object(std::string name, MdsObject o) {
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  auto has = [&](std::string_view w) { return name.find(w) != std::string::npos; };
  switch (o) {
    case MdsObject::kRampVelocityPositive:
    case MdsObject::kRampVelocityNegative: return has("ramp") && has("velocity");
    case MdsObject::kRampJerkControl: return has("jerk");
    case MdsObject::kSlatConfiguration:
    case MdsObject::kSlatSetPoint:
    case MdsObject::kSlatTimeDelay: return has("slat");
  }
  return false;
}

bool integer_type(canopen::DataType t) {
  switch (t) {
    case canopen::DataType::kBoolean:
    case canopen::DataType::kReal32:
    case canopen::DataType::kReal64:
    case canopen::DataType::kVisibleString:
    case canopen::DataType::kOctetString:
    case canopen::DataType::kUnicodeString:
    case canopen::DataType::kTimeOfDay:
    case canopen::DataType::kTimeDifference:
    case canopen::DataType::kDomain: return false;
    default: return true;
  }
}

/// The direct_control key that asks for a write of `o`; empty when the
/// write is made without being asked (the SLAT-disabled writes without
/// `slat:`), nullopt when `o` is not written at all.
std::optional<std::string> asking_key(const DirectControlSettings& d, MdsObject o) {
  switch (o) {
    case MdsObject::kRampVelocityPositive:
      return d.ramp_velocity_positive ? std::optional<std::string>("direct_control.ramp.velocity_positive") : std::nullopt;
    case MdsObject::kRampVelocityNegative:
      return d.ramp_velocity_negative ? std::optional<std::string>("direct_control.ramp.velocity_negative") : std::nullopt;
    case MdsObject::kRampJerkControl:
      return d.ramp_jerk_control ? std::optional<std::string>("direct_control.ramp.jerk_control") : std::nullopt;
    case MdsObject::kSlatConfiguration: return d.slat_set ? "direct_control.slat.configuration" : "";
    case MdsObject::kSlatSetPoint: return d.slat_set ? "direct_control.slat.set_point" : "";
    case MdsObject::kSlatTimeDelay: return d.slat_set ? "direct_control.slat.time_delay_ms" : "";
  }
  return std::nullopt;
}

}  // namespace

void check_mds_objects_in_eds(const Config& cfg, AxisSettings& a, std::size_t ai, const std::string& who,
                              std::vector<Diagnostic>& diags) {
  DriveSettings& ds = a.drive;
  if (!a.direct.present || !ds.eds_data) return;
  const eds::Eds& e = *ds.eds_data;
  bool said_slat = false;  // the three SLAT writes left out: said once
  for (std::size_t i = 0; i < cia402::kMdsObjectCount; ++i) {
    const auto o = static_cast<MdsObject>(i);
    const std::optional<std::string> key = asking_key(a.direct, o);
    if (!key) continue;
    const cia402::ObjectAddress at = ds.mds_objects.at[i];
    const eds::Object* obj = e.find(at.index);
    const eds::SubObject* s = obj != nullptr ? obj->find(at.sub) : nullptr;
    if (s == nullptr) continue;  // absent: eds::check() refuses or skips it
    const bool placed = !ds.mds_object_keys[i].empty();
    const std::string& name = !s->name.empty() ? s->name : obj->name;
    // At the default address the object must be the project's own (by its
    // name); anywhere it must hold an integer, as the master writes one.
    const bool other_name = !placed && !names_mds_object(name, o) && !names_mds_object(obj->name, o);
    const bool other_type = !integer_type(s->type);
    if (!other_name && !other_type) continue;
    ds.mds_not_in_eds[i] = true;
    const std::string mds_key = fmt::format("axes[{}].drive.mds_objects.{}", ai, cia402::kMdsObjectInfo[i].key);
    const std::string what =
        fmt::format("{}:{}: 0x{:04X}:{:02X} is '{}' ({})", e.file, s->line, at.index, at.sub, name,
                    canopen::data_type_name(s->type));
    const std::string role = fmt::format(
        "{} {}", cia402::kMdsObjectInfo[i].key,
        placed ? fmt::format("(placed there by {}), which the master writes as an integer", ds.mds_object_keys[i])
               : fmt::format("(the project's own object there, the default of {})", mds_key));
    const std::string where = placed ? ds.mds_object_keys[i] : mds_key;
    if (key->empty()) {  // SLAT disabled, written unasked: the three left out together
      for (const MdsObject slat : {MdsObject::kSlatConfiguration, MdsObject::kSlatSetPoint, MdsObject::kSlatTimeDelay})
        ds.mds_not_in_eds[static_cast<std::size_t>(slat)] = true;
      if (std::exchange(said_slat, true)) continue;
      diags.push_back({Severity::kWarning, cfg.path, a.direct.where, where,
                       fmt::format("{}: {}, not {}: the SLAT-disabled writes are left out and the drive keeps its "
                                   "own SLAT setting; if the drive has SLAT objects, give them with "
                                   "axes[{}].drive.mds_objects.slat_*",
                                   who, what, role, ai)});
      continue;
    }
    diags.push_back({Severity::kError, cfg.path, a.direct.where, fmt::format("axes[{}].{}", ai, *key),
                     fmt::format("{}: {}, not {}: set {} to where this drive keeps it, or remove axes[{}].{}", who,
                                 what, role, where, ai, *key)});
  }
}

}  // namespace canmotion::config
