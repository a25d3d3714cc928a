#pragma once
/// \file
/// The cyclic executive: runs one noexcept callable per period on the RT
/// thread (or, for `--sim`, on the calling thread with a virtual clock), with
/// absolute deadlines, overrun detection and statistics. See rt/README.md.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>

#include "rt/clock.hpp"
#include "rt/cycle_stats.hpp"
#include "rt/rt_setup.hpp"
#include "rt/sized_thread.hpp"

namespace canmotion::rt {

/// What the cycle callable is told about the cycle it runs.
struct CycleInfo {
  std::uint64_t cycle = 0;  ///< 0, 1, 2, ... executed cycles (planner time = cycle * period)
  Nanos deadline{0};        ///< absolute deadline this cycle was scheduled for
  Nanos wake{0};            ///< when the loop woke (wake - deadline = latency)
  Nanos period{0};          ///< configured period
  std::uint32_t missed = 0; ///< deadlines skipped just before this cycle (overrun policy)
};

/// Returned by the cycle callable.
enum class CycleResult : std::uint8_t {
  run_on = 0,  ///< keep going
  stop = 1,    ///< this was the last cycle (e.g. the script ended in --sim)
};

/// Why a run ended.
enum class StopReason : std::uint8_t {
  none = 0,        ///< still running / never ran
  requested = 1,   ///< request_stop()
  callable = 2,    ///< the callable returned CycleResult::stop
  max_cycles = 3,  ///< run(max_cycles) reached its count
};

/// Configuration of a CyclicExecutive.
struct ExecutiveConfig {
  /// Cycle period (> 0).
  Nanos period{1'000'000};
  /// Applied on the loop thread before the first cycle. Use RtSettings::none()
  /// for --sim.
  RtSettings rt{};
  /// The system calls used by the RT set-up (tests inject failures).
  RtSyscalls syscalls = RtSyscalls::real();
  /// Stack of the thread start() creates (run() uses the caller's). All of
  /// it is locked by mlockall; the cycle of 16 axes uses about 12 KiB. At
  /// least 2 x rt.prefault_stack_bytes is used, so that the prefault fits.
  std::size_t stack_bytes = 512 * 1024;
  /// Name of the RT thread (max 15 characters, pthread_setname_np).
  std::string thread_name = "canmotion-rt";
  /// Receives the ONE warning when the RT set-up was not permitted. Called on
  /// the thread that called start()/run(), never on the cyclic path. Empty =
  /// spdlog::warn.
  std::function<void(std::string_view)> warn;
  /// Optional hook called once on the loop thread after RT set-up and before
  /// the first cycle (tests use it to start counting allocations). Not on the
  /// cyclic path.
  std::function<void()> on_loop_start;
};

/// Runs a per-cycle callable with absolute deadlines.
///
/// Loop (each cycle k): sleep_until(deadline_k); wake = now(); call the
/// callable; end = now(); record latency = wake - deadline_k, execution time
/// = end - wake, period = wake - previous wake; then the next deadline is
/// deadline_k + period, unless the cycle ended after it (an OVERRUN): then
/// the missed deadlines are SKIPPED and the next deadline is the first one on
/// the original grid (start + n * period) after `end`. Cycles are never run
/// back to back to catch up. A stop request is honoured at the cycle boundary.
///
/// Threads: start()/join()/run() from one non-RT thread; request_stop(),
/// cycle_count(), running() and statistics() from any thread.
class CyclicExecutive {
 public:
  /// `clock` must outlive the executive.
  CyclicExecutive(ExecutiveConfig config, Clock& clock);
  /// Requests a stop and joins the RT thread if it runs.
  ~CyclicExecutive();
  CyclicExecutive(const CyclicExecutive&) = delete;
  CyclicExecutive& operator=(const CyclicExecutive&) = delete;

  /// Set the per-cycle callable (before start()/run()). F must be invocable
  /// as `CycleResult f(const CycleInfo&) noexcept` or `void f(const CycleInfo&)
  /// noexcept`; the executive keeps a copy. The callable runs on the loop
  /// thread and must follow the RT rules (no allocation, locks, logging,
  /// exceptions). Not realtime-safe (allocates the holder once).
  template <typename F>
  void set_cycle(F f) {
    static_assert(std::is_nothrow_invocable_v<F&, const CycleInfo&>,
                  "the cycle callable must be noexcept and take (const CycleInfo&)");
    using R = std::invoke_result_t<F&, const CycleInfo&>;
    static_assert(std::is_same_v<R, void> || std::is_same_v<R, CycleResult>,
                  "the cycle callable returns void or CycleResult");
    body_ = std::make_unique<Body<F>>(std::move(f));
  }

  /// Start the loop on a new thread. Returns after the RT set-up ran on it:
  /// an error if there is no callable, the executive already runs, or a
  /// set-up step failed for a reason other than permissions (hard_error()).
  /// A step that is not permitted logs ONE warning (config.warn) and the
  /// loop runs anyway. Not realtime-safe.
  std::error_code start();

  /// Run the loop on the calling thread until stop is requested, the callable
  /// returns stop, or `max_cycles` cycles ran (0 = no limit). Used with a
  /// VirtualClock for --sim and tests. Same RT set-up and warning as start().
  std::error_code run(std::uint64_t max_cycles = 0);

  /// Ask the loop to stop at the end of the current cycle. Any thread,
  /// async-signal-safe (one atomic store). A request made while the loop does
  /// not run ends the next run before its first cycle.
  void request_stop() noexcept { stop_requested_.store(true, std::memory_order_release); }
  /// Wait for the thread started by start() to end. Not realtime-safe.
  void join();
  /// request_stop() + join().
  void stop() {
    request_stop();
    join();
  }

  /// True between start()/run() and the end of the loop. Any thread.
  bool running() const noexcept { return running_.load(std::memory_order_acquire); }
  /// Cycles executed so far (the watchdog checks that it advances). Any
  /// thread, realtime-safe.
  std::uint64_t cycle_count() const noexcept { return cycles_.load(std::memory_order_acquire); }
  /// Why the last run ended.
  StopReason stop_reason() const noexcept { return stop_reason_.load(std::memory_order_acquire); }
  /// Live statistics (any thread; snapshot() is not realtime-safe).
  const CycleStatistics& statistics() const noexcept { return stats_; }
  /// Statistics copy with percentiles. Not realtime-safe.
  CycleStats stats() const noexcept { return stats_.snapshot(); }
  /// Result of the RT set-up of the last start()/run(). The PM QoS request it
  /// opened is held by the executive (cpu_latency_fd reads -1) and dropped
  /// when the loop ends.
  const RtSetupReport& setup_report() const noexcept { return report_; }
  /// The configured period.
  Nanos period() const noexcept { return config_.period; }

 private:
  struct BodyBase {
    virtual ~BodyBase() = default;
    virtual CycleResult call(const CycleInfo& info) noexcept = 0;
  };
  template <typename F>
  struct Body final : BodyBase {
    explicit Body(F fn) : f(std::move(fn)) {}
    CycleResult call(const CycleInfo& info) noexcept override {
      if constexpr (std::is_same_v<std::invoke_result_t<F&, const CycleInfo&>, void>) {
        f(info);
        return CycleResult::run_on;
      } else {
        return f(info);
      }
    }
    F f;
  };

  std::error_code check_startable() const;
  std::error_code setup_on_this_thread();
  void release_cpu_latency() noexcept;
  void emit_warning() const;
  void loop(std::uint64_t max_cycles) noexcept;

  ExecutiveConfig config_;
  Clock& clock_;
  std::unique_ptr<BodyBase> body_;
  CycleStatistics stats_;
  RtSetupReport report_;
  int cpu_latency_fd_ = -1;  ///< PM QoS request held while the loop runs (loop thread only)
  SizedThread thread_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> cycles_{0};
  std::atomic<StopReason> stop_reason_{StopReason::none};
};

/// Error codes of CyclicExecutive::start()/run() besides the RT set-up's own.
enum class ExecutiveError {
  no_callable = 1,      ///< set_cycle() was not called
  already_running = 2,  ///< start()/run() while the loop runs
  bad_period = 3,       ///< period <= 0
  thread_failed = 4,    ///< the thread could not be created (pthread_create)
};
/// Category of ExecutiveError ("canmotion.rt").
const std::error_category& executive_category() noexcept;
/// Makes an error_code from an ExecutiveError.
std::error_code make_error_code(ExecutiveError e) noexcept;

}  // namespace canmotion::rt

template <>
struct std::is_error_code_enum<canmotion::rt::ExecutiveError> : std::true_type {};
