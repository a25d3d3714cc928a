#include "rt/pm_qos.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

namespace canmotion::rt {

int open_cpu_latency_request(std::int32_t us, const char* path) noexcept {
  if (us < 0 || us > kMaxCpuLatencyUs) return -EINVAL;
  const int fd = ::open(path, O_WRONLY | O_CLOEXEC);
  if (fd < 0) return -errno;
  // The binary form (exactly 4 bytes); the kernel also takes a hex string.
  const ssize_t n = ::write(fd, &us, sizeof(us));
  if (n != static_cast<ssize_t>(sizeof(us))) {
    const int e = n < 0 ? errno : EIO;
    ::close(fd);
    return -e;
  }
  return fd;
}

void close_cpu_latency_request(int fd) noexcept {
  if (fd >= 0) ::close(fd);
}

std::optional<std::int32_t> read_cpu_latency(const char* path) noexcept {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::int32_t v = 0;
  const ssize_t n = ::read(fd, &v, sizeof(v));
  ::close(fd);
  if (n != static_cast<ssize_t>(sizeof(v))) return std::nullopt;
  return v;
}

}  // namespace canmotion::rt
