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

// The emulator's own objects, one row each (a row with `subs` or `pdos`
// above 1 stands for a run of sub-indices or for PDOs 1..4). Columns:
// index, first sub-index, last sub-index, where the power-on value comes
// from, the value (Default::kValue) or PDO 1's mapping entry, the Hot entry
// the application reads and writes it through (a Hot array for a run of
// sub-indices), how many PDOs (consecutive indices), only with
// EmulatorBehaviour::error_behaviour. Data type, access and PDO mapping come
// from the project's one table of CiA 301/402 objects,
// canopen::object_info() (canopen/object_names.hpp). Data table.
// clang-format off
const Emulator::ObjectRow Emulator::kObjectTable[] = {
  // ---- CiA 301 communication profile -------------------------------------------------------
  {0x1000, 0, 0, Default::kValue, 0x00020192},                     // device type: CiA 402, servo drive
  {0x1001, 0, 0, Default::kValue, 0, &Hot::error_register},
  {0x1003, 0, 8, Default::kValue, 0},                              // pre-defined error field
  {0x1005, 0, 0, Default::kValue, 0x80, &Hot::sync_cob},
  {obj::kCommunicationCyclePeriod, 0, 0, Default::kValue, 0},
  {0x1007, 0, 0, Default::kValue, 0},
  {0x1008, 0, 0, Default::kDeviceName, 0},
  {0x1009, 0, 0, Default::kHardwareVersion, 0},
  {0x100A, 0, 0, Default::kSoftwareVersion, 0},
  {0x1014, 0, 0, Default::kEmcyCobId, 0, &Hot::emcy_cob},
  {0x1015, 0, 0, Default::kValue, 0},
  {0x1016, 0, 0, Default::kValue, 4},
  {0x1016, 1, 4, Default::kValue, 0, nullptr, &Hot::consumer_hb},
  {0x1017, 0, 0, Default::kValue, 0, &Hot::producer_hb},
  {obj::kIdentity, 0, 0, Default::kValue, 4},
  {obj::kIdentity, 1, 1, Default::kVendorId, 0},
  {obj::kIdentity, 2, 2, Default::kProductCode, 0},
  {obj::kIdentity, 3, 3, Default::kRevision, 0},
  {obj::kIdentity, 4, 4, Default::kNodeId, 0},
  {obj::kSyncCounterOverflow, 0, 0, Default::kValue, 0},
  {0x1029, 0, 0, Default::kValue, 1, nullptr, nullptr, 1, true},
  {0x1029, 1, 1, Default::kValue, 0, nullptr, nullptr, 1, true},  // communication error: enter Pre-operational
  {0x1200, 0, 0, Default::kValue, 2},
  {0x1200, 1, 1, Default::kSdoRxCobId, 0},
  {0x1200, 2, 2, Default::kSdoTxCobId, 0},
  // PDOs 1..4. PDO1 at power-on: CiA 402's predefined RPDO1/TPDO1
  // (controlword / statusword only, event-driven), or (permissive,
  // EmulatorBehaviour::cia402_default_pdos false) the master's CSP mapping.
  {0x1400, 0, 0, Default::kValue, 2, nullptr, nullptr, 4},
  {0x1400, 1, 1, Default::kRpdoCobId, 0, nullptr, nullptr, 4},
  {0x1400, 2, 2, Default::kPdo1TransmissionType, 0, nullptr, nullptr, 4},
  {0x1600, 0, 0, Default::kPdo1MapCount, 0, nullptr, nullptr, 4},
  {0x1600, 1, 1, Default::kPdo1Map, 0x60400010, nullptr, nullptr, 4},     // controlword
  {0x1600, 2, 2, Default::kPdo1CspMap, 0x607A0020, nullptr, nullptr, 4},  // target position
  {0x1600, 3, 8, Default::kValue, 0, nullptr, nullptr, 4},
  {0x1800, 0, 0, Default::kValue, 6, nullptr, nullptr, 4},
  {0x1800, 1, 1, Default::kTpdoCobId, 0, nullptr, nullptr, 4},
  {0x1800, 2, 2, Default::kPdo1TransmissionType, 0, nullptr, nullptr, 4},
  {0x1800, 3, 3, Default::kValue, 0, nullptr, nullptr, 4},               // inhibit time (100 us)
  {0x1800, 5, 5, Default::kValue, 0, nullptr, nullptr, 4},               // event timer (ms)
  {0x1800, 6, 6, Default::kValue, 0, nullptr, nullptr, 4},               // SYNC start value
  {0x1A00, 0, 0, Default::kPdo1MapCount, 0, nullptr, nullptr, 4},
  {0x1A00, 1, 1, Default::kPdo1Map, 0x60410010, nullptr, nullptr, 4},     // statusword
  {0x1A00, 2, 2, Default::kPdo1CspMap, 0x60640020, nullptr, nullptr, 4},  // position actual value
  {0x1A00, 3, 8, Default::kValue, 0, nullptr, nullptr, 4},
  // ---- manufacturer area ------------------------------------------------------------------
  {Emulator::kFaultInjection, 0, 0, Default::kValue, 0},
  // ---- CiA 402 drive profile ------------------------------------------------------------------
  {obj::kErrorCode, 0, 0, Default::kValue, 0, &Hot::error_code},
  {obj::kControlword, 0, 0, Default::kValue, 0, &Hot::controlword},
  {obj::kStatusword, 0, 0, Default::kValue, 0, &Hot::statusword},
  {obj::kQuickStopOptionCode, 0, 0, Default::kValue, 2, &Hot::quick_stop_option},
  {obj::kShutdownOptionCode, 0, 0, Default::kValue, 0},
  {obj::kDisableOperationOptionCode, 0, 0, Default::kValue, 1},
  {obj::kHaltOptionCode, 0, 0, Default::kValue, 1},
  {obj::kFaultReactionOptionCode, 0, 0, Default::kValue, 2},
  {obj::kModesOfOperation, 0, 0, Default::kValue, 8, &Hot::modes},
  {obj::kModesOfOperationDisplay, 0, 0, Default::kValue, 8, &Hot::mode_display},
  {obj::kPositionDemandValue, 0, 0, Default::kValue, 0, &Hot::position_demand},
  {obj::kPositionActualInternalValue, 0, 0, Default::kValue, 0, &Hot::position_internal},
  {obj::kPositionActualValue, 0, 0, Default::kValue, 0, &Hot::position_actual},
  {obj::kFollowingErrorWindow, 0, 0, Default::kFollowingErrorWindow, 0, &Hot::fe_window},
  {obj::kFollowingErrorTimeOut, 0, 0, Default::kValue, 0, &Hot::fe_timeout},
  {obj::kPositionWindow, 0, 0, Default::kValue, 100},
  {obj::kPositionWindowTime, 0, 0, Default::kValue, 0},
  {obj::kVelocityDemandValue, 0, 0, Default::kValue, 0},
  {obj::kVelocityActualValue, 0, 0, Default::kValue, 0, &Hot::velocity_actual},
  {obj::kTargetTorque, 0, 0, Default::kValue, 0, &Hot::target_torque},
  {obj::kMaxTorque, 0, 0, Default::kValue, 3000, &Hot::max_torque},
  {0x6074, 0, 0, Default::kValue, 0},                              // torque demand
  {0x6076, 0, 0, Default::kValue, 1000},                           // motor rated torque
  {obj::kTorqueActualValue, 0, 0, Default::kValue, 0, &Hot::torque_actual},
  {obj::kTargetPosition, 0, 0, Default::kValue, 0, &Hot::target_position},
  {obj::kHomeOffset, 0, 0, Default::kValue, 0, &Hot::home_offset},
  {obj::kSoftwarePositionLimit, 0, 0, Default::kValue, 2},
  {obj::kSoftwarePositionLimit, 1, 1, Default::kValue, 0x80000000u},
  {obj::kSoftwarePositionLimit, 2, 2, Default::kValue, 0x7FFFFFFFu},
  {obj::kMaxProfileVelocity, 0, 0, Default::kMaxVelocity, 0, &Hot::max_profile_velocity},
  {obj::kProfileVelocity, 0, 0, Default::kValue, 100000},
  // Ramps of CSV (MDS): by default as fast as the model can go.
  {obj::kProfileAcceleration, 0, 0, Default::kMaxAcceleration, 0, &Hot::profile_accel},
  {obj::kProfileDeceleration, 0, 0, Default::kMaxAcceleration, 0, &Hot::profile_decel},
  {obj::kQuickStopDeceleration, 0, 0, Default::kMaxAcceleration, 0, &Hot::quick_stop_decel},
  {obj::kHomingMethod, 0, 0, Default::kValue, 35, &Hot::homing_method},
  {obj::kHomingSpeeds, 0, 0, Default::kValue, 2},
  {obj::kHomingSpeeds, 1, 1, Default::kValue, 100000, &Hot::homing_speed_switch},
  {obj::kHomingSpeeds, 2, 2, Default::kValue, 10000},
  {obj::kHomingAcceleration, 0, 0, Default::kValue, 1000000},
  {obj::kPositionOffset, 0, 0, Default::kValue, 0, &Hot::position_offset},
  {obj::kVelocityOffset, 0, 0, Default::kValue, 0, &Hot::velocity_offset},
  {obj::kTorqueOffset, 0, 0, Default::kValue, 0, &Hot::torque_offset},
  {obj::kInterpolationSubModeSelect, 0, 0, Default::kValue, 0},  // 0: linear interpolation (the only one modelled)
  {obj::kInterpolationDataRecord, 0, 0, Default::kValue, 1},
  {obj::kInterpolationDataRecord, 1, 1, Default::kValue, 0, &Hot::ip_data},
  {obj::kInterpolationTimePeriod, 0, 0, Default::kValue, 2},
  {obj::kInterpolationTimePeriod, 1, 1, Default::kValue, 1, &Hot::ip_value},
  {obj::kInterpolationTimePeriod, 2, 2, Default::kValue, 0xFD, &Hot::ip_index},  // -3: milliseconds
  {obj::kFollowingErrorActualValue, 0, 0, Default::kValue, 0, &Hot::fe_actual},
  {obj::kDigitalInputs, 0, 0, Default::kValue, 0},
  {obj::kTargetVelocity, 0, 0, Default::kValue, 0, &Hot::target_velocity},
  {obj::kSupportedDriveModes, 0, 0, Default::kSupportedModes, 0, &Hot::supported_modes},
};
// clang-format on

std::uint64_t Emulator::default_of(const ObjectRow& r, std::uint8_t pdo) const noexcept {
  const std::uint8_t n = cfg_.node;
  const bool cia402_pdos = cfg_.behaviour.cia402_default_pdos;
  const auto pn = static_cast<std::uint8_t>(pdo + 1);
  const std::uint32_t invalid = pdo == 0 ? 0 : canopen::kPdoInvalid;  // PDOs 2..4 start invalid
  switch (r.from) {
    case Default::kValue: return r.value;
    case Default::kNodeId: return n;
    case Default::kEmcyCobId: return canopen::cob::emcy(n);
    case Default::kSdoRxCobId: return canopen::cob::sdo_rx(n);
    case Default::kSdoTxCobId: return canopen::cob::sdo_tx(n);
    case Default::kVendorId: return cfg_.vendor_id;
    case Default::kProductCode: return cfg_.product_code;
    case Default::kRevision: return cfg_.revision;
    case Default::kFollowingErrorWindow: return cfg_.following_error_window;
    case Default::kMaxVelocity: return static_cast<std::uint32_t>(cfg_.max_velocity);
    case Default::kMaxAcceleration: return static_cast<std::uint32_t>(cfg_.max_acceleration);
    case Default::kSupportedModes: return cfg_.supported_modes;
    case Default::kDeviceName:
    case Default::kHardwareVersion:
    case Default::kSoftwareVersion: return 0;  // text_of()
    case Default::kRpdoCobId: return canopen::cob::rpdo(pn, n) | invalid;
    case Default::kTpdoCobId: return canopen::cob::tpdo(pn, n) | invalid;
    case Default::kPdo1TransmissionType: return pdo == 0 && cia402_pdos ? 255 : 1;
    case Default::kPdo1MapCount: return pdo != 0 ? 0 : cia402_pdos ? 1 : 2;
    case Default::kPdo1Map: return pdo == 0 ? r.value : 0;
    case Default::kPdo1CspMap: return pdo == 0 && !cia402_pdos ? r.value : 0;
  }
  return 0;
}

const std::string* Emulator::text_of(const ObjectRow& r) const noexcept {
  switch (r.from) {
    case Default::kDeviceName: return &device_name_;
    case Default::kHardwareVersion: return &hw_version_;
    case Default::kSoftwareVersion: return &sw_version_;
    default: return nullptr;
  }
}

void Emulator::build_dictionary() {
  od_.clear();
  for (const ObjectRow& r : kObjectTable) {
    if (r.error_behaviour_only && !cfg_.behaviour.error_behaviour) continue;
    for (std::uint8_t p = 0; p < r.pdos; ++p) {
      const std::uint64_t v = default_of(r, p);
      for (unsigned s = r.sub; s <= r.sub_last; ++s)
        add(static_cast<std::uint16_t>(r.index + p), static_cast<std::uint8_t>(s), v, text_of(r));
    }
  }
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
  // Every object of kObjectTable is added by build_dictionary(); one named in
  // EmulatorConfig::absent_objects is nullptr here, which val()/sval()/put()
  // accept (the drive then behaves as if it were 0 and ignores writes).
  Hot& h = hot_;
  for (const ObjectRow& r : kObjectTable) {
    if (r.wire != nullptr) h.*r.wire = find(r.index, r.sub);
    if (r.wires != nullptr)
      for (unsigned s = r.sub; s <= r.sub_last; ++s) (h.*r.wires)[s - r.sub] = find(r.index, static_cast<std::uint8_t>(s));
  }
  auto mds = [&](cia402::MdsObject o) { return find(cfg_.mds_objects[o].index, cfg_.mds_objects[o].sub); };
  h.ramp_vpos = mds(cia402::MdsObject::kRampVelocityPositive);
  h.ramp_vneg = mds(cia402::MdsObject::kRampVelocityNegative);
  h.ramp_jerk = mds(cia402::MdsObject::kRampJerkControl);
  h.slat_config = mds(cia402::MdsObject::kSlatConfiguration);
  h.slat_set_point = mds(cia402::MdsObject::kSlatSetPoint);
  h.slat_delay = mds(cia402::MdsObject::kSlatTimeDelay);
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
