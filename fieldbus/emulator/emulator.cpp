#include "fieldbus/emulator/emulator.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/emcy.hpp"

namespace canmotion::emulator {

using canopen::SdoAbort;
using cia402::State;
namespace obj = cia402::obj;

namespace {
constexpr std::uint16_t kFaultInjection = 0x2000;
bool is_rpdo_comm(std::uint16_t i) { return i >= 0x1400 && i <= 0x1403; }
bool is_rpdo_map(std::uint16_t i) { return i >= 0x1600 && i <= 0x1603; }
bool is_tpdo_comm(std::uint16_t i) { return i >= 0x1800 && i <= 0x1803; }
bool is_tpdo_map(std::uint16_t i) { return i >= 0x1A00 && i <= 0x1A03; }

using cia402::round_half_away;

std::uint8_t error_register_for(std::uint16_t code) {
  std::uint8_t r = canopen::kErrGeneric;
  switch (code >> 12) {
    case 0x2: r |= canopen::kErrCurrent; break;
    case 0x3: r |= canopen::kErrVoltage; break;
    case 0x4: r |= canopen::kErrTemperature; break;
    case 0x8:
      if ((code >> 8) == 0x81 || (code >> 8) == 0x82) {
        r |= canopen::kErrCommunication;
      } else {
        r |= canopen::kErrDeviceProfile;
      }
      break;
    case 0xF: r |= canopen::kErrManufacturer; break;
    default: break;
  }
  return r;
}
}  // namespace

EmulatorBehaviour EmulatorBehaviour::permissive() noexcept {
  EmulatorBehaviour b;
  b.optional_objects_absent = false;
  b.ip_index_read_only = false;
  b.remap_preoperational_only = false;
  b.cia402_default_pdos = false;
  b.rpdo_too_long_emcy = false;
  b.check_sync_length = false;
  b.sync_timeout = false;
  b.error_behaviour = false;
  b.boot_ns = 0;
  b.sdo_reply_delay_ns = 0;
  b.one_transition_per_sync = false;
  b.fault_cause_syncs = 0;
  b.mode_switch_syncs = 0;
  b.refuse_unsupported_modes = false;
  b.homing_takes_time = false;
  return b;
}

Emulator::Emulator(const EmulatorConfig& cfg)
    : cfg_(cfg),
      device_name_(cfg.device_name),
      hw_version_("emulated 1.0"),
      sw_version_("canmotion 0.1"),
      sdo_(cfg.node, *this) {
  cfg_.lag_cycles = std::min<std::uint32_t>(cfg_.lag_cycles, kMaxLag);
  build_dictionary();
  resolve_hot();
  pos_ = cfg_.initial_position;
  torque_per_acc_ = 1000.0 / cfg_.max_acceleration;
}

// ============================================================================
// Object dictionary
// ============================================================================
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

void Emulator::rebuild_pdos() noexcept {
  for (std::uint8_t p = 0; p < 4; ++p) {
    for (int dir = 0; dir < 2; ++dir) {
      const bool rx = dir == 0;
      const auto comm = static_cast<std::uint16_t>((rx ? 0x1400 : 0x1800) + p);
      const auto map = static_cast<std::uint16_t>((rx ? 0x1600 : 0x1A00) + p);
      canopen::PdoMap m;
      m.dir = rx ? canopen::PdoDir::kRpdo : canopen::PdoDir::kTpdo;
      m.number = static_cast<std::uint8_t>(p + 1);
      const auto cob = static_cast<std::uint32_t>(get(comm, 1));
      m.cob_id = cob & 0x7FFu;
      m.transmission_type = static_cast<std::uint8_t>(get(comm, 2));
      const auto count = static_cast<std::uint8_t>(get(map, 0));
      for (std::uint8_t s = 1; s <= count && s <= 8; ++s) {
        const auto e = canopen::decode_mapping_entry(static_cast<std::uint32_t>(get(map, s)));
        m.add(e.index, e.sub, e.bits);
      }
      const bool ok = m.finalize();
      const bool valid = (cob & canopen::kPdoInvalid) == 0 && ok && m.count > 0 && served(comm, 1) != nullptr;
      auto& cache = rx ? rpdo_entries_[p] : tpdo_entries_[p];
      cache = {};
      for (std::uint8_t i = 0; i < m.count; ++i) {
        const canopen::PdoEntry& pe = m.entries[i];
        MappedEntry& me = cache[i];
        me.entry = find(pe.index, pe.sub);
        me.is_statusword = pe.index == obj::kStatusword && pe.sub == 0;
        me.is_controlword = pe.index == obj::kControlword;
      }
      (rx ? rpdo_plan_[p] : tpdo_plan_[p]) = canopen::PdoPlan::of(m);
      if (rx) {
        rpdo_[p] = m;
        rpdo_valid_[p] = valid;
      } else {
        tpdo_[p] = m;
        tpdo_valid_[p] = valid;
        tpdo_sync_count_[p] = 0;
        tpdo_sent_[p] = false;  // types 0/254/255: the next chance sends it
      }
    }
  }
  rpdo_active_count_ = tpdo_active_count_ = 0;
  for (std::uint8_t p = 0; p < 4; ++p) {
    if (rpdo_valid_[p]) rpdo_active_[rpdo_active_count_++] = p;
    if (tpdo_valid_[p]) tpdo_active_[tpdo_active_count_++] = p;
  }
  ++accept_gen_;
}

SdoAbort Emulator::check_pdo_write(std::uint16_t index, std::uint8_t sub, std::uint64_t v) const noexcept {
  if (cfg_.behaviour.remap_preoperational_only && nmt_ == canopen::NmtState::kOperational) return SdoAbort::kDeviceState;
  if (is_rpdo_comm(index) || is_tpdo_comm(index)) {
    if (sub == 1) {
      const auto cur = static_cast<std::uint32_t>(get(index, 1));
      const auto nv = static_cast<std::uint32_t>(v);
      if ((nv & 0x20000000u) != 0) return SdoAbort::kInvalidValue;  // 29-bit IDs not supported
      const bool cur_valid = (cur & canopen::kPdoInvalid) == 0;
      const bool new_valid = (nv & canopen::kPdoInvalid) == 0;
      // CiA 301: the CAN-ID may only change while the PDO is invalid.
      if (cur_valid && new_valid && (cur & 0x7FFu) != (nv & 0x7FFu)) return SdoAbort::kInvalidValue;
      if (new_valid && (nv & 0x7FFu) == 0) return SdoAbort::kInvalidValue;
    }
    if (sub == 2 && v >= 241 && v <= 251) return SdoAbort::kInvalidValue;
    return SdoAbort::kNone;
  }
  const bool rx = is_rpdo_map(index);
  const auto comm = static_cast<std::uint16_t>(index - 0x200);
  if ((get(comm, 1) & canopen::kPdoInvalid) == 0) return SdoAbort::kDeviceState;  // PDO must be invalid first
  if (sub == 0) {
    if (v > 8) return SdoAbort::kPdoLength;
    unsigned bits = 0;
    for (std::uint8_t s = 1; s <= v; ++s) {
      const auto e = canopen::decode_mapping_entry(static_cast<std::uint32_t>(get(index, s)));
      if (e.index == 0) return SdoAbort::kParameterIncompatible;
      bits += e.bits;
    }
    if (bits > 64) return SdoAbort::kPdoLength;
    return SdoAbort::kNone;
  }
  if (get(index, 0) != 0) return SdoAbort::kDeviceState;  // sub0 must be 0 while entries change
  if (v == 0) return SdoAbort::kNone;
  const auto e = canopen::decode_mapping_entry(static_cast<std::uint32_t>(v));
  const Entry* target = served(e.index, e.sub);
  if (target == nullptr) return index_exists(e.index) ? SdoAbort::kNoSubindex : SdoAbort::kNoObject;
  const bool mappable = rx ? (target->pdo == canopen::PdoMappable::kRpdo || target->pdo == canopen::PdoMappable::kBoth)
                           : (target->pdo == canopen::PdoMappable::kTpdo || target->pdo == canopen::PdoMappable::kBoth);
  if (!mappable) return SdoAbort::kNotMappable;
  if (e.bits != canopen::data_type_size(target->type) * 8) return SdoAbort::kParameterIncompatible;
  return SdoAbort::kNone;
}

SdoAbort Emulator::sdo_read(std::uint16_t index, std::uint8_t sub, std::span<std::uint8_t> out, std::size_t& len) noexcept {
  const Entry* e = served(index, sub);
  if (e == nullptr) return index_exists(index) ? SdoAbort::kNoSubindex : SdoAbort::kNoObject;
  if (e->access == canopen::Access::kWo) return SdoAbort::kWriteOnly;
  if (e->text != nullptr) {
    len = std::min(e->text->size(), out.size());
    std::copy_n(e->text->begin(), len, out.begin());
    return SdoAbort::kNone;
  }
  std::uint64_t v = e->value;
  if (index == obj::kStatusword && sub == 0) v = statusword();
  len = std::min(canopen::data_type_size(e->type), out.size());
  for (std::size_t i = 0; i < len; ++i) out[i] = static_cast<std::uint8_t>(v >> (8 * i));
  return SdoAbort::kNone;
}

SdoAbort Emulator::sdo_write(std::uint16_t index, std::uint8_t sub, std::span<const std::uint8_t> data) noexcept {
  Entry* e = find(index, sub);
  if (e == nullptr || e->hidden) return index_exists(index) ? SdoAbort::kNoSubindex : SdoAbort::kNoObject;
  if (e->access == canopen::Access::kRo || e->access == canopen::Access::kConst) return SdoAbort::kReadOnly;
  const std::size_t n = canopen::data_type_size(e->type);
  if (data.size() > n) return SdoAbort::kLengthTooHigh;
  if (data.size() < n) return SdoAbort::kLengthTooLow;
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(data[i]) << (8 * i);
  const bool pdo_obj = is_rpdo_comm(index) || is_tpdo_comm(index) || is_rpdo_map(index) || is_tpdo_map(index);
  if (pdo_obj) {
    const SdoAbort a = check_pdo_write(index, sub, v);
    if (a != SdoAbort::kNone) return a;
  }
  if (index == obj::kModesOfOperation && !mode_supported(static_cast<std::int8_t>(v))) return SdoAbort::kInvalidValue;
  if (index == obj::kHomingMethod && !homing_method_supported(static_cast<std::int8_t>(v))) return SdoAbort::kInvalidValue;
  if (index == obj::kSyncCounterOverflow && cfg_.behaviour.check_sync_length) {
    // CiA 301, as CANopenNode's CO_ODF_1019: only while 0x1006 is 0, and 0 or 2..240.
    if (get(obj::kCommunicationCyclePeriod) != 0) return SdoAbort::kDeviceState;
    if (v == 1 || v > 240) return SdoAbort::kInvalidValue;
  }
  if (index == 0x1029 && sub == 1 && v > 2) return SdoAbort::kInvalidValue;
  if (index == obj::kInterpolationTimePeriod && sub == 1 && v == 0) return SdoAbort::kInvalidValue;
  const std::optional<cia402::MdsObject> mds = cfg_.mds_objects.find(index, sub);
  if (mds == cia402::MdsObject::kRampJerkControl && v > 100) return SdoAbort::kValueTooHigh;
  if (mds == cia402::MdsObject::kSlatConfiguration && v > 2) return SdoAbort::kInvalidValue;
  if (index == obj::kInterpolationTimePeriod && sub == 2) {
    const auto i = static_cast<std::int8_t>(v);
    if (i < -9) return SdoAbort::kValueTooLow;
    if (i > 0) return SdoAbort::kValueTooHigh;
  }
  if (index == 0x1003 && sub == 0) {
    if (v != 0) return SdoAbort::kInvalidValue;
    for (std::uint8_t s = 1; s <= 8; ++s) set(0x1003, s, 0);
  }
  if (index == 0x1016 && sub >= 1) {
    const auto ms = v & 0xFFFF;
    const auto id = (v >> 16) & 0xFF;
    if ((v >> 24) != 0) return SdoAbort::kInvalidValue;
    if (ms != 0 && (id == 0 || id > 127)) return SdoAbort::kInvalidValue;
  }
  set(index, sub, v);
  if (pdo_obj) rebuild_pdos();
  if (index == 0x1017) next_heartbeat_ns_ = now_ns_ + static_cast<std::int64_t>(v) * 1'000'000;
  if (index == 0x1016) consumers_[static_cast<std::size_t>(std::min<std::uint8_t>(sub, 4) - 1)] = Consumer{};
  if (index == kFaultInjection && sub == 0 && v != 0 && !mds) inject_fault(static_cast<std::uint16_t>(v));
  // A mode written over SDO outside Operation enabled is taken at once, as
  // an SDO controlword makes its transition at once: no motion is handed
  // over, and a master may set the mode before it produces any SYNC (a drive
  // whose 0x6060 starts at 0, e.g. from its EDS). While enabled the switch
  // waits EmulatorBehaviour::mode_switch_syncs SYNCs (update_mode_display()).
  if (index == obj::kModesOfOperation && state_ != State::kOperationEnabled && !cfg_.refuse_mode_switch) {
    mode_wanted_ = static_cast<std::int8_t>(v);
    mode_countdown_ = 0;
    set_mode_display(mode_wanted_);
  }
  if (index == obj::kControlword && out_ != nullptr && cfg_.remote) apply_controlword(static_cast<std::uint16_t>(v), *out_);
  return SdoAbort::kNone;
}

// ============================================================================
// Communication
// ============================================================================
void Emulator::send_emcy(std::uint16_t code, canopen::FrameSink& out) noexcept {
  if (nmt_ == canopen::NmtState::kStopped) return;
  const auto cob = static_cast<std::uint32_t>(val(hot_.emcy_cob));
  if ((cob & canopen::kPdoInvalid) != 0) return;
  canopen::Emcy e;
  e.node = cfg_.node;
  e.code = code;
  e.error_register = static_cast<std::uint8_t>(val(hot_.error_register));
  can::Frame f = canopen::make_emcy_frame(e);
  f.id = cob & 0x7FFu;
  out.send(f);
  ++counters_.emcys;
}

void Emulator::power_on(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  now_ns_ = now_ns;
  powered_ = true;
  reset_dictionary(false);
  sdo_.reset();
  state_ = State::kNotReadyToSwitchOn;  // transition 0
  // Transition 1 when the DC bus has charged (automatic_transitions()).
  boot_ready_ns_ = now_ns + cfg_.behaviour.boot_ns;
  last_cw_ = 0;
  settled_cw_ = {};
  active_fault_ = pending_fault_ = 0;
  fault_cause_syncs_left_ = 0;
  rpdo_short_error_ = rpdo_long_error_ = sync_length_error_ = sync_timeout_error_ = false;
  last_sync_ns_ = -1;
  rpdo_short_mask_ = rpdo_long_mask_ = 0;
  homing_active_ = homing_done_ = homing_error_ = false;
  homing_phase_ = HomingPhase::kIdle;
  sdo_queue_size_ = 0;
  following_error_ = false;
  vel_ = acc_ = 0;
  mode_wanted_ = static_cast<std::int8_t>(get(obj::kModesOfOperation));
  mode_countdown_ = 0;
  set_mode_display(mode_wanted_);
  set(obj::kPositionActualValue, 0, static_cast<std::uint32_t>(position()));
  set(obj::kTargetPosition, 0, static_cast<std::uint32_t>(position()));
  nmt_ = canopen::NmtState::kPreOperational;
  out.send(canopen::make_heartbeat_frame(cfg_.node, canopen::NmtState::kBootUp));
  ++counters_.boot_ups;
  next_heartbeat_ns_ = now_ns;
  automatic_transitions(false, out);  // transition 1 at once when boot_ns is 0
}

void Emulator::handle_nmt(const can::Frame& f, std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  const auto nmt = canopen::decode_nmt(f);
  if (!nmt || (nmt->node != 0 && nmt->node != cfg_.node)) return;
  switch (nmt->command) {
    case 0x01: nmt_ = canopen::NmtState::kOperational; break;
    case 0x02: nmt_ = canopen::NmtState::kStopped; break;
    case 0x80: nmt_ = canopen::NmtState::kPreOperational; break;
    case 0x81: power_on(now_ns, out); break;
    case 0x82:
      reset_dictionary(true);
      last_sync_ns_ = -1;  // 0x1006 back to its default: the SYNC watch starts again
      sync_timeout_error_ = false;
      sdo_.reset();
      sdo_queue_size_ = 0;
      nmt_ = canopen::NmtState::kPreOperational;
      out.send(canopen::make_heartbeat_frame(cfg_.node, canopen::NmtState::kBootUp));
      ++counters_.boot_ups;
      next_heartbeat_ns_ = now_ns;
      break;
    default: break;
  }
}

/// FrameSink that holds the SDO server's replies in the emulator's delay
/// queue (EmulatorBehaviour::sdo_reply_delay_ns) instead of sending them.
class DelayedSdoSink final : public canopen::FrameSink {
 public:
  explicit DelayedSdoSink(Emulator& e) noexcept : e_(e) {}
  bool send(const can::Frame& f) noexcept override {
    if (e_.sdo_queue_size_ == e_.sdo_queue_.size()) {
      ++e_.counters_.sdo_replies_dropped;  // a drive's SDO buffer overrun
      return false;
    }
    const std::size_t tail = (e_.sdo_queue_head_ + e_.sdo_queue_size_) % e_.sdo_queue_.size();
    e_.sdo_queue_[tail] = Emulator::DelayedFrame{f, e_.now_ns_ + e_.cfg_.behaviour.sdo_reply_delay_ns};
    ++e_.sdo_queue_size_;
    return true;
  }

 private:
  Emulator& e_;
};

void Emulator::flush_sdo_replies(canopen::FrameSink& out) noexcept {
  // Strictly later than the call that queued them (due_ns > that call's time).
  while (sdo_queue_size_ > 0 && sdo_queue_[sdo_queue_head_].due_ns <= now_ns_) {
    out.send(sdo_queue_[sdo_queue_head_].frame);
    sdo_queue_head_ = (sdo_queue_head_ + 1) % sdo_queue_.size();
    --sdo_queue_size_;
  }
}

void Emulator::on_frame(const can::TimedFrame& tf, canopen::FrameSink& out) noexcept {
  const can::Frame& f = tf.frame;
  if (!powered_ || f.extended() || f.error()) return;
  out_ = &out;
  if (f.id == canopen::cob::kNmt) {
    handle_nmt(f, now_ns_, out);
    out_ = nullptr;
    return;
  }
  if (f.id == (val(hot_.sync_cob) & 0x7FFu)) {
    if (nmt_ == canopen::NmtState::kOperational || nmt_ == canopen::NmtState::kPreOperational) {
      // CiA 301: a SYNC carries the counter byte exactly when 0x1019 > 0.
      const std::uint8_t want = get(0x1019) == 0 ? 0 : 1;
      const bool bad = cfg_.behaviour.check_sync_length && f.len != want;
      comm_error(sync_length_error_, bad, canopen::emcy_code::kUnexpectedSyncLength, out);
      if (bad) {
        ++counters_.sync_length_errors;  // not processed
      } else {
        last_sync_ns_ = now_ns_;
        comm_error(sync_timeout_error_, false, canopen::emcy_code::kCommunication, out);
        handle_sync(now_ns_, out);
      }
    }
    out_ = nullptr;
    return;
  }
  // What classify() would say, without the full switch: an SDO request to
  // this node is 0x600 + node; a heartbeat is 0x700 + node (node 1..127).
  const std::uint32_t fc = f.id & 0x780u;
  const auto from_node = static_cast<std::uint8_t>(f.id & 0x7Fu);
  if (f.id == canopen::cob::sdo_rx(cfg_.node) && cfg_.node >= 1 && cfg_.node <= 127) {
    if (nmt_ != canopen::NmtState::kStopped && !f.remote()) {
      ++counters_.sdo_requests;
      if (cfg_.behaviour.sdo_reply_delay_ns > 0) {
        DelayedSdoSink delayed(*this);
        sdo_.on_frame(f, now_ns_, delayed);
      } else {
        sdo_.on_frame(f, now_ns_, out);
      }
    }
  } else if (fc == 0x700u && from_node != 0 && f.id <= 0x7FFu) {
    for (std::uint8_t s = 1; s <= 4; ++s) {
      const auto v = val(hot_.consumer_hb[s - 1]);
      if ((v & 0xFFFF) != 0 && ((v >> 16) & 0xFF) == from_node) {
        Consumer& k = consumers_[s - 1];
        k.armed = true;
        k.lost = false;
        k.last_ns = now_ns_;
      }
    }
  } else if (nmt_ == canopen::NmtState::kOperational && !f.remote()) {
    for (std::uint8_t k = 0; k < rpdo_active_count_; ++k) {
      const std::size_t p = rpdo_active_[k];
      if (f.id != rpdo_[p].cob_id) continue;
      // CiA 301: a short RPDO is not processed (EMCY 8210h); a long one is
      // processed with its first bytes (EMCY 8220h, strict). Each EMCY once
      // while the error lasts, 0000h when a right one follows.
      const bool short_pdo = f.len < rpdo_[p].size_bytes;
      const bool long_pdo = cfg_.behaviour.rpdo_too_long_emcy && f.len > rpdo_[p].size_bytes;
      const auto bit = static_cast<std::uint8_t>(1u << p);
      rpdo_short_mask_ = static_cast<std::uint8_t>(short_pdo ? rpdo_short_mask_ | bit : rpdo_short_mask_ & ~bit);
      rpdo_long_mask_ = static_cast<std::uint8_t>(long_pdo ? rpdo_long_mask_ | bit : rpdo_long_mask_ & ~bit);
      comm_error(rpdo_short_error_, rpdo_short_mask_ != 0, canopen::emcy_code::kPdoLength, out);
      comm_error(rpdo_long_error_, rpdo_long_mask_ != 0, canopen::emcy_code::kPdoLengthExceeded, out);
      if (short_pdo) {
        ++counters_.rpdo_length_errors;
        continue;
      }
      ++counters_.rpdos;
      if (rpdo_[p].transmission_type >= 254) {
        // Event-driven RPDO: applied on receipt, not at the next SYNC.
        if (apply_rpdo(p, canopen::payload_word(f))) evaluate_controlword(out);
      } else {
        rpdo_latch_[p] = canopen::payload_word(f);  // all handle_sync() reads of it
        rpdo_pending_ = static_cast<std::uint8_t>(rpdo_pending_ | (1u << p));
      }
    }
  }
  out_ = nullptr;
}

void Emulator::accepted_ids(std::array<std::uint64_t, 2048 / 64>& ids,
                            std::array<std::uint64_t, 2048 / 64>& openers) const noexcept {
  // Keep in step with on_frame(): exactly the identifiers it can act on.
  ids = {};
  openers = {};
  auto add = [](std::array<std::uint64_t, 2048 / 64>& set, std::uint32_t id) noexcept {
    if (id < 2048) set[id >> 6] |= std::uint64_t{1} << (id & 63u);
  };
  add(ids, canopen::cob::kNmt);
  add(ids, static_cast<std::uint32_t>(val(hot_.sync_cob) & 0x7FFu));
  add(ids, canopen::cob::sdo_rx(cfg_.node));
  // Only NMT (reset: the defaults again) and SDO writes (0x1005, 0x14xx,
  // 0x16xx) change what is accepted; SYNC, RPDOs and heartbeats do not.
  add(openers, canopen::cob::kNmt);
  add(openers, canopen::cob::sdo_rx(cfg_.node));
  // Heartbeats 0x701..0x77F (any producer: the consumer entries 0x1016 pick theirs).
  static_assert(canopen::cob::kHeartbeatBase % 128 == 0);
  ids[canopen::cob::kHeartbeatBase >> 6] |= ~std::uint64_t{1};  // 0x701..0x73F
  ids[(canopen::cob::kHeartbeatBase >> 6) + 1] = ~std::uint64_t{0};  // 0x740..0x77F
  for (std::uint8_t k = 0; k < rpdo_active_count_; ++k) add(ids, rpdo_[rpdo_active_[k]].cob_id);
}

void Emulator::step(std::int64_t now_ns, canopen::FrameSink& out) noexcept {
  now_ns_ = now_ns;
  if (!powered_) return;
  out_ = &out;
  const auto hb_ms = static_cast<std::int64_t>(val(hot_.producer_hb));
  if (hb_ms > 0 && now_ns >= next_heartbeat_ns_) {
    out.send(canopen::make_heartbeat_frame(cfg_.node, nmt_));
    ++counters_.heartbeats;
    next_heartbeat_ns_ = std::max(next_heartbeat_ns_ + hb_ms * 1'000'000, now_ns + 1);
  }
  for (std::uint8_t s = 1; s <= 4; ++s) {
    Consumer& k = consumers_[s - 1];
    const auto v = val(hot_.consumer_hb[s - 1]);
    const auto ms = static_cast<std::int64_t>(v & 0xFFFF);
    if (!k.armed || k.lost || ms == 0) continue;
    if (now_ns - k.last_ns > ms * 1'000'000) {
      k.lost = true;
      refresh_error_register();  // communication error
      switch (cfg_.heartbeat_loss_reaction) {
        case HeartbeatLossReaction::kFault: pending_fault_ = canopen::emcy_code::kHeartbeatError; break;
        case HeartbeatLossReaction::kQuickStop:
          if (state_ == State::kOperationEnabled) state_ = State::kQuickStopActive;  // transition 11
          send_emcy(canopen::emcy_code::kHeartbeatError, out);
          break;
        case HeartbeatLossReaction::kNone: send_emcy(canopen::emcy_code::kHeartbeatError, out); break;
      }
      automatic_transitions(false, out);  // 13 now, not at the next SYNC (the master may be gone)
      apply_error_behaviour();
    }
  }
  // The SYNC watch (0x1006, EmulatorBehaviour::sync_timeout): 1.5 periods
  // without a SYNC, once one came (CANopenNode's CO_SYNC_process).
  const auto period_us = static_cast<std::int64_t>(get(cia402::obj::kCommunicationCyclePeriod));
  if (cfg_.behaviour.sync_timeout && period_us > 0 && last_sync_ns_ >= 0 && !sync_timeout_error_ &&
      (nmt_ == canopen::NmtState::kOperational || nmt_ == canopen::NmtState::kPreOperational) &&
      now_ns - last_sync_ns_ > period_us * 1'500) {
    ++counters_.sync_timeouts;
    comm_error(sync_timeout_error_, true, canopen::emcy_code::kCommunication, out);
    apply_error_behaviour();
  }
  automatic_transitions(false, out);
  sdo_.step(now_ns, out);
  flush_sdo_replies(out);
  if (nmt_ == canopen::NmtState::kOperational) {
    put(hot_.statusword, statusword());  // an SDO controlword or a fault may have changed it
    send_tpdos(false, out);
  }
  out_ = nullptr;
}

void Emulator::service(can::Transport& bus, std::int64_t now_ns) noexcept {
  canopen::TransportSink sink(bus);
  now_ns_ = now_ns;
  for (;;) {
    const std::size_t n = bus.receive(rx_buf_);
    for (std::size_t i = 0; i < n; ++i) on_frame(rx_buf_[i], sink);
    if (n < rx_buf_.size()) break;
  }
  step(now_ns, sink);
}

namespace {
/// FrameSink straight to a SimBus endpoint (a direct call: Endpoint is final).
class SimEndpointSink final : public canopen::FrameSink {
 public:
  explicit SimEndpointSink(can::SimBus::Endpoint& ep) noexcept : ep_(ep) {}
  bool send(const can::Frame& f) noexcept override { return ep_.send(f) == can::SendResult::kOk; }

 private:
  can::SimBus::Endpoint& ep_;
};
}  // namespace

void Emulator::service(can::SimBus::Endpoint& bus, std::int64_t now_ns) noexcept {
  SimEndpointSink sink(bus);
  now_ns_ = now_ns;
  // What this endpoint sends never comes back to it, so the frames stay put
  // while they are handled (see SimBus::Endpoint::peek).
  for (std::span<const can::TimedFrame> run = bus.peek(); !run.empty(); run = bus.peek()) {
    for (const can::TimedFrame& f : run) on_frame(f, sink);
    bus.consume(run.size());
  }
  step(now_ns, sink);
}

// ============================================================================
// CiA 402
// ============================================================================
std::uint16_t Emulator::statusword() const noexcept {
  std::uint16_t sw = cia402::state_bits(state_);
  if (cfg_.remote) sw |= cia402::sw::kRemote;
  switch (state_) {
    case State::kReadyToSwitchOn:
    case State::kSwitchedOn:
    case State::kOperationEnabled:
    case State::kQuickStopActive:
    case State::kFaultReactionActive: sw |= cia402::sw::kVoltageEnabled; break;
    default: break;
  }
  if (state_ == State::kSwitchOnDisabled || state_ == State::kFault) sw |= cia402::sw::kQuickStop;
  const auto mode = static_cast<cia402::Mode>(mode_display_);
  if (state_ == State::kOperationEnabled) {
    if (cia402::is_cyclic(mode)) sw |= cia402::sw::kFollowsCommand;
    if (mode == cia402::Mode::kHoming) {
      if (homing_done_) sw |= cia402::sw::kHomingAttained | cia402::sw::kTargetReached;
      if (homing_error_) sw |= cia402::sw::kHomingError | (vel_ == 0.0 ? cia402::sw::kTargetReached : 0);
      if (!homing_active_ && !homing_done_ && !homing_error_) sw |= cia402::sw::kTargetReached;  // interrupted / not started
    }
  }
  if (following_error_ && mode == cia402::Mode::kCsp) sw |= cia402::sw::kFollowingError;
  return sw;
}

std::int32_t Emulator::position() const noexcept {
  const double p = round_half_away(pos_);
  return static_cast<std::int32_t>(std::clamp(p, -2147483648.0, 2147483647.0));
}

void Emulator::enter_fault(std::uint16_t code, canopen::FrameSink& out) noexcept {
  active_fault_ = code;
  set(obj::kErrorCode, 0, code);
  refresh_error_register();
  for (std::uint8_t s = 8; s > 1; --s) set(0x1003, s, get(0x1003, static_cast<std::uint8_t>(s - 1)));
  set(0x1003, 1, code);
  set(0x1003, 0, std::min<std::uint64_t>(get(0x1003, 0) + 1, 8));
  if (state_ != State::kFault) state_ = State::kFaultReactionActive;  // transition 13
  send_emcy(code, out);
}

void Emulator::apply_controlword(std::uint16_t cw, canopen::FrameSink& out) noexcept {
  const auto qs = static_cast<std::int16_t>(sval(hot_.quick_stop_option));
  std::uint16_t prev = last_cw_;
  // Permissive: 0x000F from Ready to switch on gives 3 and 4 in this call;
  // strict: one transition, the next at the next SYNC (handle_sync()).
  const int max_transitions = cfg_.behaviour.one_transition_per_sync ? 1 : 2;
  for (int i = 0; i < max_transitions; ++i) {
    const cia402::StepResult r = cia402::apply_controlword(state_, prev, cw, qs);
    if (r.transition == cia402::kNoTransition) {
      if (prev == cw) settled_cw_ = SettledControlword{true, state_, cw, qs};
      break;
    }
    if (r.transition == 15) {
      if (fault_cause_remains()) {
        ++counters_.refused_fault_resets;  // stays in Fault; the edge is used up
        break;
      }
      active_fault_ = 0;
      following_error_ = false;
      following_error_cycles_ = 0;
      set(obj::kErrorCode, 0, 0);
      if (cfg_.behaviour.fault_cause_syncs == 0) {
        for (auto& k : consumers_) k.lost = false;  // permissive: the reset forgets a lost heartbeat
      }
      refresh_error_register();
      send_emcy(canopen::emcy_code::kNoError, out);  // error reset
    }
    if (r.next == State::kOperationEnabled) {
      // Enabling never jumps: the delay line starts at the present target.
      const Setpoint sp{static_cast<std::int32_t>(sval(hot_.target_position)),
                        static_cast<std::int32_t>(sval(hot_.target_velocity)),
                        static_cast<std::int16_t>(sval(hot_.target_torque))};
      delay_.fill(sp);
      prev_demand_ = sp.position;
      if (!cfg_.refuse_mode_switch && cfg_.behaviour.mode_switch_syncs == 0 && mode_supported(static_cast<std::int8_t>(sval(hot_.modes))))
        set_mode_display(static_cast<std::int8_t>(sval(hot_.modes)));
      reset_direct_model();
    }
    state_ = r.next;
    prev = cw;
  }
  // Homing start: rising edge of bit 4 in Operation enabled, mode 6.
  if (state_ == State::kOperationEnabled && mode_display_ == static_cast<std::int8_t>(cia402::Mode::kHoming) &&
      (cw & cia402::cw::kHomingStart) != 0 && (last_cw_ & cia402::cw::kHomingStart) == 0) {
    start_homing();
  }
  if ((cw & cia402::cw::kHomingStart) == 0) homing_active_ = false;
  last_cw_ = cw;
}

void Emulator::advance_motor(double dt) noexcept {
  // 1 / dt, computed when 0x60C2 changes: multiplications instead of the
  // ~15-cycle divisions of the CSP path on every SYNC (a deliberate change
  // of the last bit of some results against dividing by dt).
  const double inv_dt = sync_period_.inv_dt;
  const Setpoint now_sp{static_cast<std::int32_t>(sval(hot_.target_position) + sval(hot_.position_offset)),
                        static_cast<std::int32_t>(sval(hot_.target_velocity) + sval(hot_.velocity_offset)),
                        static_cast<std::int16_t>(sval(hot_.target_torque) + sval(hot_.torque_offset))};
  // Delay line: the setpoint used now is the one received lag_cycles SYNCs ago.
  const std::size_t len = cfg_.lag_cycles + 1;
  // delay_head_ < len (lag_cycles is fixed at construction), so the slot
  // lag_cycles back, (head + len - lag_cycles) % len, is the next one: no division.
  delay_[delay_head_] = now_sp;
  const std::size_t next = delay_head_ + 1 == len ? 0 : delay_head_ + 1;
  const Setpoint sp = delay_[next];
  delay_head_ = next;

  const double vmax = std::min(cfg_.max_velocity, static_cast<double>(val(hot_.max_profile_velocity)));
  double amax = cfg_.max_acceleration;
  double v_des = 0;
  const auto mode = static_cast<cia402::Mode>(mode_display_);
  double torque = 0;
  bool stop_immediately = false;
  if (state_ == State::kOperationEnabled) {
    switch (mode) {
      case cia402::Mode::kCsp: {
        const double demand = sp.position;
        // Feed-forward of the demand's change plus a proportional correction
        // of the error left from the previous SYNC: a ramp is followed exactly
        // (the only following error is the lag), a step settles geometrically.
        const double v_ff = (demand - prev_demand_) * inv_dt;
        v_des = v_ff + cfg_.position_gain * (prev_demand_ - pos_) * inv_dt;
        prev_demand_ = demand;
        put(hot_.position_demand, static_cast<std::uint32_t>(sp.position));
        break;
      }
      case cia402::Mode::kCsv: v_des = csv_ramp(sp.velocity, dt); break;
      case cia402::Mode::kCst: {
        const double tmax = static_cast<double>(val(hot_.max_torque));
        v_des = cst_step(std::clamp(static_cast<double>(sp.torque), -tmax, tmax), sp.velocity, dt, torque);
        break;
      }
      case cia402::Mode::kHoming: v_des = homing_velocity(dt, amax, stop_immediately); break;
      default: break;
    }
  } else if (state_ == State::kQuickStopActive) {
    amax = static_cast<double>(val(hot_.quick_stop_decel));
    v_des = 0;
  } else {
    stop_immediately = true;  // power stage off: the model stops (brake)
  }
  if (stop_immediately) {
    acc_ = 0;
    vel_ = 0;
    reset_direct_model();
  } else {
    v_des = std::clamp(v_des, -vmax, vmax);
    const double dv = std::clamp(v_des - vel_, -amax * dt, amax * dt);
    acc_ = dv * inv_dt;
    vel_ += dv;
    pos_ += vel_ * dt;
  }
  const double trq = mode == cia402::Mode::kCst && state_ == State::kOperationEnabled ? torque : acc_ * torque_per_acc_;
  torque_ = trq;
  put(hot_.torque_actual, static_cast<std::uint16_t>(static_cast<std::int16_t>(std::clamp(round_half_away(trq), -32768.0, 32767.0))));
}

void Emulator::update_outputs() noexcept {
  const std::int32_t p = position();
  put(hot_.position_actual, static_cast<std::uint32_t>(p));
  put(hot_.position_internal, static_cast<std::uint32_t>(p));
  put(hot_.velocity_actual, static_cast<std::uint32_t>(static_cast<std::int32_t>(round_half_away(vel_))));
  put(hot_.fe_actual, static_cast<std::uint32_t>(static_cast<std::int32_t>(sval(hot_.target_position) - p)));
  put(hot_.statusword, statusword());
}

std::uint64_t Emulator::tpdo_payload(std::size_t p) const noexcept {
  const canopen::PdoMap& m = tpdo_[p];
  const auto& cache = tpdo_entries_[p];
  const canopen::PdoPlan& plan = tpdo_plan_[p];
  std::uint64_t w = 0;  // the payload, stored at once
  for (std::uint8_t i = 0; i < m.count; ++i) {
    const MappedEntry& me = cache[i];
    // Callers store statusword() in 0x6041 first (update_outputs(), step()).
    w = plan.put(w, i, me.is_statusword ? val(hot_.statusword) : val(me.entry));
  }
  return w;
}

void Emulator::send_tpdos(bool at_sync, canopen::FrameSink& out) noexcept {
  for (std::uint8_t k = 0; k < tpdo_active_count_; ++k) {  // the valid ones, ascending
    const std::size_t p = tpdo_active_[k];
    const canopen::PdoMap& m = tpdo_[p];
    const std::uint8_t t = m.transmission_type;
    if (t >= 241 && t <= 253) continue;  // RTR-only / reserved: never sent by themselves
    const bool event = t >= 254;
    if (!event && !at_sync) continue;  // synchronous types: only at a SYNC
    if (t >= 1 && t <= 240) {
      ++tpdo_sync_count_[p];
      if (t >= 2 && tpdo_sync_count_[p] % t != 0) continue;  // (1: every SYNC, no division)
    }
    const std::uint64_t w = tpdo_payload(p);
    if (t == 0 || event) {
      const bool changed = !tpdo_sent_[p] || w != tpdo_last_payload_[p];
      if (t == 0 && !changed) continue;  // acyclic synchronous: at the SYNC after a change
      if (event) {
        const auto comm = static_cast<std::uint16_t>(0x1800 + p);
        const std::int64_t since = now_ns_ - tpdo_last_sent_ns_[p];
        const auto event_ms = static_cast<std::int64_t>(get(comm, 5));
        const bool timer = tpdo_sent_[p] && event_ms > 0 && since >= event_ms * 1'000'000;
        if (!changed && !timer) continue;
        const auto inhibit_100us = static_cast<std::int64_t>(get(comm, 3));
        if (tpdo_sent_[p] && since < inhibit_100us * 100'000) continue;  // sent when the inhibit time is over
      }
    }
    can::Frame f;
    f.id = m.cob_id;
    f.len = m.size_bytes;
    canopen::set_payload_word(f, w);
    out.send(f);
    tpdo_last_payload_[p] = w;
    tpdo_last_sent_ns_[p] = now_ns_;
    tpdo_sent_[p] = true;
    ++counters_.tpdos;
  }
}

bool Emulator::apply_rpdo(std::size_t p, std::uint64_t w) noexcept {
  const canopen::PdoMap& m = rpdo_[p];
  const canopen::PdoPlan& plan = rpdo_plan_[p];
  const auto& cache = rpdo_entries_[p];
  bool cw_written = false;
  for (std::uint8_t i = 0; i < m.count; ++i) {
    const MappedEntry& me = cache[i];
    put(me.entry, plan.get(w, i));
    if (me.is_controlword) cw_written = true;
  }
  return cw_written;
}

void Emulator::evaluate_controlword(canopen::FrameSink& out) noexcept {
  if (!cfg_.remote) return;  // local control: the bus's controlword is ignored
  const auto cw = static_cast<std::uint16_t>(val(hot_.controlword));
  // The controlword of the last call again, in a state where it was seen
  // to cause no transition without an edge: apply_controlword() would
  // change nothing (no transition, no homing edge, homing_active_ already
  // cleared if bit 4 is 0), so it is not called (most SYNCs).
  const bool settled = cw == last_cw_ && settled_cw_.valid && settled_cw_.state == state_ && settled_cw_.cw == cw &&
                       settled_cw_.qs == static_cast<std::int16_t>(sval(hot_.quick_stop_option)) &&
                       ((cw & cia402::cw::kHomingStart) != 0 || !homing_active_);
  if (!settled) apply_controlword(cw, out);
}

bool Emulator::mode_supported(std::int8_t mode) const noexcept {
  if (mode == 0) return true;  // no mode
  // 0x6502 as the drive serves it (an EDS's value with cia402-emu --eds);
  // EmulatorConfig::supported_modes when the drive has no 0x6502.
  const std::uint64_t modes = hot_.supported_modes != nullptr ? hot_.supported_modes->value : cfg_.supported_modes;
  return (modes & cia402::supported_mode_bit(static_cast<cia402::Mode>(mode))) != 0;
}

void Emulator::set_mode_display(std::int8_t mode) noexcept {
  mode_display_ = mode;
  put(hot_.mode_display, static_cast<std::uint8_t>(mode));
}

void Emulator::switch_mode(std::int8_t mode) noexcept {
  if (state_ == State::kOperationEnabled && mode != mode_display_) {
    // Mode switch while enabled: the new mode starts from the present state.
    prev_demand_ = pos_;
    delay_.fill(Setpoint{position(), static_cast<std::int32_t>(sval(hot_.target_velocity)),
                         static_cast<std::int16_t>(sval(hot_.target_torque))});
    reset_direct_model();
  }
  set_mode_display(mode);
}

void Emulator::update_mode_display() noexcept {
  if (cfg_.refuse_mode_switch) return;  // fault injection: 0x6061 keeps showing the old mode
  const auto modes = static_cast<std::int8_t>(sval(hot_.modes));
  if (cfg_.behaviour.refuse_unsupported_modes && !mode_supported(modes)) {
    mode_wanted_ = mode_display_;  // an RPDO wrote a mode the drive lacks: not taken
    return;
  }
  if (modes != mode_wanted_) {
    mode_wanted_ = modes;
    mode_countdown_ = cfg_.behaviour.mode_switch_syncs;
  }
  if (mode_countdown_ > 0) {
    --mode_countdown_;
    return;
  }
  if (mode_wanted_ != mode_display_) switch_mode(mode_wanted_);
}

bool Emulator::fault_cause_remains() const noexcept {
  if (fault_cause_held_ || fault_cause_syncs_left_ > 0) return true;
  if (cfg_.behaviour.fault_cause_syncs == 0) return false;
  for (const Consumer& k : consumers_)
    if (k.lost) return true;  // the master's heartbeat has not come back
  return false;
}

void Emulator::refresh_error_register() noexcept {
  std::uint8_t r = active_fault_ != 0 ? error_register_for(active_fault_) : 0;
  bool comm = rpdo_short_error_ || rpdo_long_error_ || sync_length_error_ || sync_timeout_error_;
  for (const Consumer& k : consumers_) comm = comm || k.lost;
  if (comm) r |= canopen::kErrGeneric | canopen::kErrCommunication;
  put(hot_.error_register, r);
}

void Emulator::comm_error(bool& flag, bool active, std::uint16_t code, canopen::FrameSink& out) noexcept {
  if (flag == active) return;
  flag = active;
  refresh_error_register();
  send_emcy(active ? code : canopen::emcy_code::kNoError, out);
}

void Emulator::apply_error_behaviour() noexcept {
  if (!cfg_.behaviour.error_behaviour) return;
  switch (get(0x1029, 1)) {
    case 0:
      if (nmt_ == canopen::NmtState::kOperational) nmt_ = canopen::NmtState::kPreOperational;
      break;
    case 2: nmt_ = canopen::NmtState::kStopped; break;
    default: break;  // 1: no change of the NMT state
  }
}

void Emulator::automatic_transitions(bool at_sync, canopen::FrameSink& out) noexcept {
  // 1: initialisation done (the DC bus has charged).
  if (state_ == State::kNotReadyToSwitchOn && now_ns_ >= boot_ready_ns_) state_ = State::kSwitchOnDisabled;
  if (at_sync) {
    // 12: the quick stop has stopped the motor (0x605A = 1..4; 5..8 stay).
    if (state_ == State::kQuickStopActive && vel_ == 0.0 &&
        !cia402::quick_stop_stays(static_cast<std::int16_t>(sval(hot_.quick_stop_option))))
      state_ = State::kSwitchOnDisabled;
    // 14: the fault reaction, begun before this SYNC, is complete.
    if (state_ == State::kFaultReactionActive) state_ = State::kFault;
    if (fault_cause_syncs_left_ > 0) --fault_cause_syncs_left_;
  }
  // 13: a fault was detected (injected, following error, heartbeat lost).
  if (pending_fault_ != 0) {
    const std::uint16_t code = pending_fault_;
    pending_fault_ = 0;
    if (code != canopen::emcy_code::kHeartbeatError && code != canopen::emcy_code::kFollowingError)
      fault_cause_syncs_left_ = cfg_.behaviour.fault_cause_syncs;  // an injected fault's cause lasts
    enter_fault(code, out);
  }
}

void Emulator::handle_sync(std::int64_t /*now_ns*/, canopen::FrameSink& out) noexcept {
  ++counters_.syncs;
  const bool operational = nmt_ == canopen::NmtState::kOperational;
  // Synchronous RPDOs received since the last SYNC take effect now.
  bool cw_written = false;
  if (operational) {
    for (unsigned pending = rpdo_pending_; pending != 0; pending &= pending - 1) {  // ascending
      const auto p = static_cast<std::size_t>(std::countr_zero(pending));
      // The latched frame was at least rpdo_[p].size_bytes long (checked in on_frame).
      cw_written = apply_rpdo(p, rpdo_latch_[p]) || cw_written;
    }
    rpdo_pending_ = 0;
  }
  // The drive application runs in every NMT state that processes SYNC (CiA
  // 301: the NMT state gates communication, here the RPDOs above, not the
  // CiA 402 device): strict, the controlword is evaluated at every SYNC, so
  // that 4 follows 3 also for a controlword written over SDO in
  // pre-operational; and 0x6061 follows 0x6060 there too (found by
  // tests/peers/conformance.py against cia402-emu, vcan.peer.conformance_emu).
  if (cw_written || cfg_.behaviour.one_transition_per_sync) evaluate_controlword(out);
  update_mode_display();
  if (cfg_.fail_after_syncs != 0 && counters_.syncs == cfg_.fail_after_syncs) pending_fault_ = cfg_.fail_emcy_code;
  // Motor: advances by the interpolation period 0x60C2, only here.
  const cia402::InterpolationPeriod ip{static_cast<std::uint8_t>(val(hot_.ip_value)),
                                        static_cast<std::int8_t>(sval(hot_.ip_index))};
  if (!sync_period_.valid || ip.value != sync_period_.ip.value || ip.index != sync_period_.ip.index) {
    std::int64_t ns = cia402::interpolation_period_ns(ip);
    if (ns <= 0) ns = 1'000'000;
    sync_period_ = SyncPeriod{ip, ns, static_cast<double>(ns) / 1e9, 1e9 / static_cast<double>(ns), true};
  }
  const std::int64_t period_ns = sync_period_.ns;
  advance_motor(sync_period_.dt);
  // Following error monitoring (CSP, Operation enabled).
  const auto window = static_cast<std::uint32_t>(val(hot_.fe_window));
  if (state_ == State::kOperationEnabled && mode_display_ == static_cast<std::int8_t>(cia402::Mode::kCsp) &&
      window != 0xFFFFFFFFu) {
    const double fe = std::abs(static_cast<double>(sval(hot_.target_position)) - pos_);
    if (fe > window) {
      following_error_ = true;
      ++following_error_cycles_;
      const auto timeout_ms = static_cast<double>(val(hot_.fe_timeout));
      if (static_cast<double>(following_error_cycles_) * static_cast<double>(period_ns) / 1e6 >= timeout_ms &&
          pending_fault_ == 0)
        pending_fault_ = canopen::emcy_code::kFollowingError;
    } else {
      following_error_ = false;
      following_error_cycles_ = 0;
    }
  }
  automatic_transitions(true, out);
  update_outputs();
  if (operational) send_tpdos(true, out);
}

}  // namespace canmotion::emulator
