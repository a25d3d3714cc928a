#pragma once
/// \file
/// PM QoS CPU latency request through `/dev/cpu_dma_latency`: while a
/// process keeps the device open after writing a value (binary s32, in
/// microseconds), the kernel's cpuidle governor keeps every CPU out of the
/// idle states whose exit latency is above it; closing the file (or the
/// process ending) drops the request. 0 = stay in the shallowest state
/// (poll / C1), which is what cyclictest does by default. Without it a CPU
/// idle between two 1 ms cycles may enter a deep C-state, and waking from it
/// adds tens (on some machines hundreds) of microseconds to the cycle's
/// wake-up latency. See Documentation/power/pm_qos_interface.rst.
///
/// Not realtime-safe (system calls): used once by the RT set-up
/// (rt_setup.hpp, step RtStep::cpu_latency), before the first cycle.

#include <cstdint>
#include <optional>

namespace canmotion::rt {

/// The PM QoS character device (misc device, root:root 0600 by default).
inline constexpr const char* kCpuDmaLatencyPath = "/dev/cpu_dma_latency";

/// Largest request accepted (the kernel's PM_QOS_CPU_LATENCY_DEFAULT_VALUE,
/// 2000 s: "no constraint").
inline constexpr std::int32_t kMaxCpuLatencyUs = 2'000'000'000;

/// Opens `path` for writing and writes `us` as a binary s32: the request is
/// active from then until the returned descriptor is closed. Returns the
/// file descriptor (>= 0), or -errno (-ENOENT: no such device, e.g. in a
/// container; -EACCES: not root and no udev rule granting the group).
/// Not realtime-safe.
int open_cpu_latency_request(std::int32_t us, const char* path = kCpuDmaLatencyPath) noexcept;

/// Closes a descriptor returned by open_cpu_latency_request(): the kernel
/// drops the request. Ignores fd < 0.
void close_cpu_latency_request(int fd) noexcept;

/// The kernel's current aggregate CPU latency constraint (the smallest of
/// all open requests, or the 2000 s default), read from `path`; nullopt when
/// it cannot be read. For tests and diagnostics. Not realtime-safe.
std::optional<std::int32_t> read_cpu_latency(const char* path = kCpuDmaLatencyPath) noexcept;

}  // namespace canmotion::rt
