// Array tags of the `arrays:` section (issue #5): CAM arrays (MCCP input),
// CAM_PROFILE arrays (MCCP output) and REAL arrays (MAM EventDistance /
// CalculatedData).
//
// Who owns what:
//  * storage is allocated here, when the Controller is built, and attached to
//    the planner (attach_cam_array / attach_cam_profile / attach_real_array);
//    nothing is resized afterwards;
//  * a program's write (script `pts[3].Master := 2;`, canmotionctl SET) goes
//    through the command ring as cmd::WriteArray, like an instruction
//    request, and the RT thread applies it in program order (cycle step 4);
//  * CAM arrays are written only by programs, so the non-RT side keeps its own
//    copy (cam_shadow_) for reads; REAL arrays are also written by the planner
//    (CalculatedData), so they are read from the status snapshot.
#include <cctype>
#include <cmath>
#include <stdexcept>

#include "rt/controller/controller.hpp"

namespace canmotion::rt {
namespace {

bool same_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

/// CAM member 0 Master, 1 Slave, 2 SegmentType of `p` := `value` (both copies).
void set_cam_member(motion::cam::CamPoint& p, std::uint8_t member, double value) noexcept {
  if (member == 0) p.master = value;
  else if (member == 1) p.slave = value;
  else p.segment_type = static_cast<std::int32_t>(value);
}

}  // namespace

void Controller::build_arrays() {
  using T = ArraySpec::Type;
  std::size_t real_total = 0;
  for (const ArraySpec& a : spec_.arrays)
    if (a.type == T::kReal) real_total += a.size;
  if (real_total > kMaxRealElements)
    throw std::invalid_argument("REAL arrays hold " + std::to_string(real_total) + " elements together; at most " +
                                std::to_string(kMaxRealElements));
  real_store_.assign(real_total, 0.0);  // reserved once: the spans below stay valid
  std::size_t real_arrays = 0;
  for (const ArraySpec& a : spec_.arrays) {
    const std::string what = "array '" + a.name + "'";
    if (a.size == 0) throw std::invalid_argument(what + " has size 0");
    ArrayRef ref;
    ref.type = a.type;
    ref.size = static_cast<std::uint32_t>(a.size);
    switch (a.type) {
      case T::kCam: {
        if (a.cam_values.size() > a.size) throw std::invalid_argument(what + ": more values than its size");
        if (cam_arrays_.size() >= motion::kMaxCamArrays)
          throw std::invalid_argument(what + ": at most " + std::to_string(motion::kMaxCamArrays) + " CAM arrays");
        std::vector<motion::cam::CamPoint> pts(a.size);
        std::copy(a.cam_values.begin(), a.cam_values.end(), pts.begin());
        ref.id = static_cast<std::uint16_t>(cam_arrays_.size());
        cam_arrays_.push_back(pts);
        cam_shadow_.push_back(std::move(pts));
        if (!planner_.attach_cam_array(ref.id, cam_arrays_.back()))
          throw std::invalid_argument(what + ": the planner refused the CAM array");
        break;
      }
      case T::kCamProfile: {
        if (cams_.size() >= motion::kMaxCamProfiles)
          throw std::invalid_argument(what + ": at most " + std::to_string(motion::kMaxCamProfiles) +
                                      " CAM_PROFILE arrays (cams included)");
        ref.id = static_cast<std::uint16_t>(cams_.size());
        cams_.push_back(std::make_unique<motion::cam::CamProfile>(a.size));
        if (!planner_.attach_cam_profile(ref.id, cams_.back().get()))
          throw std::invalid_argument(what + ": the planner refused the CAM_PROFILE array");
        break;
      }
      case T::kReal: {
        if (a.real_values.size() > a.size) throw std::invalid_argument(what + ": more values than its size");
        ref.id = static_cast<std::uint16_t>(real_arrays++);
        // offset = elements of the REAL arrays before this one
        std::size_t off = 0;
        for (const ArrayRef& r : array_refs_)
          if (r.type == T::kReal) off += r.size;
        ref.offset = static_cast<std::uint32_t>(off);
        std::copy(a.real_values.begin(), a.real_values.end(), real_store_.begin() + static_cast<std::ptrdiff_t>(off));
        if (!planner_.attach_real_array(ref.id, std::span<double>(real_store_.data() + off, a.size)))
          throw std::invalid_argument(what + ": at most " + std::to_string(motion::kMaxRealArrays) + " REAL arrays");
        break;
      }
    }
    array_refs_.push_back(ref);
  }
}

std::optional<ArrayRef> Controller::find_array(std::string_view name) const {
  for (std::size_t i = 0; i < spec_.arrays.size(); ++i)
    if (same_name(spec_.arrays[i].name, name)) return array_refs_[i];
  return std::nullopt;
}

std::uint64_t Controller::write_array(const ArrayRef& a, std::uint32_t element, std::uint8_t member, double value) {
  if (element >= a.size || a.type == ArraySpec::Type::kCamProfile) return 0;
  cmd::WriteArray w;
  w.type = a.type;
  w.array = a.id;
  w.element = a.type == ArraySpec::Type::kReal ? a.offset + element : element;
  w.member = member;
  w.value = value;
  std::lock_guard lock(names_mu_);
  if (!commands_.try_push(Queued{w, next_seq_})) return 0;
  if (a.type == ArraySpec::Type::kCam && a.id < cam_shadow_.size()) set_cam_member(cam_shadow_[a.id][element], member, value);
  return next_seq_++;
}

double Controller::read_cam_point(const ArrayRef& a, std::uint32_t element, std::uint8_t member) const {
  std::lock_guard lock(names_mu_);
  if (a.type != ArraySpec::Type::kCam || a.id >= cam_shadow_.size() || element >= cam_shadow_[a.id].size()) return 0.0;
  const motion::cam::CamPoint& p = cam_shadow_[a.id][element];
  return member == 0 ? p.master : (member == 1 ? p.slave : static_cast<double>(p.segment_type));
}

void Controller::take(const cmd::WriteArray& c, std::int64_t) noexcept {
  if (c.type == ArraySpec::Type::kReal) {
    if (c.element < real_store_.size()) real_store_[c.element] = c.value;
    return;
  }
  if (c.type != ArraySpec::Type::kCam || c.array >= cam_arrays_.size() || c.element >= cam_arrays_[c.array].size())
    return;
  set_cam_member(cam_arrays_[c.array][c.element], c.member, c.value);
}

}  // namespace canmotion::rt
