#include "motion/cam/cam_profile.hpp"

#include <Eigen/Core>
#include <cmath>
#include <stdexcept>
#include <string>

namespace canmotion::motion::cam {

CamProfile::CamProfile(std::size_t capacity) {
  if (capacity == 0 || capacity > kMaxCapacity) {
    throw std::invalid_argument("CamProfile capacity must be 1.." + std::to_string(kMaxCapacity) +
                                " elements, got " + std::to_string(capacity));
  }
  elems_.resize(capacity);
  masters_.assign(capacity, 0.0);
  scratch_.assign(6 * capacity, 0.0);
}

CamError CamProfile::acquire() noexcept {
  if (!calculated()) return CamError::CamProfileNotCalculated;
  ++elems_[0].status;
  return CamError::None;
}

void CamProfile::release() noexcept {
  if (elems_[0].status > profile_status::kCalculated) --elems_[0].status;
}

CamError CamProfile::invalidate() noexcept {
  if (elems_[0].status > profile_status::kCalculated) return CamError::CamProfileBeingUsed;
  elems_[0].status = profile_status::kNotCalculated;
  return CamError::None;
}

void CamProfile::write_status(std::int32_t status) noexcept { elems_[0].status = status; }

std::size_t CamProfile::find_segment(double master) const noexcept {
  // Largest i in [0, count_-2] with M_i <= master (0 if master < M_0).
  // Branch-light lower-bound style search on the contiguous master copy.
  const double* m = masters_.data();
  std::size_t base = 0;
  std::size_t len = count_ - 1;  // candidate segments [base, base + len)
  while (len > 1) {
    const std::size_t half = len / 2;
    base = m[base + half] <= master ? base + half : base;
    len -= half;
  }
  return base;
}

std::size_t CamProfile::find_segment(double master, CamCursor& cursor) const noexcept {
  const double* m = masters_.data();
  const std::size_t last = count_ - 2;  // last segment index
  std::size_t s = cursor.segment <= last ? cursor.segment : last;
  // Step a few segments in the direction of travel, then give up and bisect.
  constexpr int kMaxSteps = 4;
  for (int i = 0; i < kMaxSteps; ++i) {
    if (master < m[s]) {
      if (s == 0) break;
      --s;
    } else if (s < last && master >= m[s + 1]) {
      ++s;
    } else {
      cursor.segment = s;
      return s;
    }
  }
  if (s == 0 && master < m[0]) {
    cursor.segment = 0;
    return 0;
  }
  s = find_segment(master);
  cursor.segment = s;
  return s;
}

CamSample CamProfile::eval_in_segment(std::size_t seg, double master) const noexcept {
  const CamProfileElement& e = elems_[seg];
  const double u = master - e.master;
  return CamSample{
      e.a0 + u * (e.a1 + u * (e.a2 + u * e.a3)),
      e.a1 + u * (2.0 * e.a2 + u * 3.0 * e.a3),
      2.0 * e.a2 + 6.0 * e.a3 * u,
  };
}

CamSample CamProfile::eval_outside(double master, EndBehaviour end) const noexcept {
  const bool before = master < elems_[0].master;
  const CamProfileElement& knot = before ? elems_[0] : elems_[count_ - 1];
  if (end == EndBehaviour::Clamp) return CamSample{knot.slave, 0.0, 0.0};
  // Tangent at the end: derivative of the first segment at u = 0, or of the
  // last segment at u = h.
  double slope = 0.0;
  if (before) {
    slope = elems_[0].a1;
  } else {
    const CamProfileElement& e = elems_[count_ - 2];
    const double h = knot.master - e.master;
    slope = e.a1 + h * (2.0 * e.a2 + h * 3.0 * e.a3);
  }
  return CamSample{knot.slave + slope * (master - knot.master), slope, 0.0};
}

CamSample CamProfile::evaluate(double master, EndBehaviour end) const noexcept {
  if (!calculated()) return CamSample{};
  if (master < elems_[0].master || master > elems_[count_ - 1].master) {
    return eval_outside(master, end);
  }
  return eval_in_segment(find_segment(master), master);
}

CamSample CamProfile::evaluate(double master, CamCursor& cursor, EndBehaviour end) const noexcept {
  if (!calculated()) return CamSample{};
  if (master < elems_[0].master) {
    cursor.segment = 0;
    return eval_outside(master, end);
  }
  if (master > elems_[count_ - 1].master) {
    cursor.segment = count_ - 2;
    return eval_outside(master, end);
  }
  return eval_in_segment(find_segment(master, cursor), master);
}

namespace {

MccpResult fail(CamError err, std::int32_t exerr, std::int64_t index, const char* reason) noexcept {
  return MccpResult{err, exerr, index, 0, reason};
}

MccpResult fail_length(CamError err, std::int64_t length, const char* reason) noexcept {
  return MccpResult{err, 0, -1, length, reason};
}

/// MCCP checks 1.-6. (the order of mccp()'s contract); ok() when the
/// request may be calculated.
MccpResult check_request(const MccpRequest& req, const CamProfile& profile) noexcept {
  using namespace mccp_operand;
  // 1. Profile state.
  const std::int32_t status = profile.status();
  if (status == profile_status::kCalculating) {
    return fail(CamError::CamProfileBeingCalculated, 0, -1, "the cam profile is being calculated (Status 1)");
  }
  if (status > profile_status::kCalculated) {
    return fail(CamError::CamProfileBeingUsed, 0, -1,
                "the cam profile is in use by a cam (Status > 2); stop the MAPC/MATC first");
  }
  // 2.-4. Index, length, capacity.
  const auto cam_size = static_cast<std::int64_t>(req.cam.size());
  if (req.start_index < 0 || req.start_index >= cam_size) {
    return fail(CamError::ParameterOutOfRange, kCam, req.start_index, "the Cam index is outside the CAM array");
  }
  if (req.length < 2) {
    return fail_length(CamError::IllegalCamLength, req.length, "Length must be at least 2 cam points");
  }
  if (req.length > cam_size - req.start_index) {
    return fail_length(CamError::IllegalCamLength, req.length,
                "Cam index + Length runs past the end of the CAM array");
  }
  if (req.length > static_cast<std::int64_t>(profile.capacity())) {
    return fail_length(CamError::IllegalCamProfileLength, req.length,
                "the CAM_PROFILE array has fewer elements than Length");
  }
  // 5. Slopes.
  if (!std::isfinite(req.start_slope)) {
    return fail(CamError::ParameterOutOfRange, kStartSlope, -1, "StartSlope is not a finite number");
  }
  if (!std::isfinite(req.end_slope)) {
    return fail(CamError::ParameterOutOfRange, kEndSlope, -1, "EndSlope is not a finite number");
  }
  // 6. Points.
  const auto n = static_cast<std::size_t>(req.length);
  const CamPoint* pts = req.cam.data() + req.start_index;
  for (std::size_t i = 0; i < n; ++i) {
    const auto index = req.start_index + static_cast<std::int64_t>(i);
    if (!std::isfinite(pts[i].master) || !std::isfinite(pts[i].slave)) {
      return fail(CamError::ParameterOutOfRange, kCam, index, "a cam point's Master or Slave is not a finite number");
    }
    if (i + 1 < n && pts[i].segment_type != kSegmentLinear && pts[i].segment_type != kSegmentCubic) {
      return fail(CamError::IllegalCamType, 0, index, "SegmentType must be 0 (linear) or 1 (cubic)");
    }
    if (i > 0 && !(pts[i].master > pts[i - 1].master)) {
      return fail(CamError::IllegalCamOrder, 0, index, "cam master values must strictly increase");
    }
    if (i > 0 && !std::isfinite(pts[i].master - pts[i - 1].master)) {
      return fail(CamError::ParameterOutOfRange, kCam, index, "the master distance between two cam points overflows");
    }
  }
  return MccpResult{};
}

/// The knot slopes of the n points in `el` into r = scratch + 3 * cap (and the
/// per-segment 1/h and chord slopes into scratch + 4 cap, + 5 cap).
void knot_slopes(const MccpRequest& req, const CamProfileElement* el, std::size_t n, double* scratch,
                 std::size_t cap) noexcept {
  // Knot slopes m_k from a tridiagonal system (see README "Spline rule"):
  //  * knot between two cubic segments: C2 row
  //      m_{k-1}/h_{k-1} + 2 (1/h_{k-1} + 1/h_k) m_k + m_{k+1}/h_k
  //        = 3 (d_{k-1}/h_{k-1} + d_k/h_k)
  //  * knot 0 with a cubic first segment: m_0 = StartSlope
  //  * last knot with a cubic last segment: m_{n-1} = EndSlope
  //  * knot between a cubic and a linear segment: m_k = the linear segment's slope
  //  * knot between two linear segments: unused (m_k = 0)
  const auto nn = static_cast<Eigen::Index>(n);
  Eigen::Map<Eigen::VectorXd> lo(scratch, nn);            // sub-diagonal
  Eigen::Map<Eigen::VectorXd> di(scratch + cap, nn);      // diagonal (then its inverse)
  Eigen::Map<Eigen::VectorXd> up(scratch + 2 * cap, nn);  // super-diagonal
  Eigen::Map<Eigen::VectorXd> r(scratch + 3 * cap, nn);   // right-hand side, then m_k
  Eigen::Map<Eigen::VectorXd> ih(scratch + 4 * cap, nn);  // 1 / h_s per segment
  Eigen::Map<Eigen::VectorXd> dd(scratch + 5 * cap, nn);  // chord slope d_s per segment
  for (Eigen::Index s = 0; s + 1 < nn; ++s) {
    const auto i = static_cast<std::size_t>(s);
    const double hs = el[i + 1].master - el[i].master;
    ih[s] = 1.0 / hs;
    dd[s] = (el[i + 1].slave - el[i].slave) / hs;
  }
  auto cubic = [&](Eigen::Index seg) { return seg + 1 < nn && el[static_cast<std::size_t>(seg)].type == kSegmentCubic; };
  for (Eigen::Index k = 0; k < nn; ++k) {
    const bool left = k > 0 && cubic(k - 1);
    const bool right = cubic(k);
    lo[k] = 0.0;
    up[k] = 0.0;
    di[k] = 1.0;
    if (left && right) {
      const double il = ih[k - 1];
      const double ir = ih[k];
      lo[k] = il;
      di[k] = 2.0 * (il + ir);
      up[k] = ir;
      r[k] = 3.0 * (dd[k - 1] * il + dd[k] * ir);
    } else if (right) {
      r[k] = k == 0 ? req.start_slope : dd[k - 1];
    } else if (left) {
      r[k] = k + 1 == nn ? req.end_slope : dd[k];
    } else {
      r[k] = 0.0;
    }
  }
  // Banded (tridiagonal) LU without pivoting, in place on the Eigen vectors.
  // The matrix is strictly diagonally dominant (C2 rows: 2(a+b) > a+b; other
  // rows are identity rows), so no pivoting is needed and the solve is stable.
  // Eigen offers no allocation-free banded solver, so the two sweeps are here.
  // di[k] is replaced by its inverse once row k is final (one division per row).
  for (Eigen::Index k = 1; k < nn; ++k) {
    di[k - 1] = 1.0 / di[k - 1];
    const double w = lo[k] * di[k - 1];
    di[k] -= w * up[k - 1];
    r[k] -= w * r[k - 1];
  }
  di[nn - 1] = 1.0 / di[nn - 1];
  r[nn - 1] *= di[nn - 1];
  for (Eigen::Index k = nn - 2; k >= 0; --k) {
    r[k] = (r[k] - up[k] * r[k + 1]) * di[k];
  }
}

/// Segment polynomials from the knot slopes (knot_slopes' scratch).
void coefficients(CamProfileElement* el, std::size_t n, const double* scratch, std::size_t cap) noexcept {
  const auto nn = static_cast<Eigen::Index>(n);
  Eigen::Map<const Eigen::VectorXd> r(scratch + 3 * cap, nn);
  Eigen::Map<const Eigen::VectorXd> ih(scratch + 4 * cap, nn);
  Eigen::Map<const Eigen::VectorXd> dd(scratch + 5 * cap, nn);
  for (Eigen::Index s = 0; s + 1 < nn; ++s) {
    CamProfileElement& e = el[static_cast<std::size_t>(s)];
    e.a0 = e.slave;
    const double ds = dd[s];
    if (e.type == kSegmentCubic) {
      const double m0 = r[s];
      const double m1 = r[s + 1];
      e.a1 = m0;
      e.a2 = (3.0 * ds - 2.0 * m0 - m1) * ih[s];
      e.a3 = (m0 + m1 - 2.0 * ds) * (ih[s] * ih[s]);
    } else {
      e.a1 = ds;
      e.a2 = 0.0;
      e.a3 = 0.0;
    }
  }
  CamProfileElement& last = el[n - 1];
  last.a0 = last.slave;
  last.a1 = last.a2 = last.a3 = 0.0;
}

}  // namespace

MccpResult mccp(const MccpRequest& req, CamProfile& profile) noexcept {
  if (MccpResult bad = check_request(req, profile); !bad.ok()) return bad;
  const auto n = static_cast<std::size_t>(req.length);
  const CamPoint* pts = req.cam.data() + req.start_index;
  // Calculation. Status is 1 while it runs (visible to nobody else in this
  // single-threaded design, but it keeps the Logix sequence).
  auto& el = profile.elems_;
  el[0].status = profile_status::kCalculating;
  for (std::size_t i = 0; i < n; ++i) {
    el[i].master = pts[i].master;
    profile.masters_[i] = pts[i].master;
    el[i].slave = pts[i].slave;
    el[i].type = i + 1 < n ? pts[i].segment_type : kSegmentLinear;
  }
  knot_slopes(req, el.data(), n, profile.scratch_.data(), profile.capacity());
  coefficients(el.data(), n, profile.scratch_.data(), profile.capacity());
  profile.count_ = n;
  el[0].status = profile_status::kCalculated;
  return MccpResult{};
}

std::string describe(const MccpResult& result) {
  if (result.ok()) return "MCCP OK";
  std::string s = "MCCP ERR " + std::to_string(err_code(result.err)) + " " + std::string(to_string(result.err));
  if (result.err == CamError::ParameterOutOfRange) s += " (EXERR " + std::to_string(result.exerr) + ")";
  s += ": ";
  s += result.reason;
  const bool about_point = result.err == CamError::IllegalCamType || result.err == CamError::IllegalCamOrder ||
                           (result.err == CamError::ParameterOutOfRange && result.exerr == mccp_operand::kCam);
  if (result.err == CamError::IllegalCamLength || result.err == CamError::IllegalCamProfileLength) {
    s += " (Length " + std::to_string(result.length) + ")";
  } else if (about_point) {
    s += " (cam[" + std::to_string(result.cam_index) + "])";
  }
  return s;
}

}  // namespace canmotion::motion::cam
