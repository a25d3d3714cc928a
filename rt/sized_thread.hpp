#pragma once
/// \file
/// A thread with a chosen stack size. std::thread always gets the default
/// stack (8 MiB, RLIMIT_STACK), and under mlockall(MCL_CURRENT | MCL_FUTURE)
/// every page of it is locked, used or not: the cyclic thread uses about
/// 12 KiB (measured with 16 axes), the watchdog thread less. Not realtime-safe.

#include <pthread.h>

#include <cstddef>
#include <functional>
#include <system_error>

namespace canmotion::rt {

class SizedThread {
 public:
  SizedThread() = default;
  SizedThread(const SizedThread&) = delete;
  SizedThread& operator=(const SizedThread&) = delete;
  /// Joins the thread if it still runs.
  ~SizedThread() { join(); }

  /// Runs `fn` on a new thread whose stack is `stack_bytes` (rounded up to
  /// whole pages, at least PTHREAD_STACK_MIN). Returns the error of
  /// pthread_create (e.g. EAGAIN), or invalid_argument when a thread is
  /// already running.
  std::error_code start(std::size_t stack_bytes, std::function<void()> fn);
  bool joinable() const noexcept { return started_; }
  /// Waits for the thread to end. No-op when not started.
  void join() noexcept;

 private:
  static void* trampoline(void* self) noexcept;
  pthread_t thread_{};
  bool started_ = false;
  std::function<void()> fn_;
};

}  // namespace canmotion::rt
