#pragma once
/// \file
/// Fast text output for the daemon's --trace and --csv files, without stdio
/// or iostreams: an exact `%.6f` formatter (format_fixed6) and a file written
/// in large blocks with write(2) (OutputFile). The bytes are the ones the
/// printf/fwrite code they replace wrote (tests/rt/test_text_output.cpp
/// compares them with snprintf). Used on non-RT threads: the RT thread only
/// pushes records into rings (see rt/controller/outputs.hpp).

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace canmotion::rt {

/// Longest text format_fixed6() writes: '-' + 309 integer digits (DBL_MAX) +
/// '.' + 6 decimals.
inline constexpr std::size_t kFixed6Max = 1 + 309 + 1 + 6;

/// Writes `v` exactly as `printf("%.6f", v)` does (glibc, default rounding
/// mode: the exact binary value rounded half to even), e.g. "-0.000000" for
/// -1e-9, "nan", "-inf", and returns the end. `out` must hold kFixed6Max bytes.
/// Realtime-safe (no allocation, no locale).
///
/// Why not std::to_chars(fixed, 6) alone: it gives the same bytes but costs
/// about 5x more per value (150 against 30 ns measured, snprintf 600 ns);
/// the fast path computes |v| x 10^6 in double and is used only when that
/// product, give or take its rounding error, cannot lie on the other side of
/// a rounding boundary; every other value (ties, |v| >= 2^50 / 10^6, NaN,
/// infinities) goes to std::to_chars.
char* format_fixed6(char* out, double v) noexcept;

/// Writes the decimal digits of `v` (std::to_chars) and returns the end;
/// `out` must hold 20 bytes. Realtime-safe.
char* format_u64(char* out, unsigned long long v) noexcept;

/// An output file written with write(2) from one large buffer: callers
/// format straight into reserve()d space and commit() what they wrote.
/// Not thread-safe (one writer thread). Write errors are kept, not thrown:
/// error() returns the first (errno), and later data is dropped.
class OutputFile {
 public:
  /// Default buffer: 256 KiB (about 6000 trace lines or 3000 CSV rows).
  static constexpr std::size_t kDefaultBuffer = std::size_t{256} << 10;

  OutputFile() = default;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  /// Flushes and closes (errors are only recorded).
  ~OutputFile();

  /// Creates or truncates `path` (mode 0666 & ~umask). Throws
  /// std::system_error whose message names the file.
  void open(const std::string& path, std::size_t buffer_bytes = kDefaultBuffer);
  bool is_open() const noexcept { return fd_ >= 0; }
  const std::string& path() const noexcept { return path_; }

  /// Space for at least `n` bytes (n <= the buffer size), flushing first if
  /// the buffer has less room. Write into it, then commit(end).
  char* reserve(std::size_t n) {
    if (capacity_ - used_ < n) flush();
    return buf_.get() + used_;
  }
  /// The bytes up to `end` (inside the last reserve()) are part of the file.
  void commit(const char* end) noexcept { used_ = static_cast<std::size_t>(end - buf_.get()); }
  /// Appends `s` (any length).
  void write(std::string_view s);
  /// Hands the buffered bytes to the kernel (write(2), retried on EINTR and
  /// short writes).
  void flush() noexcept;
  /// flush() + close(2). Safe to call twice.
  void close() noexcept;
  /// First write error (errno), 0 if none.
  int error() const noexcept { return error_; }

 private:
  int fd_ = -1;
  int error_ = 0;
  std::string path_;
  std::unique_ptr<char[]> buf_;
  std::size_t capacity_ = 0;
  std::size_t used_ = 0;
};

}  // namespace canmotion::rt
