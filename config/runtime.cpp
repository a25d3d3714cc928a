#include "config/runtime.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/cia402/units.hpp"
#include "fieldbus/emulator/eds_dictionary.hpp"

namespace canmotion::config {

namespace {

/// An SDO write of index:sub (value 0) whose size is that of the object's data
/// type in the one object table (canopen::known_objects()). consteval: an object
/// missing from the table, or not expedited (1 .. 4 bytes), does not compile.
/// (A loop over the table rather than object_info(): GCC 12 with UBSan does
/// not accept comparing the pointer object_info() returns with nullptr in a
/// constant expression.)
consteval cia402::SdoWrite od_write(std::uint16_t index, std::uint8_t sub) {
  for (const canopen::ObjectInfo& o : canopen::known_objects()) {
    if (index < o.index_first || index > o.index_last || sub < o.sub_first || sub > o.sub_last) continue;
    const std::size_t size = canopen::data_type_size(o.type);
    if (size == 0 || size > 4) throw "not an expedited SDO object";
    return {index, sub, static_cast<std::uint8_t>(size), 0};
  }
  throw "object not in canopen::known_objects()";
}

/// A `cams:` entry's points or a CAM array's values as the motion library's
/// CAM elements (segment type 0 linear, 1 cubic).
std::vector<motion::cam::CamPoint> motion_points(const std::vector<CamPoint>& points) {
  std::vector<motion::cam::CamPoint> out;
  out.reserve(points.size());
  for (const CamPoint& p : points)
    out.push_back({p.master, p.slave, p.cubic ? motion::cam::kSegmentCubic : motion::cam::kSegmentLinear});
  return out;
}

}  // namespace

namespace {
/// direct_control_writes() with the `direct_control:` key behind each write
/// (relative to the axis, e.g. "direct_control.ramp.velocity_positive"), and
/// for an MDS object placed by `drive.mds_objects` that key too.
struct KeyedWrite {
  cia402::SdoWrite write;
  std::string key;
};
std::vector<KeyedWrite> keyed_direct_control_writes(const AxisSettings& a) {
  std::vector<KeyedWrite> w;
  w.reserve(8);  // at most 8 writes: 0x6083, 0x6084 and the six MDS objects
  const DirectControlSettings& d = a.direct;
  if (!d.present || a.axis.type != motion::AxisType::CipDrive) return w;
  namespace obj = cia402::obj;
  using cia402::MdsObject;
  // In the drive's units (README "Drive units"); a unit that cannot be known
  // refuses the configuration (check_drive_descriptions): 0 then.
  // Units read at boot (`units_at_boot`): the value in counts, which the
  // drive proxy writes in the unit it read (SdoWrite::per).
  const double conv = a.axis.conversion_constant;
  const bool at_boot = a.drive.units_at_boot;
  const double vel = at_boot ? conv : a.drive.velocity_counts ? conv / *a.drive.velocity_counts : 0.0;
  const double acc = at_boot ? conv : a.drive.acceleration_counts ? conv / *a.drive.acceleration_counts : 0.0;
  using Per = cia402::SdoWrite::Per;
  struct Value {
    std::uint32_t value;
    Per per;
    double counts;
  };
  auto in_units = [&](double v, double f, Per per) {
    return Value{static_cast<std::uint32_t>(std::llround(v * f)), at_boot ? per : Per::kNone, v * conv};
  };
  auto velocity = [&](double v) { return in_units(v, vel, Per::kVelocity); };
  auto acceleration = [&](double v) { return in_units(v, acc, Per::kAcceleration); };
  auto plain = [](std::uint32_t v) { return Value{v, Per::kNone, 0.0}; };
  auto standard = [&](cia402::SdoWrite x, Value v, const char* key) {
    x.value = v.value;
    x.per = v.per;
    x.counts = v.counts;
    w.push_back(KeyedWrite{x, std::string(key)});
  };
  // An object CiA 402 lacks, where this drive keeps it (drive.mds_objects).
  auto mds = [&](MdsObject o, Value v, const char* key) {
    if (a.drive.mds_not_in_eds[static_cast<std::size_t>(o)]) return;  // another object there (check_mds_objects_in_eds)
    const cia402::ObjectAddress at = a.drive.mds_objects[o];
    const std::string& placed = a.drive.mds_object_keys[static_cast<std::size_t>(o)];
    std::string k = key;
    if (!placed.empty()) k += fmt::format(" (written to 0x{:04X}:{}, placed by {})", at.index, at.sub, placed);
    cia402::SdoWrite x{at.index, at.sub, cia402::info(o).size, v.value};
    x.per = v.per;
    x.counts = v.counts;
    w.push_back(KeyedWrite{x, std::move(k)});
  };
  if (d.ramp_acceleration)
    standard(od_write(obj::kProfileAcceleration, 0), acceleration(*d.ramp_acceleration), "direct_control.ramp.acceleration");
  if (d.ramp_deceleration)
    standard(od_write(obj::kProfileDeceleration, 0), acceleration(*d.ramp_deceleration), "direct_control.ramp.deceleration");
  if (d.ramp_velocity_positive)
    mds(MdsObject::kRampVelocityPositive, velocity(*d.ramp_velocity_positive), "direct_control.ramp.velocity_positive");
  if (d.ramp_velocity_negative)
    mds(MdsObject::kRampVelocityNegative, velocity(*d.ramp_velocity_negative), "direct_control.ramp.velocity_negative");
  if (d.ramp_jerk_control) mds(MdsObject::kRampJerkControl, plain(*d.ramp_jerk_control), "direct_control.ramp.jerk_control");
  // The SLAT objects are vendor-area (cia402.hpp): written always, so that a
  // drive keeps no SLAT from an earlier configuration, but without `slat:`
  // in the file (SLAT disabled) a drive that lacks them is fine (it has no
  // SLAT): optional, said once at boot. The ramp objects above are written
  // only when their key is set, and then a drive without them fails its boot
  // naming the key: MDS is validated only if the drive supports the ramp
  // attributes the configuration asks for [seed 002].
  const std::size_t slat_first = w.size();
  mds(MdsObject::kSlatConfiguration, plain(d.slat_configuration), "direct_control.slat.configuration");
  mds(MdsObject::kSlatSetPoint, velocity(d.slat_set_point), "direct_control.slat.set_point");
  mds(MdsObject::kSlatTimeDelay, plain(d.slat_time_delay_ms), "direct_control.slat.time_delay_ms");
  for (std::size_t i = slat_first; i < w.size(); ++i) w[i].write.optional = !d.slat_set;
  return w;
}
}  // namespace

std::vector<cia402::SdoWrite> direct_control_writes(const AxisSettings& a) {
  std::vector<cia402::SdoWrite> w;
  for (const KeyedWrite& k : keyed_direct_control_writes(a)) w.push_back(k.write);
  return w;
}

double drive_wait_limit_s(const DriveTimeouts& t) noexcept {
  if (t.wait_ms > 0) return static_cast<double>(t.wait_ms) / 1e3;
  return (3.0 * t.boot_ms + t.mode_switch_ms + 4.0 * t.transition_ms) / 1e3;
}

/// A typed sdo_writes value: its bytes kept by the DriveConfig (shared by
/// its copies), the write referencing them (no copy at boot).
static void reference_typed_bytes(const std::vector<std::uint8_t>& bytes, cia402::SdoWrite& x, cia402::DriveConfig& d) {
  d.value_storage.push_back(std::make_shared<const std::vector<std::uint8_t>>(bytes));
  x.data = d.value_storage.back()->data();
  x.data_len = static_cast<std::uint32_t>(bytes.size());
  x.value = 0;
  for (std::size_t b = 0; b < bytes.size() && b < 4; ++b) x.value |= static_cast<std::uint32_t>(bytes[b]) << (8 * b);
}

namespace {
/// `drive.dcf` (README "DCF download"): its values first among the extra
/// writes (`store` false), left out at boot when 0x1020 shows the drive
/// holds them; its store last, after every write (`store` true).
void dcf_writes(const DriveSettings& ds, cia402::DriveConfig& d, bool store) {
  const DcfSettings& dcf = ds.dcf;
  if (dcf.file.empty()) return;
  if (store) {
    if (!dcf.store) return;
    cia402::SdoWrite w{0x1010, 1, 4, 0x65766173u};  // 0x1010:1 store parameters: "save" (CiA 301)
    w.dcf = true;
    w.timeout_ns = static_cast<std::int64_t>(dcf.store_timeout_ms) * 1'000'000;
    d.extra_writes.push_back(w);
    d.hints.extra.push_back(fmt::format("{}.store", dcf.key));
    return;
  }
  for (const DcfValue& v : dcf.writes) {
    cia402::SdoWrite w{v.index, v.sub, v.size, v.value};
    w.dcf = true;
    if (!v.bytes.empty()) reference_typed_bytes(v.bytes, w, d);
    d.extra_writes.push_back(w);
    d.hints.extra.push_back(fmt::format("{} ({}:{})", dcf.key, ds.eds, v.line));
  }
  if (dcf.dated) {
    d.dcf_dated = true;
    d.dcf_date = dcf.date;
    d.dcf_time = dcf.time;
    d.hints.dcf = dcf.key;
  }
}
/// Drive units (README "Drive units"): as the file tells them, or read at
/// boot; what needs them, named in a boot failure.
void drive_units_config(const AxisSettings& a, const std::string& axis, cia402::DriveConfig& d) {
  // `units.velocity` is written before that read and any value in it.
  d.units.read_at_boot = a.drive.units_at_boot;
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  d.units.velocity_counts = a.drive.units_at_boot ? 1.0 : a.drive.velocity_counts.value_or(unknown);
  d.units.acceleration_counts = a.drive.units_at_boot ? 1.0 : a.drive.acceleration_counts.value_or(unknown);
  if (a.drive.velocity_unit) {
    d.units.has_write_velocity = true;
    d.units.write_velocity = *a.drive.velocity_unit;
    d.hints.velocity_unit = fmt::format("{} (line {}; needs a writable 0x60A9)", a.drive.units_key, a.drive.units_where.line);
  }
  auto need = [](std::string& to, const std::string& what) { to += (to.empty() ? "" : " and ") + what; };
  if (a.direct.present) {
    const bool torque = a.axis.direct_mode == motion::AxisConfig::DirectMode::Torque;
    need(d.units.velocity_needed_by, fmt::format("{}.direct_control (MDS in {})", axis, torque ? "CST" : "CSV"));
    if (a.direct.ramp_acceleration || a.direct.ramp_deceleration)
      need(d.units.acceleration_needed_by, fmt::format("{}.direct_control.ramp (0x6083/0x6084)", axis));
  }
  if (a.axis.homing.mode == motion::HomingConfig::Mode::Active &&
      a.axis.homing.sequence != motion::HomingConfig::Sequence::Immediate) {
    need(d.units.velocity_needed_by, fmt::format("{}.homing (speeds, 0x6099)", axis));
    need(d.units.acceleration_needed_by, fmt::format("{}.homing (acceleration, 0x609A)", axis));
  }
}

void identity_config(const DriveIdentitySettings& id, cia402::DriveIdentity& out) {
  out.has_device_type = id.device_type.has_value();
  out.device_type = id.device_type.value_or(0);
  out.has_vendor_id = id.vendor_id.has_value();
  out.vendor_id = id.vendor_id.value_or(0);
  out.has_product_code = id.product_code.has_value();
  out.product_code = id.product_code.value_or(0);
  out.has_revision = id.revision.has_value();
  out.revision = id.revision.value_or(0);
}
}  // namespace

cia402::DriveConfig drive_config(const AxisSettings& a, const BusSettings& bus, double period_s, std::size_t axis_index) {
  cia402::DriveConfig d;
  const std::string axis = fmt::format("axes[{}]", axis_index);
  // Keys under `drive:` may also come from the `drives:` defaults.
  auto drive_key = [&](std::string_view k) { return fmt::format("{}.drive.{} (or drives.{})", axis, k, k); };
  d.hints.interpolation_period = "controller.period_ms";
  d.hints.pdo = drive_key("pdo");
  d.hints.producer_heartbeat = drive_key("heartbeat_ms");
  d.hints.consumer_heartbeat = drive_key("master_heartbeat_timeout_ms");
  d.hints.identity = fmt::format("{}.drive.identity", axis);
  d.hints.mode_switch_timeout = drive_key("timeouts.mode_switch_ms");
  d.hints.sync_watch = drive_key("sync_watch");
  d.hints.sync_counter = fmt::format("buses[].sync_counter_overflow of bus '{}' (line {})", bus.name, bus.where.line);
  d.sync_watch = a.drive.sync_watch;
  identity_config(a.drive.identity, d.identity);
  // Modes the axis may switch to besides CSP: checked against 0x6502 at boot.
  if (a.direct.present) {
    const bool torque = a.axis.direct_mode == motion::AxisConfig::DirectMode::Torque;
    d.needed_modes.push_back({torque ? cia402::Mode::kCst : cia402::Mode::kCsv,
                              fmt::format("{}.direct_control.mode: {} (MDS)", axis, torque ? "torque" : "velocity")});
  }
  if (a.axis.homing.mode == motion::HomingConfig::Mode::Active &&
      a.axis.homing.sequence != motion::HomingConfig::Sequence::Immediate)
    d.needed_modes.push_back({cia402::Mode::kHoming, fmt::format("{}.homing.sequence (MAH homes on the drive, mode 6)", axis)});
  d.node = a.node;
  d.mode = a.drive.mode;  // csp, or ip (drive.mode: ip): the position stream's mode
  d.hints.mode = fmt::format("{}.drive.mode: {} (or drives.mode)", axis,
                             d.mode == cia402::Mode::kInterpolatedPosition ? "ip" : "csp");
  d.cycle_ns = period_ns(period_s);
  d.pdo_profile = a.drive.pdo;
  d.producer_heartbeat_ms = a.drive.heartbeat_ms;
  d.consumer_heartbeat_ms = bus.master_heartbeat_ms > 0 ? a.drive.master_heartbeat_timeout_ms : 0;
  // 0x1016 is optional (CiA 301): required only when the file sets
  // master_heartbeat_timeout_ms; from the default, a drive whose EDS lacks it
  // is not asked (and the controller does not disarm it at the end).
  d.consumer_heartbeat_optional = !a.drive.master_heartbeat_timeout_set;
  d.dictionary = a.drive.dictionary;
  if (d.consumer_heartbeat_optional && d.dictionary && d.dictionary->has(0x1016, 1) == canopen::Presence::kAbsent)
    d.consumer_heartbeat_ms = 0;
  d.boot_timeout_ns = static_cast<std::int64_t>(a.drive.timeouts.boot_ms) * 1'000'000;
  d.start_timeout_ns = d.boot_timeout_ns;
  d.sdo_timeout_ns = static_cast<std::int64_t>(a.drive.timeouts.sdo_ms) * 1'000'000;
  d.transition_timeout_ns = static_cast<std::int64_t>(a.drive.timeouts.transition_ms) * 1'000'000;
  if (a.drive.following_error_window > 0) {
    cia402::SdoWrite w = od_write(cia402::obj::kFollowingErrorWindow, 0);
    w.value = a.drive.following_error_window;
    d.extra_writes.push_back(w);
    d.hints.extra.push_back(drive_key("following_error_window") + " (0 leaves it out)");
  }
  if (a.drive.quick_stop_option) {
    cia402::SdoWrite w = od_write(cia402::obj::kQuickStopOptionCode, 0);
    w.value = static_cast<std::uint16_t>(*a.drive.quick_stop_option);
    d.extra_writes.push_back(w);
    d.hints.extra.push_back(drive_key("quick_stop_option") + " (leave it out to keep the drive's own)");
  }
  d.mode_switch_timeout_ns = static_cast<std::int64_t>(a.drive.timeouts.mode_switch_ms) * 1'000'000;
  d.homing_timeout_ns = static_cast<std::int64_t>(a.drive.timeouts.homing_ms) * 1'000'000;
  drive_units_config(a, axis, d);
  dcf_writes(a.drive, d, false);
  for (const KeyedWrite& k : keyed_direct_control_writes(a)) {
    d.extra_writes.push_back(k.write);
    d.hints.extra.push_back(fmt::format("{}.{}", axis, k.key));
  }
  for (std::size_t i = 0; i < a.drive.sdo_writes.size(); ++i) {
    const SdoWrite& w = a.drive.sdo_writes[i];
    d.extra_writes.push_back({w.index, w.sub, w.size, static_cast<std::uint32_t>(static_cast<std::int64_t>(w.value))});
    if (!w.bytes.empty()) reference_typed_bytes(w.bytes, d.extra_writes.back(), d);
    d.hints.extra.push_back(fmt::format("{}.drive.sdo_writes[{}] (line {})", axis, i, w.where.line));
  }
  dcf_writes(a.drive, d, true);
  return d;
}

emulator::EmulatorConfig emulator_config(const AxisSettings& a) {
  emulator::EmulatorConfig e;
  e.node = a.node;
  e.behaviour = emulator::EmulatorBehaviour::strict();  // --sim drives behave like real ones (README "Emulator profiles")
  // The simulated drive lacks the optional objects (EmulatorBehaviour::
  // optional_objects_absent) except those the configuration asks for: 0x1016
  // when the file sets master_heartbeat_timeout_ms, the MDS objects (where
  // drive.mds_objects puts them) with `direct_control:`. Those a real drive
  // must have (its boot fails naming the key otherwise).
  e.behaviour.optional_objects_absent = false;
  e.mds_objects = a.drive.mds_objects;
  if (!(a.drive.master_heartbeat_timeout_set && a.drive.master_heartbeat_timeout_ms > 0)) e.absent_objects.push_back(0x1016);
  if (!a.direct.present)
    for (const cia402::ObjectAddress& at : a.drive.mds_objects.at)
      if (std::find(e.absent_objects.begin(), e.absent_objects.end(), at.index) == e.absent_objects.end())
        e.absent_objects.push_back(at.index);
  const double conv = a.axis.conversion_constant;
  // Give the model headroom over the axis's own limits, so that the emulated
  // drive follows any profile the planner may command.
  e.max_velocity = std::max(e.max_velocity, 2.0 * a.axis.max_speed * conv);
  e.max_acceleration = std::max(e.max_acceleration, 4.0 * std::max(a.axis.max_accel, a.axis.max_decel) * conv);
  if (a.drive.following_error_window > 0) e.following_error_window = a.drive.following_error_window;
  // A drive with an EDS is emulated with exactly its objects (as cia402-emu --eds).
  if (a.drive.eds_data) e.served = emulator::served_objects(*a.drive.eds_data, a.node);
  return e;
}

namespace {

/// A `buses:` entry as the controller sees it, without its transport.
rt::BusSpec bus_spec(const BusSettings& b) {
  rt::BusSpec bs;
  bs.name = b.name;
  bs.network.master.node_id = b.master_node;
  bs.network.master.heartbeat_period_ms = b.master_heartbeat_ms;
  bs.network.master.sync_counter_overflow = b.sync_counter_overflow;
  return bs;
}

/// An `axes:` entry (the `index`th): its planner configuration, and for a
/// CIP axis its bus (an index into cfg.buses) and drive configuration.
rt::AxisSpec axis_spec(const Config& cfg, const AxisSettings& a, std::size_t index) {
  rt::AxisSpec as;
  as.name = a.name;
  as.config = a.axis;
  if (a.axis.type != motion::AxisType::CipDrive) return as;
  std::size_t bi = 0;
  while (bi < cfg.buses.size() && cfg.buses[bi].name != a.bus) ++bi;
  as.bus = static_cast<int>(bi);
  as.drive = drive_config(a, cfg.buses[bi], cfg.controller.period_s, index);
  as.config.drive_wait_limit = drive_wait_limit_s(a.drive.timeouts);
  return as;
}

rt::CamSpec cam_spec(const CamSettings& c) {
  rt::CamSpec cs;
  cs.name = c.name;
  cs.start_slope = c.start_slope;
  cs.end_slope = c.end_slope;
  cs.points = motion_points(c.points);
  return cs;
}

rt::ArraySpec array_spec(const ArraySettings& a) {
  rt::ArraySpec as;
  as.name = a.name;
  as.size = a.size;
  as.type = a.type == ArraySettings::Type::kCam          ? rt::ArraySpec::Type::kCam
            : a.type == ArraySettings::Type::kCamProfile ? rt::ArraySpec::Type::kCamProfile
                                                         : rt::ArraySpec::Type::kReal;
  as.cam_values = motion_points(a.cam_values);
  as.real_values = a.real_values;
  return as;
}

/// A `coordinate_systems:` entry, its members named by their index in `axes`.
rt::CoordSystemSpec coordinate_system_spec(const CoordinateSystemSettings& c, const std::vector<rt::AxisSpec>& axes) {
  rt::CoordSystemSpec cs;
  cs.name = c.name;
  motion::CoordSystemConfig& m = cs.config;
  m.dim = static_cast<int>(c.axes.size());
  for (std::size_t k = 0; k < c.axes.size(); ++k) {
    for (std::size_t a = 0; a < axes.size(); ++a)
      if (axes[a].name == c.axes[k]) m.axes[k] = static_cast<motion::AxisId>(a);
    if (k < c.conversion_ratios.size()) m.ratio[k] = c.conversion_ratios[k];
  }
  m.max_speed = c.max_speed;
  m.max_accel = c.max_accel;
  m.max_decel = c.max_decel;
  m.max_accel_jerk = c.max_accel_jerk;
  m.max_decel_jerk = c.max_decel_jerk;
  m.actual_tolerance = c.actual_position_tolerance;
  m.command_tolerance = c.command_position_tolerance;
  return cs;
}

}  // namespace

RuntimeSpec build_spec(const Config& cfg, bool force_sim) {
  RuntimeSpec r;
  rt::ControllerSpec& spec = r.controller;
  spec.period_ns = cfg.controller.period_ns();
  spec.sync_first = cfg.controller.sync_first;
  // The simulated buses' indices in the SimWorld (added in order), per bus.
  std::vector<std::size_t> sim_index(cfg.buses.size(), 0);
  std::size_t sim_buses = 0;
  for (std::size_t bi = 0; bi < cfg.buses.size(); ++bi) {
    const BusSettings& b = cfg.buses[bi];
    rt::BusSpec bs = bus_spec(b);
    if (force_sim || b.is_sim()) {
      if (!r.sim) r.sim = std::make_unique<rt::SimWorld>();
      bs.transport = &r.sim->add_bus(b.name);
      sim_index[bi] = sim_buses++;
      r.trace_names.push_back(b.name);
    } else {
      r.trace_names.push_back(b.interface);  // transport left null: a SocketCAN bus is opened by its user
    }
    spec.buses.push_back(bs);
  }
  for (const AxisSettings& a : cfg.axes) {
    spec.axes.push_back(axis_spec(cfg, a, spec.axes.size()));
    const int bi = spec.axes.back().bus;
    if (bi >= 0 && spec.buses[static_cast<std::size_t>(bi)].transport != nullptr)
      r.sim->add_drive(sim_index[static_cast<std::size_t>(bi)], emulator_config(a));
  }
  for (const CamSettings& c : cfg.cams) spec.cams.push_back(cam_spec(c));
  for (const ArraySettings& a : cfg.arrays) spec.arrays.push_back(array_spec(a));
  for (const CoordinateSystemSettings& c : cfg.coordinate_systems)
    spec.coordinate_systems.push_back(coordinate_system_spec(c, spec.axes));
  return r;
}

Runtime build_runtime(const Config& cfg, RuntimeSpec spec, std::vector<std::unique_ptr<can::SocketCanBus>> sockets) {
  for (const rt::BusSpec& b : spec.controller.buses)
    if (b.transport == nullptr)
      throw std::logic_error(fmt::format("{}: bus '{}' has no transport: open its SocketCAN interface first", cfg.path, b.name));
  Runtime rt;
  rt.sockets = std::move(sockets);
  rt.sim = std::move(spec.sim);
  rt.trace_names = std::move(spec.trace_names);
  try {
    rt.controller = std::make_unique<rt::Controller>(std::move(spec.controller));
  } catch (const std::invalid_argument& e) {
    // e.g. a cam whose MCCP fails: name the file (the message names the cam).
    throw std::runtime_error(fmt::format("{}: {}", cfg.path, e.what()));
  }
  return rt;
}

Runtime simulated_runtime(const Config& cfg) { return build_runtime(cfg, build_spec(cfg, true)); }

std::vector<Diagnostic> startup_warnings(const Config& cfg) {
  std::vector<Diagnostic> w;
  for (std::size_t i = 0; i < cfg.axes.size(); ++i) {
    const AxisSettings& a = cfg.axes[i];
    if (a.axis.type != motion::AxisType::CipDrive || a.axis.position_error_tolerance > 0) continue;
    Diagnostic d;
    d.severity = Diagnostic::Severity::kWarning;
    d.file = cfg.path;
    d.where = a.where;
    d.key = fmt::format("axes[{}].position_error_tolerance", i);
    const std::string window =
        a.drive.following_error_window > 0
            ? fmt::format("{} counts, set by drive.following_error_window", a.drive.following_error_window)
            : std::string("the drive's own value: drive.following_error_window is not set");
    d.message = fmt::format(
        "axis '{}' (AXIS_CIP_DRIVE) has no position_error_tolerance: the master does not check its position error, "
        "and the drive's own 0x6065 following error window ({}) is then its only guard",
        a.name, window);
    w.push_back(std::move(d));
  }
  return w;
}

}  // namespace canmotion::config
