#pragma once
/// \file
/// Real-time set-up of the cyclic thread: mlockall, stack prefault,
/// SCHED_FIFO priority, CPU affinity and the PM QoS CPU latency request
/// (/dev/cpu_dma_latency, rt/pm_qos.hpp). Each step reports its own error.
/// A step that is not permitted (non-root, container, RLIMIT_RTPRIO 0,
/// RLIMIT_MEMLOCK too small) does not stop the engine: the report says so and
/// warning() gives ONE message that says what is lost and how to grant it.
/// None of this is realtime-safe: it runs once, before the first cycle.

#include <sched.h>
#include <sys/resource.h>
#include <sys/types.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>

namespace canmotion::rt {

/// What to do to make the calling thread real-time.
struct RtSettings {
  /// mlockall(MCL_CURRENT | MCL_FUTURE): no page faults in the cycle.
  bool lock_memory = true;
  /// Bytes of stack touched once so they are mapped (and locked). 0 = skip.
  /// At most kMaxPrefaultBytes.
  std::size_t prefault_stack_bytes = 256 * 1024;
  /// SCHED_FIFO priority 1..99 for the calling thread; 0 = leave the
  /// scheduling policy alone (normal SCHED_OTHER thread).
  int priority = 80;
  /// CPU the calling thread is pinned to; -1 = no affinity.
  int cpu = -1;
  /// PM QoS: hold /dev/cpu_dma_latency at this many microseconds while the
  /// loop runs (0 = keep the CPUs out of every idle state deeper than the
  /// shallowest, as cyclictest does); -1 = leave the CPU idle states alone.
  /// The request is released when the loop ends (release_rt_settings()).
  std::int32_t cpu_dma_latency_us = 0;

  /// Bound on prefault_stack_bytes: the default thread stack is 8 MiB.
  static constexpr std::size_t kMaxPrefaultBytes = 4 * 1024 * 1024;

  /// Nothing real-time at all (`--sim`, tests).
  static RtSettings none() noexcept { return RtSettings{false, 0, 0, -1, -1}; }
};

/// The system calls the set-up makes. Each returns 0 or an errno value.
/// Tests replace them to exercise the "not permitted" paths deterministically.
struct RtSyscalls {
  int (*mlockall)(int flags) = nullptr;
  /// Applies to the calling thread (tid 0), like sched_setscheduler(0, ...).
  int (*set_fifo)(int priority) = nullptr;
  /// Applies to the calling thread (tid 0), like sched_setaffinity(0, ...).
  int (*set_affinity)(const cpu_set_t* set) = nullptr;
  /// Reads the calling thread's allowed CPUs (for messages and validation).
  int (*get_affinity)(cpu_set_t* set) = nullptr;
  /// getrlimit(); used only to explain a failure.
  int (*get_rlimit)(int resource, rlimit* out) = nullptr;
  /// Opens /dev/cpu_dma_latency and writes `us` (open_cpu_latency_request()):
  /// returns the descriptor to keep open (>= 0) or -errno.
  int (*hold_cpu_latency)(std::int32_t us) = nullptr;
  /// Closes what hold_cpu_latency returned: the request is dropped.
  void (*release_cpu_latency)(int fd) = nullptr;

  /// The real Linux calls.
  static RtSyscalls real() noexcept;
};

/// The set-up steps, in the order they run.
enum class RtStep : std::uint8_t { lock_memory = 0, prefault_stack = 1, scheduler = 2, affinity = 3, cpu_latency = 4 };

/// Printable name of a step ("mlockall", "stack prefault", "SCHED_FIFO", "CPU affinity", "cpu_dma_latency").
std::string_view to_string(RtStep step) noexcept;

/// What happened to one step.
struct RtStepOutcome {
  RtStep step = RtStep::lock_memory;
  bool requested = false;   ///< false: the settings did not ask for it
  std::error_code error;    ///< empty: done (or not requested)

  /// The step failed because the process lacks a privilege or a limit is too
  /// low (EPERM, EACCES; for mlockall also ENOMEM/EAGAIN: RLIMIT_MEMLOCK), or
  /// (cpu_dma_latency) the device is not there (ENOENT, ENODEV, ENXIO, EROFS,
  /// ENOSYS: a kernel without it, a container that hides it).
  bool not_permitted() const noexcept;
  /// Requested and done.
  bool done() const noexcept { return requested && !error; }
};

/// The result of apply_rt_settings(): one outcome per step.
struct RtSetupReport {
  std::array<RtStepOutcome, 5> steps{};
  RtSettings settings{};
  /// Soft limits read when a step failed (for the message); -1 = unknown,
  /// RLIM_INFINITY is reported as -2.
  long long rlimit_rtprio = -1;
  long long rlimit_memlock = -1;
  /// Allowed CPUs, e.g. "0-1" (filled when affinity failed).
  std::string allowed_cpus;
  /// The /dev/cpu_dma_latency descriptor apply_rt_settings() opened (-1: none).
  /// Its owner closes it with release_rt_settings() after the last cycle;
  /// CyclicExecutive takes it over (its setup_report() shows -1).
  int cpu_latency_fd = -1;

  const RtStepOutcome& outcome(RtStep step) const noexcept {
    return steps[static_cast<std::size_t>(step)];
  }
  /// Every requested step was done.
  bool realtime() const noexcept;
  /// At least one requested step was not permitted (the engine still runs).
  bool degraded() const noexcept;
  /// The first error that is NOT a permission problem (invalid priority,
  /// CPU that does not exist): the engine must not start. Empty if none.
  std::error_code hard_error() const noexcept;
  /// ONE message for the user when degraded(): what was not permitted, what
  /// that costs, and how to grant it. Empty when there is nothing to warn about.
  std::string warning() const;
  /// One line per requested step, "SCHED_FIFO 80: ok" / ": Operation not permitted".
  std::string describe() const;
  /// When hard_error() is set: one sentence naming the step, the value and
  /// what would be valid, e.g. "cannot pin the real-time thread to CPU 5:
  /// Invalid argument (allowed CPUs: 0-1)". Empty otherwise.
  std::string error_message() const;
};

/// Runs the steps in order on the CALLING thread (scheduler and affinity are
/// per thread, mlockall and the PM QoS request are per process). Every step
/// is attempted even if an earlier one failed. Not realtime-safe: call once
/// before the first cycle, and release_rt_settings() after the last.
RtSetupReport apply_rt_settings(const RtSettings& settings,
                                const RtSyscalls& sys = RtSyscalls::real());

/// Undoes what must not outlive the loop: drops the PM QoS request (closes
/// report.cpu_latency_fd). The memory lock, priority and affinity stay (they
/// end with the thread or process). Safe to call twice. Not realtime-safe.
void release_rt_settings(RtSetupReport& report, const RtSyscalls& sys = RtSyscalls::real()) noexcept;

}  // namespace canmotion::rt
