#include "fieldbus/trace/format.hpp"

#include <linux/can/error.h>

#include <array>
#include <iterator>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/trace/report_detail.hpp"

namespace canmotion::trace {
namespace {

namespace co = canmotion::canopen;
namespace sdo = canmotion::canopen::sdo;

constexpr char kHex[] = "0123456789ABCDEF";

using detail::put;

void put_hex(fmt::memory_buffer& out, std::uint32_t v, int digits) {
  for (int i = digits - 1; i >= 0; --i) out.push_back(kHex[(v >> (4 * i)) & 0xFU]);
}

void put_dec(fmt::memory_buffer& out, std::int64_t v) {
  std::array<char, 24> tmp{};
  std::uint64_t u = v < 0 ? static_cast<std::uint64_t>(-(v + 1)) + 1 : static_cast<std::uint64_t>(v);
  std::size_t n = 0;
  do {
    tmp[n++] = static_cast<char>('0' + u % 10);
    u /= 10;
  } while (u != 0);
  if (v < 0) out.push_back('-');
  while (n > 0) out.push_back(tmp[--n]);
}

void put_raw(fmt::memory_buffer& out, const can::Frame& f) {
  if (f.error()) {
    put_hex(out, (f.id & 0x1FFFFFFFU) | 0x20000000U, 8);
  } else if (f.extended()) {
    put_hex(out, f.id & 0x1FFFFFFFU, 8);
  } else {
    put_hex(out, f.id & 0x7FFU, 3);
  }
  out.push_back('#');
  if (f.remote() && !f.error()) {
    out.push_back('R');
    if (f.len != 0) out.push_back(static_cast<char>('0' + f.len));
    return;
  }
  for (std::size_t i = 0; i < f.len && i < can::kMaxPayload; ++i) put_hex(out, f.data[i], 2);
}

const co::DeviceDictionary* dictionary_of(const NodeDictionaries* names, std::uint8_t node) {
  return names != nullptr && node < names->size() ? (*names)[node] : nullptr;
}

void put_obj(fmt::memory_buffer& out, const co::DeviceDictionary* dict, std::uint16_t index, std::uint8_t sub) {
  put(out, "0x");
  put_hex(out, index, 4);
  out.push_back(':');
  put_hex(out, sub, 2);
  // The node's EDS name (cantrace --eds), else the CiA 301/402 name.
  const std::string_view name = dict != nullptr ? dict->name_or_standard(index, sub) : co::object_name(index, sub);
  if (!name.empty()) {
    out.push_back(' ');
    put(out, name);
  }
}

void put_statusword(fmt::memory_buffer& out, std::uint16_t sw) {
  put(out, "0x");
  put_hex(out, sw, 4);
  put(out, " [");
  put(out, statusword_state_name(sw));
  if ((sw & cia402::sw::kWarning) != 0) put(out, ", warning");
  put(out, "]");
}

void put_controlword(fmt::memory_buffer& out, std::uint16_t cw) {
  put(out, "0x");
  put_hex(out, cw, 4);
  put(out, " [");
  put(out, controlword_command_name(cw));
  if ((cw & cia402::cw::kHalt) != 0) put(out, ", halt");
  put(out, "]");
}

// A value of index:sub, typed by the object table.
void put_value(fmt::memory_buffer& out, const co::DeviceDictionary* dict, std::uint16_t index, std::uint8_t sub,
               std::span<const std::uint8_t> v, std::uint32_t total) {
  const co::ObjectInfo* info = co::object_info(index, sub);
  const co::DeviceDictionary::Entry* described = dict != nullptr ? dict->find(index, sub) : nullptr;
  const co::DataType type = described != nullptr ? described->type : info != nullptr ? info->type : co::DataType::kDomain;
  std::uint64_t u = 0;
  for (std::size_t i = 0; i < v.size() && i < 8; ++i) u |= static_cast<std::uint64_t>(v[i]) << (8 * i);
  if (type == co::DataType::kVisibleString) {
    out.push_back('"');
    for (std::uint8_t c : v) {
      if (c >= 0x20 && c < 0x7F && c != '"' && c != '\\') {
        out.push_back(static_cast<char>(c));
      } else {
        put(out, "\\x");
        put_hex(out, c, 2);
      }
    }
    out.push_back('"');
    if (total > v.size()) fmt::format_to(fmt::appender(out), " ({} bytes, first {} shown)", total, v.size());
    return;
  }
  const std::size_t size = co::data_type_size(type);
  if (info == nullptr || size == 0 || v.size() > 8) {
    // Unknown object: bytes, plus the little-endian number when it fits.
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (i != 0) out.push_back(' ');
      put_hex(out, v[i], 2);
    }
    if (!v.empty() && v.size() <= 4) {
      put(out, " (");
      put_dec(out, static_cast<std::int64_t>(u));
      put(out, ")");
    }
    if (total > v.size()) fmt::format_to(fmt::appender(out), " ({} bytes, first {} shown)", total, v.size());
    return;
  }
  if (v.size() != size) fmt::format_to(fmt::appender(out), "[{} bytes for a {}-byte type] ", v.size(), size);
  if (index == cia402::obj::kControlword && sub == 0) return put_controlword(out, static_cast<std::uint16_t>(u));
  if (index == cia402::obj::kStatusword && sub == 0) return put_statusword(out, static_cast<std::uint16_t>(u));
  if ((index == cia402::obj::kModesOfOperation || index == cia402::obj::kModesOfOperationDisplay) && sub == 0) {
    const auto m = static_cast<std::int8_t>(u & 0xFFU);
    put_dec(out, m);
    put(out, " [");
    put(out, cia402::mode_name(m));
    put(out, "]");
    return;
  }
  const bool map = (index >= 0x1600 && index <= 0x17FF) || (index >= 0x1A00 && index <= 0x1BFF);
  if (map && sub >= 1) {
    const MapEntry e = MapEntry::from_raw(static_cast<std::uint32_t>(u));
    put(out, "0x");
    put_hex(out, static_cast<std::uint32_t>(u), 8);
    put(out, " (");
    put_obj(out, dict, e.index, e.sub);
    fmt::format_to(fmt::appender(out), ", {} bit)", e.bits);
    return;
  }
  const bool comm = (index >= 0x1400 && index <= 0x15FF) || (index >= 0x1800 && index <= 0x19FF);
  if ((comm && sub == 1) || index == 0x1014 || index == 0x1005) {
    const auto x = static_cast<std::uint32_t>(u);
    put(out, "0x");
    put_hex(out, x, 8);
    fmt::format_to(fmt::appender(out), " (CAN id 0x{:03X}{}{})", x & 0x7FFU, (x & 0x80000000U) != 0 ? ", invalid" : "",
                   (x & 0x40000000U) != 0 && index == 0x1005 ? ", producer" : "");
    return;
  }
  if (co::data_type_signed(type)) {
    put_dec(out, static_cast<std::int64_t>(u << (64 - 8 * size)) >> (64 - 8 * size));
    return;
  }
  put(out, "0x");
  put_hex(out, static_cast<std::uint32_t>(u), static_cast<int>(size > 4 ? 8 : 2 * size));
  put(out, " (");
  put_dec(out, static_cast<std::int64_t>(u));
  put(out, ")");
}

void describe_sdo(const Decoded& d, fmt::memory_buffer& out, const co::DeviceDictionary* dict) {
  const sdo::SdoFrame& s = d.sdo;
  fmt::format_to(fmt::appender(out), "SDO node {} ", d.node);
  auto val = [&] {
    put(out, " = ");
    put_value(out, dict, d.sdo_index, d.sdo_sub, d.value, d.sdo_total);
  };
  // An initiate frame that carries data: the value (expedited) or the size.
  auto initiate = [&](const char* verb) {
    put(out, verb);
    put_obj(out, dict, d.sdo_index, d.sdo_sub);
    if (s.expedited) {
      val();
    } else {
      put(out, ": segmented");
      if (s.size_indicated) fmt::format_to(fmt::appender(out), ", {} bytes", s.size);
    }
  };
  switch (s.kind) {
    case sdo::SdoFrameKind::kInitiateDownloadRequest:
      initiate("write ");
      break;
    case sdo::SdoFrameKind::kInitiateDownloadResponse:
      put(out, "write ");
      put_obj(out, dict, d.sdo_index, d.sdo_sub);
      put(out, ": OK");
      break;
    case sdo::SdoFrameKind::kDownloadSegmentRequest:
      fmt::format_to(fmt::appender(out), "write segment (toggle {}, {} bytes{})", s.toggle ? 1 : 0, s.data_len,
                     s.last ? ", last" : "");
      if (d.sdo_has_value) {
        put(out, ": ");
        put_obj(out, dict, d.sdo_index, d.sdo_sub);
        val();
      }
      break;
    case sdo::SdoFrameKind::kDownloadSegmentResponse:
      fmt::format_to(fmt::appender(out), "write segment OK (toggle {})", s.toggle ? 1 : 0);
      if (d.sdo_complete) {
        put(out, ": ");
        put_obj(out, dict, d.sdo_index, d.sdo_sub);
        fmt::format_to(fmt::appender(out), " written, {} bytes", d.sdo_total);
      }
      break;
    case sdo::SdoFrameKind::kInitiateUploadRequest:
      put(out, "read ");
      put_obj(out, dict, d.sdo_index, d.sdo_sub);
      break;
    case sdo::SdoFrameKind::kInitiateUploadResponse:
      initiate("read ");
      break;
    case sdo::SdoFrameKind::kUploadSegmentRequest:
      fmt::format_to(fmt::appender(out), "read segment request (toggle {})", s.toggle ? 1 : 0);
      break;
    case sdo::SdoFrameKind::kUploadSegmentResponse:
      fmt::format_to(fmt::appender(out), "read segment (toggle {}, {} bytes{})", s.toggle ? 1 : 0, s.data_len,
                     s.last ? ", last" : "");
      if (d.sdo_has_value) {
        put(out, ": ");
        put_obj(out, dict, d.sdo_index, d.sdo_sub);
        val();
      }
      break;
    case sdo::SdoFrameKind::kAbort:
      put(out, d.sdo_response ? "abort by server " : "abort by client ");
      put_obj(out, dict, d.sdo_index, d.sdo_sub);
      fmt::format_to(fmt::appender(out), ": 0x{:08X} {}", s.abort_code, co::sdo_abort_text(s.abort_code));
      break;
    case sdo::SdoFrameKind::kBlock:
      put(out, d.sdo_response ? "block transfer response" : "block transfer request");
      break;
    case sdo::SdoFrameKind::kInvalid:
      put(out, d.sdo_response ? "invalid response" : "invalid request");
      break;
  }
  if (d.sdo_orphan) put(out, " (no matching initiate frame in the trace)");
}

void describe_pdo(const Decoded& d, fmt::memory_buffer& out) {
  put(out, d.pdo_tx ? "TPDO" : "RPDO");
  put_dec(out, d.pdo_number);
  put(out, " node ");
  put_dec(out, d.node);
  put(out, ": ");
  if (d.layout == LayoutSource::kNone || d.tf.frame.remote()) {
    if (d.tf.frame.remote()) {
      put(out, "remote request");
    } else {
      fmt::format_to(fmt::appender(out), "{} bytes, mapping unknown", d.tf.frame.len);
    }
    return;
  }
  if (d.field_count == 0) {
    put(out, "mapping disabled (0 objects)");
    return;
  }
  for (std::uint8_t i = 0; i < d.field_count; ++i) {
    const PdoField& f = d.fields[i];
    if (i != 0) put(out, ", ");
    if (!f.name.empty()) {
      put(out, f.name);
    } else {
      put(out, "0x");
      put_hex(out, f.index, 4);
      out.push_back(':');
      put_hex(out, f.sub, 2);
    }
    out.push_back('=');
    if (!f.present) {
      put(out, "(missing)");
      continue;
    }
    if (f.sub == 0 && f.index == cia402::obj::kStatusword) {
      put_statusword(out, static_cast<std::uint16_t>(f.value));
    } else if (f.sub == 0 && f.index == cia402::obj::kControlword) {
      put_controlword(out, static_cast<std::uint16_t>(f.value));
    } else if (f.sub == 0 &&
               (f.index == cia402::obj::kModesOfOperation || f.index == cia402::obj::kModesOfOperationDisplay)) {
      put_dec(out, static_cast<std::int8_t>(f.value));
      put(out, " [");
      put(out, cia402::mode_tag(static_cast<std::int8_t>(f.value)));
      put(out, "]");
    } else {
      put_dec(out, f.value);
    }
  }
  if (d.pdo_length_mismatch) {
    fmt::format_to(fmt::appender(out), " (frame has {} bytes, the {} mapping {} bits)", d.tf.frame.len,
                   layout_source_name(d.layout), d.pdo_mapped_bits);
  }
}


void json_sdo(const Decoded& d, const FormatOptions& opt, fmt::memory_buffer& out) {
  fmt::format_to(fmt::appender(out), ",\"sdo\":\"{}\",\"index\":{},\"sub\":{}", sdo::sdo_frame_kind_name(d.sdo.kind),
                 d.sdo_index, d.sdo_sub);
  if (!co::object_name(d.sdo_index, d.sdo_sub).empty()) {
    put(out, ",\"name\":");
    append_json_string(out, co::object_name(d.sdo_index, d.sdo_sub));
  }
  if (d.sdo.kind == sdo::SdoFrameKind::kAbort) {
    fmt::format_to(fmt::appender(out), ",\"abort_code\":{},\"abort_text\":", d.sdo.abort_code);
    append_json_string(out, co::sdo_abort_text(d.sdo.abort_code));
  }
  if (d.sdo_has_value) {
    put(out, ",\"value_hex\":\"");
    for (std::uint8_t b : d.value) put_hex(out, b, 2);
    put(out, "\",\"value\":");
    fmt::memory_buffer v;
    put_value(v, dictionary_of(opt.names, d.node), d.sdo_index, d.sdo_sub, d.value, d.sdo_total);
    append_json_string(out, std::string_view(v.data(), v.size()));
    fmt::format_to(fmt::appender(out), ",\"size\":{}", d.sdo_total);
  }
  if (d.sdo_complete) put(out, ",\"complete\":true");
}

void json_pdo(const Decoded& d, fmt::memory_buffer& out) {
  fmt::format_to(fmt::appender(out), ",\"pdo\":{},\"layout\":\"{}\",\"fields\":[", d.pdo_number,
                 layout_source_name(d.layout));
  for (std::uint8_t i = 0; i < d.field_count; ++i) {
    const PdoField& fl = d.fields[i];
    if (i != 0) out.push_back(',');
    fmt::format_to(fmt::appender(out), "{{\"index\":{},\"sub\":{},\"bits\":{},\"name\":", fl.index, fl.sub, fl.bits);
    append_json_string(out, fl.name);
    put(out, ",\"value\":");
    if (fl.present) {
      put_dec(out, fl.value);
    } else {
      put(out, "null");
    }
    out.push_back('}');
  }
  out.push_back(']');
}

}  // namespace

void append_emcy(fmt::memory_buffer& out, std::uint16_t code, std::uint8_t error_register) {
  fmt::format_to(fmt::appender(out), "0x{:04X} {}; error register 0x{:02X}", code, co::emcy_code_text(code),
                 error_register);
  if (error_register == 0) return;
  put(out, " (");
  bool first = true;
  for (unsigned b = 0; b < 8; ++b) {
    if ((error_register & (1U << b)) == 0) continue;
    if (!first) put(out, ", ");
    first = false;
    put(out, co::error_register_bit_name(b));
  }
  put(out, ")");
}

void append_emcy_json(fmt::memory_buffer& out, std::uint16_t code, std::uint8_t error_register) {
  fmt::format_to(fmt::appender(out), ",\"code\":{},\"error_register\":{},\"text\":", code, error_register);
  append_json_string(out, co::emcy_code_text(code));
}

std::string_view statusword_state_name(std::uint16_t statusword) noexcept {
  return cia402::state_name(cia402::decode_state(statusword));
}

std::string_view controlword_command_name(std::uint16_t controlword) noexcept {
  return cia402::command_name(cia402::decode_command(controlword));
}

std::string_view error_class_name(unsigned bit) noexcept {
  // CAN_ERR_* class bits of <linux/can/error.h>, named as candump -e names them.
  constexpr std::array<std::string_view, 9> names = {
      "tx-timeout", "lost-arbitration", "controller-problem", "protocol-violation", "transceiver-status",
      "no-acknowledgement-on-tx", "bus-off", "bus-error", "restarted-after-bus-off"};
  return bit < names.size() ? names[bit] : std::string_view{};
}

void append_error_classes(fmt::memory_buffer& out, std::uint32_t err_class) {
  bool first = true;
  for (unsigned bit = 0; bit < 32; ++bit) {
    if ((err_class & (1U << bit)) == 0) continue;
    if (!first) out.push_back(',');
    first = false;
    const std::string_view n = error_class_name(bit);
    if (n.empty()) {
      fmt::format_to(fmt::appender(out), "class-bit-{}", bit);
    } else {
      put(out, n);
    }
  }
  if (first) put(out, "no class bits");
}

void append_error_details(fmt::memory_buffer& out, std::uint32_t err_class, const std::array<std::uint8_t, 8>& data,
                          std::uint8_t len) {
  append_error_classes(out, err_class);
  if ((err_class & CAN_ERR_CRTL) != 0 && len > 1 && data[1] != 0) {
    constexpr std::array<std::string_view, 7> crtl = {"rx-overflow",      "tx-overflow",      "rx-error-warning",
                                                      "tx-error-warning", "rx-error-passive", "tx-error-passive",
                                                      "back-to-error-active"};
    put(out, " {");
    bool first = true;
    for (unsigned b = 0; b < crtl.size(); ++b) {
      if ((data[1] & (1U << b)) == 0) continue;
      if (!first) out.push_back(',');
      first = false;
      put(out, crtl[b]);
    }
    put(out, "}");
  }
  if (len == 8 && (data[6] != 0 || data[7] != 0)) {
    fmt::format_to(fmt::appender(out), " tx-errors={} rx-errors={}", data[6], data[7]);
  }
}

void append_time(fmt::memory_buffer& out, std::int64_t t_ns, int digits) {
  if (t_ns < 0) {
    out.push_back('-');
    t_ns = -t_ns;
  }
  put_dec(out, t_ns / 1'000'000'000);
  out.push_back('.');
  std::int64_t frac = t_ns % 1'000'000'000;
  int n = 9;
  if (digits != 9) {
    frac /= 1000;
    n = 6;
  }
  std::array<char, 9> tmp{};
  for (int i = n - 1; i >= 0; --i) {
    tmp[static_cast<std::size_t>(i)] = static_cast<char>('0' + frac % 10);
    frac /= 10;
  }
  out.append(tmp.data(), tmp.data() + n);
}

std::string_view event_kind_name(const Decoded& d) noexcept {
  switch (d.kind) {
    case EventKind::kNmt: return "nmt";
    case EventKind::kSync: return "sync";
    case EventKind::kTime: return "time";
    case EventKind::kEmcy: return "emcy";
    case EventKind::kBootUp: return "bootup";
    case EventKind::kHeartbeat: return "heartbeat";
    case EventKind::kNodeGuardRequest: return "node_guard_request";
    case EventKind::kSdo: return d.sdo_response ? "sdo_response" : "sdo_request";
    case EventKind::kPdo: return d.pdo_tx ? "tpdo" : "rpdo";
    case EventKind::kLss: return "lss";
    case EventKind::kErrorFrame: return "error_frame";
    case EventKind::kUnknown: break;
  }
  return "unknown";
}

void format_description(const Decoded& d, fmt::memory_buffer& out, const NodeDictionaries* names) {
  const can::Frame& f = d.tf.frame;
  switch (d.kind) {
    case EventKind::kNmt:
      if (d.problem == nullptr) {
        put(out, "NMT ");
        put(out, co::nmt_command_name(d.nmt_command));
        if (co::nmt_command_name(d.nmt_command) == "unknown") fmt::format_to(fmt::appender(out), " 0x{:02X}", d.nmt_command);
        if (d.nmt_target == 0) {
          put(out, " -> all nodes");
        } else {
          fmt::format_to(fmt::appender(out), " -> node {}", d.nmt_target);
        }
      } else {
        put(out, "NMT");
      }
      break;
    case EventKind::kSync:
      put(out, "SYNC");
      if (d.sync_has_counter) fmt::format_to(fmt::appender(out), " counter={}", d.sync_counter);
      break;
    case EventKind::kTime:
      put(out, "TIME stamp");
      break;
    case EventKind::kEmcy:
      fmt::format_to(fmt::appender(out), "EMCY node {}: ", d.node);
      append_emcy(out, d.emcy_code, d.emcy_register);
      if (d.emcy_vendor != std::array<std::uint8_t, 5>{}) {
        put(out, "; vendor");
        for (std::uint8_t b : d.emcy_vendor) {
          out.push_back(' ');
          put_hex(out, b, 2);
        }
      }
      break;
    case EventKind::kBootUp:
      fmt::format_to(fmt::appender(out), "Boot-up node {}", d.node);
      break;
    case EventKind::kHeartbeat:
      fmt::format_to(fmt::appender(out), "Heartbeat node {}: {}", d.node, co::nmt_state_name(d.nmt_state));
      if (d.guard_toggle) put(out, " (toggle 1)");
      break;
    case EventKind::kNodeGuardRequest:
      fmt::format_to(fmt::appender(out), "Node guarding request node {}", d.node);
      break;
    case EventKind::kSdo:
      describe_sdo(d, out, dictionary_of(names, d.node));
      break;
    case EventKind::kPdo:
      describe_pdo(d, out);
      break;
    case EventKind::kLss:
      put(out, f.id == co::cob::kLssMasterToSlave ? "LSS master -> slave" : "LSS slave -> master");
      break;
    case EventKind::kErrorFrame:
      put(out, "ERROR FRAME: ");
      append_error_details(out, f.id, f.data, f.len);
      break;
    case EventKind::kUnknown:
      put(out, f.extended() ? "extended id (not CANopen)" : "unknown CAN id");
      break;
  }
  if (d.problem != nullptr) {
    put(out, " !! ");
    put(out, d.problem);
  }
}

void format_text(const Decoded& d, std::string_view iface, const FormatOptions& opt, fmt::memory_buffer& out) {
  if (opt.has_time) {
    append_time(out, d.tf.t_ns, opt.time_digits);
  } else {
    out.push_back('-');
  }
  out.push_back(' ');
  put(out, iface);
  out.push_back(' ');
  const std::size_t start = out.size();
  put_raw(out, d.tf.frame);
  // Pad the raw frame to the width of the longest standard frame (3 + 1 + 16).
  for (std::size_t w = out.size() - start; w < 20; ++w) out.push_back(' ');
  put(out, "  ");
  format_description(d, out, opt.names);
  out.push_back('\n');
}

void append_json_string(fmt::memory_buffer& out, std::string_view s) {
  out.push_back('"');
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out.push_back('\\');
      out.push_back(c);
    } else if (u < 0x20) {
      fmt::format_to(fmt::appender(out), "\\u{:04x}", u);
    } else {
      out.push_back(c);
    }
  }
  out.push_back('"');
}

namespace {

/// The members of d's protocol (NMT command, SYNC counter, EMCY, NMT state,
/// SDO transfer, PDO fields, error classes).
void json_protocol(const Decoded& d, const FormatOptions& opt, fmt::memory_buffer& out) {
  switch (d.kind) {
    case EventKind::kNmt:
      if (d.problem == nullptr) {
        fmt::format_to(fmt::appender(out), ",\"command\":{},\"command_name\":\"{}\",\"target_node\":{}", d.nmt_command,
                       co::nmt_command_name(d.nmt_command), d.nmt_target);
      }
      break;
    case EventKind::kSync:
      if (d.sync_has_counter) fmt::format_to(fmt::appender(out), ",\"counter\":{}", d.sync_counter);
      break;
    case EventKind::kEmcy:
      append_emcy_json(out, d.emcy_code, d.emcy_register);
      break;
    case EventKind::kBootUp:
    case EventKind::kHeartbeat:
      fmt::format_to(fmt::appender(out), ",\"nmt_state\":\"{}\"", co::nmt_state_name(d.nmt_state));
      break;
    case EventKind::kSdo:
      json_sdo(d, opt, out);
      break;
    case EventKind::kPdo:
      json_pdo(d, out);
      break;
    case EventKind::kErrorFrame:
      put(out, ",\"classes\":\"");
      append_error_classes(out, d.tf.frame.id);
      out.push_back('"');
      break;
    default:
      break;
  }
}

/// The CiA 402 values the frame carries.
void json_cia402(const Decoded& d, fmt::memory_buffer& out) {
  if (d.has_statusword) {
    fmt::format_to(fmt::appender(out), ",\"statusword\":{},\"state\":\"{}\"", d.statusword,
                   statusword_state_name(d.statusword));
  }
  if (d.has_controlword) {
    fmt::format_to(fmt::appender(out), ",\"controlword\":{},\"command\":\"{}\"", d.controlword,
                   controlword_command_name(d.controlword));
  }
  if (d.has_target) fmt::format_to(fmt::appender(out), ",\"target_position\":{}", d.target_position);
  if (d.has_actual) fmt::format_to(fmt::appender(out), ",\"actual_position\":{}", d.actual_position);
}

}  // namespace

void format_json(const Decoded& d, std::string_view iface, const FormatOptions& opt, fmt::memory_buffer& out) {
  put(out, "{\"t\":");
  if (opt.has_time) {
    append_time(out, d.tf.t_ns, opt.time_digits);
  } else {
    put(out, "null");
  }
  put(out, ",\"iface\":");
  append_json_string(out, iface);
  put(out, ",\"raw\":\"");
  put_raw(out, d.tf.frame);
  put(out, "\",\"kind\":\"");
  put(out, event_kind_name(d));
  put(out, "\"");
  if (d.node != 0) fmt::format_to(fmt::appender(out), ",\"node\":{}", d.node);
  json_protocol(d, opt, out);
  json_cia402(d, out);
  put(out, ",\"text\":");
  fmt::memory_buffer desc;
  format_description(d, desc, opt.names);
  append_json_string(out, std::string_view(desc.data(), desc.size()));
  if (d.problem != nullptr) {
    put(out, ",\"problem\":");
    append_json_string(out, d.problem);
  }
  put(out, "}\n");
}

}  // namespace canmotion::trace
