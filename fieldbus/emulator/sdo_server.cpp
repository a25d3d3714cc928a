// The emulated drive's SDO server backend (CiA 301 SDO aborts, the PDO
// re-mapping rules, the objects whose write acts on the drive) and the
// delayed SDO replies of EmulatorBehaviour::sdo_reply_delay_ns.
#include "fieldbus/emulator/emulator.hpp"

#include <algorithm>

namespace canmotion::emulator {

using canopen::SdoAbort;
using cia402::State;
namespace obj = cia402::obj;

namespace {
bool is_rpdo_comm(std::uint16_t i) { return i >= 0x1400 && i <= 0x1403; }
bool is_rpdo_map(std::uint16_t i) { return i >= 0x1600 && i <= 0x1603; }
bool is_tpdo_comm(std::uint16_t i) { return i >= 0x1800 && i <= 0x1803; }
bool is_tpdo_map(std::uint16_t i) { return i >= 0x1A00 && i <= 0x1A03; }
}  // namespace

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
  // IP sub-modes: only 0 (linear interpolation) is modelled.
  if (index == obj::kInterpolationSubModeSelect && v != 0) return SdoAbort::kInvalidValue;
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
  // 0x1010 store parameters (CiA 301): "save" makes the values the ones a
  // reset or power-on starts from; any other value is refused.
  if (index == 0x1010 && sub >= 1) {
    if (v != 0x65766173u) return SdoAbort::kDataTransfer;
    for (Entry& x : od_) x.default_value = x.value;
    return SdoAbort::kNone;  // (it still reads what it can store: 1, on command)
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

void Emulator::on_sdo_request(const can::Frame& f, canopen::FrameSink& out) noexcept {
  if (nmt_ == canopen::NmtState::kStopped || f.remote()) return;
  ++counters_.sdo_requests;
  if (cfg_.behaviour.sdo_reply_delay_ns > 0) {
    DelayedSdoSink delayed(*this);
    sdo_.on_frame(f, now_ns_, delayed);
  } else {
    sdo_.on_frame(f, now_ns_, out);
  }
}

void Emulator::flush_sdo_replies(canopen::FrameSink& out) noexcept {
  // Strictly later than the call that queued them (due_ns > that call's time).
  while (sdo_queue_size_ > 0 && sdo_queue_[sdo_queue_head_].due_ns <= now_ns_) {
    out.send(sdo_queue_[sdo_queue_head_].frame);
    sdo_queue_head_ = (sdo_queue_head_ + 1) % sdo_queue_.size();
    --sdo_queue_size_;
  }
}

}  // namespace canmotion::emulator
