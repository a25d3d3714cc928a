#include "rt/controller/host.hpp"

#include <fmt/format.h>

#include "motion/st_parser.hpp"

namespace canmotion::rt {

std::optional<std::string> ControllerHost::bind(std::string_view call, motion::Request& out, std::string* control_tag) {
  const motion::ParseResult pr = motion::parse_st_call(call);
  if (!pr.ok()) return fmt::format("column {}: {}", pr.error.column, pr.error.message);
  const motion::ParsedCall& pc = *pr.call;
  const motion::InstrSig& sig = motion::signature(pc.instr);
  motion::Symbols sym;
  for (std::size_t a = 0; a < c_.axis_count(); ++a) sym.axes.emplace(c_.axis_name(static_cast<motion::AxisId>(a)), static_cast<motion::AxisId>(a));
  for (std::size_t i = 0; i < pc.operands.size() && i < sig.operands.size(); ++i) {
    if (sig.operands[i].kind != motion::OperandKind::Control || pc.operands[i].kind != motion::StOperand::Kind::Tag) continue;
    const auto id = c_.control_id(pc.operands[i].text);
    if (!id) return fmt::format("no room for control tag '{}' (all {} are in use)", pc.operands[i].text, motion::kMaxControlTags);
    sym.controls.emplace(pc.operands[i].text, *id);
    if (control_tag) *control_tag = pc.operands[i].text;
  }
  for (const auto& [name, value] : tags_.user_tags()) sym.numeric_tags.emplace(name, value);
  // REAL array elements as numeric operands (`MAM(X, m, 0, ed[1], ...)`): their
  // current value from the status snapshot, as for any numeric tag.
  for (std::size_t i = 0; i < pc.operands.size() && i < sig.operands.size(); ++i) {
    const motion::StOperand& op = pc.operands[i];
    const auto k = sig.operands[i].kind;
    if (op.kind != motion::StOperand::Kind::Tag || !op.index ||
        (k != motion::OperandKind::Real && k != motion::OperandKind::Int && k != motion::OperandKind::Enum))
      continue;
    const auto arr = c_.find_array(op.text);
    if (!arr || arr->type != ArraySpec::Type::kReal) continue;
    const std::string name = op.text + "[" + std::to_string(*op.index) + "]";
    std::string e;
    if (const auto v = tags_.read(refresh(), name, &e)) sym.numeric_tags.emplace(name, *v);
    else return fmt::format("operand {} ({}): {}", i, sig.operands[i].name, e);
  }
  for (std::size_t i = 0; i < c_.spec().coordinate_systems.size(); ++i)
    sym.coordinate_systems.emplace(c_.spec().coordinate_systems[i].name, static_cast<std::uint16_t>(i));
  for (const auto& cam : c_.spec().cams)
    sym.cam_profiles.emplace(cam.name, *c_.cam_id(cam.name));
  for (const auto& arr : c_.spec().arrays) {  // `arrays:` tags, by kind
    const auto ref = c_.find_array(arr.name);
    if (arr.type == ArraySpec::Type::kCam) sym.cams.emplace(arr.name, ref->id);
    else if (arr.type == ArraySpec::Type::kCamProfile) sym.cam_profiles.emplace(arr.name, ref->id);
    else sym.real_arrays.emplace(arr.name, ref->id);
  }
  return motion::bind_call(pc, sym, out);
}

std::optional<std::string> ControllerHost::check_call(std::string_view call) {
  motion::Request r;
  return bind(call, r, nullptr);
}

std::optional<std::string> ControllerHost::check_tag(std::string_view tag, bool for_write) {
  std::string e;
  const auto t = tags_.resolve(tag, &e);
  if (for_write) {
    if (t && !t->writable) return fmt::format("tag '{}' is read-only", tag);
    if (!t && !TagTable::is_user_tag_name(tag)) return e;  // e.g. an array element out of range
    return std::nullopt;  // a new numeric tag is created by its first assignment
  }
  if (t) return std::nullopt;
  // A control tag first used by a later call in the same script is fine.
  if (const std::size_t dot = tag.find('.'); dot != std::string_view::npos) {
    const std::string_view base = tag.substr(0, dot);
    if (!c_.axis_id(base) && base != "Controller") {
      (void)c_.control_id(base);
      if (tags_.resolve(tag, &e)) return std::nullopt;
    }
  }
  return e;
}

std::optional<std::string> ControllerHost::execute(std::string_view call, std::string* control_tag) {
  cmd::Instruction c;
  if (auto e = bind(call, c.request, control_tag)) return e;
  const std::uint64_t seq = c_.submit(c);
  if (seq == 0) return std::string("the command queue to the RT thread is full; try again");
  last_seq_ = seq;
  return std::nullopt;
}

std::optional<std::string> ControllerHost::set_mode(motion::ControllerMode m) {
  const std::uint64_t seq = c_.submit(cmd::ControllerMode{m});
  if (seq == 0) return std::string("the command queue to the RT thread is full; try again");
  last_seq_ = seq;
  return std::nullopt;
}

const Status& ControllerHost::refresh() {
  c_.read_status(*status_);
  return *status_;
}

bool ControllerHost::settled() { return refresh().done_seq >= last_seq_; }

std::optional<double> ControllerHost::read(std::string_view tag, std::string* error) {
  return tags_.read(refresh(), tag, error);
}

void ControllerHost::declare(std::string_view tag) {
  std::string e;
  if (!tags_.resolve(tag, &e)) (void)tags_.write(tag, 0.0, true);
}

std::optional<std::string> ControllerHost::write(std::string_view tag, double value) {
  auto e = tags_.write(tag, value, true);
  // An array element write is a command to the RT thread: settled() waits for it.
  if (!e && tags_.last_write_seq() > last_seq_) last_seq_ = tags_.last_write_seq();
  return e;
}

}  // namespace canmotion::rt
