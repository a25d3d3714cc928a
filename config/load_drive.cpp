// The loader's `drives:` / `drive:` section: timeouts, PDO profile,
// heartbeats, identity, EDS, extra SDO writes, MDS object placement.
#include <filesystem>
#include <optional>

#include "config/load_sections.hpp"
#include "fieldbus/cia402/units.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::config::load {

namespace {

void timeouts(Reader& r, const YAML::Node& n, const std::string& path, DriveTimeouts& t) {
  if (!r.check_map(n, path, {"sdo_ms", "boot_ms", "transition_ms", "mode_switch_ms", "homing_ms", "wait_ms"})) return;
  r.scalar(n, path, "sdo_ms", t.sdo_ms, 1u, 60'000u, "ms");
  r.scalar(n, path, "boot_ms", t.boot_ms, 10u, 600'000u, "ms");
  r.scalar(n, path, "transition_ms", t.transition_ms, 1u, 60'000u, "ms");
  r.scalar(n, path, "mode_switch_ms", t.mode_switch_ms, 1u, 60'000u, "ms");
  r.scalar(n, path, "homing_ms", t.homing_ms, 0u, 3'600'000u, "ms (0 = no limit)");
  r.scalar(n, path, "wait_ms", t.wait_ms, 0u, 3'600'000u,
           "ms (0 = 3 x boot_ms + mode_switch_ms + 4 x transition_ms)");
}

/// `mds_objects:` {ramp_velocity_positive: "0x3000:1", ...}: each an
/// INDEX:SUB in the manufacturer-specific or device-profile area. Clashes
/// are checked per axis, once `drives:` and the axis's own are merged
/// (mds_object_checks).
void mds_objects(Reader& r, const YAML::Node& m, const std::string& path, DriveSettings& d) {
  std::vector<std::string_view> keys;
  for (const cia402::MdsObjectInfo& i : cia402::kMdsObjectInfo) keys.push_back(i.key);
  if (!r.check_map(m, path, keys)) return;
  for (std::size_t i = 0; i < cia402::kMdsObjectCount; ++i) {
    const cia402::MdsObjectInfo& info = cia402::kMdsObjectInfo[i];
    const YAML::Node v = m[std::string(info.key)];
    if (!v) continue;
    const std::string k = sub(path, info.key);
    const std::optional<cia402::ObjectAddress> a = v.IsScalar() ? cia402::parse_object_address(v.Scalar()) : std::nullopt;
    if (!a) {
      r.error(v, k, fmt::format("'{}' is not an object INDEX:SUB (e.g. \"0x{:04X}:{}\", or \"0x2011\" for sub-index 0; "
                                "sub-index 0 .. 254)",
                                v.IsScalar() ? v.Scalar() : std::string("<non-scalar>"), info.standard.index,
                                info.standard.sub));
      continue;
    }
    if (a->index < 0x2000 || a->index > 0x9FFF) {
      r.error(v, k, fmt::format("0x{:04X}:{} is outside the manufacturer-specific (0x2000 .. 0x5FFF) and device profile "
                                "(0x6000 .. 0x9FFF) areas where a drive keeps such objects",
                                a->index, a->sub));
      continue;
    }
    d.mds_objects.at[i] = *a;
    d.mds_object_keys[i] = k;
    d.mds_object_where[i] = r.loc(v);
  }
}

/// `identity:` {device_type, vendor_id, product_code, revision}: what 0x1000
/// and 0x1018:1..3 must read (each compared only when given).
void identity(Reader& r, const YAML::Node& id, const std::string& p, DriveIdentitySettings& out) {
  if (!r.check_map(id, p, {"device_type", "vendor_id", "product_code", "revision"})) return;
  auto u32 = [&](std::string_view key, std::optional<std::uint32_t>& v32) {
    std::uint32_t v = 0;
    if (id[std::string(key)] && r.scalar(id, p, key, v, 0u, 0xFFFFFFFFu)) v32 = v;
  };
  u32("device_type", out.device_type);
  u32("vendor_id", out.vendor_id);
  u32("product_code", out.product_code);
  u32("revision", out.revision);
}

/// One `sdo_writes:` entry {index, sub, size, value} at `p`; nullopt when it
/// is not a mapping or lacks index or value (reported). An object of the one
/// object table (canopen::known_objects()) has its size and signedness from there.
std::optional<SdoWrite> sdo_write(Reader& r, const YAML::Node& e, const std::string& p) {
  SdoWrite s;
  s.where = r.loc(e);
  if (!r.check_map(e, p, {"index", "sub", "size", "value", "type", "file"})) return std::nullopt;
  if (!e["index"] || (!e["value"] && !e["file"])) {
    r.error(e, p, "needs at least index and value (or file)");
    return std::nullopt;
  }
  r.scalar(e, p, "index", s.index, std::uint16_t{0x1000}, std::uint16_t{0xFFFF});
  r.scalar(e, p, "sub", s.sub, std::uint8_t{0}, std::uint8_t{254});
  // An object of the one object table (canopen::known_objects()) has
  // its size from there: `size:` may be left out, and must match.
  const canopen::ObjectInfo* known = canopen::object_info(s.index, s.sub);
  const std::size_t known_size = known != nullptr ? canopen::data_type_size(known->type) : 0;
  if (known != nullptr && (known->access == canopen::Access::kRo || known->access == canopen::Access::kConst))
    r.error(e["index"], p + ".index", fmt::format("0x{:04X}:{:02X} ({}) is read-only", s.index, s.sub, known->name));
  // A CiA 301 type (given, or a table type the integer path cannot carry):
  // the bytes are prepared here.
  const bool table_typed = known != nullptr && known_size != 1 && known_size != 2 && known_size != 4;
  if (e["type"] || e["file"] || table_typed) {
    if (e["size"]) r.error(e["size"], p + ".size", "is for the integer form; a typed entry takes its size from its type");
    if (typed_sdo_write(r, e, p, known, s)) {
      s.size = static_cast<std::uint8_t>(std::min<std::size_t>(s.bytes.size(), 255));
      return s;
    }
  }
  if (known_size == 1 || known_size == 2 || known_size == 4) s.size = static_cast<std::uint8_t>(known_size);
  if (const YAML::Node sz = e["size"]) {
    std::uint8_t given = 0;
    if (r.scalar(e, p, "size", given, std::uint8_t{1}, std::uint8_t{4})) {
      if (given == 3)
        r.error(sz, p + ".size", "must be 1, 2 or 4 bytes, got 3");
      else if (known_size != 0 && given != known_size)
        r.error(sz, p + ".size",
                fmt::format("0x{:04X}:{:02X} ({}) is {} byte{}, got {}", s.index, s.sub, known->name, known_size,
                            known_size == 1 ? "" : "s", given));
      else
        s.size = given;
    }
  }
  if (r.scalar(e, p, "value", s.value, std::int64_t{-2147483648LL}, std::int64_t{4294967295LL})) {
    // The object's own type when known (INTEGERn signed, UNSIGNEDn
    // unsigned); otherwise either reading of `size` bytes.
    const int bits = 8 * s.size;
    const bool is_signed = known_size != 0 && canopen::data_type_signed(known->type);
    const bool is_unsigned = known_size != 0 && !is_signed;
    const std::int64_t lo = is_unsigned ? 0 : -(std::int64_t{1} << (bits - 1));
    const std::int64_t hi = is_signed ? (std::int64_t{1} << (bits - 1)) - 1 : (std::int64_t{1} << bits) - 1;
    if (s.value < lo || s.value > hi)
      r.error(e["value"], p + ".value",
              fmt::format("{} does not fit in {} byte{} ({} .. {})", s.value, s.size, s.size == 1 ? "" : "s", lo, hi));
  }
  return s;
}

/// `dcf: FILE` or `dcf: {file, store, store_timeout_ms}` of drive map `n`:
/// the DCF becomes the drive's description too (an `eds:` of `drives:` is
/// replaced; both in one map are refused).
void dcf(Reader& r, const YAML::Node& n, const YAML::Node& f, const std::string& path, DriveSettings& d) {
  const std::string key = path + ".dcf";
  DcfSettings s;
  s.key = key;
  s.where = r.loc(f);
  if (f.IsMap()) {
    if (!r.check_map(f, key, {"file", "store", "store_timeout_ms"})) return;
    if (!f["file"]) {
      r.error(f, key, "needs file: the DCF (CiA 306) to write at boot");
      return;
    }
    if (!r.string(f, key, "file", s.file)) return;
    r.scalar(f, key, "store", s.store, false, true);
    r.scalar(f, key, "store_timeout_ms", s.store_timeout_ms, 1u, 600'000u, "ms");
  } else if (!r.string(n, path, "dcf", s.file)) {
    return;
  }
  if (n["eds"]) {
    r.error(f, key, fmt::format("give {} or {}.eds, not both: a DCF is the drive's EDS with its values", key, path));
    return;
  }
  const std::filesystem::path e(s.file);
  d.eds = s.file;
  d.eds_path = e.is_absolute() ? e.string() : (std::filesystem::path(r.file()).parent_path() / e).lexically_normal().string();
  d.eds_key = key;
  d.eds_where = s.where;
  d.dcf = std::move(s);
}

}  // namespace

void drive(Reader& r, const YAML::Node& n, const std::string& path, DriveSettings& d) {
  if (!r.check_map(n, path, {"timeouts", "mode", "pdo", "heartbeat_ms", "master_heartbeat_timeout_ms",
                             "following_error_window", "sdo_writes", "identity", "quick_stop_option", "eds", "sync_watch",
                             "mds_objects", "units", "dcf"}))
    return;
  if (const YAML::Node u = n["units"]) {
    const std::string up = path + ".units";
    std::string v;
    if (r.check_map(u, up, {"velocity"}) && u["velocity"] && r.string(u, up, "velocity", v)) {
      if (const auto code = cia402::units::velocity_unit_code(v)) {
        d.velocity_unit = *code;
        d.units_key = up + ".velocity";
        d.units_where = r.loc(u["velocity"]);
      } else {
        r.error(u["velocity"], up + ".velocity", fmt::format("'{}' is not a velocity unit: inc/s or rpm", v));
      }
    }
  }
  if (std::int16_t q = 0; r.scalar(n, path, "quick_stop_option", q, std::int16_t{-32768}, std::int16_t{8},
                                   "(0x605A: 0 coast, 1/2 ramp then Switch on disabled, 5/6 ramp and stay in Quick stop "
                                   "active, ...; < 0 manufacturer-specific)"))
    d.quick_stop_option = q;
  if (const YAML::Node id = n["identity"]) identity(r, id, path + ".identity", d.identity);
  if (n["master_heartbeat_timeout_ms"]) d.master_heartbeat_timeout_set = true;
  if (n["eds"] && r.string(n, path, "eds", d.eds)) {
    // Relative to the YAML file's folder, like a vendor's EDS shipped beside the configuration.
    const std::filesystem::path e(d.eds);
    d.eds_path = e.is_absolute() ? e.string() : (std::filesystem::path(r.file()).parent_path() / e).lexically_normal().string();
    d.eds_key = path + ".eds";
    d.eds_where = r.loc(n["eds"]);
  }
  if (const YAML::Node f = n["dcf"]) dcf(r, n, f, path, d);
  if (n["timeouts"]) timeouts(r, n["timeouts"], path + ".timeouts", d.timeouts);
  if (r.enumeration(n, path, "mode", d.mode, {{"csp", cia402::Mode::kCsp}, {"ip", cia402::Mode::kInterpolatedPosition}}))
    d.mode_where = r.loc(n["mode"]);
  r.enumeration(n, path, "pdo", d.pdo,
                {{"csp", cia402::PdoProfile::kCsp}, {"csp_csv_cst", cia402::PdoProfile::kCspCsvCst}});
  r.scalar(n, path, "heartbeat_ms", d.heartbeat_ms, std::uint16_t{0}, std::uint16_t{65535}, "ms");
  r.scalar(n, path, "master_heartbeat_timeout_ms", d.master_heartbeat_timeout_ms, std::uint16_t{0},
           std::uint16_t{65535}, "ms");
  r.scalar(n, path, "following_error_window", d.following_error_window, std::uint16_t{0}, std::uint16_t{65535},
           "counts");
  r.scalar(n, path, "sync_watch", d.sync_watch, false, true);
  if (const YAML::Node m = n["mds_objects"]) mds_objects(r, m, path + ".mds_objects", d);
  if (const YAML::Node w = n["sdo_writes"]) {
    if (!w.IsSequence()) {
      r.error(w, path + ".sdo_writes", "must be a list of {index, sub, size, value}");
    } else {
      d.sdo_writes.clear();  // an axis's own list replaces the `drives:` one
      for (std::size_t i = 0; i < w.size(); ++i)
        if (auto s = sdo_write(r, w[i], fmt::format("{}.sdo_writes[{}]", path, i))) d.sdo_writes.push_back(*s);
    }
  }
}

}  // namespace canmotion::config::load
