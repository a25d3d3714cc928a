#pragma once
// Test rig for the coordinated path generator (motion/coord): builds move
// requests, steps the generator and records every cycle.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "motion/coord/path_generator.hpp"
#include "tests/motion/prop_util.hpp"

namespace canmotion::motion::coord::test {

using canmotion::motion::test::Rng;
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kTwoPi = 2 * std::numbers::pi;

inline Vec3 v3(double x, double y = 0, double z = 0) { return Vec3{{x, y, z}}; }

inline Limits lim(double v, double a, double d, double ja = kInf, double jd = kInf) { return Limits{v, a, d, ja, jd}; }

inline MoveRequest line(std::uint32_t id, const Vec3& target, const Limits& l,
                        Termination tt = Termination::NoSettle, bool incremental = false) {
  MoveRequest r;
  r.id = id;
  r.path.kind = PathKind::Line;
  r.path.incremental = incremental;
  r.path.position = target;
  r.limits = l;
  r.termination = tt;
  return r;
}

inline MoveRequest arc(std::uint32_t id, const Vec3& target, CircleType type, const Vec3& aux, CircleDirection dir,
                       const Limits& l, Termination tt = Termination::NoSettle, bool incremental = false) {
  MoveRequest r = line(id, target, l, tt, incremental);
  r.path.kind = PathKind::Circle;
  r.path.circle_type = type;
  r.path.aux = aux;
  r.path.direction = dir;
  return r;
}

/// One recorded cycle.
struct Sample {
  Output o;
  std::uint64_t cycle = 0;
};

struct Rig {
  PathGenerator g;
  SystemConfig cfg;
  Present now;
  std::vector<Sample> log;
  std::uint64_t cycle = 0;

  explicit Rig(int dim = 2, double period = 0.001, double ct = 0.0, double at = 0.0) {
    cfg.dim = dim;
    cfg.period = period;
    cfg.command_tolerance = ct;
    cfg.actual_tolerance = at;
    g.configure(cfg);
  }
  /// Submit; the events of the call are appended to `ev` if given.
  Err submit(const MoveRequest& r, Events* ev = nullptr) {
    Events e;
    const Err err = g.submit(r, now, e);
    if (ev) *ev = e;
    last_submit_events = e;
    return err;
  }
  Events last_submit_events;
  bool record = true;  ///< keep every cycle in `log` (else only `last`)
  Output last;
  const Output& step() {
    ++cycle;
    g.step(now, last);
    if (record) log.push_back(Sample{last, cycle});
    return last;
  }
  /// Step until nothing moves and nothing is queued (or max cycles).
  void run(std::uint64_t max_cycles = 10'000'000) {
    for (std::uint64_t i = 0; i < max_cycles && (!g.idle() || g.stopping()); ++i) step();
  }
  /// Cycle index (into log) of the first event of that kind for that id; -1 if none.
  long find(std::uint32_t id, EventKind k) const {
    for (std::size_t i = 0; i < log.size(); ++i)
      for (int j = 0; j < log[i].o.events.n; ++j)
        if (log[i].o.events.e[static_cast<std::size_t>(j)].id == id &&
            log[i].o.events.e[static_cast<std::size_t>(j)].kind == k)
          return static_cast<long>(i);
    return -1;
  }
};

inline bool has_event(const Events& ev, std::uint32_t id, EventKind k) {
  for (int j = 0; j < ev.n; ++j)
    if (ev.e[static_cast<std::size_t>(j)].id == id && ev.e[static_cast<std::size_t>(j)].kind == k) return true;
  return false;
}

inline bool bit(std::uint32_t st, unsigned b) { return (st >> b) & 1u; }

/// Distance from p to the segment a-b.
inline double dist_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double l2 = dot(d, d);
  double t = l2 > 0 ? dot(p - a, d) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return norm(p - (a + t * d));
}

/// Limits that make a move of length L last roughly 0.05 .. 1 s.
inline Limits limits_for(Rng& r, double L, bool scurve) {
  Limits l;
  l.v = L / r.uni(0.05, 0.5);
  l.a = l.v / r.uni(0.01, 0.2);
  l.d = r.coin(0.3) ? l.a : l.v / r.uni(0.01, 0.2);
  if (scurve) {
    l.ja = l.a / r.uni(0.002, 0.05);
    l.jd = r.coin(0.3) ? l.ja : l.d / r.uni(0.002, 0.05);
  } else {
    l.ja = l.jd = kInf;
  }
  return l;
}

inline Vec3 random_point(Rng& r, int dim, double range) {
  Vec3 p;
  for (int i = 0; i < dim; ++i) p[i] = r.uni(-range, range);
  return p;
}

inline Vec3 random_unit(Rng& r, int dim) {
  for (;;) {
    Vec3 p = random_point(r, dim, 1.0);
    const double n = norm(p);
    if (n > 0.1 && n <= 1.0) return (1.0 / n) * p;
  }
}

}  // namespace canmotion::motion::coord::test
