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
#include "config/runtime.hpp"

namespace canmotion::config {

namespace {

using Severity = Diagnostic::Severity;

constexpr std::uint16_t kVerifyConfiguration = 0x1020;

bool pdo_parameter(std::uint16_t index) { return index >= 0x1400 && index <= 0x1BFF; }

bool command_object(std::uint16_t index) {
  return index == 0x1010 || index == 0x1011 || (index >= 0x1F50 && index <= 0x1F5F);
}

/// Types whose value the boot writes from a DCF: 1 to 4 bytes, expedited.
bool expedited_type(canopen::DataType t) {
  const std::size_t n = canopen::data_type_size(t);
  return n >= 1 && n <= 4 && t != canopen::DataType::kVisibleString && t != canopen::DataType::kOctetString &&
         t != canopen::DataType::kUnicodeString && t != canopen::DataType::kDomain;
}

/// The first `n` lines as "file:L1, :L2 ... (k more)".
std::string lines_of(const std::string& file, const std::vector<int>& lines) {
  std::string s;
  for (std::size_t i = 0; i < lines.size() && i < 6; ++i) s += i == 0 ? fmt::format("{}:{}", file, lines[i]) : fmt::format(", :{}", lines[i]);
  if (lines.size() > 6) s += fmt::format(" ({} more)", lines.size() - 6);
  return s;
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
      if (!expedited_type(s.type)) {
        type_lines.push_back(s.line);
        continue;
      }
      DcfValue v{o.index, s.sub, static_cast<std::uint8_t>(s.size()),
                 static_cast<std::uint32_t>(s.parameter_value->resolve(a.node, s.size())), s.line};
      const auto mine = std::find_if(own.begin(), own.end(), [&](const cia402::BootWrite& w) {
        return !w.is_read() && w.w.index == v.index && w.w.sub == v.sub;
      });
      if (pdo_parameter(o.index)) {
        if (mine == own.end() || mine->w.value != v.value) pdo_lines.push_back(s.line);
        continue;
      }
      if (mine != own.end()) {
        if (mine->w.value == v.value) continue;  // the master writes it, to the same value
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
                     fmt::format("{}: {} value{} of more than 4 bytes, strings or domains left out (the boot writes "
                                 "a DCF's values of 1 to 4 bytes): {}",
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
