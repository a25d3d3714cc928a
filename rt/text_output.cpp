#include "rt/text_output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>

namespace canmotion::rt {

namespace {

// "00" "01" ... "99": two decimal digits per table lookup.
constexpr char kDigitPairs[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

inline char* put_pair(char* p, std::uint32_t v) noexcept {
  std::memcpy(p, kDigitPairs + 2 * v, 2);
  return p + 2;
}

}  // namespace

char* format_fixed6(char* out, double v) noexcept {
  const double a = std::fabs(v);
  const double y = a * 1e6;  // |v| x 10^6, rounded: within half an ulp of the exact product
  // Fast path for y < 2^50 (|v| < 1.1e9). Adding and removing 2^52 rounds y
  // to the nearest integer r (ties to even), exactly. d = y - r is exact. If
  // |d| stays 2 ulps away from 1/2, the exact product rounds to r as well, so
  // r is what printf prints. (If the compiler fuses the multiply into the
  // add, r is the exact product's rounding, which is right too.)
  if (y < 0x1p50) {  // false for NaN
    const double r = (y + 0x1p52) - 0x1p52;
    const double d = y - r;
    const double ulp2 = 0x1p-51 * (y > 1.0 ? y : 1.0);
    if (std::fabs(d) < 0.5 - ulp2) {
      const auto q = static_cast<std::uint64_t>(r);
      char* p = out;
      if (std::signbit(v)) *p++ = '-';  // printf: "-0.000000" for -0.0 and -1e-9
      const std::uint64_t ip = q / 1'000'000U;
      const auto fp = static_cast<std::uint32_t>(q - ip * 1'000'000U);
      p = std::to_chars(p, p + 20, ip).ptr;
      *p++ = '.';
      p = put_pair(p, fp / 10'000U);
      p = put_pair(p, (fp / 100U) % 100U);
      return put_pair(p, fp % 100U);
    }
  }
  // Exact in every case (Ryu printf in libstdc++): ties, large values, NaN, inf.
  return std::to_chars(out, out + kFixed6Max, v, std::chars_format::fixed, 6).ptr;
}

char* format_u64(char* out, unsigned long long v) noexcept { return std::to_chars(out, out + 20, v).ptr; }

OutputFile::~OutputFile() { close(); }

void OutputFile::open(const std::string& path, std::size_t buffer_bytes) {
  close();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "cannot write '" + path + "'");
  fd_ = fd;
  error_ = 0;
  path_ = path;
  capacity_ = buffer_bytes < 4096 ? 4096 : buffer_bytes;
  buf_ = std::make_unique<char[]>(capacity_);
  used_ = 0;
}

void OutputFile::write(std::string_view s) {
  while (!s.empty()) {
    const std::size_t room = capacity_ - used_;
    if (room == 0) {
      flush();
      continue;
    }
    const std::size_t n = s.size() < room ? s.size() : room;
    std::memcpy(buf_.get() + used_, s.data(), n);
    used_ += n;
    s.remove_prefix(n);
  }
}

void OutputFile::flush() noexcept {
  const char* p = buf_.get();
  std::size_t left = used_;
  used_ = 0;
  if (fd_ < 0 || error_ != 0) return;  // after an error the rest is dropped
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      error_ = errno;
      return;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

void OutputFile::close() noexcept {
  if (fd_ < 0) return;
  flush();
  if (::close(fd_) != 0 && error_ == 0) error_ = errno;
  fd_ = -1;
}

}  // namespace canmotion::rt
