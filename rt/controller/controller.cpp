#include "rt/controller/controller.hpp"

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace canmotion::rt {

using cia402::round_half_away;

motion::DriveState drive_state_of(cia402::State s, bool operational) noexcept {
  using S = cia402::State;
  switch (s) {
    case S::kFault:
    case S::kFaultReactionActive: return motion::DriveState::Fault;
    case S::kOperationEnabled: return operational ? motion::DriveState::Enabled : motion::DriveState::SwitchedOn;
    case S::kSwitchedOn: return motion::DriveState::SwitchedOn;
    default: return motion::DriveState::NotReady;
  }
}

/// Sends through the bus's transport and records each sent frame for the trace.
class Controller::RecordingSink final : public canopen::FrameSink {
 public:
  RecordingSink(Controller& c, std::uint8_t bus) noexcept : c_(c), bus_(bus) {}
  bool send(const can::Frame& f) noexcept override {
    BusRt& b = c_.buses_[bus_];
    const bool ok = b.transport->send(f) == can::SendResult::kOk;
    if (!ok) {
      ++b.rejected;
      return false;
    }
    if (c_.sync_timing_ && f.id == canopen::cob::kSync) [[unlikely]]
      c_.sync_timing_->record(bus_, now_ns);
    if (c_.trace_on_.load(std::memory_order_relaxed)) c_.record(bus_, can::TimedFrame{f, now_ns}, true);
    return true;
  }
  std::int64_t now_ns = 0;

 private:
  Controller& c_;
  std::uint8_t bus_;
};

Controller::Controller(ControllerSpec spec)
    : spec_(std::move(spec)),
      planner_(static_cast<double>(spec_.period_ns) * 1e-9),
      snapshot_(std::make_unique<SnapshotBuffer<Status>>()) {
  if (spec_.period_ns <= 0) throw std::invalid_argument("controller period must be > 0");
  if (spec_.buses.size() > kMaxBuses)
    throw std::invalid_argument("at most " + std::to_string(kMaxBuses) + " buses, got " +
                                std::to_string(spec_.buses.size()));
  if (spec_.axes.size() > motion::kMaxAxes)
    throw std::invalid_argument("at most " + std::to_string(motion::kMaxAxes) + " axes, got " +
                                std::to_string(spec_.axes.size()));
  buses_.resize(spec_.buses.size());
  for (std::size_t b = 0; b < spec_.buses.size(); ++b) {
    if (spec_.buses[b].transport == nullptr)
      throw std::invalid_argument("bus '" + spec_.buses[b].name + "' has no transport");
    buses_[b].transport = spec_.buses[b].transport;
    spec_.buses[b].network.sync_first = spec_.sync_first;
    buses_[b].network = std::make_unique<cia402::DriveNetwork>(spec_.buses[b].network);
    buses_[b].sink = std::make_unique<RecordingSink>(*this, static_cast<std::uint8_t>(b));
  }
  if (spec_.cams.size() > motion::kMaxCamProfiles)
    throw std::invalid_argument("at most " + std::to_string(motion::kMaxCamProfiles) + " cam profiles, got " +
                                std::to_string(spec_.cams.size()));
  for (std::size_t c = 0; c < spec_.cams.size(); ++c) {
    const CamSpec& cs = spec_.cams[c];
    if (cs.points.empty()) throw std::invalid_argument("cam '" + cs.name + "' has no points");
    auto prof = std::make_unique<motion::cam::CamProfile>(cs.points.size());
    motion::cam::MccpRequest req;
    req.cam = cs.points;
    req.length = static_cast<std::int64_t>(cs.points.size());
    req.start_slope = cs.start_slope;
    req.end_slope = cs.end_slope;
    const motion::cam::MccpResult res = motion::cam::mccp(req, *prof);
    if (res.err != motion::cam::CamError::None)
      throw std::invalid_argument("cam '" + cs.name + "': " + motion::cam::describe(res));
    if (!planner_.attach_cam_profile(static_cast<std::uint16_t>(c), prof.get()))
      throw std::invalid_argument("cam '" + cs.name + "': the planner refused the profile");
    cams_.push_back(std::move(prof));
  }
  build_arrays();
  // SYNC first: the drives apply a cycle's command one cycle later.
  (void)planner_.set_command_lag(spec_.sync_first ? 1 : 0);
  axes_.resize(spec_.axes.size());
  for (std::size_t a = 0; a < spec_.axes.size(); ++a) {
    AxisSpec& s = spec_.axes[a];
    if (!planner_.configure_axis(static_cast<motion::AxisId>(a), s.config))
      throw std::invalid_argument("axis '" + s.name + "': the planner rejected its configuration");
    axes_[a].conv = s.config.conversion_constant;
    axes_[a].vel = s.config.conversion_constant / s.drive.units.velocity_counts;
    axes_[a].acc = s.config.conversion_constant / s.drive.units.acceleration_counts;
    if (s.config.type == motion::AxisType::CipDrive) {
      if (s.bus < 0 || static_cast<std::size_t>(s.bus) >= buses_.size())
        throw std::invalid_argument("axis '" + s.name + "' (AXIS_CIP_DRIVE) has no valid bus");
      s.drive.cycle_ns = spec_.period_ns;
      axes_[a].bus = s.bus;
      axes_[a].proxy = &buses_[static_cast<std::size_t>(s.bus)].network->add_drive(s.drive);
    }
  }
  if (spec_.coordinate_systems.size() > motion::kMaxCoordSystems)
    throw std::invalid_argument("more than " + std::to_string(motion::kMaxCoordSystems) + " coordinate systems");
  for (std::size_t c = 0; c < spec_.coordinate_systems.size(); ++c) {
    const CoordSystemSpec& cs = spec_.coordinate_systems[c];
    if (!planner_.configure_coordinate_system(static_cast<motion::CoordSystemId>(c), cs.config))
      throw std::invalid_argument("coordinate system '" + cs.name + "': the planner rejected its configuration");
  }
}

std::optional<motion::AxisId> Controller::axis_id(std::string_view name) const {
  for (std::size_t a = 0; a < spec_.axes.size(); ++a)
    if (spec_.axes[a].name == name) return static_cast<motion::AxisId>(a);
  return std::nullopt;
}

namespace {
std::string lower_name(std::string_view s) {
  std::string o(s);
  for (char& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}
}  // namespace

std::optional<motion::ControlId> Controller::control_id(std::string_view name_in) {
  const std::string name = lower_name(name_in);  // Logix tag names are case-insensitive
  std::lock_guard lock(names_mu_);
  if (auto it = control_names_.find(name); it != control_names_.end()) return it->second;
  if (control_names_.size() >= motion::kMaxControlTags) return std::nullopt;
  const auto id = static_cast<motion::ControlId>(control_names_.size());
  control_names_.emplace(name, id);
  controls_in_use_.store(control_names_.size(), std::memory_order_release);
  return id;
}

std::optional<motion::CoordSystemId> Controller::coordinate_system_id(std::string_view name) const {
  const std::string want = lower_name(name);
  for (std::size_t c = 0; c < spec_.coordinate_systems.size(); ++c)
    if (lower_name(spec_.coordinate_systems[c].name) == want) return static_cast<motion::CoordSystemId>(c);
  return std::nullopt;
}

std::optional<std::uint16_t> Controller::cam_id(std::string_view name) const {
  const std::string want = lower_name(name);
  for (std::size_t c = 0; c < spec_.cams.size(); ++c)
    if (lower_name(spec_.cams[c].name) == want) return static_cast<std::uint16_t>(c);
  if (const auto a = find_array(name); a && a->type == ArraySpec::Type::kCamProfile) return a->id;
  return std::nullopt;
}

std::optional<motion::ControlId> Controller::find_control(std::string_view name_in) const {
  const std::string name = lower_name(name_in);
  std::lock_guard lock(names_mu_);
  if (auto it = control_names_.find(name); it != control_names_.end()) return it->second;
  return std::nullopt;
}

std::vector<std::pair<std::string, motion::ControlId>> Controller::controls() const {
  std::lock_guard lock(names_mu_);
  return {control_names_.begin(), control_names_.end()};
}

std::uint64_t Controller::submit(const Command& c) {
  std::lock_guard lock(names_mu_);
  if (!commands_.try_push(Queued{c, next_seq_})) return 0;
  return next_seq_++;
}

void Controller::record(std::uint8_t bus, const can::TimedFrame& f, bool tx) noexcept {
  if (!trace_on_.load(std::memory_order_relaxed)) return;
  if (!trace_.try_push(TraceRecord{f, bus, tx})) ++trace_dropped_;
}

void Controller::emit(const Event& e) noexcept { (void)events_.try_push(e); }

// A bus's event (rare): out of line, so that receive() builds no Event in
// the cycles that have none.
[[gnu::cold, gnu::noinline]] void Controller::emit_bus_event(std::size_t b, Event::Kind k, std::uint64_t value,
                                                             can::BusState state) noexcept {
  Event e;
  e.kind = k;
  e.bus = static_cast<std::uint8_t>(b);
  e.cycle = cycle_index_;
  e.value = value;
  e.bus_state = state;
  emit(e);
}

// Called once per bus per cycle from cycle() only: inlined there.
[[gnu::always_inline]] inline void Controller::receive(std::size_t b, std::int64_t now_ns) noexcept {
  BusRt& bus = buses_[b];
  // Bus events first: a bus-off reported now applies to this cycle's feedback.
  std::array<can::BusEvent, 16>& ev = bus_ev_;
  bool link_went_down = false, link_came_up = false;
  for (std::size_t n; (n = bus.transport->poll_events(ev)) > 0;) {
    for (std::size_t i = 0; i < n; ++i) {
      if (ev[i].kind == can::BusEvent::Kind::kLinkDown) {
        link_went_down = true;
        emit_bus_event(b, Event::Kind::kLinkDown, ev[i].detail);
      } else if (ev[i].kind == can::BusEvent::Kind::kLinkUp) {
        link_came_up = true;
      } else if (ev[i].kind == can::BusEvent::Kind::kStateChanged || ev[i].kind == can::BusEvent::Kind::kRestarted) {
        emit_bus_event(b, Event::Kind::kBusState, 0, ev[i].state);
      } else if (ev[i].kind == can::BusEvent::Kind::kErrorFrame) {
        // Reported when the classes change, else at most once a second (a
        // bus without ACK sends one error frame per frame sent).
        const auto cls = static_cast<std::uint32_t>(ev[i].detail);
        if (cls != bus.err_classes || now_ns - bus.err_reported_ns >= 1'000'000'000) {
          bus.err_classes = cls;
          bus.err_reported_ns = now_ns;
          emit_bus_event(b, Event::Kind::kBusError, cls);
        }
      }
    }
    if (n < ev.size()) break;
  }
  const bool was_off = bus.bus_off;
  bus.bus_off = bus.transport->state() == can::BusState::kBusOff;
  if (was_off && !bus.bus_off) {
    // Back from bus-off: the drives may have faulted or rebooted meanwhile
    // (their watch of the master expired): boot and configure them again.
    bus.network->reboot_all();
    emit_bus_event(b, Event::Kind::kBusRecovered);
  }
  // The interface went down (a send or receive failed with ENETDOWN): the
  // axes fault as at bus-off, in this cycle even if it is already up again;
  // once it is up, the drives have missed SYNCs and heartbeats (their watch
  // of the master may have expired): boot and configure them again.
  const bool was_down = bus.link_down;
  bus.link_down = link_went_down || bus.transport->link_down();
  if (!bus.link_down && (was_down || link_came_up)) [[unlikely]] {
    bus.network->reboot_all();
    emit_bus_event(b, Event::Kind::kLinkUp);
  }
  for (std::size_t n; (n = bus.transport->receive(rx_)) > 0;) {
    const bool tracing = trace_on_.load(std::memory_order_relaxed);
    for (std::size_t i = 0; i < n; ++i) {
      if (tracing) record(static_cast<std::uint8_t>(b), rx_[i], false);
      bus.network->on_frame(rx_[i]);
    }
    if (n < rx_.size()) break;
  }
}

// Called once per axis per cycle from cycle() only: inlined there (no call per axis).
[[gnu::always_inline]] inline void Controller::feedback(std::size_t a) noexcept {
  AxisRt& ax = axes_[a];
  motion::AxisFeedback& f = fb_[a];
  if (ax.proxy == nullptr) return;  // virtual axis: the planner ignores feedback
  const cia402::DriveProxy& p = *ax.proxy;
  const cia402::Feedback& d = p.feedback();
  const bool operational = p.phase() == cia402::Phase::kOperational;
  ax.vel = ax.conv / p.velocity_counts();  // as known now (read at boot when the configuration could not tell)
  ax.acc = ax.conv / p.acceleration_counts();
  f.position = static_cast<double>(d.position) / ax.conv;  // 64-bit counts (DriveProxy unwraps 0x6064)
  // 0x606C in the drive's velocity unit; a unit that cannot be known is not read.
  const bool vel_mapped = p.pdos().tpdo_count > 1 && ax.vel == ax.vel;
  if (vel_mapped) {
    f.velocity = static_cast<double>(d.velocity) / ax.vel;
  } else if (ax.have_prev) {  // differentiate when 0x606C is not mapped
    f.velocity = static_cast<double>(d.position - ax.prev_counts) / ax.conv / period_s();
  }
  ax.prev_counts = d.position;
  ax.have_prev = d.tpdo_count > 0;
  // Operation enabled that may predate a command out of it (the drive has not
  // shown the transition yet, DriveProxy::leaving_enabled) is not Enabled:
  // an MSO then waits for the drive to leave it and be enabled again.
  // In CSP, Operation enabled without statusword bit 12 (the drive does not
  // follow the command yet, DriveProxy::awaiting_follow()) is not Enabled
  // either: MSO ends only once the drive follows.
  f.drive = drive_state_of(p.state(), operational && !p.leaving_enabled() && !p.awaiting_follow());
  // Statusword bits 7, 11 and 13 (by mode): one event on each rising edge.
  if (operational) {
    const cia402::StatusBits sb = cia402::decode_status_bits(d.statusword, static_cast<cia402::Mode>(d.mode_display));
    const auto bits = static_cast<std::uint8_t>((sb.warning ? 1u : 0u) | (sb.internal_limit ? 2u : 0u) |
                                                (sb.following_error ? 4u : 0u));
    if (const auto rising = static_cast<std::uint8_t>(bits & ~ax.status_bits); rising != 0) [[unlikely]]
      emit_status_bits(a, rising);
    ax.status_bits = bits;
  } else {
    ax.status_bits = 0;  // reported again if still set once the drive is back
  }
  using FK = cia402::FailureKind;
  const FK kind = p.failure().kind;
  // A refused mode switch (0x6061 never showed the mode, drive.timeouts.mode_switch_ms)
  // and a drive that reset itself while running reach the planner as a drive
  // fault, handled per its exception action (MAFR clears it).
  f.drive_fault = f.drive == motion::DriveState::Fault || kind == FK::kModeSwitchTimeout || kind == FK::kUnexpectedBootUp;
  f.emcy_code = p.last_emcy_code();
  // A lost heartbeat and a node out of NMT operational: the node is lost
  // (AxisFault.ModuleFault) while the condition lasts.
  f.node_lost = p.heartbeat_lost() || p.left_operational();
  f.transition_timeout = kind == FK::kTransitionTimeout;
  if (operational) {
    f.link = motion::DriveLink::Up;
  } else if (p.phase() == cia402::Phase::kFailed) {
    // No answer at all (no boot-up, no SDO response, no TPDO) is a missing
    // module; an answer that refuses a write is a configuration fault.
    const bool no_answer = kind == FK::kBootTimeout || kind == FK::kStartTimeout ||
                           (kind == FK::kSdoAbort && p.failure().sdo_abort == static_cast<std::uint32_t>(canopen::SdoAbort::kTimeout));
    f.link = no_answer ? motion::DriveLink::NoModule : motion::DriveLink::ConfigFailed;
  } else {
    f.link = motion::DriveLink::Configuring;
  }
  const BusRt& bus = buses_[static_cast<std::size_t>(ax.bus)];
  f.bus_off = bus.bus_off || bus.link_down;  // nothing reaches the drive either way (exception bus_off)
  // The proxy's view of the homing it started: never a bit left from an
  // earlier homing (DriveProxy::start_homing).
  using HR = cia402::HomingResult;
  const HR hr = p.homing_result();
  f.homing_attained = hr == HR::kCompleted;
  f.homing_error = hr == HR::kError || hr == HR::kTimeout || hr == HR::kRefused;
  f.homing_exerr = hr == HR::kRefused ? std::int8_t{3} : std::int8_t{16};  // invalid value / device in wrong state
  // Reported when recorded, and again when it gains detail (an EMCY that
  // came later, the statusword read from a node out of NMT operational).
  if (p.failed() && (!ax.failure_reported || ax.failure_rev != p.failure_revision())) {
    Event e;
    e.kind = Event::Kind::kDriveFailed;
    e.bus = static_cast<std::uint8_t>(ax.bus);
    e.axis = static_cast<std::int16_t>(a);
    e.failure = p.failure();
    e.cycle = cycle_index_;
    emit(e);
  }
  ax.failure_reported = p.failed();
  ax.failure_rev = p.failure_revision();
}

// A statusword bit's rising edge (rare): out of line, one event per bit
// (`rising`: 1 bit 7 warning, 2 bit 11 internal limit, 4 bit 13 following error).
[[gnu::cold, gnu::noinline]] void Controller::emit_status_bits(std::size_t a, std::uint8_t rising) noexcept {
  const AxisRt& ax = axes_[a];
  const cia402::DriveProxy& p = *ax.proxy;
  constexpr std::array<std::uint8_t, 3> kBit{7, 11, 13};
  for (std::size_t k = 0; k < kBit.size(); ++k) {
    if (!(rising & (1u << k))) continue;
    Event e;
    e.kind = Event::Kind::kDriveStatusBit;
    e.bus = static_cast<std::uint8_t>(ax.bus);
    e.axis = static_cast<std::int16_t>(a);
    e.value = kBit[k];
    e.cycle = cycle_index_;
    e.drive = Event::DriveView{p.phase(), p.state(), p.feedback().statusword, p.node()};
    e.mode_display = p.feedback().mode_display;
    emit(e);
  }
}

// Called once per axis per cycle from cycle() only: inlined there (no call per axis).
[[gnu::always_inline]] inline void Controller::apply(std::size_t a, const motion::AxisOutput& out) noexcept {
  AxisRt& ax = axes_[a];
  if (ax.proxy == nullptr) return;
  cia402::DriveProxy& p = *ax.proxy;
  if (out.fault_reset) p.fault_reset();
  const bool wants_enabled = p.wanted() == cia402::State::kOperationEnabled;
  if (out.enable && !wants_enabled && !p.failed()) p.enable();
  if (!out.enable && wants_enabled) p.disable();
  auto mode = static_cast<cia402::Mode>(static_cast<std::int8_t>(out.mode));
  if (mode == cia402::Mode::kCsp) mode = p.position_mode();  // IP drives (drive.mode: ip) take the position in mode 7
  if (mode != p.mode() && (cia402::is_position_stream(mode) || mode == cia402::Mode::kCsv || mode == cia402::Mode::kCst))
    (void)p.set_mode(mode);
  // Homing (MAH on a CIP drive): mode 6 and the parameters on the planner's
  // rising edge (retried next cycle when the SDO queue is full), dropped on its falling edge.
  const bool homing = out.homing_start && out.mode == motion::DriveMode::Homing;
  if (homing && !ax.homing_out) {
    // Speeds (0x6099) and acceleration (0x609A) in the drive's units.
    auto u32 = [&](double v, double factor) noexcept -> std::uint32_t {
      const double c = round_half_away(std::fabs(v) * factor);
      return !(c == c) ? 0u : (c > 4294967295.0 ? 0xFFFFFFFFu : static_cast<std::uint32_t>(c));
    };
    cia402::HomingParams hp;
    hp.method = out.homing.method;
    hp.speed_search = u32(out.homing.speed_search, ax.vel);
    hp.speed_zero = u32(out.homing.speed_zero, ax.vel);
    hp.accel = u32(out.homing.accel, ax.acc);
    hp.write_offset = out.homing.write_offset;
    const double off = round_half_away(out.homing.offset * ax.conv);
    hp.offset = static_cast<std::int32_t>(std::clamp(off == off ? off : 0.0, -2147483648.0, 2147483647.0));
    ax.homing_out = p.start_homing(hp);
  } else if (!homing && ax.homing_out) {
    p.cancel_homing();
    ax.homing_out = false;
  }
  // Targets in drive units, saturated to the object's range.
  auto sat32 = [](double v) noexcept -> std::int32_t {
    if (!(v == v)) return 0;
    v = round_half_away(v);
    if (v > std::numeric_limits<std::int32_t>::max()) return std::numeric_limits<std::int32_t>::max();
    if (v < std::numeric_limits<std::int32_t>::min()) return std::numeric_limits<std::int32_t>::min();
    return static_cast<std::int32_t>(v);
  };
  // The position in the drive frame of 64-bit counts (0x607A carries its
  // low 32 bits: DriveProxy); a command that is not a number holds the last
  // target. Beyond 2^62 counts (never reached: 2^53 is the last exact double,
  // README "Positions past 32 bits") it is held at that bound.
  const double pc = round_half_away(out.position * ax.conv);
  if (pc == pc) p.set_target_position(static_cast<std::int64_t>(std::clamp(pc, -0x1p62, 0x1p62)));
  p.set_target_velocity(sat32(out.velocity * ax.vel));  // drive velocity units; NaN (unknown): 0
  const double t = out.torque == 0.0 ? 0.0 : round_half_away(out.torque);  // CSP and CSV axes: 0
  p.set_target_torque(static_cast<std::int16_t>(t > 32767 ? 32767 : (t < -32768 ? -32768 : t)));
}

void Controller::cycle(std::int64_t now_ns) noexcept {
  receive_all(now_ns);                                       // 1
  if (spec_.sync_first) sync_all(now_ns);                    // 2
  for (std::size_t a = 0; a < axes_.size(); ++a) feedback(a);  // 3
  take_commands(now_ns);                                     // 4
  plan();                                                    // 5
  for (std::size_t a = 0; a < axes_.size(); ++a) apply(a, out_[a]);  // 6
  send_all(now_ns);                                          // 7
  if (halt_ == Halt::kDisarming) advance_halt(now_ns);
  publish(now_ns);                                           // 8
  ++cycle_index_;
  cycle_.store(cycle_index_, std::memory_order_release);
}

// 2. SYNC first (ControllerSpec::sync_first): right after the reads and
// before anything whose time varies (planner, RPDOs), so that the SYNC
// leaves at a nearly fixed offset from the wake-up. The reads come first so
// that every frame read in a cycle arrived before its SYNC: the TPDOs read
// answer the last cycle's SYNC, and those answering this one are read in the
// next cycle, however fast the drive answers. (Reading after the SYNC, a
// drive that answered before the reads had its TPDO taken one cycle early
// and counted missed in the next: in the VM on vcan 2.7-5.6 % of TPDOs came
// within 250 us of their SYNC, and TpdoMissed doubled.)
void Controller::sync_all(std::int64_t now_ns) noexcept {
  for (std::size_t b = 0; b < buses_.size() && halt_ != Halt::kHalted; ++b) {
    auto& sink = static_cast<RecordingSink&>(*buses_[b].sink);
    sink.now_ns = now_ns;
    buses_[b].network->sync(sink);
  }
}

// 1. Drain received frames on every bus; heartbeat timeouts and node events
// reach the drive proxies now, before the planner reads them.
void Controller::receive_all(std::int64_t now_ns) noexcept {
  for (std::size_t b = 0; b < buses_.size(); ++b) receive(b, now_ns);
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    buses_[b].network->update(now_ns);
    canopen::NodeEvent ne;
    while (buses_[b].network->poll_event(ne)) {
      Event e;
      e.kind = Event::Kind::kNode;
      e.bus = static_cast<std::uint8_t>(b);
      e.node = ne;
      e.cycle = cycle_index_;
      emit(e);
    }
  }
}

// 4. Pending commands, in submission order: at most kMaxRequestsPerCycle
// instructions; an array write after an instruction waits for the next cycle.
void Controller::take_commands(std::int64_t now_ns) noexcept {
  nreq_ = 0;
  bool deferred = false;
  for (;;) {
    Queued& q = popped_;
    if (held_) {
      q = *held_;
      held_.reset();
    } else if (!commands_.try_pop(q)) {
      break;
    }
    if (must_wait(q.command)) {
      held_ = q;
      deferred = true;
      break;
    }
    std::visit([this, now_ns](const auto& c) noexcept { take(c, now_ns); }, q.command);
    done_seq_ = q.seq;
  }
  if (deferred) ++deferred_;
}

bool Controller::must_wait(const Command& c) const noexcept {
  if (std::holds_alternative<cmd::WriteArray>(c)) return nreq_ > 0;  // program order: the instruction runs first
  if (std::holds_alternative<cmd::Instruction>(c)) return nreq_ == requests_.size();
  return false;
}

void Controller::take(const cmd::Instruction& c, std::int64_t) noexcept { requests_[nreq_++] = c.request; }

void Controller::take(const cmd::ResetControl& c, std::int64_t) noexcept { planner_.reset_control(c.control); }

void Controller::take(const cmd::EnableDrives&, std::int64_t) noexcept {
  for (auto& b : buses_) b.network->enable_all();
}

void Controller::take(const cmd::ControllerMode& c, std::int64_t) noexcept { planner_.set_controller_mode(c.mode); }

void Controller::take(const cmd::DirectCommand& c, std::int64_t) noexcept {
  if (c.axis >= spec_.axes.size()) return;
  // DirectCommandVelocity is the MDS command in velocity mode and the SLAT
  // speed reference in torque mode; DirectCommandTorque only exists in torque mode.
  const bool torque_mode = spec_.axes[c.axis].config.direct_mode == motion::AxisConfig::DirectMode::Torque;
  const auto id = static_cast<motion::AxisId>(c.axis);
  if (c.torque) {
    if (torque_mode) (void)planner_.set_direct_command(id, c.value);
  } else if (torque_mode) {
    (void)planner_.set_direct_velocity_command(id, c.value);
  } else {
    (void)planner_.set_direct_command(id, c.value);
  }
}

// The controlled stop, first step: the drives stop watching the master's
// heartbeat, or they fault (EMCY 0x8130) once the master is gone.
void Controller::take(const cmd::PreOperational&, std::int64_t now_ns) noexcept {
  if (halt_ != Halt::kRunning) return;
  for (auto& ax : axes_) {
    if (ax.proxy == nullptr || ax.proxy->config().consumer_heartbeat_ms == 0) continue;  // not armed
    auto& sdo = buses_[static_cast<std::size_t>(ax.bus)].network->master().sdo(ax.proxy->node());
    (void)sdo.download_value<std::uint32_t>(0x1016, 1, 0, kDisarmTag);
  }
  halt_ = Halt::kDisarming;
  halt_since_ns_ = now_ns;
}

// 5. Plan.
void Controller::plan() noexcept {
  motion::Input in;
  in.cycle = cycle_index_;
  in.feedback = std::span<const motion::AxisFeedback>(fb_.data(), axes_.size());
  in.requests = std::span<const motion::Request>(requests_.data(), nreq_);
  motion::Output out;
  out.axes = std::span<motion::AxisOutput>(out_.data(), axes_.size());
  (void)planner_.update(in, out);
}

// 7. RPDOs, then SYNC, per bus (the drive state machines stepped in apply());
// with sync_first the RPDOs only (the SYNC went out in sync_all()).
void Controller::send_all(std::int64_t now_ns) noexcept {
  for (std::size_t b = 0; b < buses_.size() && halt_ != Halt::kHalted; ++b) {
    auto& sink = static_cast<RecordingSink&>(*buses_[b].sink);
    sink.now_ns = now_ns;
    buses_[b].network->cycle(now_ns, sink);
  }
}

// The controlled stop, second step: once the 0x1016 writes are answered (or
// after kDisarmTimeoutNs), NMT pre-operational after this cycle's SYNC, so
// its TPDOs still come back; then silence. (With sync_first the RPDOs sent
// after that SYNC are never applied: no SYNC follows them.)
void Controller::advance_halt(std::int64_t now_ns) noexcept {
  bool done = true;
  for (auto& ax : axes_) {
    if (ax.proxy == nullptr) continue;
    auto& sdo = buses_[static_cast<std::size_t>(ax.bus)].network->master().sdo(ax.proxy->node());
    canopen::SdoResult r;
    while (sdo.poll_tag(kDisarmTag, r)) {
    }
    done = done && sdo.idle();
  }
  if (done || now_ns - halt_since_ns_ > kDisarmTimeoutNs) {
    for (auto& b : buses_) b.network->master().send_nmt(canopen::NmtCommand::kEnterPreOperational, 0, *b.sink);
    halt_ = Halt::kHalted;
  }
}

void Controller::publish(std::int64_t now_ns) noexcept {
  (void)now_ns;
  Status& s = snapshot_->write_slot();
  s.cycle = cycle_index_;
  s.time_ns = static_cast<std::int64_t>(cycle_index_) * spec_.period_ns;
  s.done_seq = done_seq_;
  s.axis_count = static_cast<std::uint16_t>(axes_.size());
  s.bus_count = static_cast<std::uint8_t>(buses_.size());
  const bool tele = telemetry_on_.load(std::memory_order_relaxed);
  for (std::size_t a = 0; a < axes_.size(); ++a) {
    const motion::AxisTag& tag = planner_.axis(static_cast<motion::AxisId>(a));
    const double err = std::abs(tag.position_error);
    if (err > max_err_[a]) max_err_[a] = err;
    // Each exception the axis latched as a fault this cycle, once (MAFR/MASR
    // clear them; a fault latched again is reported again).
    AxisRt& ax = axes_[a];
    if (const std::uint32_t fresh = tag.exception_faults & ~ax.exception_faults; fresh != 0) {
      for (std::size_t k = 0; k < tag.exception_fault_values.size(); ++k) {
        if (!(fresh & (1u << k))) continue;
        Event e;
        e.kind = Event::Kind::kAxisFault;
        e.axis = static_cast<std::int16_t>(a);
        e.value = k;
        e.detail = tag.exception_fault_values[k];
        e.cycle = cycle_index_;
        emit(e);
      }
    }
    ax.exception_faults = tag.exception_faults;
    // An instruction that waited on the drive and ended with an error: once each.
    if (tag.drive_wait_errors != ax.drive_wait_errors) {
      ax.drive_wait_errors = tag.drive_wait_errors;
      Event e;
      e.kind = Event::Kind::kDriveWait;
      e.axis = static_cast<std::int16_t>(a);
      e.bus = static_cast<std::uint8_t>(ax.bus < 0 ? 0 : ax.bus);
      e.wait = tag.last_drive_wait;
      e.cycle = cycle_index_;
      if (const cia402::DriveProxy* p = ax.proxy) {
        e.drive = Event::DriveView{p->phase(), p->state(), p->feedback().statusword, p->node()};
        e.failure = p->failure();
      }
      emit(e);
    }
    if (tele) {
      const Sample smp{cycle_index_,       static_cast<std::uint16_t>(a), tag.command_position,
                       tag.actual_position, tag.command_velocity,      tag.actual_velocity,
                       tag.motion_status,   tag.axis_status};
      if (!telemetry_.try_push(smp)) ++telemetry_dropped_;
    }
  }
  // The transports can change between cycles (the simulated drives run after
  // the controller's cycle): their part is taken now.
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    s.buses[b].state = buses_[b].transport->state();
    s.buses[b].counters = buses_[b].transport->counters();
    s.buses[b].send_rejected = buses_[b].rejected;
    s.buses[b].syncs_sent = buses_[b].network->master().syncs_sent();
    s.buses[b].syncs_refused = buses_[b].network->master().syncs_refused();
  }
  s.trace_dropped = trace_dropped_;
  s.telemetry_dropped = telemetry_dropped_;
  s.commands_deferred = deferred_;
  s.halted = halt_ == Halt::kHalted;
  s.mode = planner_.controller_mode();
  // Control tags handed out so far (requests can only name those).
  publish_nctl_ = controls_in_use_.load(std::memory_order_acquire);
  publish_pending_ = true;
  if (!deferred_publish_) finish_publish();
}

void Controller::finish_publish() const noexcept {
  // Everything below changes only in cycle(): with deferred publishing it is
  // copied when read_status() is called, before the next cycle.
  Status& s = snapshot_->write_slot();
  for (std::size_t a = 0; a < axes_.size(); ++a) {
    AxisSnapshot& x = s.axes[a];
    x.tag = planner_.axis(static_cast<motion::AxisId>(a));
    x.max_abs_position_error = max_err_[a];
    if (const cia402::DriveProxy* p = axes_[a].proxy) {
      x.phase = p->phase();
      x.drive_state = p->state();
      x.statusword = p->feedback().statusword;
      x.controlword = p->controlword();
      x.target_counts = p->target_position();
      x.actual_counts = p->feedback().position;
      x.mode_display = p->feedback().mode_display;
      x.last_emcy = p->last_emcy_code();
      x.tpdo_missed = p->feedback().tpdo_missed;
      x.failure = p->failure();
    }
  }
  for (std::size_t c = 0; c < publish_nctl_; ++c) s.controls[c] = planner_.control(static_cast<motion::ControlId>(c));
  for (std::size_t c = 0; c < cams_.size(); ++c) s.cam_status[c] = cams_[c]->status();
  for (std::size_t c = 0; c < spec_.coordinate_systems.size(); ++c)
    s.systems[c] = planner_.coordinate_system(static_cast<motion::CoordSystemId>(c));
  std::copy(real_store_.begin(), real_store_.end(), s.real_values.begin());  // <= kMaxRealElements
  snapshot_->commit();
  publish_pending_ = false;
}

}  // namespace canmotion::rt
