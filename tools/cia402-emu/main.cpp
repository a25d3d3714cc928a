// cia402-emu: one or more emulated CiA 402 servo drives on a SocketCAN
// interface. Argument parsing and I/O only; the drive is
// canmotion::emulator::Emulator.
#include <poll.h>
#include <signal.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldbus/can/socketcan_bus.hpp"
#include "fieldbus/canopen/frame_sink.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/eds/eds.hpp"
#include "fieldbus/emulator/eds_dictionary.hpp"
#include "fieldbus/emulator/emulator.hpp"

using namespace canmotion;

namespace {
volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

constexpr const char* kFooter = R"(Examples:
  cia402-emu --interface vcan0 --node 2
      one drive, node 2, on vcan0 (boot-up 0x702 is sent at start)
  cia402-emu -i vcan0 -n 2 -n 3 -n 4 --lag 3
      three drives whose position lags the target by 3 SYNCs
  cia402-emu -i vcan0 -n 2 --fail-after 5000 --fail-code 0x2310
      node 2 faults (EMCY 0x2310) at the 5000th SYNC
  cansend vcan0 602#4000100000000000
      (from another shell) SDO upload of 0x1000 from node 2: reply 582#4300100092010200
  cansend vcan0 602#2B00200011860000
      inject a following-error fault (EMCY 0x8611) through object 0x2000
  cia402-emu -i vcan0 -n 2 --viscous-friction 0.01 --rated-torque-acceleration 1000000
      CST with a load: torque accelerates against friction (SLAT 0x2020..0x2022)
  cia402-emu -i vcan0 -n 2 --mds-objects ramp_velocity_positive=0x3000:1,slat_set_point=0x3011
      MDS objects at the drive's own indices (the others at their defaults, 0x2010:2,
      0x2011, 0x2020, 0x2022; nothing at 0x2010:1 or 0x2021): as canmotiond's drive.mds_objects
  cia402-emu -i vcan0 -n 2 --refuse-mode-switch
      0x6061 never follows 0x6060: the master's mode-switch timeout fires
  cia402-emu -i vcan0 -n 2 --without-object 0x1016 --without-object 0x1403 --without-object 0x1603
      a drive without the optional 0x1016 and without RPDO4 (SDO aborts 0x06020000)
  cia402-emu -i vcan0 -n 2 --eds config/examples/minimal-drive.eds
      a drive with exactly the objects of that EDS (no 0x1016, 2 RPDOs, 2 TPDOs),
      its PDO mapping flags, access types and defaults
  cia402-emu -i vcan0 -n 2 --profile permissive
      the lenient drive: every object, instant boot, same-call SDO replies
  cia402-emu -i vcan0 -n 2 --boot-ms 2000 --sdo-delay-ms 5 --no-remote
      strict, 2 s of DC bus charging, SDO replies 5 ms late, local control

Profiles (--profile; a flag changes one behaviour of the profile):
  strict      (default) what a real drive does: 0x1016 and the MDS objects absent
              (--optional-objects-absent), 0x60C2:2 read-only (--ip-index-ro), PDO
              changes only in Pre-operational (--remap-preop-only), CiA 402
              predefined PDO1 = controlword/statusword, type 255
              (--cia402-pdos), over-long RPDO EMCY 8220h (--long-rpdo-emcy),
              SYNC length checked against 0x1019, EMCY 8240h, 0x1019 written
              only while 0x1006 is 0 (--sync-length), SYNC watched at 1.5 x
              0x1006 when it is not 0, EMCY 8100h (--sync-timeout),
              0x1029 error behaviour (--error-behaviour), 100 ms in Not ready
              to switch on (--boot-ms), SDO replies a call later
              (--sdo-delay-ms), one transition per SYNC (--one-transition),
              fault cause lasts 20 SYNCs (--fault-cause-syncs), 0x6061 follows
              0x6060 2 SYNCs later (--mode-switch-syncs), modes outside 0x6502
              refused (--refuse-unsupported-modes), homing moves per method
              (--homing-model)
  permissive  none of the above (each flag's off/0 value)
Both: TPDO types 0/1..240/254/255 and RPDO 254/255 per CiA 301, EMCY 8210h
once with error register bits 0 and 4, 0000h when it clears.

The drive waits in NMT pre-operational until a master configures it over SDO
and starts it (NMT 0x000 01 <node>). It sends its TPDOs per their transmission
type (0x18xx:2) and moves only on SYNC (0x080), by the period in 0x60C2. Object dictionary, PDO
mapping and fault injection: see fieldbus/README.md.

Exit status: 0 after SIGINT/SIGTERM or --duration, 1 on error.)";

/// --mds-objects KEY=INDEX[:SUB][,KEY=INDEX[:SUB]...] (keys of
/// cia402::kMdsObjectInfo) applied to `m`; an error message, or empty.
std::string parse_mds_objects(const std::string& arg, cia402::MdsObjects& m) {
  std::size_t from = 0;
  while (from <= arg.size()) {
    const std::size_t comma = std::min(arg.find(',', from), arg.size());
    const std::string item = arg.substr(from, comma - from);
    from = comma + 1;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) return "'" + item + "' is not KEY=INDEX:SUB (e.g. slat_set_point=0x3011:0)";
    const std::string k = item.substr(0, eq);
    std::size_t i = 0;
    while (i < cia402::kMdsObjectCount && cia402::kMdsObjectInfo[i].key != k) ++i;
    if (i == cia402::kMdsObjectCount) {
      std::string keys;
      for (const auto& info : cia402::kMdsObjectInfo) keys += (keys.empty() ? "" : ", ") + std::string(info.key);
      return "unknown MDS object '" + k + "' (one of: " + keys + ")";
    }
    const auto a = cia402::parse_object_address(item.substr(eq + 1));
    if (!a || a->index < 0x2000 || a->index > 0x9FFF)
      return "'" + item.substr(eq + 1) + "' is not an object INDEX:SUB in 0x2000..0x9FFF (sub-index 0..254)";
    m.at[i] = *a;
  }
  for (std::size_t i = 0; i < cia402::kMdsObjectCount; ++i)
    for (std::size_t j = i + 1; j < cia402::kMdsObjectCount; ++j)
      if (m.at[i] == m.at[j])
        return std::string(cia402::kMdsObjectInfo[i].key) + " and " + std::string(cia402::kMdsObjectInfo[j].key) +
               " are both at the same object";
  return {};
}

/// A whole string as an unsigned number (decimal, 0x hex or 0 octal); nullopt
/// if it is not one.
std::optional<unsigned long> parse_unsigned(const std::string& s) {
  std::size_t pos = 0;
  unsigned long v = 0;
  try {
    v = std::stoul(s, &pos, 0);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (pos != s.size() || s.empty() || s[0] == '-') return std::nullopt;
  return v;
}

std::uint16_t parse_code(const std::string& s) {
  const std::optional<unsigned long> v = parse_unsigned(s);
  if (!v || *v > 0xFFFF) throw CLI::ValidationError("--fail-code", "'" + s + "' is not a 16-bit EMCY code (e.g. 0x2310)");
  return static_cast<std::uint16_t>(*v);
}

/// Everything the command line says.
struct Options {
  std::string iface;
  std::vector<int> nodes;
  std::uint64_t fail_after = 0;
  std::string fail_code = "0x2310";
  std::uint32_t lag = 2;
  std::uint32_t fe_window = 100'000;
  double max_velocity = 2'000'000.0;
  double max_accel = 50'000'000.0;
  std::string hb_reaction = "fault";
  double duration = 0;
  bool verbose = false;
  double rated_torque_accel = 0.0, load_torque = 0.0, viscous = 0.0;
  bool refuse_mode = false;
  std::vector<std::string> absent;
  std::vector<std::string> mds_args;
  std::string eds_file;
  std::string profile = "strict";
  std::optional<bool> f_optional, f_ip_ro, f_remap, f_pdos, f_long, f_sync, f_sync_to, f_errb, f_one, f_modes, f_homing;
  std::optional<double> boot_ms, sdo_delay_ms;
  std::optional<std::uint32_t> fault_cause_syncs, mode_switch_syncs;
  bool no_remote = false;
  std::string supported_modes;
  bool check_args = false;
};

/// The drives' options: interface, nodes, the motor model, faults, objects.
void add_drive_options(CLI::App& app, Options& o) {
  app.add_option("-i,--interface", o.iface, "CAN interface (vcan0, can0)")->required();
  app.add_option("-n,--node", o.nodes, "node-ID of an emulated drive (1..127); repeat for several drives")
      ->required()
      ->check(CLI::Range(1, 127));
  app.add_option("--fail-after", o.fail_after, "inject a fault after N SYNCs (0 = never)");
  app.add_option("--fail-code", o.fail_code, "EMCY code of the injected fault")->default_str("0x2310");
  app.add_option("--lag", o.lag, "targets take effect N SYNCs late (0..64)")->check(CLI::Range(0, 64))->default_val(2);
  app.add_option("--following-error-window", o.fe_window, "default of 0x6065, counts")->default_val(100000);
  app.add_option("--max-velocity", o.max_velocity, "velocity limit of the motor model, counts/s")->default_val(2000000.0);
  app.add_option("--max-acceleration", o.max_accel, "acceleration limit of the motor model, counts/s^2")
      ->default_val(50000000.0);
  app.add_option("--heartbeat-reaction", o.hb_reaction, "reaction to a lost master heartbeat (0x1016)")
      ->check(CLI::IsMember({"fault", "quickstop", "none"}))
      ->default_val("fault");
  app.add_option("--rated-torque-acceleration", o.rated_torque_accel,
                 "CST load model: acceleration at 1000 per mille torque, counts/s^2 (0 = --max-acceleration)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--load-torque", o.load_torque, "CST load model: constant load torque, per mille (against + rotation)");
  app.add_option("--viscous-friction", o.viscous, "CST load model: friction, per mille per count/s")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--refuse-mode-switch", o.refuse_mode,
               "fault injection: accept 0x6060 but never show a new mode in 0x6061 (the master's mode-switch timeout)");
  app.add_option("--without-object", o.absent,
                 "emulate a drive without this object (index, e.g. 0x1016); SDO access aborts with 0x06020000; repeat "
                 "for several");
  app.add_option("--mds-objects", o.mds_args,
                 "where this drive keeps the MDS objects CiA 402 lacks, KEY=INDEX:SUB,... with KEY one of "
                 "ramp_velocity_positive, ramp_velocity_negative, ramp_jerk_control, slat_configuration, "
                 "slat_set_point, slat_time_delay (default: 0x2010:1, 0x2010:2, 0x2011, 0x2020, 0x2021, 0x2022); "
                 "repeat or separate with commas");
  app.add_option("--eds", o.eds_file,
                 "serve exactly the objects of this EDS or DCF (CiA 306): absent objects abort 0x06020000, PDO "
                 "counts, mapping flags, access types and defaults from the file")
      ->check(CLI::ExistingFile);
}

/// The profile, its flags, and the run's options.
void add_profile_options(CLI::App& app, Options& o) {
  app.add_option("--profile", o.profile,
                 "strict (a real drive's behaviours) or permissive (the lenient drive)")
      ->check(CLI::IsMember({"strict", "permissive"}))
      ->default_val("strict");
  auto flag_opt = [&app](const char* name, std::optional<bool>& v, const char* what) {
    app.add_option(name, v, std::string(what) + " (true/false; default: the profile's)");
  };
  flag_opt("--optional-objects-absent", o.f_optional,
           "0x1016 and the MDS objects (0x2010..0x2022 or --mds-objects) absent (abort 0x06020000)");
  flag_opt("--ip-index-ro", o.f_ip_ro, "0x60C2:2 read-only (abort 0x06010002)");
  flag_opt("--remap-preop-only", o.f_remap, "PDO parameters change only in Pre-operational (abort 0x08000022)");
  flag_opt("--cia402-pdos", o.f_pdos, "CiA 402 predefined PDO1 (controlword / statusword, type 255) at power-on");
  flag_opt("--long-rpdo-emcy", o.f_long, "an over-long RPDO sends EMCY 8220h");
  flag_opt("--sync-length", o.f_sync,
           "SYNC length checked against 0x1019 (EMCY 8240h); 0x1019 takes 0, 2..240, only while 0x1006 is 0 (0x08000022)");
  flag_opt("--sync-timeout", o.f_sync_to,
           "with 0x1006 not 0, no SYNC for 1.5 x 0x1006 sends EMCY 8100h and takes 0x1029's reaction");
  flag_opt("--error-behaviour", o.f_errb, "0x1029 exists and acts on a lost master heartbeat or SYNC");
  flag_opt("--one-transition", o.f_one, "one commanded transition per SYNC (3 and 4 in two SYNCs)");
  flag_opt("--refuse-unsupported-modes", o.f_modes, "an RPDO's mode outside 0x6502 is not taken");
  flag_opt("--homing-model", o.f_homing, "homing moves per method family over several SYNCs");
  app.add_option("--boot-ms", o.boot_ms, "time in Not ready to switch on after power-on, ms (strict 100)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--sdo-delay-ms", o.sdo_delay_ms, "SDO reply delay, ms (0 = at once; strict: the next call)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--fault-cause-syncs", o.fault_cause_syncs, "SYNCs an injected fault's cause lasts (strict 20)");
  app.add_option("--mode-switch-syncs", o.mode_switch_syncs, "SYNCs until 0x6061 shows a new 0x6060 (strict 2)");
  app.add_flag("--no-remote", o.no_remote, "statusword bit 9 = 0: local control, the bus's controlword is ignored");
  app.add_option("--supported-modes", o.supported_modes,
                 "0x6502 (e.g. 0x3A0 = HM, CSP, CSV, CST: the default; 0x3E0 adds IP; 0x60 = HM and IP only, an IP-only drive); 0x6060 outside it is refused");
  app.add_option("--duration", o.duration, "exit after this many seconds (0 = run until SIGINT/SIGTERM)");
  app.add_flag("-v,--verbose", o.verbose, "print NMT and CiA 402 state changes");
  app.add_flag("--check-args", o.check_args,
               "parse and check the arguments, then exit (0 = valid) without opening the interface");
}

/// --profile and the flags that change one of its behaviours.
emulator::EmulatorBehaviour behaviour_of(const Options& o) {
  emulator::EmulatorBehaviour behaviour =
      o.profile == "permissive" ? emulator::EmulatorBehaviour::permissive() : emulator::EmulatorBehaviour::strict();
  auto apply = [](bool& field, const std::optional<bool>& v) {
    if (v) field = *v;
  };
  apply(behaviour.optional_objects_absent, o.f_optional);
  apply(behaviour.ip_index_read_only, o.f_ip_ro);
  apply(behaviour.remap_preoperational_only, o.f_remap);
  apply(behaviour.cia402_default_pdos, o.f_pdos);
  apply(behaviour.rpdo_too_long_emcy, o.f_long);
  apply(behaviour.check_sync_length, o.f_sync);
  apply(behaviour.sync_timeout, o.f_sync_to);
  apply(behaviour.error_behaviour, o.f_errb);
  apply(behaviour.one_transition_per_sync, o.f_one);
  apply(behaviour.refuse_unsupported_modes, o.f_modes);
  apply(behaviour.homing_takes_time, o.f_homing);
  if (o.boot_ms) behaviour.boot_ns = static_cast<std::int64_t>(*o.boot_ms * 1e6);
  if (o.sdo_delay_ms)
    behaviour.sdo_reply_delay_ns = std::max<std::int64_t>(static_cast<std::int64_t>(*o.sdo_delay_ms * 1e6), 0);
  if (o.fault_cause_syncs) behaviour.fault_cause_syncs = *o.fault_cause_syncs;
  if (o.mode_switch_syncs) behaviour.mode_switch_syncs = *o.mode_switch_syncs;
  return behaviour;
}

/// What the options give every drive, checked (the node is set per drive).
struct DriveSetup {
  std::uint16_t fail_code = 0;
  std::vector<std::uint16_t> absent_objects;
  cia402::MdsObjects mds_objects;
  std::optional<eds::Eds> description;
  std::uint32_t modes_mask = emulator::EmulatorConfig{}.supported_modes;
};

/// The options checked and converted; an error message (printed after
/// "cia402-emu: "), or empty.
std::string check_options(const Options& o, DriveSetup& d) {
  try {
    d.fail_code = parse_code(o.fail_code);
  } catch (const std::exception&) {
    return "--fail-code '" + o.fail_code + "' is not a 16-bit EMCY code (e.g. 0x2310)";
  }
  for (const std::string& a : o.absent) {
    const std::optional<unsigned long> v = parse_unsigned(a);
    if (!v || *v < 0x1000 || *v > 0xFFFF)
      return "--without-object '" + a + "' is not an object index 0x1000..0xFFFF (e.g. 0x1016)";
    d.absent_objects.push_back(static_cast<std::uint16_t>(*v));
  }
  for (const std::string& a : o.mds_args)
    if (std::string why = parse_mds_objects(a, d.mds_objects); !why.empty()) return "--mds-objects: " + why;
  if (!o.eds_file.empty()) {
    try {
      d.description = eds::load(o.eds_file);
    } catch (const std::exception& e) {
      return std::string("--eds: ") + e.what();
    }
  }
  if (!o.supported_modes.empty()) {
    const std::optional<unsigned long> v = parse_unsigned(o.supported_modes);
    if (!v || *v > 0xFFFFFFFFul)
      return "--supported-modes '" + o.supported_modes + "' is not a 32-bit 0x6502 value (e.g. 0x3A0)";
    d.modes_mask = static_cast<std::uint32_t>(*v);
  }
  for (std::size_t i = 0; i < o.nodes.size(); ++i)
    for (std::size_t j = i + 1; j < o.nodes.size(); ++j)
      if (o.nodes[i] == o.nodes[j]) return "node " + std::to_string(o.nodes[i]) + " given twice";
  return {};
}

/// The configuration of the drive with node-ID `node`.
emulator::EmulatorConfig drive_config(const Options& o, const DriveSetup& d, int node) {
  emulator::EmulatorConfig c;
  c.node = static_cast<std::uint8_t>(node);
  c.lag_cycles = o.lag;
  c.following_error_window = o.fe_window;
  c.max_velocity = o.max_velocity;
  c.max_acceleration = o.max_accel;
  c.fail_after_syncs = o.fail_after;
  c.fail_emcy_code = d.fail_code;
  c.rated_torque_acceleration = o.rated_torque_accel;
  c.load_torque = o.load_torque;
  c.viscous_friction = o.viscous;
  c.refuse_mode_switch = o.refuse_mode;
  c.absent_objects = d.absent_objects;
  c.mds_objects = d.mds_objects;
  if (d.description) c.served = emulator::served_objects(*d.description, c.node);
  c.behaviour = behaviour_of(o);
  c.remote = !o.no_remote;
  c.supported_modes = d.modes_mask;
  c.heartbeat_loss_reaction = o.hb_reaction == "fault"       ? emulator::HeartbeatLossReaction::kFault
                              : o.hb_reaction == "quickstop" ? emulator::HeartbeatLossReaction::kQuickStop
                                                             : emulator::HeartbeatLossReaction::kNone;
  return c;
}

/// With --verbose: a line for each drive whose NMT or CiA 402 state changed.
struct StateLog {
  std::vector<canopen::NmtState> nmt;
  std::vector<cia402::State> state;
  void print_changes(const std::vector<std::unique_ptr<emulator::Emulator>>& emus) {
    nmt.resize(emus.size(), canopen::NmtState::kUnknown);
    state.resize(emus.size(), cia402::State::kUnknown);
    for (std::size_t i = 0; i < emus.size(); ++i) {
      const auto& e = *emus[i];
      if (e.nmt_state() == nmt[i] && e.state() == state[i]) continue;
      nmt[i] = e.nmt_state();
      state[i] = e.state();
      std::fprintf(stderr, "cia402-emu: node %u: NMT %s, %s (statusword 0x%04X), position %d\n", e.node(),
                   std::string(canopen::nmt_state_name(e.nmt_state())).c_str(),
                   std::string(cia402::state_name(e.state())).c_str(), e.statusword(), e.position());
    }
  }
};

/// The drives on the bus until SIGINT/SIGTERM or --duration; the exit status.
int run(const Options& o, can::SocketCanBus& bus, std::vector<std::unique_ptr<emulator::Emulator>>& emus) {
  struct sigaction sa{};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  canopen::TransportSink sink(bus);
  const std::int64_t t0 = monotonic_ns();
  for (auto& e : emus) e->power_on(t0, sink);
  std::fprintf(stderr, "cia402-emu: %zu drive(s) on %s:", emus.size(), o.iface.c_str());
  for (int n : o.nodes) std::fprintf(stderr, " %d", n);
  std::fprintf(stderr, " (boot-up sent, NMT pre-operational)\n");
  StateLog log;
  std::array<can::TimedFrame, 64> buf;
  while (!g_stop) {
    pollfd p{bus.fd(), POLLIN, 0};
    const int r = ::poll(&p, 1, 1);  // 1 ms: heartbeat timing resolution
    if (r < 0 && errno != EINTR) {
      std::fprintf(stderr, "cia402-emu: poll on %s failed: %s\n", o.iface.c_str(), std::strerror(errno));
      return 1;
    }
    const std::int64_t now = monotonic_ns();
    for (;;) {
      const std::size_t n = bus.receive(buf);
      for (std::size_t i = 0; i < n; ++i) {
        for (auto& e : emus) {
          e->set_time(now);
          e->on_frame(buf[i], sink);
        }
      }
      if (n < buf.size()) break;
    }
    for (auto& e : emus) e->step(now, sink);
    if (o.verbose) log.print_changes(emus);
    if (o.duration > 0 && static_cast<double>(now - t0) / 1e9 >= o.duration) break;
  }
  for (const auto& e : emus) {
    const auto& c = e->counters();
    std::fprintf(stderr, "cia402-emu: node %u: %llu SYNC, %llu RPDO, %llu TPDO, %llu SDO requests, %llu EMCY, final %s at %d\n",
                 e->node(), static_cast<unsigned long long>(c.syncs), static_cast<unsigned long long>(c.rpdos),
                 static_cast<unsigned long long>(c.tpdos), static_cast<unsigned long long>(c.sdo_requests),
                 static_cast<unsigned long long>(c.emcys), std::string(cia402::state_name(e->state())).c_str(),
                 e->position());
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cia402-emu - emulated CiA 402 servo drives (CANopen slaves) on SocketCAN", "cia402-emu"};
  app.footer(kFooter);
  Options o;
  add_drive_options(app, o);
  add_profile_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 1;
  }
  DriveSetup setup;
  if (const std::string why = check_options(o, setup); !why.empty()) {
    std::fprintf(stderr, "cia402-emu: %s\n", why.c_str());
    return 1;
  }
  if (o.check_args) {
    std::printf("cia402-emu: arguments OK (%zu drive(s) on %s); nothing was opened\n", o.nodes.size(), o.iface.c_str());
    return 0;
  }
  std::error_code ec;
  std::string detail;
  auto bus = can::SocketCanBus::open(o.iface, {}, ec, &detail);
  if (!bus) {
    std::fprintf(stderr, "cia402-emu: cannot open %s: %s\n", o.iface.c_str(),
                 detail.empty() ? ec.message().c_str() : detail.c_str());
    return 1;
  }
  std::vector<std::unique_ptr<emulator::Emulator>> emus;
  for (int n : o.nodes) emus.push_back(std::make_unique<emulator::Emulator>(drive_config(o, setup, n)));
  return run(o, *bus, emus);
}
