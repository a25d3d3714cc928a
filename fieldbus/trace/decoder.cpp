#include "fieldbus/trace/decoder.hpp"

#include <algorithm>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/object_names.hpp"

namespace canmotion::trace {
namespace {

namespace co = canmotion::canopen;

std::int64_t sign_extend(std::uint64_t v, unsigned bits) noexcept {
  if (bits == 0 || bits >= 64) return static_cast<std::int64_t>(v);
  const std::uint64_t m = 1ULL << (bits - 1);
  return static_cast<std::int64_t>((v ^ m) - m);
}

bool valid_node(std::uint8_t node) noexcept { return node >= 1 && node <= kMaxNode; }

}  // namespace

std::string_view layout_source_name(LayoutSource s) noexcept {
  switch (s) {
    case LayoutSource::kConfig: return "config";
    case LayoutSource::kTrace: return "trace";
    case LayoutSource::kDefault: return "default";
    case LayoutSource::kNone: break;
  }
  return "none";
}

PdoLayout default_rpdo1() noexcept {
  PdoLayout l;
  l.entries[0] = MapEntry{cia402::obj::kControlword, 0, 16};
  l.entries[1] = MapEntry{cia402::obj::kTargetPosition, 0, 32};
  l.count = 2;
  return l;
}

PdoLayout default_tpdo1() noexcept {
  PdoLayout l;
  l.entries[0] = MapEntry{cia402::obj::kStatusword, 0, 16};
  l.entries[1] = MapEntry{cia402::obj::kPositionActualValue, 0, 32};
  l.count = 2;
  return l;
}

Decoder::Resolved Decoder::resolve(const PdoLayout& l) noexcept {
  Resolved r;
  r.layout = l;
  r.layout.count = static_cast<std::uint8_t>(std::min<std::size_t>(l.count, kMaxPdoEntries));
  for (std::size_t i = 0; i < r.layout.count; ++i) {
    const MapEntry& e = r.layout.entries[i];
    if (e.index >= 0x0001 && e.index <= 0x0007) {  // dummy mapping (data type index)
      r.names[i] = "dummy";
      if (co::data_type_signed(static_cast<co::DataType>(e.index))) r.signed_mask |= static_cast<std::uint8_t>(1U << i);
      continue;
    }
    if (const co::ObjectInfo* o = co::object_info(e.index, e.sub)) {
      r.names[i] = o->name;
      if (co::data_type_signed(o->type)) r.signed_mask |= static_cast<std::uint8_t>(1U << i);
    }
  }
  return r;
}

Decoder::Decoder() noexcept {
  for (std::uint32_t id = 0; id < routes_.size(); ++id) {
    const co::CobInfo c = co::classify(id);
    Route r;
    r.node = c.node;
    r.pdo = c.pdo_number;
    switch (c.kind) {
      case co::FrameKind::kNmt: r.kind = EventKind::kNmt; break;
      case co::FrameKind::kSync: r.kind = EventKind::kSync; break;
      case co::FrameKind::kEmcy: r.kind = EventKind::kEmcy; break;
      case co::FrameKind::kTime: r.kind = EventKind::kTime; break;
      case co::FrameKind::kTpdo: r.kind = EventKind::kPdo; r.tx = true; break;
      case co::FrameKind::kRpdo: r.kind = EventKind::kPdo; r.tx = false; break;
      case co::FrameKind::kSdoTx: r.kind = EventKind::kSdo; r.tx = true; break;
      case co::FrameKind::kSdoRx: r.kind = EventKind::kSdo; r.tx = false; break;
      case co::FrameKind::kHeartbeat: r.kind = EventKind::kHeartbeat; break;
      case co::FrameKind::kLss: r.kind = EventKind::kLss; break;
      case co::FrameKind::kUnknown: r.kind = EventKind::kUnknown; break;
    }
    routes_[id] = r;
  }
  for (std::uint8_t node = 1; node <= kMaxNode; ++node) {
    for (std::uint8_t n = 1; n <= kPdosPerDirection; ++n) {
      nodes_[node].rpdo[n - 1].cob_id = co::cob::rpdo(n, node);
      nodes_[node].tpdo[n - 1].cob_id = co::cob::tpdo(n, node);
    }
  }
  default_rpdo_ = resolve(default_rpdo1());
  default_tpdo_ = resolve(default_tpdo1());
}

bool Decoder::set_config_layout(std::uint8_t node, bool tx, std::uint8_t number, const PdoLayout& layout) noexcept {
  if (!valid_node(node) || number < 1 || number > kPdosPerDirection) return false;
  Pdo& p = tx ? nodes_[node].tpdo[number - 1] : nodes_[node].rpdo[number - 1];
  p.config = resolve(layout);
  p.has_config = true;
  return true;
}

const Decoder::Resolved* Decoder::active_layout(const Pdo& p, std::uint8_t number, bool tx,
                                                LayoutSource& src) const noexcept {
  if (p.has_config) {
    src = LayoutSource::kConfig;
    return &p.config;
  }
  if (p.has_trace) {
    src = LayoutSource::kTrace;
    return &p.trace;
  }
  if (number == 1) {
    src = LayoutSource::kDefault;
    return tx ? &default_tpdo_ : &default_rpdo_;
  }
  src = LayoutSource::kNone;
  return nullptr;
}

LayoutSource Decoder::layout_of(std::uint8_t node, bool tx, std::uint8_t number, PdoLayout& out) const noexcept {
  if (!valid_node(node) || number < 1 || number > kPdosPerDirection) return LayoutSource::kNone;
  const Pdo& p = tx ? nodes_[node].tpdo[number - 1] : nodes_[node].rpdo[number - 1];
  LayoutSource src = LayoutSource::kNone;
  if (const Resolved* r = active_layout(p, number, tx, src)) out = r->layout;
  return src;
}

std::uint8_t Decoder::tpdo_transmission_type(std::uint8_t node, std::uint8_t number) const noexcept {
  if (!valid_node(node) || number < 1 || number > kPdosPerDirection) return 255;
  return nodes_[node].tpdo[number - 1].transmission;
}

void Decoder::reroute(std::uint8_t node, bool tx, std::uint8_t number, std::uint32_t cob) noexcept {
  Pdo& p = tx ? nodes_[node].tpdo[number - 1] : nodes_[node].rpdo[number - 1];
  const bool valid = (cob & 0x80000000U) == 0 && (cob & 0x20000000U) == 0;
  const std::uint32_t id = cob & 0x7FFU;
  // Give the old id back to its pre-defined meaning if it pointed to this PDO.
  if (p.cob_id < routes_.size()) {
    Route& old = routes_[p.cob_id];
    if (old.kind == EventKind::kPdo && old.node == node && old.pdo == number && old.tx == tx) {
      const co::CobInfo c = co::classify(p.cob_id);
      const bool is_pdo = c.kind == co::FrameKind::kTpdo || c.kind == co::FrameKind::kRpdo;
      old = Route{is_pdo ? EventKind::kPdo : EventKind::kUnknown, c.node, c.pdo_number,
                  c.kind == co::FrameKind::kTpdo};
    }
  }
  p.cob_valid = valid;
  p.cob_id = id;
  if (valid) routes_[id] = Route{EventKind::kPdo, node, number, tx};
}

void Decoder::apply_write(std::uint8_t node, const detail::ConfirmedWrite& w) noexcept {
  const std::uint16_t index = w.index;
  const std::uint8_t sub = w.sub;
  const std::uint32_t value = w.value;
  if (index == 0x1006 && sub == 0) {
    // 0 is no period (SYNC watch off): canmotiond writes it to every drive
    // before 0x1019, and with drive.sync_watch the period after it; the next
    // node's 0 must not drop the period the previous node got.
    if (value != 0) sync_period_ns_ = static_cast<std::int64_t>(value) * 1000;
    return;
  }
  const bool comm_r = index >= 0x1400 && index < 0x1400 + kPdosPerDirection;
  const bool comm_t = index >= 0x1800 && index < 0x1800 + kPdosPerDirection;
  const bool map_r = index >= 0x1600 && index < 0x1600 + kPdosPerDirection;
  const bool map_t = index >= 0x1A00 && index < 0x1A00 + kPdosPerDirection;
  if (comm_r || comm_t) {
    const auto number = static_cast<std::uint8_t>((index & 0xFFU) + 1);
    if (sub == 1) reroute(node, comm_t, number, value);
    if (sub == 2) {
      Pdo& p = comm_t ? nodes_[node].tpdo[number - 1] : nodes_[node].rpdo[number - 1];
      p.transmission = static_cast<std::uint8_t>(value);
    }
    return;
  }
  if (map_r || map_t) {
    const auto number = static_cast<std::uint8_t>((index & 0xFFU) + 1);
    Pdo& p = map_t ? nodes_[node].tpdo[number - 1] : nodes_[node].rpdo[number - 1];
    if (sub == 0) {
      PdoLayout l = p.pending;
      l.count = static_cast<std::uint8_t>(std::min<std::uint32_t>(value & 0xFFU, kMaxPdoEntries));
      p.trace = resolve(l);
      p.has_trace = true;
    } else if (sub <= kMaxPdoEntries) {
      p.pending.entries[sub - 1] = MapEntry::from_raw(value);
    }
  }
}

void Decoder::decode_pdo(Decoded& d) noexcept {
  const can::Frame& f = d.tf.frame;
  const Route& r = routes_[f.id];
  Pdo& p = r.tx ? nodes_[r.node].tpdo[r.pdo - 1] : nodes_[r.node].rpdo[r.pdo - 1];
  LayoutSource src = LayoutSource::kNone;
  const Resolved* lay = active_layout(p, r.pdo, r.tx, src);
  d.layout = src;
  if (f.remote()) {
    d.problem = "remote request for a PDO";
    return;
  }
  if (lay == nullptr) return;
  std::uint64_t raw = 0;
  for (std::size_t i = 0; i < f.len && i < 8; ++i) raw |= static_cast<std::uint64_t>(f.data[i]) << (8 * i);
  const unsigned avail = static_cast<unsigned>(f.len) * 8U;
  unsigned offset = 0;
  const std::uint8_t count = lay->layout.count;
  for (std::uint8_t i = 0; i < count; ++i) {
    const MapEntry& e = lay->layout.entries[i];
    PdoField& fld = d.fields[i];
    fld.name = lay->names[i];
    fld.index = e.index;
    fld.sub = e.sub;
    fld.bits = e.bits;
    fld.is_signed = (lay->signed_mask >> i) & 1U;
    if (e.bits == 0 || e.bits > 64 || offset + e.bits > avail) {
      fld.present = false;
      offset += e.bits;
      continue;
    }
    const std::uint64_t mask = e.bits == 64 ? ~0ULL : ((1ULL << e.bits) - 1);
    const std::uint64_t v = offset >= 64 ? 0 : (raw >> offset) & mask;
    fld.value = fld.is_signed ? sign_extend(v, e.bits) : static_cast<std::int64_t>(v);
    fld.present = true;
    offset += e.bits;
    if (e.sub == 0) detail::set_cia402(d, e.index, v, fld.value);
  }
  d.field_count = count;
  d.pdo_mapped_bits = static_cast<std::uint16_t>(offset);
  if (offset != avail) {
    d.pdo_length_mismatch = true;
    d.problem = "PDO length differs from its mapping";
  }
}

const Decoded& Decoder::decode_error(std::uint32_t err_class, std::int64_t t_ns) noexcept {
  can::TimedFrame tf;
  tf.t_ns = t_ns;
  tf.frame.id = err_class & 0x1FFFFFFFU;
  tf.frame.flags = can::kError;
  tf.frame.len = 8;
  return decode(tf);
}

const Decoded& Decoder::decode(const can::TimedFrame& tf) noexcept {
  Decoded& d = out_;
  d = Decoded{};
  d.tf = tf;
  const can::Frame& f = d.tf.frame;
  if (f.len > can::kMaxPayload) d.tf.frame.len = static_cast<std::uint8_t>(can::kMaxPayload);
  if (f.error()) {
    d.kind = EventKind::kErrorFrame;
    return d;
  }
  if (f.extended() || f.id >= routes_.size()) {
    d.kind = EventKind::kUnknown;
    return d;
  }
  const Route& r = routes_[f.id];
  d.kind = r.kind;
  d.node = r.node;
  switch (r.kind) {
    case EventKind::kNmt:
      if (f.len != 2 || f.remote()) {
        d.problem = "NMT command is not 2 bytes long";
      } else {
        d.nmt_command = f.data[0];
        d.nmt_target = f.data[1];
      }
      break;
    case EventKind::kSync:
      if (f.len == 1) {
        d.sync_has_counter = true;
        d.sync_counter = f.data[0];
      } else if (f.len != 0) {
        d.problem = "SYNC longer than 1 byte";
      }
      break;
    case EventKind::kEmcy:
      if (const auto e = co::decode_emcy(f)) {
        d.emcy_code = e->code;
        d.emcy_register = e->error_register;
        d.emcy_vendor = e->vendor;
        if (f.len != 8) d.problem = "EMCY is not 8 bytes long";
      } else {
        d.problem = "EMCY shorter than 2 bytes";
      }
      break;
    case EventKind::kHeartbeat:
      if (f.remote()) {
        d.kind = EventKind::kNodeGuardRequest;
      } else if (f.len < 1) {
        d.problem = "heartbeat without state byte";
      } else {
        d.nmt_state = co::nmt_state_from_byte(f.data[0]);
        d.guard_toggle = (f.data[0] & 0x80U) != 0;
        if (d.nmt_state == co::NmtState::kBootUp && !d.guard_toggle) d.kind = EventKind::kBootUp;
        if (d.nmt_state == co::NmtState::kUnknown) d.problem = "heartbeat state byte is not an NMT state";
        if (f.len != 1) d.problem = "heartbeat is not 1 byte long";
      }
      break;
    case EventKind::kSdo:
      d.sdo_response = r.tx;
      if (f.remote()) {
        d.problem = "remote request on an SDO id";
      } else {
        if (const auto w = nodes_[r.node].sdo.step(d)) apply_write(d.node, *w);
      }
      break;
    case EventKind::kPdo:
      d.pdo_tx = r.tx;
      d.pdo_number = r.pdo;
      decode_pdo(d);
      break;
    case EventKind::kTime:
    case EventKind::kLss:
    case EventKind::kUnknown:
    case EventKind::kBootUp:
    case EventKind::kNodeGuardRequest:
    case EventKind::kErrorFrame:
      break;
  }
  return d;
}

}  // namespace canmotion::trace
