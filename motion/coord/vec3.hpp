#pragma once
/// \file motion/coord/vec3.hpp
/// A tiny 3-vector for coordinated paths (dimension 1..3; unused components
/// stay 0). Written here rather than taken from Eigen: the path generator
/// needs only + - * dot cross norm on three doubles, and a plain aggregate
/// keeps the per-cycle code free of expression templates and alignment
/// rules (measured in tests/motion_coord/bench_coord.cpp). Realtime-safe.

#include <array>
#include <cmath>

namespace canmotion::motion::coord {

/// Coordination-unit vector; components past the system's dimension are 0.
struct Vec3 {
  std::array<double, 3> c{};

  constexpr double& operator[](int i) noexcept { return c[static_cast<std::size_t>(i)]; }
  constexpr double operator[](int i) const noexcept { return c[static_cast<std::size_t>(i)]; }
  friend constexpr Vec3 operator+(const Vec3& a, const Vec3& b) noexcept { return {{a.c[0] + b.c[0], a.c[1] + b.c[1], a.c[2] + b.c[2]}}; }
  friend constexpr Vec3 operator-(const Vec3& a, const Vec3& b) noexcept { return {{a.c[0] - b.c[0], a.c[1] - b.c[1], a.c[2] - b.c[2]}}; }
  friend constexpr Vec3 operator*(double k, const Vec3& a) noexcept { return {{k * a.c[0], k * a.c[1], k * a.c[2]}}; }
  constexpr Vec3& operator+=(const Vec3& b) noexcept { c[0] += b.c[0]; c[1] += b.c[1]; c[2] += b.c[2]; return *this; }
  constexpr Vec3& operator-=(const Vec3& b) noexcept { c[0] -= b.c[0]; c[1] -= b.c[1]; c[2] -= b.c[2]; return *this; }
  friend constexpr bool operator==(const Vec3&, const Vec3&) noexcept = default;
};

constexpr double dot(const Vec3& a, const Vec3& b) noexcept { return a.c[0] * b.c[0] + a.c[1] * b.c[1] + a.c[2] * b.c[2]; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {{a.c[1] * b.c[2] - a.c[2] * b.c[1], a.c[2] * b.c[0] - a.c[0] * b.c[2], a.c[0] * b.c[1] - a.c[1] * b.c[0]}};
}
inline double norm(const Vec3& a) noexcept { return std::sqrt(dot(a, a)); }
/// Largest |component| (scale for relative tolerances).
inline double max_abs(const Vec3& a) noexcept {
  return std::fmax(std::fabs(a.c[0]), std::fmax(std::fabs(a.c[1]), std::fabs(a.c[2])));
}

}  // namespace canmotion::motion::coord
