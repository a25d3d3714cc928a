// The planner's public API (motion/planner.hpp): a cycle, and the execution
// of one instruction: checks against the signature table, decode into the
// typed params, one std::visit to the family's start().
#include "motion/planner.hpp"

#include <algorithm>
#include <array>
#include <variant>

#include "motion/instr/ctx.hpp"
#include "motion/instr/direct.hpp"
#include "motion/instr/stop.hpp"
#include "motion/instructions.hpp"

namespace canmotion::motion {
namespace {

/// What every execution is checked for before its start(), in this order:
/// operand count (ERR 13, EXERR = the count given or expected), executable
/// (ERR 75), axis and group operands exist (ERR 11), operand values against
/// the signature table (ERR 13 with the operand index).
Err check_request(Ctx& x) noexcept {
  const Request& r = x.r;
  const InstrSig& sig = signature(r.instr);
  if (r.count != sig.operands.size()) {
    x.exerr = static_cast<std::int8_t>(std::min<std::size_t>(r.count, sig.operands.size()));
    return Err::ParameterOutOfRange;
  }
  if (!sig.executable) return Err::InstructionNotSupported;
  for (std::size_t i = 0; i < sig.operands.size(); ++i) {
    const auto k = sig.operands[i].kind;
    const auto ref = r.op[i].ref;
    if (k == OperandKind::Axis && (ref >= kMaxAxes || !x.c.axes[ref].present)) return Err::AxisNotConfigured;
    if (k == OperandKind::Group && ref >= kMaxGroups) return Err::AxisNotConfigured;
    if (k == OperandKind::CoordSystem && (ref >= kMaxCoordSystems || !x.c.systems[ref].present))
      return Err::AxisNotConfigured;
  }
  std::array<double, kMaxOperands> vals{};
  for (std::size_t i = 0; i < kMaxOperands; ++i) vals[i] = r.op[i].value;
  const OperandCheck oc = check_operands(r.instr, std::span<const double>(vals.data(), sig.operands.size()));
  return oc.ok ? Err::None : x.reject_operand(oc.index);
}

}  // namespace

void Planner::set_controller_mode(ControllerMode m) noexcept {
  if (m == c_.mode) return;
  c_.mode = m;
  stop::change_mode(c_, m == ControllerMode::Program);
  for (std::size_t k = 0; k < c_.axis_count; ++k)
    if (c_.axes[k].present) c_.update_status(c_.axes[k]);
}

Result Planner::update(const Input& in, Output& out) noexcept {
  if (c_.started && in.cycle <= c_.cycle) return Result::ErrorCycleNotIncreasing;
  c_.read_feedback(in);                             // 1. feedback and exceptions, against last cycle's command
  for (const Request& r : in.requests) execute(r);  // 2. requests in program order
  c_.step(in.cycle, out);                           // 3. every axis, masters before slaves: outputs, tags
  stop::finish_group_stops(c_);                     // 4. group stops: PC when their ramps ended
  return Result::Ok;
}

Err Planner::execute(const Request& r) noexcept {
  if (r.control >= kMaxControlTags) return Err::ParameterOutOfRange;
  ControlTag& tag = c_.controls[r.control];
  tag.begin_execution();
  Ctx x{c_, r, tag, OwnerRef{r.control, tag.generation}};
  Err e = check_request(x);
  if (e == Err::None && c_.mode == ControllerMode::Program && signature(r.instr).starts_motion) e = Err::IllegalControllerMode;
  // the typed params (from the table-checked request) to the family's start()
  if (e == Err::None) e = std::visit([&x](const auto& p) noexcept { return start(x, p); }, decode(r));
  if (e != Err::None) tag.reject(e, x.exerr);
  // refresh the tags of the axes this request named (all axes for group instructions)
  const auto ops = signature(r.instr).operands;
  for (std::size_t i = 0; i < ops.size() && i < r.count; ++i) {
    if (ops[i].kind == OperandKind::Axis && r.op[i].ref < kMaxAxes && c_.axes[r.op[i].ref].present)
      c_.update_status(c_.axes[r.op[i].ref]);
    if (ops[i].kind == OperandKind::CoordSystem && r.op[i].ref < kMaxCoordSystems && c_.systems[r.op[i].ref].present) {
      const CoordSystemRt& s = c_.systems[r.op[i].ref];
      for (int m = 0; m < s.cfg.dim; ++m) c_.update_status(c_.axes[s.cfg.axes[static_cast<std::size_t>(m)]]);
    }
    if (ops[i].kind == OperandKind::Group)
      for (std::size_t k = 0; k < c_.axis_count; ++k)
        if (c_.axes[k].present) c_.update_status(c_.axes[k]);
  }
  return e;
}

bool Planner::set_direct_command(AxisId id, double value) noexcept { return direct::set_command(c_, id, value); }

bool Planner::set_direct_velocity_command(AxisId id, double value) noexcept {
  return direct::set_velocity_command(c_, id, value);
}

bool Planner::configure_coordinate_system(CoordSystemId id, const CoordSystemConfig& cfg) noexcept {
  return coordsys::configure(c_, id, cfg);
}

bool Planner::attach_cam_profile(std::uint16_t id, cam::CamProfile* profile) noexcept {
  if (id >= kMaxCamProfiles) return false;
  c_.cam_profiles[id] = profile;
  return true;
}

bool Planner::attach_cam_array(std::uint16_t id, std::span<cam::CamPoint> points) noexcept {
  if (id >= kMaxCamArrays) return false;
  c_.cam_arrays[id] = points;
  return true;
}

bool Planner::attach_real_array(std::uint16_t id, std::span<double> values) noexcept {
  if (id >= kMaxRealArrays) return false;
  c_.real_arrays[id] = values;
  return true;
}

}  // namespace canmotion::motion
