// `drive.dcf` (README "DCF download"): the ParameterValues of a DCF's
// writable objects, as a CiA 302 configuration manager downloads them, made
// into boot writes. What the master configures itself is not taken from the
// file: the PDO parameters (drive.pdo), heartbeats, SYNC objects, 0x6060 and
// 0x60C2 are left out with one warning (a commissioning tool's DCF holds its
// own values there: heartbeat 0, profile position mode). A value the
// configuration also writes (drive.sdo_writes, direct_control,
// quick_stop_option, ...) is refused when it differs, naming both: the user
// said two things. Commands (0x1010 store,
// 0x1011 restore, 0x1F51 program control) and objects flagged "refuse write
// on download" (ObjFlags bit 0, CiA 306) are never written. 0x1020 verify
// configuration goes last, so that a drive that stopped half-way is written
// again at the next boot.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "config/eds_check.hpp"
#include "config/load_sections.hpp"
#include "config/runtime.hpp"

namespace canmotion::config {

namespace {

using Severity = Diagnostic::Severity;

constexpr std::uint16_t kVerifyConfiguration = 0x1020;

bool pdo_parameter(std::uint16_t index) { return index >= 0x1400 && index <= 0x1BFF; }

bool command_object(std::uint16_t index) {
  return index == 0x1010 || index == 0x1011 || (index >= 0x1F50 && index <= 0x1F5F);
}

/// Types whose value the boot writes from a DCF as 1 to 4 bytes (expedited).
bool expedited_type(canopen::DataType t) {
  const std::size_t n = canopen::data_type_size(t);
  return n >= 1 && n <= 4 && t != canopen::DataType::kVisibleString && t != canopen::DataType::kOctetString &&
         t != canopen::DataType::kUnicodeString && t != canopen::DataType::kDomain;
}

/// The bytes of a value the boot writes as a typed write: 40- to 64-bit
/// integers and REAL64 (little endian), VISIBLE_STRING, OCTET_STRING and
/// DOMAIN as the file gives them, UNICODE_STRING as UTF-16LE. Empty: a type
/// it does not write (TIME_OF_DAY, TIME_DIFFERENCE), an empty value, or
/// invalid UTF-8.
std::vector<std::uint8_t> typed_bytes(const eds::SubObject& s, std::uint8_t node) {
  using canopen::DataType;
  const eds::Value& v = *s.parameter_value;
  switch (s.type) {
    case DataType::kVisibleString:
    case DataType::kOctetString:
    case DataType::kDomain: return {v.data.begin(), v.data.end()};
    case DataType::kUnicodeString: return load::utf16le(v.data).value_or(std::vector<std::uint8_t>{});
    case DataType::kTimeOfDay:
    case DataType::kTimeDifference: return {};
    default: break;
  }
  const std::size_t n = canopen::data_type_size(s.type);
  if (n < 5 || n > 8) return {};
  const std::uint64_t bits = v.resolve(node, n);
  std::vector<std::uint8_t> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<std::uint8_t>(bits >> (8 * i));
  return out;
}

/// The first `n` lines as "file:L1, :L2 ... (k more)".
std::string lines_of(const std::string& file, const std::vector<int>& lines) {
  std::string s;
  for (std::size_t i = 0; i < lines.size() && i < 6; ++i) s += i == 0 ? fmt::format("{}:{}", file, lines[i]) : fmt::format(", :{}", lines[i]);
  if (lines.size() > 6) s += fmt::format(" ({} more)", lines.size() - 6);
  return s;
}

/// The master's write `mine` writes what DCF value `v` holds. A typed write
/// is compared byte for byte from `keyed` (whose storage holds its bytes).
bool same_value(const cia402::DriveConfig& keyed, const cia402::BootWrite& mine, const DcfValue& v) {
  for (const cia402::SdoWrite& w : keyed.extra_writes) {
    if (w.index != v.index || w.sub != v.sub || w.dcf) continue;
    if (w.data == nullptr) return v.bytes.empty() && w.value == v.value;
    return w.data_len == v.bytes.size() && std::equal(v.bytes.begin(), v.bytes.end(), w.data);
  }
  return v.bytes.empty() && mine.w.value == v.value;
}

}  // namespace

void dcf_download(const Config& cfg, AxisSettings& a, std::size_t ai, const BusSettings& bus, const std::string& who,
                  std::vector<Diagnostic>& diags) {
  DriveSettings& ds = a.drive;
  DcfSettings& dcf = ds.dcf;
  if (dcf.file.empty() || !ds.eds_data) return;
  dcf.writes.clear();
  const eds::Eds& e = *ds.eds_data;
  // What the master writes itself (without the DCF's values: not made yet).
  const std::vector<cia402::BootWrite> own = boot_writes(a, bus, cfg.controller.period_s, ai);
  const cia402::DriveConfig keyed = drive_config(a, bus, cfg.controller.period_s, ai);
  std::vector<int> pdo_lines, type_lines, defect_lines;
  std::vector<std::string> master_own;  // left out: the master's own settings
  std::vector<DcfValue> last;  // 0x1020:1/2
  bool any = false;
  for (const eds::Object& o : e.objects)
    for (const eds::SubObject& s : o.subs) {
      if (!s.parameter_value || !eds::writable(s.access) || command_object(o.index) || (s.obj_flags & 1u) != 0) continue;
      any = true;
      if (!s.defects.empty() || !o.defects.empty()) {
        defect_lines.push_back(s.line);
        continue;
      }
      DcfValue v{o.index, s.sub, static_cast<std::uint8_t>(s.size()), 0, {}, s.line};
      if (expedited_type(s.type)) {
        v.value = static_cast<std::uint32_t>(s.parameter_value->resolve(a.node, s.size()));
      } else {
        v.bytes = typed_bytes(s, a.node);
        if (v.bytes.empty()) {
          type_lines.push_back(s.line);
          continue;
        }
        for (std::size_t b = 0; b < v.bytes.size() && b < 4; ++b) v.value |= static_cast<std::uint32_t>(v.bytes[b]) << (8 * b);
      }
      const auto mine = std::find_if(own.begin(), own.end(), [&](const cia402::BootWrite& w) {
        return !w.is_read() && w.w.index == v.index && w.w.sub == v.sub;
      });
      if (pdo_parameter(o.index)) {
        if (mine == own.end() || mine->w.value != v.value) pdo_lines.push_back(s.line);
        continue;
      }
      if (mine != own.end()) {
        if (same_value(keyed, *mine, v)) continue;  // the master writes it, to the same value
        if (mine->origin != cia402::WriteOrigin::kExtra) {  // the master's own setting wins
          master_own.push_back(fmt::format("0x{:04X}:{:02X} at :{}", v.index, v.sub, s.line));
          continue;
        }
        const std::string* k = cia402::write_hint_key(keyed.hints, *mine);
        diags.push_back({Severity::kError, cfg.path, dcf.where, dcf.key,
                         fmt::format("{}: {}:{}: 0x{:04X}:{:02X} ({}) ParameterValue={} (0x{:X}), but the master "
                                     "writes {} (0x{:X}) there{}: change one of them",
                                     who, e.file, s.line, v.index, v.sub, s.name.empty() ? o.name : s.name,
                                     s.parameter_value->text, v.value, mine->w.value, mine->w.value,
                                     k != nullptr && !k->empty() ? fmt::format(" ({})", *k) : std::string())});
        continue;
      }
      if (o.index == kVerifyConfiguration) {
        last.push_back(v);
        continue;
      }
      dcf.writes.push_back(v);
    }
  if (!any)
    diags.push_back({Severity::kWarning, cfg.path, dcf.where, dcf.key,
                     fmt::format("{}: {} has no ParameterValue of a writable object: nothing to write at boot", who,
                                 e.file)});
  if (!pdo_lines.empty())
    diags.push_back({Severity::kWarning, cfg.path, dcf.where, dcf.key,
                     fmt::format("{}: {} PDO parameter value{} of the DCF {} left out: the master configures the PDOs "
                                 "itself ({}): {}",
                                 who, pdo_lines.size(), pdo_lines.size() == 1 ? "" : "s",
                                 pdo_lines.size() == 1 ? "is" : "are", keyed.hints.pdo, lines_of(e.file, pdo_lines))});
  if (!master_own.empty()) {
    std::string list;
    for (const std::string& m : master_own) list += (list.empty() ? "" : ", ") + m;
    diags.push_back({Severity::kWarning, cfg.path, dcf.where, dcf.key,
                     fmt::format("{}: {}: the master sets {} itself (heartbeats, SYNC, mode, interpolation period): "
                                 "the DCF's value{} left out: {}",
                                 who, e.file, master_own.size() == 1 ? "this object" : "these objects",
                                 master_own.size() == 1 ? " is" : "s are", list)});
  }
  if (!type_lines.empty())
    diags.push_back({Severity::kWarning, cfg.path, dcf.where, dcf.key,
                     fmt::format("{}: {} value{} left out: empty strings or domains, invalid UTF-8, or "
                                 "TIME_OF_DAY/TIME_DIFFERENCE values: {}",
                                 who, type_lines.size(), type_lines.size() == 1 ? "" : "s", lines_of(e.file, type_lines))});
  if (!defect_lines.empty())
    diags.push_back({Severity::kWarning, cfg.path, dcf.where, dcf.key,
                     fmt::format("{}: {} value{} of objects the file describes with a defect left out: {}", who,
                                 defect_lines.size(), defect_lines.size() == 1 ? "" : "s",
                                 lines_of(e.file, defect_lines))});
  std::sort(last.begin(), last.end(), [](const DcfValue& x, const DcfValue& y) { return x.sub < y.sub; });
  const auto date = std::find_if(last.begin(), last.end(), [](const DcfValue& v) { return v.sub == 1; });
  const auto time = std::find_if(last.begin(), last.end(), [](const DcfValue& v) { return v.sub == 2; });
  dcf.dated = date != last.end() && time != last.end();
  if (dcf.dated) {
    dcf.date = date->value;
    dcf.time = time->value;
  }
  dcf.writes.insert(dcf.writes.end(), last.begin(), last.end());
}

}  // namespace canmotion::config
