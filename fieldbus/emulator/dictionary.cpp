// The emulated drive's object dictionary: built from the object table
// (kObjectTable), then the MDS objects, absent objects, presets and an EDS's
// object set (eds_dictionary.cpp); lookup and raw access.
#include "fieldbus/emulator/emulator.hpp"

#include <algorithm>

#include "fieldbus/canopen/cob_id.hpp"

namespace canmotion::emulator {

namespace obj = cia402::obj;

void Emulator::add(std::uint16_t index, std::uint8_t sub, std::uint64_t value, const std::string* text) {
  const canopen::ObjectInfo* info = canopen::object_info(index, sub);
  Entry e{key(index, sub),
          info ? info->type : canopen::DataType::kUnsigned32,
          info ? info->access : canopen::Access::kRw,
          info ? info->pdo : canopen::PdoMappable::kNo,
          value,
          value,
          text,
          0,
          0,
          false};
  set_type(e, e.type);
  od_.push_back(e);
}

void Emulator::set_type(Entry& e, canopen::DataType t) noexcept {
  e.type = t;
  const std::size_t size = canopen::data_type_size(t);
  const bool full = size >= 8 || size == 0;
  e.mask = full ? ~std::uint64_t{0} : (std::uint64_t{1} << (8 * size)) - 1;
  e.sign = canopen::data_type_signed(t) && !full ? std::uint64_t{1} << (8 * size - 1) : 0;
}

void Emulator::build_dictionary() {
  const std::uint8_t n = cfg_.node;
  od_.clear();
  add(0x1000, 0, 0x00020192);  // CiA 402, servo drive
  add(0x1001, 0, 0);
  add(0x1003, 0, 0);
  for (std::uint8_t s = 1; s <= 8; ++s) add(0x1003, s, 0);
  add(0x1005, 0, 0x80);
  add(0x1006, 0, 0);
  add(0x1007, 0, 0);
  add(0x1008, 0, 0, &device_name_);
  add(0x1009, 0, 0, &hw_version_);
  add(0x100A, 0, 0, &sw_version_);
  add(0x1014, 0, canopen::cob::emcy(n));
  add(0x1015, 0, 0);
  add(0x1016, 0, 4);
  for (std::uint8_t s = 1; s <= 4; ++s) add(0x1016, s, 0);
  add(0x1017, 0, 0);
  add(0x1018, 0, 4);
  add(0x1018, 1, cfg_.vendor_id);
  add(0x1018, 2, cfg_.product_code);
  add(0x1018, 3, cfg_.revision);
  add(0x1018, 4, n);
  add(0x1019, 0, 0);
  if (cfg_.behaviour.error_behaviour) {
    add(0x1029, 0, 1);
    add(0x1029, 1, 0);  // communication error: enter Pre-operational
  }
  add(0x1200, 0, 2);
  add(0x1200, 1, canopen::cob::sdo_rx(n));
  add(0x1200, 2, canopen::cob::sdo_tx(n));
  // PDO1 at power-on: CiA 402's predefined RPDO1/TPDO1 (controlword /
  // statusword only, event-driven), or (permissive) the master's CSP mapping.
  const bool cia402_pdos = cfg_.behaviour.cia402_default_pdos;
  const std::uint8_t pdo1_count = cia402_pdos ? 1 : 2;
  const std::uint8_t pdo1_type = cia402_pdos ? 255 : 1;
  for (std::uint8_t p = 0; p < 4; ++p) {
    const auto pn = static_cast<std::uint8_t>(p + 1);
    const std::uint32_t inval = p == 0 ? 0 : canopen::kPdoInvalid;
    add(static_cast<std::uint16_t>(0x1400 + p), 0, 2);
    add(static_cast<std::uint16_t>(0x1400 + p), 1, canopen::cob::rpdo(pn, n) | inval);
    add(static_cast<std::uint16_t>(0x1400 + p), 2, p == 0 ? pdo1_type : 1);
    add(static_cast<std::uint16_t>(0x1600 + p), 0, p == 0 ? pdo1_count : 0);
    for (std::uint8_t s = 1; s <= 8; ++s) {
      std::uint32_t v = 0;
      if (p == 0 && s == 1) v = 0x60400010;
      if (p == 0 && s == 2 && !cia402_pdos) v = 0x607A0020;
      add(static_cast<std::uint16_t>(0x1600 + p), s, v);
    }
    add(static_cast<std::uint16_t>(0x1800 + p), 0, 6);
    add(static_cast<std::uint16_t>(0x1800 + p), 1, canopen::cob::tpdo(pn, n) | inval);
    add(static_cast<std::uint16_t>(0x1800 + p), 2, p == 0 ? pdo1_type : 1);
    add(static_cast<std::uint16_t>(0x1800 + p), 3, 0);
    add(static_cast<std::uint16_t>(0x1800 + p), 5, 0);
    add(static_cast<std::uint16_t>(0x1800 + p), 6, 0);
    add(static_cast<std::uint16_t>(0x1A00 + p), 0, p == 0 ? pdo1_count : 0);
    for (std::uint8_t s = 1; s <= 8; ++s) {
      std::uint32_t v = 0;
      if (p == 0 && s == 1) v = 0x60410010;
      if (p == 0 && s == 2 && !cia402_pdos) v = 0x60640020;
      add(static_cast<std::uint16_t>(0x1A00 + p), s, v);
    }
  }
  add(kFaultInjection, 0, 0);
  add(obj::kErrorCode, 0, 0);
  add(obj::kControlword, 0, 0);
  add(obj::kStatusword, 0, 0);
  add(obj::kQuickStopOptionCode, 0, 2);
  add(obj::kShutdownOptionCode, 0, 0);
  add(obj::kDisableOperationOptionCode, 0, 1);
  add(obj::kHaltOptionCode, 0, 1);
  add(obj::kFaultReactionOptionCode, 0, 2);
  add(obj::kModesOfOperation, 0, 8);
  add(obj::kModesOfOperationDisplay, 0, 8);
  add(obj::kPositionDemandValue, 0, 0);
  add(obj::kPositionActualInternalValue, 0, 0);
  add(obj::kPositionActualValue, 0, 0);
  add(obj::kFollowingErrorWindow, 0, cfg_.following_error_window);
  add(obj::kFollowingErrorTimeOut, 0, 0);
  add(obj::kPositionWindow, 0, 100);
  add(obj::kPositionWindowTime, 0, 0);
  add(obj::kVelocityDemandValue, 0, 0);
  add(obj::kVelocityActualValue, 0, 0);
  add(obj::kTargetTorque, 0, 0);
  add(obj::kMaxTorque, 0, 3000);
  add(0x6074, 0, 0);
  add(0x6076, 0, 1000);
  add(obj::kTorqueActualValue, 0, 0);
  add(obj::kTargetPosition, 0, 0);
  add(obj::kHomeOffset, 0, 0);
  add(obj::kSoftwarePositionLimit, 0, 2);
  add(obj::kSoftwarePositionLimit, 1, 0x80000000u);
  add(obj::kSoftwarePositionLimit, 2, 0x7FFFFFFFu);
  add(obj::kMaxProfileVelocity, 0, static_cast<std::uint32_t>(cfg_.max_velocity));
  add(obj::kProfileVelocity, 0, 100000);
  // Ramps of CSV (MDS): by default as fast as the model can go.
  add(obj::kProfileAcceleration, 0, static_cast<std::uint32_t>(cfg_.max_acceleration));
  add(obj::kProfileDeceleration, 0, static_cast<std::uint32_t>(cfg_.max_acceleration));
  add(obj::kQuickStopDeceleration, 0, static_cast<std::uint32_t>(cfg_.max_acceleration));
  add(obj::kHomingMethod, 0, 35);
  add(obj::kHomingSpeeds, 0, 2);
  add(obj::kHomingSpeeds, 1, 100000);
  add(obj::kHomingSpeeds, 2, 10000);
  add(obj::kHomingAcceleration, 0, 1000000);
  add(obj::kPositionOffset, 0, 0);
  add(obj::kVelocityOffset, 0, 0);
  add(obj::kTorqueOffset, 0, 0);
  add(obj::kInterpolationTimePeriod, 0, 2);
  add(obj::kInterpolationTimePeriod, 1, 1);
  add(obj::kInterpolationTimePeriod, 2, static_cast<std::uint8_t>(std::int8_t{-3}));
  add(obj::kFollowingErrorActualValue, 0, 0);
  add(obj::kDigitalInputs, 0, 0);
  add(obj::kTargetVelocity, 0, 0);
  add(obj::kSupportedDriveModes, 0, cfg_.supported_modes);
  const std::vector<std::uint32_t> mds_keys = add_mds_objects();
  // A drive without some optional objects (EmulatorConfig::absent_objects,
  // EmulatorBehaviour::optional_objects_absent: 0x1016 and the MDS objects).
  std::erase_if(od_, [&](const Entry& e) {
    const auto index = static_cast<std::uint16_t>(e.key >> 8);
    if (cfg_.behaviour.optional_objects_absent &&
        (index == 0x1016 || std::find(mds_keys.begin(), mds_keys.end(), e.key) != mds_keys.end()))
      return true;
    return std::find(cfg_.absent_objects.begin(), cfg_.absent_objects.end(), index) != cfg_.absent_objects.end();
  });
  if (cfg_.behaviour.ip_index_read_only) {
    for (Entry& e : od_)
      if (e.key == key(obj::kInterpolationTimePeriod, 2)) e.access = canopen::Access::kRo;
  }
  for (const ObjectPreset& p : cfg_.presets) {
    for (Entry& e : od_) {
      if (e.key != key(p.index, p.sub)) continue;
      e.value = e.default_value = p.value & e.mask;
      if (p.read_only) e.access = canopen::Access::kRo;
    }
  }
  if (!cfg_.served.empty()) apply_served();  // a drive described by an EDS
  std::sort(od_.begin(), od_.end(), [](const Entry& a, const Entry& b) { return a.key < b.key; });
  od_.shrink_to_fit();  // od_ never changes size after this: Entry pointers stay valid
  rebuild_pdos();
}

std::vector<std::uint32_t> Emulator::add_mds_objects() {
  using cia402::MdsObject;
  const cia402::MdsObjects& m = cfg_.mds_objects;
  std::vector<std::uint32_t> keys;
  // Ramps of CSV (MDS): by default no limit beyond the model's own velocity.
  const auto vmax = static_cast<std::uint32_t>(cfg_.max_velocity);
  for (std::size_t i = 0; i < cia402::kMdsObjectCount; ++i) {
    const auto o = static_cast<MdsObject>(i);
    const cia402::ObjectAddress a = m[o];
    const std::uint64_t v = o == MdsObject::kRampVelocityPositive || o == MdsObject::kRampVelocityNegative ? vmax : 0;
    const std::size_t size = cia402::info(o).size;
    const canopen::DataType t = size == 1 ? canopen::DataType::kUnsigned8
                                : size == 2 ? canopen::DataType::kUnsigned16
                                            : canopen::DataType::kUnsigned32;
    // One of the emulator's own objects at that address becomes the MDS object.
    std::erase_if(od_, [&](const Entry& e) { return e.key == key(a.index, a.sub); });
    add(a.index, a.sub, v);
    Entry& e = od_.back();
    set_type(e, t);
    e.access = canopen::Access::kRw;
    e.pdo = canopen::PdoMappable::kNo;
    keys.push_back(e.key);
  }
  // A record's sub-index 0 (highest sub-index supported), unless the index has one.
  for (const cia402::ObjectAddress& a : m.at) {
    if (a.sub == 0 || std::any_of(od_.begin(), od_.end(), [&](const Entry& e) { return e.key == key(a.index, 0); }))
      continue;
    std::uint8_t highest = 0;
    for (const cia402::ObjectAddress& b : m.at)
      if (b.index == a.index) highest = std::max(highest, b.sub);
    add(a.index, 0, highest);
    Entry& e = od_.back();
    set_type(e, canopen::DataType::kUnsigned8);
    e.access = canopen::Access::kRo;
    e.pdo = canopen::PdoMappable::kNo;
    keys.push_back(e.key);
  }
  return keys;
}

std::vector<Emulator::ObjectDescription> Emulator::dictionary() const {
  std::vector<ObjectDescription> d;
  d.reserve(od_.size());
  for (const Entry& e : od_) {
    if (e.hidden) continue;
    d.push_back(ObjectDescription{static_cast<std::uint16_t>(e.key >> 8), static_cast<std::uint8_t>(e.key & 0xFF), e.type,
                                  e.access, e.pdo, e.default_value,
                                  e.text != nullptr ? std::string_view(*e.text) : std::string_view{}});
  }
  return d;
}

void Emulator::resolve_hot() noexcept {
  // Every object below is added by build_dictionary(); one named in
  // EmulatorConfig::absent_objects is nullptr here, which val()/sval()/put()
  // accept (the drive then behaves as if it were 0 and ignores writes).
  auto must_find = [this](std::uint16_t index, std::uint8_t sub = 0) { return find(index, sub); };
  Hot& h = hot_;
  h.error_register = must_find(0x1001);
  h.sync_cob = must_find(0x1005);
  h.emcy_cob = must_find(0x1014);
  for (std::uint8_t s = 1; s <= 4; ++s) h.consumer_hb[s - 1] = must_find(0x1016, s);
  h.producer_hb = must_find(0x1017);
  h.error_code = must_find(obj::kErrorCode);
  h.controlword = must_find(obj::kControlword);
  h.statusword = must_find(obj::kStatusword);
  h.quick_stop_option = must_find(obj::kQuickStopOptionCode);
  h.modes = must_find(obj::kModesOfOperation);
  h.mode_display = must_find(obj::kModesOfOperationDisplay);
  h.position_demand = must_find(obj::kPositionDemandValue);
  h.position_internal = must_find(obj::kPositionActualInternalValue);
  h.position_actual = must_find(obj::kPositionActualValue);
  h.fe_window = must_find(obj::kFollowingErrorWindow);
  h.fe_timeout = must_find(obj::kFollowingErrorTimeOut);
  h.velocity_actual = must_find(obj::kVelocityActualValue);
  h.target_torque = must_find(obj::kTargetTorque);
  h.max_torque = must_find(obj::kMaxTorque);
  h.torque_actual = must_find(obj::kTorqueActualValue);
  h.target_position = must_find(obj::kTargetPosition);
  h.home_offset = must_find(obj::kHomeOffset);
  h.max_profile_velocity = must_find(obj::kMaxProfileVelocity);
  h.quick_stop_decel = must_find(obj::kQuickStopDeceleration);
  h.homing_method = must_find(obj::kHomingMethod);
  h.homing_speed_switch = must_find(obj::kHomingSpeeds, 1);
  h.position_offset = must_find(obj::kPositionOffset);
  h.velocity_offset = must_find(obj::kVelocityOffset);
  h.torque_offset = must_find(obj::kTorqueOffset);
  h.ip_value = must_find(obj::kInterpolationTimePeriod, 1);
  h.ip_index = must_find(obj::kInterpolationTimePeriod, 2);
  h.fe_actual = must_find(obj::kFollowingErrorActualValue);
  h.target_velocity = must_find(obj::kTargetVelocity);
  h.supported_modes = must_find(obj::kSupportedDriveModes);
  h.profile_accel = must_find(obj::kProfileAcceleration);
  h.profile_decel = must_find(obj::kProfileDeceleration);
  auto mds = [&](cia402::MdsObject o) { return must_find(cfg_.mds_objects[o].index, cfg_.mds_objects[o].sub); };
  h.ramp_vpos = mds(cia402::MdsObject::kRampVelocityPositive);
  h.ramp_vneg = mds(cia402::MdsObject::kRampVelocityNegative);
  h.ramp_jerk = mds(cia402::MdsObject::kRampJerkControl);
  h.slat_config = mds(cia402::MdsObject::kSlatConfiguration);
  h.slat_set_point = mds(cia402::MdsObject::kSlatSetPoint);
  h.slat_delay = mds(cia402::MdsObject::kSlatTimeDelay);
}

std::int64_t Emulator::sval(const Entry* e) noexcept {
  if (!e) return 0;
  // canopen::sign_extend(value, 8 * size) for a signed type, with the sign bit cached (0 otherwise).
  return static_cast<std::int64_t>((e->value ^ e->sign) - e->sign);
}

void Emulator::put(Entry* e, std::uint64_t v) noexcept {
  if (!e) return;
  e->value = v & e->mask;  // the low `size` bytes (all of v for 0 or 8)
}

Emulator::Entry* Emulator::find(std::uint16_t index, std::uint8_t sub) noexcept {
  const std::uint32_t k = key(index, sub);
  auto it = std::lower_bound(od_.begin(), od_.end(), k, [](const Entry& e, std::uint32_t kk) { return e.key < kk; });
  return (it != od_.end() && it->key == k) ? &*it : nullptr;
}
const Emulator::Entry* Emulator::find(std::uint16_t index, std::uint8_t sub) const noexcept {
  return const_cast<Emulator*>(this)->find(index, sub);
}
bool Emulator::index_exists(std::uint16_t index) const noexcept {
  const std::uint32_t k = key(index, 0);
  auto it = std::lower_bound(od_.begin(), od_.end(), k, [](const Entry& e, std::uint32_t kk) { return e.key < kk; });
  for (; it != od_.end() && (it->key >> 8) == index; ++it)
    if (!it->hidden) return true;
  return false;
}
std::uint64_t Emulator::get(std::uint16_t index, std::uint8_t sub) const noexcept {
  const Entry* e = find(index, sub);
  return e ? e->value : 0;
}
std::int64_t Emulator::get_signed(std::uint16_t index, std::uint8_t sub) const noexcept { return sval(find(index, sub)); }
void Emulator::set(std::uint16_t index, std::uint8_t sub, std::uint64_t v) noexcept {
  put(find(index, sub), v);
  ++accept_gen_;  // e.g. 0x1005 (SYNC COB-ID): the accepted identifiers may change
}
std::int64_t Emulator::read_int(std::uint16_t index, std::uint8_t sub) const noexcept {
  if (index == obj::kStatusword && sub == 0) return statusword();
  return get_signed(index, sub);
}

void Emulator::reset_dictionary(bool communication_only) noexcept {
  for (Entry& e : od_) {
    const auto index = static_cast<std::uint16_t>(e.key >> 8);
    if (communication_only && (index < 0x1000 || index > 0x1FFF)) continue;
    e.value = e.default_value;
  }
  rebuild_pdos();
  consumers_ = {};
}

}  // namespace canmotion::emulator
