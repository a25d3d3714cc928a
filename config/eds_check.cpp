#include "config/eds_check.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "config/runtime.hpp"
#include "fieldbus/cia402/units.hpp"
#include "fieldbus/canopen/master.hpp"
#include "fieldbus/canopen/pdo.hpp"  // sign_extend

namespace canmotion::config {

namespace {
using Severity = Diagnostic::Severity;

/// The proxy's boot writes for `d` (a sans-IO master and proxy, no bus).
std::vector<cia402::BootWrite> proxy_writes(const cia402::DriveConfig& d, const BusSettings& bus) {
  canopen::MasterConfig mc;
  mc.node_id = bus.master_node;
  mc.heartbeat_period_ms = bus.master_heartbeat_ms;
  mc.sync_counter_overflow = bus.sync_counter_overflow;
  canopen::Master master(mc);
  const cia402::DriveProxy proxy(d, master);
  return {proxy.boot_writes().begin(), proxy.boot_writes().end()};
}

/// The boot's write of the master's interpolation time index (0x60C2:2).
bool is_ip_index_write(const cia402::BootWrite& w) {
  return w.w.index == cia402::obj::kInterpolationTimePeriod && w.w.sub == 2 && !w.is_read() && !w.is_fallback();
}

/// The EDS has 0x60C2:2 and it is writable.
bool eds_ip_index_writable(const eds::Eds& e) {
  const eds::SubObject* s = e.find(cia402::obj::kInterpolationTimePeriod, 2);
  return s != nullptr && eds::writable(s->access);
}

/// 0x60C2:2 (interpolation time index) when the EDS has it read-only or not
/// at all, as the boot treats such a drive (cia402/drive_boot.cpp): read-only
/// (ro/const), the drive takes periods in 10^DefaultValue s only and 0x60C2:1
/// is written in that unit, so the period must be a whole number 1..255 of
/// it (refused otherwise, at controller.period_ms); absent, the drive keeps
/// its own unit and 0x60C2:1 is written with the master's value (a warning).
/// A writable 0x60C2:2 is checked with the other writes.
void check_interpolation_index(const Config& cfg, const AxisSettings& a, const std::string& who,
                               std::vector<Diagnostic>& diags) {
  const eds::Eds& e = *a.drive.eds_data;
  const eds::Object* o = e.find(cia402::obj::kInterpolationTimePeriod);
  if (o == nullptr) return;  // no 0x60C2: its :1 write is refused
  const eds::SubObject* s = o->find(2);
  if (s != nullptr && eds::writable(s->access)) return;
  const std::int64_t cycle_ns = cfg.controller.period_ns();
  const auto ip = cia402::encode_interpolation_period(cycle_ns);
  const std::string period = fmt::format("{:g} ms", cfg.controller.period_ms());
  const std::string key = "controller.period_ms";
  const Location where = cfg.controller.where.line > 0 ? cfg.controller.where : a.drive.eds_where;
  if (s == nullptr) {
    diags.push_back({Severity::kWarning, cfg.path, a.drive.eds_where, a.drive.eds_key,
                     fmt::format("{}: {}:{}: 0x60C2 has no sub-index 2 (interpolation time index): it is not written, "
                                 "the drive keeps its own unit and 0x60C2:1 is written as {} (the period {} in units "
                                 "of 10^{} s)",
                                 who, e.file, o->line, ip ? ip->value : 0, period, ip ? ip->index : 0)});
    return;
  }
  const std::string what = fmt::format("0x60C2:02 ({})", s->name.empty() ? "Interpolation time index" : s->name);
  const eds::Value* v = s->value();  // ParameterValue, else DefaultValue
  if (v == nullptr || s->size() != 1) {
    diags.push_back({Severity::kWarning, cfg.path, a.drive.eds_where, a.drive.eds_key,
                     fmt::format("{}: {}:{}: {} is AccessType={} without a DefaultValue: the boot reads the drive's "
                                 "unit and fails if the period {} ({}) is not a whole number 1..255 of it",
                                 who, e.file, s->line, what, eds::access_type_name(s->access), period, key)});
    return;
  }
  const auto idx = static_cast<std::int8_t>(canopen::sign_extend(v->resolve(a.node, 1), 8));
  const std::int64_t unit = cia402::interpolation_period_ns(cia402::InterpolationPeriod{1, idx});
  if (unit > 0 && cycle_ns % unit == 0 && cycle_ns / unit >= 1 && cycle_ns / unit <= 255) return;
  diags.push_back({Severity::kError, cfg.path, where, key,
                   fmt::format("{}: {}:{}: {} is AccessType={} at {}={} (the drive takes periods in units "
                               "of 10^{} s only) and the cycle period {} is not a whole number 1..255 of that unit: "
                               "choose a period the drive can take",
                               who, e.file, s->line, what, eds::access_type_name(s->access),
                               s->parameter_value ? "ParameterValue" : "DefaultValue", v->text,
                               static_cast<int>(idx), period)});
}
}  // namespace

std::vector<cia402::BootWrite> boot_writes(const AxisSettings& a, const BusSettings& bus, double period_s,
                                           std::size_t axis_index) {
  return proxy_writes(drive_config(a, bus, period_s, axis_index), bus);
}

eds::Requirements drive_requirements(const AxisSettings& a, const BusSettings& bus, double period_s,
                                     std::size_t axis_index) {
  cia402::DriveConfig d = drive_config(a, bus, period_s, axis_index);
  d.dictionary.reset();  // every write the master may make, the optional ones included
  if (d.consumer_heartbeat_optional && d.consumer_heartbeat_ms == 0)
    d.consumer_heartbeat_ms = bus.master_heartbeat_ms > 0 ? a.drive.master_heartbeat_timeout_ms : 0;
  eds::Requirements req;
  req.node_id = a.node;
  req.pdo_key = d.hints.pdo;
  const eds::Eds* e = a.drive.eds_data.get();
  for (const cia402::BootWrite& w : proxy_writes(d, bus)) {
    if (w.check == cia402::BootCheck::kSupportedModes) continue;  // with its mode bits below
    if (is_ip_index_write(w) && e != nullptr && !eds_ip_index_writable(*e)) continue;  // check_interpolation_index()
    eds::Use u;
    u.index = w.w.index;
    u.sub = w.w.sub;
    u.optional = w.optional;
    if (w.is_read()) {  // the boot's checks: 0x1000, 0x1018 as configured, 0x6061
      u.usage = eds::Usage::kRead;
      // A read the configuration asks for names drive.identity; the others
      // (0x1000's profile, 0x6061) are the master's own (the EDS key then).
      if (w.check == cia402::BootCheck::kSyncCounter)
        u.key = d.hints.sync_counter;
      else if (w.check != cia402::BootCheck::kModeDisplay && w.check != cia402::BootCheck::kInterpolationIndex &&
               (w.check != cia402::BootCheck::kDeviceType || d.identity.has_device_type))
        u.key = d.hints.identity;
      req.uses.push_back(std::move(u));
      continue;
    }
    u.usage = eds::Usage::kWrite;
    // A typed value (sdo_writes `type:`, a DCF's string or 64-bit value): its
    // length, checked against a fixed-size type; no range check on its bytes.
    const bool typed = w.w.data != nullptr;
    u.size = typed ? static_cast<std::uint8_t>(w.w.data_len <= 8 ? w.w.data_len : 0) : w.w.size;
    // The value as the object's type reads it (INTEGERn sign-extended).
    const eds::SubObject* s = e != nullptr ? e->find(w.w.index, w.w.sub) : nullptr;
    // A read-only 0x1006 or 0x1019 is what the boot falls back on: 0x1006 = 0
    // is then not written (the drive keeps its own), and 0x1019 is fine when
    // it already holds the master's value (else refused below, naming the key).
    if (s != nullptr && !eds::writable(s->access) && w.optional &&
        (w.origin == cia402::WriteOrigin::kSyncPeriod ||
         (w.origin == cia402::WriteOrigin::kSyncCounter && s->value() != nullptr &&
          s->value()->resolve(a.node, 1) == w.w.value)))
      continue;
    const bool is_signed = s != nullptr && canopen::data_type_signed(s->type);
    if (!typed) u.value = is_signed ? canopen::sign_extend(w.w.value, 8u * w.w.size) : static_cast<std::int64_t>(w.w.value);
    if (const std::string* k = cia402::write_hint_key(d.hints, w); k != nullptr) u.key = *k;
    else if (w.origin == cia402::WriteOrigin::kUnusedPdo) u.key = d.hints.pdo;
    req.uses.push_back(std::move(u));
  }
  const cia402::DrivePdoSet pdos = cia402::default_drive_pdos(d.pdo_profile, d.node, d.mode);
  req.rpdos = pdos.rpdo_count;
  req.tpdos = pdos.tpdo_count;
  auto map = [&](const canopen::PdoMap& m, eds::Usage usage) {
    for (std::uint8_t i = 0; i < m.count; ++i)
    {
      eds::Use u;
      u.index = m.entries[i].index;
      u.sub = m.entries[i].sub;
      u.usage = usage;
      u.size = static_cast<std::uint8_t>(m.entries[i].bits / 8);
      u.key = d.hints.pdo;
      req.uses.push_back(std::move(u));
    }
  };
  for (std::uint8_t p = 0; p < pdos.rpdo_count; ++p) map(pdos.rpdo[p], eds::Usage::kMapRpdo);
  for (std::uint8_t p = 0; p < pdos.tpdo_count; ++p) map(pdos.tpdo[p], eds::Usage::kMapTpdo);
  // 0x6502: the position stream's mode (drive.mode: CSP, or IP bit 6),
  // then CSV and CST when the PDO profile carries their targets.
  eds::Use m;
  m.index = cia402::obj::kSupportedDriveModes;
  m.usage = eds::Usage::kRead;
  m.optional = true;
  std::uint64_t modes = cia402::supported_mode_bit(d.mode);
  m.required_bits = modes;
  m.key = d.hints.mode.empty() ? d.hints.pdo : d.hints.mode;
  req.uses.push_back(m);
  if (d.pdo_profile == cia402::PdoProfile::kCspCsvCst) {
    m.required_bits = cia402::supported_mode_bit(cia402::Mode::kCsv) | cia402::supported_mode_bit(cia402::Mode::kCst);
    modes |= m.required_bits;
    m.key = d.hints.pdo;
    req.uses.push_back(m);
  }
  // The other modes the proxy checks 0x6502 for at boot (MDS, homing), each
  // with the key that needs it.
  for (const cia402::ModeNeed& need : d.needed_modes) {
    const std::uint64_t bit = cia402::supported_mode_bit(need.mode);
    if ((modes & bit) != 0) continue;
    modes |= bit;
    m.required_bits = bit;
    m.key = need.key;
    req.uses.push_back(m);
  }
  return req;
}

namespace {

/// The value the drive has for index:sub by its file: ParameterValue (DCF)
/// wins over DefaultValue; nothing when the object or a value is absent.
std::optional<std::uint64_t> file_value(const eds::Eds& e, std::uint16_t index, std::uint8_t sub, std::uint8_t node) {
  const eds::SubObject* s = e.find(index, sub);
  if (s == nullptr) return std::nullopt;
  const std::optional<eds::Value>& v = s->parameter_value ? s->parameter_value : s->default_value;
  if (!v || s->size() == 0 || s->size() > 8) return std::nullopt;
  return v->resolve(node, s->size());
}

void unit_needs(const Config& cfg, const AxisSettings& a, std::size_t ai, const std::string& who,
                std::vector<Diagnostic>& diags);

/// Drive units (README "Drive units"): the counts per unit of the drive's
/// velocity (0x60A9) and acceleration (0x60AA) values from its EDS/DCF and
/// `units.velocity`, and what needs them refused when they cannot be known
/// (`velocity_unknown`, `acceleration_unknown` say why). A value the file
/// lacks but the drive has (0x60A9/0x60AA, 0x608F, 0x6091 without a value)
/// is read at boot (`units_at_boot`), and the boot fails when what it gives
/// cannot be interpreted and is needed.
void drive_units(const Config& cfg, AxisSettings& a, std::size_t ai, const std::string& who,
                 std::vector<Diagnostic>& diags) {
  namespace u = cia402::units;
  DriveSettings& ds = a.drive;
  const eds::Eds& e = *ds.eds_data;
  // The factor group as the file has it; an object the drive has but whose
  // value the file lacks is read at boot (`units_at_boot`).
  u::FactorGroup f;
  bool unvalued = false;  // an object of the group present without a value
  auto take = [&](std::uint16_t index, std::uint8_t sub, std::uint32_t& to) {
    if (e.find(index, sub) == nullptr) return;
    if (auto v = file_value(e, index, sub, a.node)) to = static_cast<std::uint32_t>(*v);
    else unvalued = true;
  };
  take(u::kSiUnitPosition, 0, f.position);
  take(u::kPositionEncoderResolution, 1, f.res.increments);
  take(u::kPositionEncoderResolution, 2, f.res.revolutions);
  take(u::kGearRatio, 1, f.gear_motor);
  take(u::kGearRatio, 2, f.gear_shaft);
  take(u::kFeedConstant, 1, f.feed);
  take(u::kFeedConstant, 2, f.feed_shaft);
  auto one = [&](std::uint16_t index, bool acceleration, std::optional<std::uint32_t> configured,
                 std::optional<double>& counts, std::string& unknown) {
    const eds::SubObject* s = e.find(index, 0);
    std::optional<std::uint64_t> si = configured ? std::optional<std::uint64_t>(*configured) : file_value(e, index, 0, a.node);
    if (s == nullptr && !configured) {  // no factor group: increments
      counts = 1.0;
      return;
    }
    if (!si) {  // the drive has the object, the file no value: read at boot
      counts.reset();
      ds.units_at_boot = true;
      return;
    }
    counts = u::counts_per_unit(static_cast<std::uint32_t>(*si), f, acceleration);
    // Factors the drive has but the file gives no value for: read at boot.
    if (!counts && unvalued) {
      ds.units_at_boot = true;
      return;
    }
    if (!counts)
      unknown = fmt::format("0x{:04X} = 0x{:08X}{}: {}", index, *si,
                            configured ? fmt::format(" ({})", ds.units_key) : fmt::format(" ({}:{})", ds.eds, s->line),
                            u::unknown_reason(static_cast<std::uint32_t>(*si), f, acceleration));
  };
  one(u::kSiUnitVelocity, false, ds.velocity_unit, ds.velocity_counts, ds.velocity_unknown);
  one(u::kSiUnitAcceleration, true, std::nullopt, ds.acceleration_counts, ds.acceleration_unknown);
  // The older factor objects (DSP 402 before the SI units): a drive that
  // scales its velocities (0x6094 velocity encoder factor, 0x6095/0x6096
  // velocity factors 1/2) or accelerations (0x6097) by a ratio other than
  // 1:1 has units this master does not interpret: unknown, not guessed.
  auto older = [&](std::uint16_t index, const char* name, std::optional<double>& counts, std::string& unknown) {
    if (e.find(index, 1) == nullptr) return;
    const auto n = file_value(e, index, 1, a.node);
    const auto d = file_value(e, index, 2, a.node);
    if (n && d && *n == *d && *n != 0) return;
    counts.reset();
    unknown = fmt::format("{}:{} has 0x{:04X} ({}){}: the older factor objects are not interpreted", ds.eds,
                          e.find(index)->line, index, name,
                          n && d ? fmt::format(" = {}:{}, not 1:1", *n, *d) : std::string(" without a value"));
  };
  for (const auto& [index, name] : {std::pair<std::uint16_t, const char*>{0x6094, "velocity encoder factor"},
                                    {0x6095, "velocity factor 1"},
                                    {0x6096, "velocity factor 2"}})
    if (ds.velocity_unknown.empty()) older(index, name, ds.velocity_counts, ds.velocity_unknown);
  if (ds.acceleration_unknown.empty()) older(0x6097, "acceleration factor", ds.acceleration_counts, ds.acceleration_unknown);
  unit_needs(cfg, a, ai, who, diags);
}

/// What needs a drive unit (MDS, homing on the drive, the MDS ramps): refused
/// when the unit cannot be known, and the ramps checked in the drive's unit
/// where the file tells it.
void unit_needs(const Config& cfg, const AxisSettings& a, std::size_t ai, const std::string& who,
                std::vector<Diagnostic>& diags) {
  const DriveSettings& ds = a.drive;
  const std::string axis = fmt::format("axes[{}]", ai);
  auto refuse = [&](Location where, const std::string& key, const std::string& what, bool velocity) {
    const std::string& why = velocity ? ds.velocity_unknown : ds.acceleration_unknown;
    diags.push_back({Severity::kError, cfg.path, where, key,
                     fmt::format("{}: {} needs the drive's {} unit, which cannot be known: {}. Nothing is guessed: "
                                 "give the EDS/DCF the value{}",
                                  who, what, velocity ? "velocity" : "acceleration", why,
                                 velocity ? " or set drive.units.velocity (a writable 0x60A9)" : "")});
  };
  if (a.direct.present) {
    const bool torque = a.axis.direct_mode == motion::AxisConfig::DirectMode::Torque;
    const std::string what = fmt::format("MDS ({}.direct_control, {})", axis, torque ? "CST" : "CSV");
    if (!ds.velocity_unknown.empty()) refuse(a.direct.where, axis + ".direct_control", what, true);
    if (!ds.acceleration_unknown.empty() && (a.direct.ramp_acceleration || a.direct.ramp_deceleration))
      refuse(a.direct.where, axis + ".direct_control.ramp", what + " ramps (0x6083/0x6084)", false);
    // The ramps in the drive's unit, where the file tells it (load_axis
    // checked them in counts): a whole 1 .. 4294967295 of it, never 0.
    const double conv = a.axis.conversion_constant;
    auto fits = [&](const std::optional<double>& v, const char* key, const char* object, bool velocity) {
      const std::optional<double>& per = velocity ? ds.velocity_counts : ds.acceleration_counts;
      if (!v || !per || ds.units_at_boot) return;
      const double u = std::round(*v * conv / *per);
      if (u >= 1 && u <= 4294967295.0) return;
      diags.push_back({Severity::kError, cfg.path, a.direct.where, axis + ".direct_control.ramp." + key,
                       fmt::format("{}: {} {} x conversion_constant {} = {} in the drive's {} unit ({} counts per "
                                   "unit), which does not fit {} (UNSIGNED32, 1 .. 4294967295)",
                                   who, *v, velocity ? "units/s" : "units/s^2", conv, u,
                                   velocity ? "velocity" : "acceleration", *per, object)});
    };
    fits(a.direct.ramp_acceleration, "acceleration", "0x6083 profile acceleration", false);
    fits(a.direct.ramp_deceleration, "deceleration", "0x6084 profile deceleration", false);
    fits(a.direct.ramp_velocity_positive, "velocity_positive", "0x2010:1 ramp velocity - positive", true);
    fits(a.direct.ramp_velocity_negative, "velocity_negative", "0x2010:2 ramp velocity - negative", true);
  }
  if (a.axis.homing.mode == motion::HomingConfig::Mode::Active &&
      a.axis.homing.sequence != motion::HomingConfig::Sequence::Immediate) {
    const std::string what = fmt::format("homing on the drive ({}.homing: speeds 0x6099, acceleration 0x609A)", axis);
    if (!ds.velocity_unknown.empty()) refuse(ds.eds_where, axis + ".homing", what, true);
    if (!ds.acceleration_unknown.empty()) refuse(ds.eds_where, axis + ".homing", what, false);
  }
}

}  // namespace

void check_drive_descriptions(Config& cfg, std::vector<Diagnostic>& diags) {
  std::map<std::string, std::pair<std::shared_ptr<const eds::Eds>, std::shared_ptr<const canopen::DeviceDictionary>>> files;
  // The files' own warnings, once per file (several axes may share one),
  // after the refusals: a defect that a refusal names is not said again.
  struct FileWarnings {
    const eds::Eds* eds;
    const AxisSettings* axis;  // the first that names the file
  };
  std::vector<FileWarnings> file_warnings;
  std::vector<std::string> refused;  // the refusals' messages
  for (std::size_t ai = 0; ai < cfg.axes.size(); ++ai) {
    AxisSettings& a = cfg.axes[ai];
    DriveSettings& ds = a.drive;
    if (a.axis.type != motion::AxisType::CipDrive) continue;
    if (ds.eds_path.empty()) {  // no file to tell the units: the drive tells at boot (README "Drive units")
      ds.units_at_boot = true;
      ds.velocity_counts.reset();
      ds.acceleration_counts.reset();
      continue;
    }
    const std::string who = fmt::format("axis '{}' (node {})", a.name, a.node);
    auto it = files.find(ds.eds_path);
    if (it == files.end()) {
      try {
        auto parsed = std::make_shared<const eds::Eds>(eds::load(ds.eds_path));
        auto dict = std::make_shared<const canopen::DeviceDictionary>(eds::device_dictionary(*parsed));
        file_warnings.push_back({parsed.get(), &a});
        it = files.emplace(ds.eds_path, std::make_pair(std::move(parsed), std::move(dict))).first;
      } catch (const eds::ParseError& e) {
        diags.push_back({Severity::kError, cfg.path, ds.eds_where, ds.eds_key,
                         fmt::format("{}: the drive's EDS cannot be used:\n{}", who, e.what())});
        files.emplace(ds.eds_path, std::make_pair(nullptr, nullptr));
        continue;
      }
    }
    if (!it->second.first) continue;  // unreadable: said once
    ds.eds_data = it->second.first;
    ds.dictionary = it->second.second;
    drive_units(cfg, a, ai, who, diags);
    check_mds_objects_in_eds(cfg, a, ai, who, diags);
    const BusSettings* bus = cfg.find_bus(a.bus);
    if (bus == nullptr) continue;  // cross_check reported it
    dcf_download(cfg, a, ai, *bus, who, diags);
    const eds::CheckResult r = eds::check(*ds.eds_data, drive_requirements(a, *bus, cfg.controller.period_s, ai));
    for (const eds::Refusal& x : r.refusals) refused.push_back(x.message);
    for (const eds::Refusal& x : r.refusals)
      diags.push_back({Severity::kError, cfg.path, ds.eds_where, x.key.empty() ? ds.eds_key : x.key,
                       // "file:line: message"; the key is the diagnostic's own.
                       fmt::format("{}: {}{}: {}", who, x.file, x.line > 0 ? fmt::format(":{}", x.line) : "", x.message)});
    check_interpolation_index(cfg, a, who, diags);
    bool said_modes = false;  // 0x6502 may be wanted by several keys: said once
    for (const eds::Use& u : r.skipped) {
      if (u.index == 0x1016)
        diags.push_back({Severity::kWarning, cfg.path, ds.eds_where, u.key,
                         fmt::format("{}: {} has no 0x{:04X}:{:02X}: the write is left out and the drive does not "
                                     "watch the master's heartbeat (set {} to 0 to say so)",
                                     who, ds.eds, u.index, u.sub, u.key)});
      else if (u.index == cia402::obj::kSyncCounterOverflow && u.usage == eds::Usage::kWrite &&
               bus->sync_counter_overflow != 0)
        diags.push_back({Severity::kWarning, cfg.path, ds.eds_where, u.key,
                         fmt::format("{}: {} has no 0x1019 (synchronous counter overflow value): the drive is not "
                                     "told that the master's SYNC carries a counter (sync_counter_overflow: {} on "
                                     "bus '{}'); it must take such SYNCs as they are",
                                     who, ds.eds, bus->sync_counter_overflow, bus->name)});
      else if (u.index == cia402::obj::kSupportedDriveModes && !std::exchange(said_modes, true))
        diags.push_back({Severity::kWarning, cfg.path, ds.eds_where, ds.eds_key,
                         fmt::format("{}: {} has no 0x6502 (supported drive modes): the modes the master uses "
                                     "are not checked",
                                     who, ds.eds)});
    }
    // 0x6502 without a value in the file (a DCF with neither ParameterValue
    // nor DefaultValue): the boot reads it from the drive and refuses a mode
    // it lacks, naming 0x6502. Said once per axis.
    if (!r.deferred.empty()) {
      const eds::Use& u = r.deferred.front();
      const eds::SubObject* s = ds.eds_data->find(u.index, u.sub);
      diags.push_back({Severity::kWarning, cfg.path, ds.eds_where, ds.eds_key,
                       fmt::format("{}: {}:{}: 0x{:04X}:{:02X} ({}) has neither ParameterValue nor DefaultValue: the "
                                   "boot reads it from the drive and refuses a mode the drive lacks",
                                   who, ds.eds_data->file, s != nullptr ? s->line : 0, u.index, u.sub,
                                   s != nullptr && !s->name.empty() ? s->name : "Supported drive modes")});
    }
  }
  for (const FileWarnings& f : file_warnings)
    for (const eds::Diagnostic& w : f.eds->warnings) {
      if (std::any_of(refused.begin(), refused.end(),
                      [&](const std::string& m) { return m.find(w.message) != std::string::npos; }))
        continue;
      diags.push_back({Severity::kWarning, cfg.path, f.axis->drive.eds_where, f.axis->drive.eds_key,
                       fmt::format("{} (read past, as python-canopen does)", w.to_string())});
    }
}

}  // namespace canmotion::config
