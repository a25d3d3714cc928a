// The loader's cross-checks: the sections against each other.
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "config/load_sections.hpp"
#include "fieldbus/canopen/bus_budget.hpp"
#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/cia402/drive_pdos.hpp"
#include "motion/planner.hpp"
#include "rt/controller/controller.hpp"
#include "rt/controller/tags.hpp"

namespace canmotion::config::load {

namespace {

/// Names that must be unique among one kind: bus names, and the names of
/// axes, cams, arrays and coordinate systems (one namespace: tags).
class UniqueNames {
 public:
  explicit UniqueNames(Reader& r) : r_(r) {}
  /// Reports `name` (as `key`, at `l`) when already taken; `what` names the kind ("bus", "axis", "tag").
  void operator()(const std::string& name, Location l, const std::string& key, const char* what) {
    if (name.empty()) return;
    auto [it, fresh] = names_.emplace(name, l);
    if (!fresh)
      r_.error_at(l, key, fmt::format("{} name '{}' is already used at line {}", what, name, it->second.line));
  }

 private:
  Reader& r_;
  std::map<std::string, Location> names_;
};

/// A `cams:` or `arrays:` name is a tag (`cam1[0].Status`, `pts[2]`): the
/// runtime's own tag-name rule.
void tag_name_check(Reader& r, const std::string& name, Location where, const std::string& key) {
  if (!name.empty() && !rt::TagTable::is_user_tag_name(name))
    r.error_at(where, key, fmt::format("'{}' is not a tag name (a letter or '_', then letters, digits or '_')", name));
}

/// `arrays:` names (unique among cams, arrays and axes) and the registry
/// capacities (motion::kMaxCamArrays, kMaxCamProfiles, kMaxRealArrays,
/// rt::kMaxRealElements).
void array_checks(Reader& r, const Config& cfg, UniqueNames& unique) {
  using T = ArraySettings::Type;
  std::size_t cams = 0, profiles = cfg.cams.size(), reals = 0, real_elems = 0;
  for (std::size_t i = 0; i < cfg.arrays.size(); ++i) {
    const ArraySettings& a = cfg.arrays[i];
    const std::string key = fmt::format("arrays[{}]", i);
    unique(a.name, a.where, key + ".name", "tag");
    tag_name_check(r, a.name, a.where, key + ".name");
    if (a.type == T::kCam && ++cams == motion::kMaxCamArrays + 1)
      r.error_at(a.where, key, fmt::format("at most {} CAM arrays", motion::kMaxCamArrays));
    if (a.type == T::kCamProfile && ++profiles == motion::kMaxCamProfiles + 1)
      r.error_at(a.where, key, fmt::format("at most {} CAM_PROFILE arrays, `cams:` entries included", motion::kMaxCamProfiles));
    if (a.type == T::kReal) {
      if (++reals == motion::kMaxRealArrays + 1) r.error_at(a.where, key, fmt::format("at most {} REAL arrays", motion::kMaxRealArrays));
      real_elems += a.size;
      if (real_elems > rt::kMaxRealElements && real_elems - a.size <= rt::kMaxRealElements)
        r.error_at(a.where, key + ".size",
                   fmt::format("REAL arrays may hold {} elements together; this one brings the total to {}",
                               rt::kMaxRealElements, real_elems));
    }
  }
}

/// `coordinate_systems:` members name configured axes, once each; the
/// capacity motion::kMaxCoordSystems.
void coordinate_system_checks(Reader& r, const Config& cfg, UniqueNames& unique) {
  std::vector<std::string_view> axis_names;
  for (const auto& a : cfg.axes) axis_names.push_back(a.name);
  for (std::size_t i = 0; i < cfg.coordinate_systems.size(); ++i) {
    const CoordinateSystemSettings& c = cfg.coordinate_systems[i];
    const std::string key = fmt::format("coordinate_systems[{}]", i);
    unique(c.name, c.where, key + ".name", "tag");
    tag_name_check(r, c.name, c.where, key + ".name");
    if (i == motion::kMaxCoordSystems) r.error_at(c.where, key, fmt::format("at most {} coordinate systems", motion::kMaxCoordSystems));
    for (std::size_t k = 0; k < c.axes.size(); ++k) {
      const std::string ak = fmt::format("{}.axes[{}]", key, k);
      if (!cfg.find_axis(c.axes[k])) {
        std::string msg = fmt::format("no axis named '{}'", c.axes[k]);
        if (auto s = nearest(c.axes[k], axis_names)) msg += fmt::format("; did you mean '{}'?", *s);
        else msg += fmt::format("; axes: {}", fmt::join(axis_names, ", "));
        r.error_at(c.axes_where[k], ak, msg);
      }
      for (std::size_t j = 0; j < k; ++j)
        if (c.axes[j] == c.axes[k])
          r.error_at(c.axes_where[k], ak, fmt::format("axis '{}' is already member {}", c.axes[k], j));
    }
  }
}

/// An axis's MDS objects (drives: and its own merged): no two at one
/// address, a record's sub-index 0 not taken while its other sub-indices
/// are, none on a CiA 402 object the master writes, maps or reads, none of
/// another size than the standard object there, and (with direct_control,
/// when they are written) none written by drive.sdo_writes too. Each
/// problem once, at the key that placed the object.
void mds_object_checks(Reader& r, const Config& cfg) {
  std::set<std::string> said;
  for (std::size_t ai = 0; ai < cfg.axes.size(); ++ai) {
    const AxisSettings& a = cfg.axes[ai];
    if (a.axis.type != motion::AxisType::CipDrive) continue;
    const DriveSettings& d = a.drive;
    auto report = [&](std::size_t i, const std::string& msg) {
      if (said.insert(d.mds_object_keys[i] + msg).second) r.error_at(d.mds_object_where[i], d.mds_object_keys[i], msg);
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

/// Names: bus names unique; axis, cam, array and coordinate system names
/// unique among themselves and tag names.
void name_checks(Reader& r, const Config& cfg) {
  UniqueNames buses(r);
  for (std::size_t i = 0; i < cfg.buses.size(); ++i) buses(cfg.buses[i].name, cfg.buses[i].where, fmt::format("buses[{}].name", i), "bus");
  UniqueNames tags(r);
  for (std::size_t i = 0; i < cfg.axes.size(); ++i) tags(cfg.axes[i].name, cfg.axes[i].where, fmt::format("axes[{}].name", i), "axis");
  for (std::size_t i = 0; i < cfg.cams.size(); ++i) {
    const CamSettings& c = cfg.cams[i];
    tags(c.name, c.where, fmt::format("cams[{}].name", i), "tag");
    tag_name_check(r, c.name, c.where, fmt::format("cams[{}].name", i));
  }
  array_checks(r, cfg, tags);
  coordinate_system_checks(r, cfg, tags);
}

/// The COB-IDs in use on one bus and who uses each: a second user is a clash.
class CobIds {
 public:
  explicit CobIds(Reader& r) : r_(r) {}
  void claim(std::uint32_t cob, const std::string& who, Location l, const std::string& key) {
    auto [it, fresh] = owner_.emplace(cob, who);
    if (!fresh) r_.error_at(l, key, fmt::format("COB-ID 0x{:03X} of {} clashes with {}", cob, who, it->second));
  }

 private:
  Reader& r_;
  std::map<std::uint32_t, std::string> owner_;  // COB-ID -> who uses it
};

/// The COB-IDs of CIP axis `ai` (its heartbeat, SDO, EMCY and PDOs) claimed
/// on its bus; returns its traffic for the bus budget.
canopen::NodeTraffic node_traffic(const Config& cfg, std::size_t ai, CobIds& cobs) {
  const AxisSettings& a = cfg.axes[ai];
  const std::string key = fmt::format("axes[{}].node", ai);
  const std::string who = fmt::format("axis '{}' (node {})", a.name, a.node);
  const auto pdos = cia402::default_drive_pdos(a.drive.pdo, a.node, a.drive.mode);
  cobs.claim(canopen::cob::heartbeat(a.node), who + " heartbeat", a.where, key);
  cobs.claim(canopen::cob::sdo_tx(a.node), who + " SDO", a.where, key);
  cobs.claim(canopen::cob::emcy(a.node), who + " EMCY", a.where, key);
  canopen::NodeTraffic t;
  for (std::uint8_t i = 0; i < pdos.rpdo_count; ++i) {
    cobs.claim(pdos.rpdo[i].cob_id, fmt::format("{} RPDO{}", who, pdos.rpdo[i].number), a.where, key);
    t.rpdo_bytes[t.rpdo_count++] = pdos.rpdo[i].size_bytes;
  }
  for (std::uint8_t i = 0; i < pdos.tpdo_count; ++i) {
    cobs.claim(pdos.tpdo[i].cob_id, fmt::format("{} TPDO{}", who, pdos.tpdo[i].number), a.where, key);
    t.tpdo_bytes[t.tpdo_count++] = pdos.tpdo[i].size_bytes;
  }
  t.heartbeat_ms = a.drive.heartbeat_ms;
  return t;
}

/// CIP axis `ai` on `bus`: its drive's watch of the master's heartbeat
/// against the master's, and no sdo_writes to 0x60C2 other than the period's.
void axis_on_bus_checks(Reader& r, const Config& cfg, const BusSettings& bus, std::size_t ai,
                        const std::optional<InterpolationPeriod>& ip) {
  const AxisSettings& a = cfg.axes[ai];
  if (a.drive.master_heartbeat_timeout_ms > 0 && bus.master_heartbeat_ms == 0)
    r.error_at(a.where, fmt::format("axes[{}].drive.master_heartbeat_timeout_ms", ai),
               fmt::format("the drive watches the master's heartbeat but bus '{}' has master_heartbeat_ms: 0", bus.name));
  if (a.drive.master_heartbeat_timeout_ms > 0 && a.drive.master_heartbeat_timeout_ms <= bus.master_heartbeat_ms)
    r.error_at(a.where, fmt::format("axes[{}].drive.master_heartbeat_timeout_ms", ai),
               fmt::format("{} ms must exceed the master's heartbeat period {} ms (CiA 301: consumer time > producer time)",
                           a.drive.master_heartbeat_timeout_ms, bus.master_heartbeat_ms));
  // drive.mode: ip streams positions only: MDS (CSV/CST) switches from CSP
  // and back, which an IP drive's RPDO (0x60C1:1, no 0x607A) cannot carry.
  if (a.drive.mode == cia402::Mode::kInterpolatedPosition && a.direct.present)
    r.error_at(a.drive.mode_where.line > 0 ? a.drive.mode_where : a.where, fmt::format("axes[{}].drive.mode", ai),
               fmt::format("'ip' (interpolated position, 0x6060 = 7) cannot be used with axes[{}].direct_control (MDS "
                           "runs the drive in CSV/CST and switches back to CSP): use mode csp or remove direct_control",
                           ai));
  for (std::size_t wi = 0; wi < a.drive.sdo_writes.size(); ++wi) {
    const SdoWrite& w = a.drive.sdo_writes[wi];
    if (w.index != 0x60C2 || !ip) continue;
    const bool mant = w.sub == 1 && w.value != ip->mantissa;
    const bool expo = w.sub == 2 && w.value != ip->exponent;
    if (mant || expo)
      r.error_at(w.where, fmt::format("axes[{}].drive.sdo_writes[{}]", ai, wi),
                 fmt::format("0x60C2:{:02X} = {} contradicts the controller period {} ms (0x60C2 = {} x 10^{} s, "
                             "written automatically; remove this write)",
                             w.sub, w.value, cfg.controller.period_ms(), ip->mantissa, ip->exponent));
  }
}

/// The worst-case load of bus `bi` with `traffic`: an error over 100 %, a warning over 70 %.
void budget_check(Reader& r, const Config& cfg, std::size_t bi, const std::vector<canopen::NodeTraffic>& traffic) {
  const BusSettings& bus = cfg.buses[bi];
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
    r.error_at(bus.where, fmt::format("buses[{}]", bi),
               msg + "; over 100 % cannot work: lengthen the period, raise the bitrate or move axes to another bus");
  else if (b.load_percent > 70.0)
    r.warning_at(bus.where, fmt::format("buses[{}]", bi), msg + "; over 70 % leaves little room for SDO and EMCY");
}

/// Bus `bi`: the axes on it, their COB-IDs, heartbeats and 0x60C2 writes, the budget.
void bus_checks(Reader& r, const Config& cfg, std::size_t bi, const std::optional<InterpolationPeriod>& ip) {
  const BusSettings& bus = cfg.buses[bi];
  CobIds cobs(r);
  if (bus.master_heartbeat_ms > 0)
    cobs.claim(canopen::cob::heartbeat(bus.master_node), fmt::format("the master's heartbeat (node {})", bus.master_node),
               bus.where, fmt::format("buses[{}].master_node", bi));
  std::vector<canopen::NodeTraffic> traffic;
  for (std::size_t ai = 0; ai < cfg.axes.size(); ++ai) {
    const AxisSettings& a = cfg.axes[ai];
    if (a.axis.type != motion::AxisType::CipDrive || a.bus != bus.name || a.node == 0) continue;
    traffic.push_back(node_traffic(cfg, ai, cobs));
    axis_on_bus_checks(r, cfg, bus, ai, ip);
  }
  budget_check(r, cfg, bi, traffic);
}

/// Each CIP axis names a configured bus, and a node id free on it.
void node_checks(Reader& r, const Config& cfg) {
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
      r.error_at(a.where, fmt::format("axes[{}].bus", ai), msg);
      continue;
    }
    auto [it, fresh] = nodes.emplace(std::make_pair(a.bus, static_cast<int>(a.node)), ai);
    if (!fresh)
      r.error_at(a.where, fmt::format("axes[{}].node", ai),
                 fmt::format("node {} on bus '{}' is already axis '{}'", a.node, a.bus, cfg.axes[it->second].name));
  }
}

}  // namespace

void cross_check(Reader& r, const Config& cfg) {
  name_checks(r, cfg);
  mds_object_checks(r, cfg);
  const auto ip = interpolation_period(cfg.controller.period_s);
  if (!ip)
    r.error_at(cfg.controller.where, "controller.period_ms",
               fmt::format("{} ms cannot be written to 0x60C2 (mantissa 1..255 x 10^exponent); use e.g. 0.5, 1, 2 or 4",
                           cfg.controller.period_ms()));
  for (std::size_t bi = 0; bi < cfg.buses.size(); ++bi) bus_checks(r, cfg, bi, ip);
  node_checks(r, cfg);
}

}  // namespace canmotion::config::load
