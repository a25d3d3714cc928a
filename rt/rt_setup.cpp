#include "rt/rt_setup.hpp"

#include "rt/pm_qos.hpp"

#include <alloca.h>
#include <fmt/format.h>
#include <sys/mman.h>

#include <unistd.h>

#include <cerrno>

namespace canmotion::rt {

namespace {

int real_mlockall(int flags) { return ::mlockall(flags) == 0 ? 0 : errno; }

int real_set_fifo(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  // tid 0 = the calling thread only (Linux): other threads keep SCHED_OTHER.
  return ::sched_setscheduler(0, SCHED_FIFO, &param) == 0 ? 0 : errno;
}

int real_set_affinity(const cpu_set_t* set) {
  return ::sched_setaffinity(0, sizeof(cpu_set_t), set) == 0 ? 0 : errno;
}

int real_get_affinity(cpu_set_t* set) {
  return ::sched_getaffinity(0, sizeof(cpu_set_t), set) == 0 ? 0 : errno;
}

int real_get_rlimit(int resource, rlimit* out) {
  return ::getrlimit(static_cast<__rlimit_resource_t>(resource), out) == 0 ? 0 : errno;
}

int real_hold_cpu_latency(std::int32_t us) { return open_cpu_latency_request(us); }

void real_release_cpu_latency(int fd) { close_cpu_latency_request(fd); }

std::error_code errc(int e) { return {e, std::generic_category()}; }

/// The device is missing (as opposed to present but refused).
bool device_missing(const std::error_code& e) {
  const int v = e.value();
  return v == ENOENT || v == ENODEV || v == ENXIO || v == ENOSYS;
}

/// Touch `bytes` of stack below the caller so the pages are mapped (and, after
/// mlockall(MCL_FUTURE), locked). noinline: the alloca'd area is released on
/// return but the pages stay mapped.
[[gnu::noinline]] void touch_stack(std::size_t bytes) {
  auto* area = static_cast<volatile unsigned char*>(alloca(bytes));
  constexpr std::size_t kPage = 4096;
  for (std::size_t i = 0; i < bytes; i += kPage) {
    area[i] = 0;
  }
  area[bytes - 1] = 0;
}

long long soft_limit(const RtSyscalls& sys, int resource) {
  rlimit lim{};
  if (sys.get_rlimit == nullptr || sys.get_rlimit(resource, &lim) != 0) {
    return -1;
  }
  if (lim.rlim_cur == RLIM_INFINITY) {
    return -2;
  }
  return static_cast<long long>(lim.rlim_cur);
}

std::string cpu_list(const cpu_set_t& set) {
  std::string out;
  int run_start = -1;
  for (int cpu = 0; cpu <= CPU_SETSIZE; ++cpu) {
    const bool in = cpu < CPU_SETSIZE && CPU_ISSET(cpu, &set);
    if (in && run_start < 0) {
      run_start = cpu;
    } else if (!in && run_start >= 0) {
      if (!out.empty()) {
        out += ',';
      }
      out += run_start == cpu - 1 ? fmt::format("{}", run_start) : fmt::format("{}-{}", run_start, cpu - 1);
      run_start = -1;
    }
  }
  return out;
}

/// Path of the running program for the setcap example (falls back to canmotiond).
std::string self_path() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("/usr/local/bin/canmotiond");
}

std::string limit_text(long long v) {
  if (v == -2) {
    return "unlimited";
  }
  if (v < 0) {
    return "unknown";
  }
  return fmt::format("{}", v);
}

}  // namespace

RtSyscalls RtSyscalls::real() noexcept {
  RtSyscalls s;
  s.mlockall = &real_mlockall;
  s.set_fifo = &real_set_fifo;
  s.set_affinity = &real_set_affinity;
  s.get_affinity = &real_get_affinity;
  s.get_rlimit = &real_get_rlimit;
  s.hold_cpu_latency = &real_hold_cpu_latency;
  s.release_cpu_latency = &real_release_cpu_latency;
  return s;
}

std::string_view to_string(RtStep step) noexcept {
  switch (step) {
    case RtStep::lock_memory: return "mlockall";
    case RtStep::prefault_stack: return "stack prefault";
    case RtStep::scheduler: return "SCHED_FIFO";
    case RtStep::affinity: return "CPU affinity";
    case RtStep::cpu_latency: return "cpu_dma_latency";
  }
  return "?";
}

bool RtStepOutcome::not_permitted() const noexcept {
  if (!requested || !error) {
    return false;
  }
  const int e = error.value();
  if (step == RtStep::cpu_latency) {
    // A latency optimisation, not a guarantee: only a value out of range
    // (EINVAL, a configuration error) stops the engine.
    return e != EINVAL;
  }
  if (e == EPERM || e == EACCES) {
    return true;
  }
  // mlockall: ENOMEM = more than RLIMIT_MEMLOCK without CAP_IPC_LOCK,
  // EAGAIN = some memory could not be locked.
  return step == RtStep::lock_memory && (e == ENOMEM || e == EAGAIN);
}

bool RtSetupReport::realtime() const noexcept {
  for (const auto& s : steps) {
    if (s.requested && s.error) {
      return false;
    }
  }
  return true;
}

bool RtSetupReport::degraded() const noexcept {
  for (const auto& s : steps) {
    if (s.not_permitted()) {
      return true;
    }
  }
  return false;
}

std::error_code RtSetupReport::hard_error() const noexcept {
  for (const auto& s : steps) {
    if (s.requested && s.error && !s.not_permitted()) {
      return s.error;
    }
  }
  return {};
}

std::string RtSetupReport::warning() const {
  if (!degraded()) {
    return {};
  }
  const bool sched = outcome(RtStep::scheduler).not_permitted();
  const bool lock = outcome(RtStep::lock_memory).not_permitted();
  const bool aff = outcome(RtStep::affinity).not_permitted();
  const bool qos = outcome(RtStep::cpu_latency).not_permitted();
  std::string lost;
  std::string grant;
  auto add = [](std::string& s, std::string_view part) {
    if (!s.empty()) {
      s += "; ";
    }
    s += part;
  };
  if (sched) {
    add(lost, fmt::format("SCHED_FIFO priority {} not permitted ({}, RLIMIT_RTPRIO={}): the cycle runs at "
                          "normal priority and any other process can delay it by milliseconds",
                          settings.priority, outcome(RtStep::scheduler).error.message(),
                          limit_text(rlimit_rtprio)));
  }
  if (lock) {
    add(lost, fmt::format("mlockall not permitted ({}, RLIMIT_MEMLOCK={} bytes): memory is not locked, "
                          "so page faults can stall a cycle",
                          outcome(RtStep::lock_memory).error.message(), limit_text(rlimit_memlock)));
  }
  if (aff) {
    add(lost, fmt::format("pinning to CPU {} not permitted ({}): the cycle may migrate between CPUs",
                          settings.cpu, outcome(RtStep::affinity).error.message()));
  }
  const std::error_code& qos_error = outcome(RtStep::cpu_latency).error;
  if (qos) {
    add(lost, fmt::format("{} ({}{}): the CPUs may sleep in deep idle states between cycles, which adds tens "
                          "to hundreds of microseconds to a wake-up",
                          device_missing(qos_error)
                              ? std::string("no PM QoS device /dev/cpu_dma_latency")
                              : fmt::format("holding /dev/cpu_dma_latency at {} us not permitted",
                                            settings.cpu_dma_latency_us),
                          qos_error.message(),
                          device_missing(qos_error) ? ": a kernel without CPU idle PM QoS, or a container that "
                                                      "does not pass the device in"
                                                    : ""));
  }
  if (sched || aff) {
    add(grant, "CAP_SYS_NICE");
  }
  if (lock) {
    add(grant, "CAP_IPC_LOCK");
  }
  std::string caps = grant;
  for (auto& c : caps) {
    if (c == ';') {
      c = ',';
    }
  }
  std::string limits;
  if (sched) {
    limits += fmt::format("LimitRTPRIO={} ", settings.priority);
  }
  if (lock) {
    limits += "LimitMEMLOCK=infinity ";
  }
  std::string conf;
  if (sched) {
    conf += fmt::format("'@canmotion - rtprio {}' ", settings.priority);
  }
  if (lock) {
    conf += "'@canmotion - memlock unlimited' ";
  }
  std::string how;
  if (sched || lock || aff) {
    how = fmt::format(
        "run as root, or give the program {} (e.g. setcap "
        "cap_sys_nice,cap_ipc_lock+ep {}), or under systemd set {}"
        "(see systemd/canmotiond.service), or add {}to /etc/security/limits.conf and log in again",
        caps, self_path(), limits, conf);
  }
  if (qos) {
    if (!how.empty()) {
      how += "; for /dev/cpu_dma_latency: ";
    }
    how += device_missing(qos_error)
               ? "use a kernel with CPU idle PM QoS, or pass the device into the container (e.g. docker run "
                 "--device /dev/cpu_dma_latency)"
               : "run as root, or let the service's group write the device with a udev rule "
                 "(systemd/60-canmotion-cpu-dma-latency.rules) and, under systemd, keep "
                 "BindPaths=-/dev/cpu_dma_latency and DeviceAllow=/dev/cpu_dma_latency rw "
                 "(see systemd/canmotiond.service)";
    how += " (canmotiond: controller.cpu_dma_latency_us: -1 stops asking)";
  }
  return fmt::format("real-time set-up incomplete, {}: {}. To grant it: {}.",
                     sched || lock || aff ? "the engine runs WITHOUT real-time guarantees"
                                          : "wake-up latency will be higher",
                     lost, how);
}

std::string RtSetupReport::describe() const {
  std::string out;
  for (const auto& s : steps) {
    if (!s.requested) {
      continue;
    }
    std::string what{to_string(s.step)};
    if (s.step == RtStep::scheduler) {
      what += fmt::format(" {}", settings.priority);
    } else if (s.step == RtStep::affinity) {
      what += fmt::format(" cpu {}", settings.cpu);
    } else if (s.step == RtStep::prefault_stack) {
      what += fmt::format(" {} KiB", settings.prefault_stack_bytes / 1024);
    } else if (s.step == RtStep::cpu_latency) {
      what += fmt::format(" {} us", settings.cpu_dma_latency_us);
    }
    out += fmt::format("{}: {}{}\n", what, s.error ? s.error.message() : "ok",
                       s.not_permitted() ? " (not permitted)" : "");
  }
  return out;
}

std::string RtSetupReport::error_message() const {
  for (const auto& s : steps) {
    if (!s.requested || !s.error || s.not_permitted()) {
      continue;
    }
    switch (s.step) {
      case RtStep::lock_memory:
        return fmt::format("mlockall failed: {}", s.error.message());
      case RtStep::prefault_stack:
        return fmt::format("stack prefault of {} bytes refused: at most {} bytes", settings.prefault_stack_bytes,
                           RtSettings::kMaxPrefaultBytes);
      case RtStep::scheduler:
        if (settings.priority < 1 || settings.priority > 99) {
          return fmt::format("SCHED_FIFO priority {} is out of range: valid priorities are 1..99 (0 = no real time)",
                             settings.priority);
        }
        return fmt::format("SCHED_FIFO priority {} failed: {}", settings.priority, s.error.message());
      case RtStep::affinity:
        return fmt::format("cannot pin the real-time thread to CPU {}: {} (allowed CPUs: {})", settings.cpu,
                           s.error.message(), allowed_cpus.empty() ? "unknown" : allowed_cpus);
      case RtStep::cpu_latency:
        return fmt::format("cpu_dma_latency request of {} us refused: {} (valid: 0 .. {} us, -1 = leave the CPU "
                           "idle states alone)",
                           settings.cpu_dma_latency_us, s.error.message(), kMaxCpuLatencyUs);
    }
  }
  return {};
}

RtSetupReport apply_rt_settings(const RtSettings& settings, const RtSyscalls& sys) {
  RtSetupReport r;
  r.settings = settings;
  for (std::size_t i = 0; i < r.steps.size(); ++i) {
    r.steps[i].step = static_cast<RtStep>(i);
  }

  auto& lock = r.steps[static_cast<std::size_t>(RtStep::lock_memory)];
  lock.requested = settings.lock_memory;
  if (lock.requested) {
    const int e = sys.mlockall ? sys.mlockall(MCL_CURRENT | MCL_FUTURE) : ENOSYS;
    lock.error = e ? errc(e) : std::error_code{};
  }

  auto& pre = r.steps[static_cast<std::size_t>(RtStep::prefault_stack)];
  pre.requested = settings.prefault_stack_bytes > 0;
  if (pre.requested) {
    if (settings.prefault_stack_bytes > RtSettings::kMaxPrefaultBytes) {
      pre.error = errc(EINVAL);
    } else {
      touch_stack(settings.prefault_stack_bytes);
    }
  }

  auto& sch = r.steps[static_cast<std::size_t>(RtStep::scheduler)];
  sch.requested = settings.priority != 0;
  if (sch.requested) {
    if (settings.priority < 1 || settings.priority > 99) {
      sch.error = errc(EINVAL);
    } else {
      const int e = sys.set_fifo ? sys.set_fifo(settings.priority) : ENOSYS;
      sch.error = e ? errc(e) : std::error_code{};
    }
  }

  auto& aff = r.steps[static_cast<std::size_t>(RtStep::affinity)];
  aff.requested = settings.cpu >= 0;
  if (aff.requested) {
    if (settings.cpu >= CPU_SETSIZE) {
      aff.error = errc(EINVAL);
    } else {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(static_cast<std::size_t>(settings.cpu), &set);
      const int e = sys.set_affinity ? sys.set_affinity(&set) : ENOSYS;
      aff.error = e ? errc(e) : std::error_code{};
    }
    if (aff.error) {
      cpu_set_t allowed;
      CPU_ZERO(&allowed);
      if (sys.get_affinity != nullptr && sys.get_affinity(&allowed) == 0) {
        r.allowed_cpus = cpu_list(allowed);
      }
    }
  }

  auto& qos = r.steps[static_cast<std::size_t>(RtStep::cpu_latency)];
  qos.requested = settings.cpu_dma_latency_us != -1;
  if (qos.requested) {
    if (settings.cpu_dma_latency_us < 0 || settings.cpu_dma_latency_us > kMaxCpuLatencyUs) {
      qos.error = errc(EINVAL);
    } else {
      const int fd = sys.hold_cpu_latency ? sys.hold_cpu_latency(settings.cpu_dma_latency_us) : -ENOSYS;
      if (fd >= 0) {
        r.cpu_latency_fd = fd;
      } else {
        qos.error = errc(-fd);
      }
    }
  }

  if (sch.error) {
    r.rlimit_rtprio = soft_limit(sys, RLIMIT_RTPRIO);
  }
  if (lock.error) {
    r.rlimit_memlock = soft_limit(sys, RLIMIT_MEMLOCK);
  }
  return r;
}

void release_rt_settings(RtSetupReport& report, const RtSyscalls& sys) noexcept {
  if (report.cpu_latency_fd >= 0 && sys.release_cpu_latency != nullptr) {
    sys.release_cpu_latency(report.cpu_latency_fd);
  }
  report.cpu_latency_fd = -1;
}

}  // namespace canmotion::rt
