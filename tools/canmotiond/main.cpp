// canmotiond: the canmotion daemon. Loads and validates a configuration,
// opens the buses (or simulates them), boots the drives and runs the cycle.
// Argument parsing and I/O only; the work is in config/ and rt/.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "config/config.hpp"
#include "config/eds_check.hpp"
#include "config/runtime.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/eds/dcf.hpp"
#include "fieldbus/can/can_netlink.hpp"
#include "fieldbus/can/candump_format.hpp"
#include "fieldbus/canopen/emcy.hpp"
#include "rt/clock.hpp"
#include "rt/controller/command_server.hpp"
#include "rt/controller/host.hpp"
#include "rt/controller/output_writer.hpp"
#include "rt/controller/script.hpp"
#include "rt/cyclic_executive.hpp"
#include "rt/systemd_notify.hpp"
#include "tools/canmotiond/bus_opener.hpp"

namespace {

using namespace canmotion;

std::atomic<int> g_signal{0};
void on_signal(int sig) { g_signal.store(sig); }

struct Options {
  std::string config;
  bool sim = false;
  double duration = 0;  // 0 = until the script ends or a signal
  std::string script;
  std::string trace;
  std::string csv;
  bool stats = false;
  std::string socket;
  std::string socket_group;
  bool quiet = false;
  double sim_rate = -1;  // --sim-rate; < 0 = default (1 with --socket, else 0 = flat out)
  double sim_clock_start = 0;  // --sim-clock-start: the virtual clock's reading at the first cycle, seconds
  bool check_args = false;  // --check-args: parse and validate, then exit (tests/docs)
  std::string write_dcf;    // --write-dcf DIR: one DCF per node of the boot writes, then exit
  std::string histogram;    // --histogram FILE: the wake-up latency histogram at the end (real time)
};

/// --write-dcf: DIR/<axis>.dcf per CIP axis, the SDO writes of its boot
/// configuration (config::boot_writes, the proxy's own list). 0, or 1 when a
/// file cannot be written.
int write_dcfs(const config::Config& cfg, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  for (std::size_t i = 0; i < cfg.axes.size(); ++i) {
    const config::AxisSettings& a = cfg.axes[i];
    const config::BusSettings* bus = cfg.find_bus(a.bus);
    if (a.axis.type != motion::AxisType::CipDrive || bus == nullptr) continue;
    const std::vector<cia402::BootWrite> writes = config::boot_writes(a, *bus, cfg.controller.period_s, i);
    const cia402::DriveConfig dc = config::drive_config(a, *bus, cfg.controller.period_s, i);
    eds::DcfSpec spec;
    spec.node_id = a.node;
    spec.baudrate_kbit = static_cast<std::uint16_t>(bus->bitrate / 1000);
    spec.node_name = a.name;
    spec.eds = a.drive.eds_data.get();
    std::size_t written = 0;
    for (const cia402::BootWrite& w : writes) {
      if (w.is_read()) continue;  // the boot's checks (0x1000, 0x6502, 0x6061, ...) are not configuration
      ++written;
      const std::string* key = cia402::write_hint_key(dc.hints, w);
      spec.writes.push_back({w.w.index, w.w.sub, w.w.size, w.w.value, key != nullptr ? *key : std::string()});
    }
    const std::string path = (std::filesystem::path(dir) / (a.name + ".dcf")).string();
    std::ofstream f(path);
    f << eds::format_dcf(spec);
    f.close();
    if (!f) {
      fmt::print(stderr, "canmotiond: --write-dcf: cannot write {}\n", path);
      return 1;
    }
    fmt::print("canmotiond: {}: node {}, {} boot writes{}\n", path, a.node, written,
               a.drive.eds.empty() ? "" : " (checked against " + a.drive.eds + ")");
  }
  return 0;
}

/// The EDS dictionary of the drive at `node` on bus `bus` (its axis's
/// drive.eds), or nullptr: notices name its objects by it.
const canopen::DeviceDictionary* dictionary_of(const rt::Controller& c, std::size_t bus, std::uint8_t node) {
  for (const rt::AxisSpec& a : c.spec().axes)
    if (a.config.type == motion::AxisType::CipDrive && a.bus == static_cast<int>(bus) && a.drive.node == node)
      return a.drive.dictionary.get();
  return nullptr;
}

/// Writes the trace and CSV files and prints events; drained from the
/// controller's rings on a non-RT thread (or inline in --sim).
class Outputs {
 public:
  Outputs(const Options& o, config::Runtime& rt, const config::Config& cfg) : rt_(rt), cfg_(cfg), sim_(o.sim) {
    rt::OutputWriterConfig wc;
    wc.trace_path = o.trace;
    wc.csv_path = o.csv;
    wc.trace_names = rt.trace_names;
    for (std::size_t a = 0; a < rt.controller->axis_count(); ++a)
      wc.axis_names.push_back(rt.controller->axis_name(static_cast<motion::AxisId>(a)));
    wc.period_s = rt.controller->period_s();
    // --sim: format and write on a writer thread (the text of hundreds of
    // simulated seconds per second), 256 KiB write(2) blocks. Real time: on
    // the draining (housekeeping) thread, 64 KiB blocks of locked memory.
    wc.threaded = o.sim;
    wc.buffer_bytes = std::size_t{o.sim ? 256u : 64u} << 10;
    writer_.emplace(std::move(wc));
    rt.controller->set_trace(writer_->tracing());
    rt.controller->set_telemetry(writer_->recording_csv());
    // Real time: every record carries CLOCK_MONOTONIC (transmitted frames
    // the cycle's time, SocketCAN receive stamps converted by SocketCanBus);
    // put all on the realtime scale like candump. In --sim every stamp is
    // virtual time.
    if (!o.sim) {
      timespec m{}, r{};
      clock_gettime(CLOCK_MONOTONIC, &m);
      clock_gettime(CLOCK_REALTIME, &r);
      mono_to_real_ = (r.tv_sec - m.tv_sec) * 1'000'000'000LL + (r.tv_nsec - m.tv_nsec);
    }
  }
  /// Writes what is left and closes both files; returns what went wrong ("" if nothing).
  std::string close() { return writer_->close(); }
  void drain(bool quiet) {
    rt::Controller& c = *rt_.controller;
    // The RT thread only pushed records; the writer formats them (no stdio).
    rt::TraceRecord tr;
    while (c.pop_trace(tr)) {
      writer_->trace(tr.frame.frame, tr.frame.t_ns + mono_to_real_, tr.bus);  // 0 in --sim
    }
    rt::Sample s;
    while (c.pop_sample(s)) writer_->sample(s);
    rt::Event e;
    while (c.pop_event(e)) {
      if (e.kind == rt::Event::Kind::kDriveFailed) {
        fmt::print(stderr, "canmotiond: axis {}: {}\n", c.axis_name(static_cast<motion::AxisId>(e.axis)),
                   e.failure.to_string());
      } else if (e.kind == rt::Event::Kind::kAxisFault) {
        const auto id = static_cast<motion::AxisId>(e.axis);
        fmt::print(stderr, "canmotiond: axis {}: {}\n", c.axis_name(id),
                   rt::describe_axis_fault(e, c.axis_spec(id), static_cast<std::size_t>(e.axis)));
      } else if (e.kind == rt::Event::Kind::kDriveWait) {
        const auto id = static_cast<motion::AxisId>(e.axis);
        std::string control;
        for (const auto& [name, cid] : c.controls())
          if (cid == e.wait.control) control = name;
        fmt::print(stderr, "canmotiond: axis {}: {}\n", c.axis_name(id),
                   rt::describe_drive_wait(e, c.axis_spec(id), static_cast<std::size_t>(e.axis), control, c.period_s()));
      } else if (e.kind == rt::Event::Kind::kDriveStatusBit) {
        const auto id = static_cast<motion::AxisId>(e.axis);
        fmt::print(stderr, "canmotiond: axis {}: {}\n", c.axis_name(id),
                   rt::describe_drive_status_bit(e, c.axis_spec(id), static_cast<std::size_t>(e.axis)));
      } else if (!quiet && e.kind == rt::Event::Kind::kNode && e.node.kind == canopen::NodeEvent::Kind::kEmcy) {
        fmt::print(stderr, "canmotiond: bus {} node {}: EMCY 0x{:04X} {}\n", cfg_.buses[e.bus].name, e.node.node,
                   e.node.emcy.code, canopen::emcy_code_text(e.node.emcy.code));
      } else if (e.kind == rt::Event::Kind::kNode && e.node.kind == canopen::NodeEvent::Kind::kHeartbeatLost) {
        fmt::print(stderr, "canmotiond: bus {} node {}: heartbeat lost\n", cfg_.buses[e.bus].name, e.node.node);
      } else if (!quiet && e.kind == rt::Event::Kind::kNode && e.node.kind == canopen::NodeEvent::Kind::kObjectAbsent) {
        fmt::print(stderr, "canmotiond: bus {} {}\n", cfg_.buses[e.bus].name,
                   cia402::describe_notice(e.node, dictionary_of(c, e.bus, e.node.node)));
      } else if (e.kind == rt::Event::Kind::kBusState) {
        fmt::print(stderr, "canmotiond: bus {}: state {}\n", cfg_.buses[e.bus].name, static_cast<int>(e.bus_state));
        // On this (housekeeping) thread, never the cycle: rtnetlink, and a
        // restart when restart-ms is 0 (fieldbus/can/can_netlink.hpp).
        if (e.bus_state == can::BusState::kBusOff && !sim_ && !cfg_.buses[e.bus].is_sim())
          if (const std::string what = can::handle_bus_off(cfg_.buses[e.bus].interface); !what.empty())
            fmt::print(stderr, "canmotiond: bus {}: bus-off: {}\n", cfg_.buses[e.bus].name, what);
      } else if (e.kind == rt::Event::Kind::kBusError) {
        fmt::print(stderr, "canmotiond: bus {}: error frames: {}\n", cfg_.buses[e.bus].name,
                   can::SocketCanBus::error_classes_text(static_cast<std::uint32_t>(e.value)));
      } else if (e.kind == rt::Event::Kind::kBusRecovered) {
        fmt::print(stderr, "canmotiond: bus {}: back from bus-off: re-booting its drives\n", cfg_.buses[e.bus].name);
      } else if (e.kind == rt::Event::Kind::kLinkDown) {
        const std::string& i = cfg_.buses[e.bus].interface;
        fmt::print(stderr,
                   "canmotiond: bus {}: interface {} is down ({}: {}): no frame goes out or comes in, its axes "
                   "fault (bus_off); canmotiond keeps trying it every cycle and re-boots its drives once it is up "
                   "(`ip link set {} up`), then MASR, MSO\n",
                   cfg_.buses[e.bus].name, i, e.value == ENETDOWN ? "ENETDOWN" : "errno " + std::to_string(e.value),
                   std::strerror(static_cast<int>(e.value)), i);
      } else if (e.kind == rt::Event::Kind::kLinkUp) {
        fmt::print(stderr, "canmotiond: bus {}: interface {} is up again: re-booting its drives\n",
                   cfg_.buses[e.bus].name, cfg_.buses[e.bus].interface);
      }
    }
  }

 private:
  config::Runtime& rt_;
  const config::Config& cfg_;
  bool sim_ = false;  // --sim: every bus is a SimBus, whatever its interface says
  std::optional<rt::OutputWriter> writer_;
  std::int64_t mono_to_real_ = 0;
};

/// The controlled stop (SIGINT/SIGTERM, or the end of the run): stop every
/// axis at its configured deceleration, disable the drives, put the nodes in
/// pre-operational. Each phase is bounded (see README).
class Shutdown {
 public:
  enum class Phase { kNone, kStopping, kDisabling, kPreOp, kDone };
  explicit Shutdown(rt::ControllerHost& h) : h_(h) {}
  Phase phase() const { return phase_; }
  void begin(double now) {
    if (phase_ != Phase::kNone) return;
    phase_ = Phase::kStopping;
    since_ = now;
    rt::Controller& c = h_.controller();
    for (std::size_t a = 0; a < c.axis_count(); ++a) {
      const std::string& n = c.axis_name(static_cast<motion::AxisId>(a));
      std::string ctl;
      // MAS(All), decel as configured (ChangeDecel No).
      (void)h_.execute(fmt::format("MAS({}, canmotiond_stop_{}, All, No, 100, %ofmaximum, No, 100, %ofmaximum)", n, a), &ctl);
    }
  }
  /// Advance; returns true when done.
  bool step(double now) {
    if (phase_ == Phase::kNone) return false;  // no snapshot copy while running normally
    rt::Controller& c = h_.controller();
    const rt::Status& s = h_.refresh();
    switch (phase_) {
      case Phase::kNone: return false;
      case Phase::kStopping: {
        bool moving = false;
        for (std::size_t a = 0; a < c.axis_count(); ++a) moving |= s.axes[a].tag.command_velocity != 0.0;
        if ((!moving && h_.settled()) || now - since_ > kStopTimeout) {
          for (std::size_t a = 0; a < c.axis_count(); ++a) {
            std::string ctl;
            (void)h_.execute(fmt::format("MSF({}, canmotiond_msf_{})", c.axis_name(static_cast<motion::AxisId>(a)), a), &ctl);
          }
          phase_ = Phase::kDisabling;
          since_ = now;
        }
        return false;
      }
      case Phase::kDisabling: {
        bool enabled = false;
        for (std::size_t a = 0; a < c.axis_count(); ++a)
          enabled |= s.axes[a].drive_state == cia402::State::kOperationEnabled;
        if ((!enabled && h_.settled()) || now - since_ > kDisableTimeout) {
          (void)c.submit(rt::cmd::PreOperational{});
          phase_ = Phase::kPreOp;
          since_ = now;
        }
        return false;
      }
      case Phase::kPreOp:
        // The NMT frame goes out at the end of the cycle that executes the
        // command (after its SYNC); the next cycle receives that SYNC's TPDOs.
        // End after it, before a SYNC that pre-operational drives ignore.
        // The controller disarms the drives' heartbeat watch (0x1016 over SDO),
        // sends NMT pre-operational after a SYNC and then halts the cyclic
        // traffic; one more cycle receives that SYNC's TPDOs.
        if (!preop_sent_) {
          if (s.halted || now - since_ > kPreOpTimeout) {
            preop_sent_ = true;
            since_ = now;
          }
        } else if (now > since_) {
          phase_ = Phase::kDone;
        }
        return phase_ == Phase::kDone;
      case Phase::kDone: return true;
    }
    return true;
  }
  static constexpr double kStopTimeout = 5.0;
  static constexpr double kDisableTimeout = 2.0;
  static constexpr double kPreOpTimeout = 2.0;

 private:
  rt::ControllerHost& h_;
  Phase phase_ = Phase::kNone;
  double since_ = 0;
  bool preop_sent_ = false;
};

void print_summary(const Options& o, config::Runtime& rt, rt::ControllerHost& host, const rt::CycleStats& st,
                   double wall_s, bool real_time) {
  const rt::Status& s = host.refresh();
  rt::Controller& c = *rt.controller;
  const double sim_s = static_cast<double>(s.cycle) * c.period_s();
  fmt::print("summary: {} cycles, {:.3f} s of controller time in {:.3f} s wall ({:.0f}x real time)\n", s.cycle, sim_s,
             wall_s, wall_s > 0 ? sim_s / wall_s : 0.0);
  if (real_time)
    fmt::print("summary: wake-up latency max {:.1f} us, p99 {:.1f} us; overruns {}\n", static_cast<double>(st.latency_max_ns) / 1e3,
               static_cast<double>(st.latency_p99_ns) / 1e3, st.overruns);
  // A SYNC the transport refused is a cycle every drive on that bus missed.
  for (std::size_t b = 0; b < c.spec().buses.size() && b < s.buses.size(); ++b) {
    const rt::BusSnapshot& bs = s.buses[b];
    fmt::print("summary: bus {}: {} SYNCs sent, {} refused by the transport (transmit queue full, bus-off or interface down); "
               "{} frames refused in all\n",
               c.spec().buses[b].name, bs.syncs_sent, bs.syncs_refused, bs.send_rejected);
  }
  // --stats: when the SYNCs left, on the cycle's clock (issue 28).
  if (const rt::SyncTiming* t = c.sync_timing())
    fmt::print("summary: {} ({}, all buses)\n", rt::format_sync_timing(t->snapshot()),
               c.spec().sync_first ? "controller.sync_first: SYNC first" : "RPDOs, then SYNC");
  // The emulated drives' side (--sim, `interface: sim`): what they received.
  if (rt.sim)
    for (std::size_t d = 0; d < rt.sim->drive_count(); ++d) {
      const emulator::Emulator& e = rt.sim->drive(d);
      const emulator::EmulatorCounters& k = e.counters();
      fmt::print("summary: emulated drive node {:>3} on bus {}: {} SYNCs taken ({} counter errors, {} of the wrong length), "
                 "{} RPDOs, {} TPDOs, {} boot-ups, {} EMCYs\n",
                 e.node(), c.spec().buses[rt.sim->drive_bus(d)].name, k.syncs, k.sync_counter_errors, k.sync_length_errors,
                 k.rpdos, k.tpdos, k.boot_ups, k.emcys);
    }
  for (std::size_t a = 0; a < c.axis_count(); ++a) {
    const rt::AxisSnapshot& x = s.axes[a];
    const auto& cfg = c.axis_spec(static_cast<motion::AxisId>(a)).config;
    if (cfg.type == motion::AxisType::CipDrive)
      fmt::print("summary: axis {:<10} node {:>3}  max following error {:.6f} {}  final position {:.4f}  TPDOs missed {}\n",
                 c.axis_name(static_cast<motion::AxisId>(a)), c.axis_spec(static_cast<motion::AxisId>(a)).drive.node,
                 x.max_abs_position_error, cfg.units_name, x.tag.actual_position, x.tpdo_missed);
    else
      fmt::print("summary: axis {:<10} virtual   final position {:.4f} {}\n", c.axis_name(static_cast<motion::AxisId>(a)),
                 x.tag.command_position, cfg.units_name);
  }
  if (!o.trace.empty()) fmt::print("summary: trace (candump -L) written to {}\n", o.trace);
  if (!o.csv.empty()) fmt::print("summary: CSV written to {}\n", o.csv);
  if (s.trace_dropped || s.telemetry_dropped)
    fmt::print("summary: WARNING: {} trace and {} CSV records were dropped (writer too slow)\n", s.trace_dropped,
               s.telemetry_dropped);
}

void print_progress(rt::ControllerHost& host) {
  const rt::Status& s = host.refresh();
  rt::Controller& c = host.controller();
  std::string line = fmt::format("t={:7.3f}", static_cast<double>(s.cycle) * c.period_s());
  for (std::size_t a = 0; a < c.axis_count(); ++a)
    line += fmt::format("  {}={:.3f}", c.axis_name(static_cast<motion::AxisId>(a)), s.axes[a].tag.actual_position);
  fmt::print("{}\n", line);
  std::fflush(stdout);
}

/// A step of run() that ends the run early; it printed why.
struct Exit {
  int status;
};

/// 1. Configuration: everything is validated before any bus is touched.
config::Config load_config(const Options& o) {
  config::Config cfg;
  try {
    cfg = config::load_file(o.config);
  } catch (const config::ConfigError& e) {
    fmt::print(stderr, "{}\ncanmotiond: configuration has errors; nothing was sent on any bus\n", e.what());
    throw Exit{2};
  } catch (const std::exception& e) {
    fmt::print(stderr, "canmotiond: {}\n", e.what());
    throw Exit{2};
  }
  for (const auto& w : cfg.warnings) fmt::print(stderr, "{}\n", w.str());
  for (const auto& w : config::startup_warnings(cfg)) fmt::print(stderr, "{}\n", w.str());  // said once, at start
  if (!o.write_dcf.empty() && !o.check_args) throw Exit{write_dcfs(cfg, o.write_dcf)};  // nothing opened
  {
    // Without drive.eds the master cannot know which optional objects a drive has: say once what it does.
    std::vector<std::string> blind;
    for (const auto& a : cfg.axes)
      if (a.axis.type == motion::AxisType::CipDrive && a.drive.eds.empty()) blind.push_back(a.name);
    if (!blind.empty() && !o.quiet)
      fmt::print(stderr,
                 "canmotiond: axes without drive.eds ({}): optional objects (PDOs not used, 0x1016 when "
                 "master_heartbeat_timeout_ms is not set) are written anyway, and a drive without them (SDO abort "
                 "0x06020000 / 0x06090011) is accepted\n",
                 fmt::join(blind, ", "));
  }
  return cfg;
}

/// 2. Buses and controller: the spec, the SocketCAN buses opened (before the
/// RT thread starts), the controller (--check-args: simulated buses, nothing opened).
config::Runtime open_runtime(const Options& o, const config::Config& cfg) {
  try {
    config::RuntimeSpec spec = config::build_spec(cfg, o.sim || o.check_args);
    daemon::OpenedBuses buses = daemon::open_buses(cfg, spec.controller);
    config::Runtime rt = config::build_runtime(cfg, std::move(spec), std::move(buses.sockets));
    for (const auto& n : buses.notes) fmt::print(stderr, "canmotiond: {}\n", n);  // e.g. a raised txqueuelen
    return rt;
  } catch (const std::exception& e) {
    fmt::print(stderr, "canmotiond: {}\n", e.what());
    throw Exit{1};
  }
}

/// The cycle statistics as tags (Controller.latency_max_ns, ...), registered
/// before the script is checked; they read the executive once `exec` is set.
void add_statistic_tags(rt::ControllerHost& host, rt::CyclicExecutive* const& exec) {
  for (std::string_view name : rt::stat_tag_names())
    host.tags().add_statistic(std::string(name), [&exec, name] {
      return exec == nullptr ? 0.0
                             : static_cast<double>(rt::stat_tag_value(exec->statistics().snapshot(), name).value_or(0));
    });
}

/// 3. The script, checked against the controller before anything runs.
std::optional<rt::script::Script> load_script(const Options& o, rt::ControllerHost& host) {
  if (o.script.empty()) return std::nullopt;
  try {
    return rt::script::load_file(o.script, host);
  } catch (const std::exception& e) {
    fmt::print(stderr, "canmotiond: {}\n", e.what());
    throw Exit{2};
  }
}

/// The cyclic executive's settings: the configuration's real-time settings,
/// none with --sim (virtual time only with --sim; `interface: sim` alone runs
/// in real time).
rt::ExecutiveConfig executive_config(const config::Config& cfg, std::chrono::nanoseconds period, bool sim) {
  rt::ExecutiveConfig ec;
  ec.period = period;
  ec.rt = sim ? rt::RtSettings::none()
              : rt::RtSettings{cfg.controller.lock_memory, cfg.controller.lock_memory ? 256u * 1024u : 0u,
                               cfg.controller.priority, cfg.controller.cpu, cfg.controller.cpu_dma_latency_us};
  ec.warn = [](std::string_view w) { fmt::print(stderr, "canmotiond: WARNING: {}\n", w); };
  return ec;
}

/// canmotionctl's socket (rt/controller/command_server.hpp), served from
/// housekeeping; null without --socket.
std::unique_ptr<rt::CommandServer> open_socket(const Options& o, rt::Controller& ctl, rt::ControllerHost& host,
                                               rt::CyclicExecutive& exec) {
  if (o.socket.empty()) return nullptr;
  rt::CommandServerOptions so;
  so.path = o.socket;
  so.group = o.socket_group;
  so.io_interval_s = o.sim ? 0.001 : 0.0;  // --sim: housekeeping runs every cycle; poll the socket once per ms
  so.log = [](const std::string& l) { fmt::print(stderr, "canmotiond: socket: {}\n", l); };
  if (!o.sim) so.cycle_stats = [&exec] { return exec.statistics().snapshot(); };
  so.shared_host = &host;  // clients and --script share user tags
  try {
    return std::make_unique<rt::CommandServer>(ctl, std::move(so));
  } catch (const std::exception& e) {
    fmt::print(stderr, "canmotiond: {}\n", e.what());
    throw Exit{1};
  }
}

/// The non-RT work of one step (between cycles in --sim, once per cycle
/// on the housekeeping thread in real time): outputs, socket, script,
/// progress, the end of the run and the controlled stop.
class Housekeeping {
 public:
  Housekeeping(const Options& o, rt::ControllerHost& host, rt::CyclicExecutive& exec, Outputs& out,
               rt::CommandServer* server, rt::script::Runner* runner)
      : o_(o), host_(host), exec_(exec), out_(out), server_(server), runner_(runner), shutdown_(host),
        period_s_(host.controller().period_s()),
        per_second_(static_cast<std::uint64_t>(std::llround(1.0 / period_s_))),
        next_progress_(per_second_),
        // --sim pacing: at most sim_rate x real time (0 = as fast as possible).
        sim_rate_(o.sim_rate >= 0 ? o.sim_rate : (server ? 1.0 : 0.0)) {}

  /// One step at `cycle`; returns true when the run is over.
  bool operator()(std::uint64_t cycle) {
    const double now = static_cast<double>(cycle) * period_s_;
    if (o_.sim && sim_rate_ > 0)
      std::this_thread::sleep_until(wall0_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                 std::chrono::duration<double>(now / sim_rate_)));
    out_.drain(o_.quiet);
    if (server_) server_->poll(now);
    step_script(now);
    if (o_.duration > 0 && now >= o_.duration) shutdown_.begin(now);
    if (g_signal.load() != 0 && shutdown_.phase() == Shutdown::Phase::kNone) {
      fmt::print(stderr, "canmotiond: signal {}: stopping axes, disabling drives\n", g_signal.load());
      shutdown_.begin(now);
    }
    if (server_ && !refusing_ && shutdown_.phase() != Shutdown::Phase::kNone) {
      refusing_ = true;  // no new motion from clients once the controlled stop has begun
      server_->refuse_motion("canmotiond is stopping (controlled stop): motion instructions and scripts are refused");
    }
    if (!o_.quiet && cycle >= next_progress_) {
      next_progress_ += per_second_;
      print_progress(host_);
      if (o_.stats && !o_.sim) fmt::print("{}\n", rt::format_line(exec_.statistics().snapshot()));
    }
    return shutdown_.step(now);
  }
  /// 1 once the script failed (or a step threw), else 0.
  int status() const noexcept { return status_; }
  void fail() noexcept { status_ = 1; }
  std::chrono::steady_clock::time_point wall0() const noexcept { return wall0_; }

 private:
  void step_script(double now) {
    if (!runner_ || shutdown_.phase() != Shutdown::Phase::kNone) return;
    const auto st = runner_->step(now);
    if (st == rt::script::Runner::Status::kFailed) {
      fmt::print(stderr, "canmotiond: script failed: {}\n", runner_->error());
      status_ = 1;
      shutdown_.begin(now);
    } else if (st == rt::script::Runner::Status::kDone && o_.duration <= 0) {
      shutdown_.begin(now);
    }
  }

  const Options& o_;
  rt::ControllerHost& host_;
  rt::CyclicExecutive& exec_;
  Outputs& out_;
  rt::CommandServer* server_;
  rt::script::Runner* runner_;
  Shutdown shutdown_;
  const std::chrono::steady_clock::time_point wall0_ = std::chrono::steady_clock::now();
  const double period_s_;
  const std::uint64_t per_second_;
  std::uint64_t next_progress_;
  const double sim_rate_;
  bool refusing_ = false;
  int status_ = 0;
};

/// --sim: the same cycle code on a virtual clock, with the non-RT work inline
/// between cycles so that runs are deterministic. Every status read (script,
/// socket, progress) runs on this thread between cycles, so the controller
/// copies its snapshot only for cycles that are read.
int run_simulated(config::Runtime& rt, rt::CyclicExecutive& exec, Housekeeping& hk, std::chrono::nanoseconds period,
                  std::int64_t start_ns) {
  rt::Controller& ctl = *rt.controller;
  ctl.set_deferred_publish(true);
  exec.set_cycle([&](const rt::CycleInfo& info) noexcept {
    const auto t = start_ns + static_cast<std::int64_t>(info.cycle) * period.count();
    if (rt.sim) rt.sim->begin_cycle(t);  // null when the configuration has no buses (virtual axes only)
    ctl.cycle(t);
    if (rt.sim) rt.sim->end_cycle(t);
    bool ended = true;
    try {
      ended = hk(info.cycle + 1);
    } catch (...) {
      hk.fail();
    }
    return ended ? rt::CycleResult::stop : rt::CycleResult::run_on;
  });
  if (auto e = exec.run(); e) {
    fmt::print(stderr, "canmotiond: cannot run the cycle: {}\n", e.message());
    return 1;
  }
  return 0;
}

/// Real time: the cycle on the RT thread, housekeeping on this one once per
/// cycle (half a period after the deadline), systemd readiness and watchdog.
int run_real_time(const Options& o, config::Runtime& rt, rt::CyclicExecutive& exec, Housekeeping& hk,
                  std::chrono::nanoseconds period) {
  rt::Controller& ctl = *rt.controller;
  // The cycle's grid for the housekeeping thread (an atomic store: RT-safe).
  std::atomic<std::int64_t> grid_ns{-1};
  exec.set_cycle([&](const rt::CycleInfo& info) noexcept {
    grid_ns.store(info.deadline.count(), std::memory_order_relaxed);
    const std::int64_t t = info.wake.count();
    if (rt.sim) rt.sim->begin_cycle(t);
    ctl.cycle(t);
    if (rt.sim) rt.sim->end_cycle(t);
  });
  if (auto e = exec.start(); e) {
    fmt::print(stderr, "canmotiond: cannot start the cyclic thread: {}\n", exec.setup_report().error_message());
    return 1;
  }
  if (o.stats) {  // what the RT set-up got (mlockall, SCHED_FIFO, cpu_dma_latency, ...), one line
    std::string steps = exec.setup_report().describe();
    for (std::size_t p; (p = steps.find('\n')) != std::string::npos;)
      steps.replace(p, 1, p + 1 < steps.size() ? "; " : "");
    fmt::print("canmotiond: real-time set-up: {}\n", steps);
  }
  rt::SdNotifier::ready();
  std::unique_ptr<rt::WatchdogThread> wd;
  if (auto iv = rt::SdNotifier::watchdog_interval()) {
    wd = std::make_unique<rt::WatchdogThread>([&exec] { return exec.cycle_count(); }, *iv / 2);
    wd->start();
  }
  // Housekeeping once per cycle, half a period after the cycle's deadline, so
  // that its wake-ups never fall together with the RT thread's. (A free
  // 1 ms sleep drifted through the cycle's grid; where both threads shared a
  // CPU, its timer and context switch then delayed the RT wake-up.)
  rt::MonotonicClock mono;
  const std::int64_t p = period.count();
  for (bool ended = false; !ended;) {
    const std::int64_t now = mono.now().count();
    const std::int64_t g = grid_ns.load(std::memory_order_relaxed);
    std::int64_t next = (g < 0 ? now : g) + p / 2;
    if (next <= now) next += ((now - next) / p + 1) * p;
    mono.sleep_until(rt::Nanos{next});
    ended = hk(ctl.cycles());
  }
  rt::SdNotifier::stopping();
  if (wd) wd->stop();
  exec.stop();
  return 0;
}

int run(const Options& o) {
  const config::Config cfg = load_config(o);  // 1
  config::Runtime rt = open_runtime(o, cfg);  // 2
  rt::Controller& ctl = *rt.controller;
  rt::ControllerHost host(ctl);
  rt::CyclicExecutive* exec_for_tags = nullptr;
  add_statistic_tags(host, exec_for_tags);
  const std::optional<rt::script::Script> script = load_script(o, host);  // 3
  if (o.check_args) {
    fmt::print("canmotiond: arguments, configuration{} OK ({} axes, {} buses); nothing was run\n",
               script ? " and script" : "", ctl.axis_count(), cfg.buses.size());
    return 0;
  }
  std::unique_ptr<rt::script::Runner> runner;
  if (script) runner = std::make_unique<rt::script::Runner>(*script, host, [](const std::string& l) {
      fmt::print("{}\n", l);
      std::fflush(stdout);
    });
  std::unique_ptr<Outputs> out;
  try {
    out = std::make_unique<Outputs>(o, rt, cfg);
  } catch (const std::exception& e) {
    fmt::print(stderr, "canmotiond: {}\n", e.what());
    return 2;
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  const auto period = std::chrono::nanoseconds(ctl.spec().period_ns);
  rt::VirtualClock vclock;
  rt::MonotonicClock mclock;
  rt::Clock& clock = o.sim ? static_cast<rt::Clock&>(vclock) : static_cast<rt::Clock&>(mclock);
  // --stats in real time: each SYNC's send time on the cycle's clock (one clock read per SYNC).
  if (o.stats && !o.sim) ctl.set_sync_clock(&mclock);
  rt::CyclicExecutive exec(executive_config(cfg, period, o.sim), clock);
  exec_for_tags = &exec;
  const std::unique_ptr<rt::CommandServer> server = open_socket(o, ctl, host, exec);

  fmt::print("canmotiond: {} axes, {} buses ({}), period {} ms{}{}\n", ctl.axis_count(), cfg.buses.size(),
             o.sim ? "simulated, virtual time" : "real time", config::period_ms(ctl.period_s()),
             ctl.spec().sync_first ? ", SYNC first" : "", script ? ", script " + o.script : std::string());
  Housekeeping hk(o, host, exec, *out, server.get(), runner.get());
  const auto sim_start_ns = static_cast<std::int64_t>(std::llround(o.sim_clock_start * 1e9));
  if (rt.sim) rt.sim->power_on(o.sim ? sim_start_ns : clock.now().count());  // boot-up frames at the run's start time
  if (const int e = o.sim ? run_simulated(rt, exec, hk, period, sim_start_ns) : run_real_time(o, rt, exec, hk, period); e != 0)
    return e;

  // The end: the rest of the outputs, the summary, a script that did not finish.
  int status = hk.status();
  out->drain(true);
  if (const std::string err = out->close(); !err.empty()) {
    fmt::print(stderr, "canmotiond: {}\n", err);
    status = 1;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - hk.wall0()).count();
  if (!o.quiet || o.stats) print_summary(o, rt, host, exec.statistics().snapshot(), wall, !o.sim);
  if (o.stats) fmt::print("{}\n", rt::format_summary(exec.statistics().snapshot()));
  if (!o.histogram.empty()) {
    std::ofstream f(o.histogram);
    f << rt::histogram_text(exec.statistics().latency());
    f.close();
    if (!f) {
      fmt::print(stderr, "canmotiond: --histogram: cannot write {}\n", o.histogram);
      status = 1;
    }
  }
  if (runner && runner->status() == rt::script::Runner::Status::kRunning && status == 0) {
    fmt::print(stderr, "canmotiond: the run ended before the script did (statement {} of {})\n",
               runner->position() + 1, script->statements.size());
    status = 1;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "canmotiond: the canmotion real-time servo master. Runs Logix motion instructions on a cyclic thread and "
      "drives CiA 402 servo drives over CANopen (SocketCAN), or simulated drives with --sim.",
      "canmotiond"};
  app.add_option("-c,--config", o.config, "configuration file (YAML)")->required()->check(CLI::ExistingFile);
  CLI::Option* sim = app.add_flag("--sim", o.sim,
                                  "simulate every bus in process with an emulated CiA 402 drive per AXIS_CIP_DRIVE "
                                  "node; virtual time, as fast as possible, deterministic");
  app.add_option("--duration", o.duration, "stop after this many seconds of controller time (default: when the "
                                           "script ends, or on SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--script", o.script, "motion script to run (see README: Motion scripts)")->check(CLI::ExistingFile);
  app.add_option("--trace", o.trace, "write every frame on every bus to FILE in candump -L format")->type_name("FILE");
  app.add_option("--csv", o.csv, "write one row per axis per cycle to FILE")->type_name("FILE");
  app.add_flag("--stats", o.stats,
               "print cycle statistics once a second and at the end (real time: with the SYNC timing, wake-up -> "
               "SYNC and |SYNC interval - period|)");
  app.add_option("--histogram", o.histogram,
                 "real time: write the cycle's wake-up latency histogram to FILE at the end (one \"lower_ns "
                 "upper_ns count\" line per non-empty bucket, as rt-latency --histogram)")
      ->type_name("FILE")
      ->excludes(sim);
  app.add_option("--socket", o.socket, "serve canmotionctl on this UNIX socket (mode 0660; see tools/canmotionctl/README.md)")
      ->type_name("PATH");
  app.add_option("--socket-group", o.socket_group, "group owning the --socket file and allowed to use it (default: the daemon's group)")
      ->type_name("GROUP");
  app.add_option("--sim-rate", o.sim_rate,
                 "with --sim: run at most this many times real time (0 = as fast as possible; default 0, or 1 "
                 "with --socket so that canmotionctl users see motion at its real speed)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--sim-clock-start", o.sim_clock_start,
                 "with --sim: the virtual clock's reading at the first cycle, in seconds (default 0). The clock the "
                 "master and the drives see, like CLOCK_MONOTONIC on a machine up that long; the script's and "
                 "--duration's controller time still start at 0. E.g. 4292000 crosses 2^32 ms after 2967 s")
      ->check(CLI::Range(0.0, 4.0e9))
      ->needs(sim);
  app.add_flag("-q,--quiet", o.quiet, "no progress lines or summary");
  app.add_flag("--check-args", o.check_args,
               "parse the arguments, load and check the configuration and the --script, then exit (0 = valid); "
               "opens no bus or socket");
  app.add_option("--write-dcf", o.write_dcf,
                 "write DIR/<axis>.dcf per CANopen axis: the SDO writes of its boot configuration (PDOs, 0x60C2, "
                 "heartbeats, sdo_writes) as a text DCF (CiA 306 INI format) for review, then exit; opens no bus")
      ->type_name("DIR");
  app.footer(
      "Examples:\n"
      "  canmotiond --config config/examples/demo.yaml --sim --script config/examples/demo.script\n"
      "  canmotiond --config config/examples/demo.yaml --write-dcf dcf/\n"
      "  canmotiond --config /etc/canmotion/canmotiond.yaml --stats\n"
      "Exit status: 0 ok, 1 run-time failure (script failed, bus error), 2 bad configuration or arguments.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return run(o);
  } catch (const Exit& e) {
    return e.status;
  }
}
