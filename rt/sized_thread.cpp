#include "rt/sized_thread.hpp"

#include <limits.h>
#include <unistd.h>

namespace canmotion::rt {

std::error_code SizedThread::start(std::size_t stack_bytes, std::function<void()> fn) {
  if (started_) return std::make_error_code(std::errc::invalid_argument);
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  std::size_t size = (stack_bytes + page - 1) / page * page;
  if (size < static_cast<std::size_t>(PTHREAD_STACK_MIN)) size = static_cast<std::size_t>(PTHREAD_STACK_MIN);
  pthread_attr_t attr;
  if (const int e = ::pthread_attr_init(&attr); e != 0) return {e, std::generic_category()};
  int e = ::pthread_attr_setstacksize(&attr, size);
  fn_ = std::move(fn);
  if (e == 0) e = ::pthread_create(&thread_, &attr, &SizedThread::trampoline, this);
  ::pthread_attr_destroy(&attr);
  if (e != 0) return {e, std::generic_category()};
  started_ = true;
  return {};
}

void* SizedThread::trampoline(void* self) noexcept {
  static_cast<SizedThread*>(self)->fn_();
  return nullptr;
}

void SizedThread::join() noexcept {
  if (!started_) return;
  ::pthread_join(thread_, nullptr);
  started_ = false;
}

}  // namespace canmotion::rt
