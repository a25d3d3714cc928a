#include "rt/cyclic_executive.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <future>
#include <memory>
#include <system_error>

namespace canmotion::rt {

namespace {

class ExecutiveCategory final : public std::error_category {
 public:
  const char* name() const noexcept override { return "canmotion.rt"; }
  std::string message(int ev) const override {
    switch (static_cast<ExecutiveError>(ev)) {
      case ExecutiveError::no_callable: return "no cycle callable set (call set_cycle() first)";
      case ExecutiveError::already_running: return "the cyclic executive is already running";
      case ExecutiveError::bad_period: return "the cycle period must be greater than 0";
      case ExecutiveError::thread_failed: return "the real-time thread could not be created";
    }
    return "unknown cyclic executive error";
  }
};

}  // namespace

const std::error_category& executive_category() noexcept {
  static const ExecutiveCategory category;
  return category;
}

std::error_code make_error_code(ExecutiveError e) noexcept {
  return {static_cast<int>(e), executive_category()};
}

CyclicExecutive::CyclicExecutive(ExecutiveConfig config, Clock& clock)
    : config_(std::move(config)), clock_(clock), stats_(config_.period) {}

CyclicExecutive::~CyclicExecutive() {
  request_stop();
  join();
}

std::error_code CyclicExecutive::check_startable() const {
  if (!body_) {
    return ExecutiveError::no_callable;
  }
  if (running() || thread_.joinable()) {
    return ExecutiveError::already_running;
  }
  if (config_.period.count() <= 0) {
    return ExecutiveError::bad_period;
  }
  return {};
}

std::error_code CyclicExecutive::setup_on_this_thread() {
  if (!config_.thread_name.empty()) {
    const std::string name = config_.thread_name.substr(0, 15);
    pthread_setname_np(pthread_self(), name.c_str());
  }
  report_ = apply_rt_settings(config_.rt, config_.syscalls);
  // The loop owns the PM QoS request from here (report_ is read by other
  // threads while the loop runs, so the loop closes its own copy).
  cpu_latency_fd_ = report_.cpu_latency_fd;
  report_.cpu_latency_fd = -1;
  return report_.hard_error();
}

void CyclicExecutive::release_cpu_latency() noexcept {
  if (cpu_latency_fd_ >= 0 && config_.syscalls.release_cpu_latency != nullptr) {
    config_.syscalls.release_cpu_latency(cpu_latency_fd_);
  }
  cpu_latency_fd_ = -1;
}

void CyclicExecutive::emit_warning() const {
  const std::string text = report_.warning();
  if (text.empty()) {
    return;
  }
  if (config_.warn) {
    config_.warn(text);
  } else {
    spdlog::warn("{}", text);
  }
}

std::error_code CyclicExecutive::start() {
  if (auto ec = check_startable()) {
    return ec;
  }
  running_.store(true, std::memory_order_release);
  auto ready = std::make_shared<std::promise<std::error_code>>();
  std::future<std::error_code> result = ready->get_future();
  // A small stack of our own (std::thread's 8 MiB would all be locked by
  // mlockall); never smaller than twice the prefault, which must fit in it.
  const std::size_t prefault = std::min(config_.rt.prefault_stack_bytes, RtSettings::kMaxPrefaultBytes);
  const std::size_t stack = std::max(config_.stack_bytes, 2 * prefault);
  const std::error_code started = thread_.start(stack, [this, ready] {
    const std::error_code ec = setup_on_this_thread();
    if (ec) {
      release_cpu_latency();
    }
    ready->set_value(ec);
    if (ec) {
      running_.store(false, std::memory_order_release);
      return;
    }
    if (config_.on_loop_start) {
      config_.on_loop_start();
    }
    loop(0);
  });
  if (started) {
    running_.store(false, std::memory_order_release);
    return ExecutiveError::thread_failed;
  }
  const std::error_code ec = result.get();
  if (ec) {
    thread_.join();
    return ec;
  }
  emit_warning();
  return {};
}

std::error_code CyclicExecutive::run(std::uint64_t max_cycles) {
  if (auto ec = check_startable()) {
    return ec;
  }
  running_.store(true, std::memory_order_release);
  if (auto ec = setup_on_this_thread()) {
    release_cpu_latency();
    running_.store(false, std::memory_order_release);
    return ec;
  }
  emit_warning();
  if (config_.on_loop_start) {
    config_.on_loop_start();
  }
  loop(max_cycles);
  return {};
}

void CyclicExecutive::join() {
  if (thread_.joinable()) {
    thread_.join();
  }
}

void CyclicExecutive::loop(std::uint64_t max_cycles) noexcept {
  const Nanos period = config_.period;
  Nanos deadline = clock_.now() + period;
  Nanos previous_wake{0};
  bool first = true;
  std::uint32_t missed = 0;
  std::uint64_t done = 0;
  StopReason reason = StopReason::none;

  for (;;) {
    // Cycle boundary: a stop request or the cycle budget ends the loop here.
    if (stop_requested_.load(std::memory_order_acquire)) {
      reason = StopReason::requested;
      break;
    }
    if (max_cycles != 0 && done >= max_cycles) {
      reason = StopReason::max_cycles;
      break;
    }

    clock_.sleep_until(deadline);
    const Nanos wake = clock_.now();
    const CycleInfo info{cycles_.load(std::memory_order_relaxed), deadline, wake, period, missed};
    const CycleResult result = body_->call(info);
    const Nanos end = clock_.now();

    stats_.record(wake - deadline, end - wake, first ? Nanos{-1} : wake - previous_wake);
    first = false;
    previous_wake = wake;
    cycles_.store(info.cycle + 1, std::memory_order_release);
    ++done;

    // Overrun policy: SKIP. If the cycle ended after the next deadline, the
    // deadlines already in the past are dropped and the loop waits for the
    // first deadline of the original grid that is not before `end`; the phase
    // of the grid is kept, cycles are never run back to back to catch up.
    Nanos next = deadline + period;
    missed = 0;
    if (end > next) {
      const std::int64_t behind = (end - deadline).count();
      const std::int64_t steps = (behind + period.count() - 1) / period.count();  // ceil, >= 2
      next = deadline + Nanos{steps * period.count()};
      missed = static_cast<std::uint32_t>(steps - 1);
      stats_.record_overrun(static_cast<std::uint64_t>(steps - 1));
    }
    deadline = next;

    if (result == CycleResult::stop) {
      reason = StopReason::callable;
      break;
    }
  }

  // After the last cycle: drop the PM QoS request (the CPUs may sleep deeply again).
  release_cpu_latency();
  stop_requested_.store(false, std::memory_order_release);
  stop_reason_.store(reason, std::memory_order_release);
  running_.store(false, std::memory_order_release);
}

}  // namespace canmotion::rt
