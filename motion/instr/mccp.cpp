// MCCP as a planner instruction (motion/instr/mccp.hpp); see
// motion/cam/README.md ("MCCP as an instruction") for the design choice: the
// calculation runs in the cycle, into the CAM_PROFILE array's storage that
// was sized at configuration. Realtime-safe.
#include "motion/instr/mccp.hpp"

#include "motion/cam/cam_profile.hpp"
#include "motion/instr/ctx.hpp"

namespace canmotion::motion {

static_assert(cam::mccp_operand::kCam == op<Instr::MCCP>("Cam") &&
                  cam::mccp_operand::kCamProfile == op<Instr::MCCP>("CamProfile"),
              "MCCP's EXERR numbers (motion/cam) are the operand positions of the signature table");

MccpParams MccpParams::decode(const Operands& q) noexcept {
  constexpr Instr I = kInstr;
  return {q.ref(op<I>("Cam")), q.integer(op<I>("Cam")), q.integer(op<I>("Length")), q.real(op<I>("StartSlope")),
          q.real(op<I>("EndSlope")), q.ref(op<I>("CamProfile"))};
}

// --- MCCP (Motion Calculate Cam Profile), reference 2.13 and section 7.
// Synchronous: the profile is calculated in this scan (Status 1 during the
// calculation, 2 after), so DN is set in the same scan, like Logix' EN/DN/ER
// instruction without IP. The cost is O(Length) and Length is bounded by the
// CAM_PROFILE array's capacity, itself bounded at configuration
// (config `arrays:`, CAM_PROFILE size <= 4096; see motion/cam/README.md).
Err start(Ctx& x, const MccpParams& p) noexcept {
  using namespace cam::mccp_operand;
  if (p.cam >= kMaxCamArrays || x.c.cam_arrays[p.cam].empty()) return x.reject_operand(kCam);
  cam::CamProfile* prof = p.cam_profile < kMaxCamProfiles ? x.c.cam_profiles[p.cam_profile] : nullptr;
  if (prof == nullptr) return x.reject_operand(kCamProfile);
  cam::MccpRequest q;
  q.cam = x.c.cam_arrays[p.cam];
  q.start_index = p.first_point;
  q.length = p.length;
  q.start_slope = p.start_slope;
  q.end_slope = p.end_slope;
  const cam::MccpResult res = cam::mccp(q, *prof);
  if (!res.ok()) {
    x.exerr = static_cast<std::int8_t>(res.exerr);
    return static_cast<Err>(cam::err_code(res.err));
  }
  x.tag.set(flag::DN, true);
  return Err::None;
}

}  // namespace canmotion::motion
