// The Builder's header sections and object lists (see builder.hpp).
#include "fieldbus/eds/builder.hpp"

#include <algorithm>
#include <iterator>

namespace canmotion::eds {

Eds Builder::build(const IniFile& ini) {
  for (const auto& [line, message] : ini.syntax_errors) error(line, message);
  for (const auto& [line, name] : ini.outside) warning(line, fmt::format("'{}' is outside any [section] (ignored)", name));
  index_sections(ini);
  if (const RawSection* s = section("FileInfo")) file_info(*s);
  if (const RawSection* s = section("DeviceInfo")) {
    device_info(*s);
  } else {
    warning(0, "no [DeviceInfo] section (CiA 306 requires one; the PDO counts are taken from the 0x1400.., "
               "0x1800.. objects)");
  }
  if (const RawSection* s = section("DummyUsage")) dummy_usage(*s);
  const RawSection* dc = section("DeviceComissioning");
  if (dc == nullptr) dc = section("DeviceCommissioning");
  if (dc != nullptr) comissioning(*dc);
  object_list(ObjectList::kMandatory);
  object_list(ObjectList::kOptional);
  object_list(ObjectList::kManufacturer);
  objects();
  if (!errors_.empty()) {
    std::stable_sort(errors_.begin(), errors_.end(), [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
    throw ParseError(std::move(errors_));
  }
  std::stable_sort(eds_.warnings.begin(), eds_.warnings.end(),
                   [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
  // Each diagnostic once (a defect of a compact array's type is found once
  // per sub-index, a section given twice may repeat a key ...).
  std::vector<Diagnostic> once;
  for (Diagnostic& d : eds_.warnings)
    if (std::none_of(once.begin(), once.end(),
                     [&](const Diagnostic& x) { return x.line == d.line && x.message == d.message; }))
      once.push_back(std::move(d));
  eds_.warnings = std::move(once);
  return std::move(eds_);
}

// ---- sections --------------------------------------------------------------
void Builder::index_sections(const IniFile& ini) {
  for (const RawSection& s : ini.sections) {
    const std::string key = to_lower(s.name);
    auto [it, fresh] = by_name_.emplace(key, &s);
    if (!fresh) {
      warning(s.line, fmt::format("section [{}] appears again (first at line {}; this one is ignored)", s.name,
                                  it->second->line));
      continue;
    }
    // Keys given twice.
    for (std::size_t i = 0; i < s.keys.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (iequals(s.keys[i].name, s.keys[j].name)) {
          warning(s.keys[i].line, fmt::format("[{}] {} is given again (first at line {}, which is read)", s.name,
                                              s.keys[i].name, s.keys[j].line));
          break;
        }
  }
}

const RawSection* Builder::section(std::string_view name) const {
  auto it = by_name_.find(to_lower(name));
  return it != by_name_.end() ? it->second : nullptr;
}

// ---- numbers ---------------------------------------------------------------
bool Builder::flag(const RawSection& s, std::string_view key, bool& out) {
  unsigned v = 0;
  if (!number(s, key, v, 1)) return false;
  out = v != 0;
  return true;
}

void Builder::text(const RawSection& s, std::string_view key, std::string& out) {
  if (const RawKey* k = s.get(key)) out = k->value;
}

// ---- [FileInfo], [DeviceInfo], [DummyUsage], [DeviceComissioning] ----------
void Builder::file_info(const RawSection& s) {
  FileInfo& f = eds_.file_info;
  text(s, "FileName", f.file_name);
  text(s, "FileVersion", f.file_version);
  text(s, "FileRevision", f.file_revision);
  text(s, "EDSVersion", f.eds_version);
  text(s, "Description", f.description);
  text(s, "CreatedBy", f.created_by);
  text(s, "ModifiedBy", f.modified_by);
}

void Builder::device_info(const RawSection& s) {
  DeviceInfo& d = eds_.device_info;
  d.line = s.line;
  text(s, "VendorName", d.vendor_name);
  text(s, "ProductName", d.product_name);
  text(s, "OrderCode", d.order_code);
  number(s, "VendorNumber", d.vendor_number, 0xFFFFFFFFu);
  number(s, "ProductNumber", d.product_number, 0xFFFFFFFFu);
  number(s, "RevisionNumber", d.revision_number, 0xFFFFFFFFu);
  for (int rate : {10, 20, 50, 125, 250, 500, 800, 1000}) {
    bool on = false;
    if (flag(s, fmt::format("BaudRate_{}", rate), on) && on) d.baud_rates.push_back(static_cast<std::uint16_t>(rate));
  }
  flag(s, "SimpleBootUpMaster", d.simple_boot_up_master);
  flag(s, "SimpleBootUpSlave", d.simple_boot_up_slave);
  number(s, "Granularity", d.granularity, 64, &d.granularity_line);
  flag(s, "DynamicChannelsSupported", d.dynamic_channels_supported);
  flag(s, "GroupMessaging", d.group_messaging);
  number(s, "NrOfRXPDO", d.nr_of_rxpdo, 512, &d.nr_of_rxpdo_line);
  number(s, "NrOfTXPDO", d.nr_of_txpdo, 512, &d.nr_of_txpdo_line);
  flag(s, "LSS_Supported", d.lss_supported);
}

void Builder::dummy_usage(const RawSection& s) {
  for (const RawKey& k : s.keys) {
    const std::string_view n = k.name;
    if (n.size() != 9 || !iequals(n.substr(0, 5), "Dummy") || !is_hex4(n.substr(5))) {
      warning(k.line, fmt::format("[DummyUsage] {}: expected Dummy0001 .. Dummy0007 (ignored)", k.name));
      continue;
    }
    const std::uint16_t type = hex4(n.substr(5));
    unsigned on = 0;
    if (!number(s, k, on, 1)) continue;
    if (type == 0 || type > 0x1F) {
      warning(k.line, fmt::format("[DummyUsage] {}: not a data type index (0x0001 .. 0x001F; ignored)", k.name));
      continue;
    }
    if (on != 0) eds_.dummy_usage |= std::uint32_t{1} << type;
  }
}

void Builder::comissioning(const RawSection& s) {
  // Commissioning values are the integrator's (a commissioning tool writes
  // NodeId=0 or Baudrate=0 for "not set"); the master takes node-ID and bit
  // rate from its configuration, so a bad one is a warning and left out.
  DeviceComissioning c;
  c.line = s.line;
  if (const RawKey* k = s.get("NodeId")) {
    if (number(s, *k, c.node_id, 0xFF) && (c.node_id == 0 || c.node_id > 127)) {
      warning(k->line, fmt::format("[{}] NodeId={} is not a node-ID (1 .. 127; ignored: the configuration gives "
                                   "the node-ID)",
                                   s.name, k->value));
      c.node_id = 0;
    }
  }
  if (const RawKey* k = s.get("Baudrate")) {
    if (number(s, *k, c.baudrate, 0xFFFF)) {
      static constexpr std::uint16_t kRates[] = {10, 20, 50, 125, 250, 500, 800, 1000};
      if (std::find(std::begin(kRates), std::end(kRates), c.baudrate) == std::end(kRates)) {
        warning(k->line, fmt::format("[{}] Baudrate={} is not a CiA 301 bit rate in kbit/s (10, 20, 50, 125, 250, "
                                     "500, 800, 1000; ignored: the bus's configuration gives the bit rate)",
                                     s.name, k->value));
        c.baudrate = 0;
      }
    }
  }
  text(s, "NodeName", c.node_name);
  text(s, "NetworkName", c.network_name);
  number(s, "NetNumber", c.net_number, 0xFFFFFFFFu);
  flag(s, "CANopenManager", c.canopen_manager);
  number(s, "LSS_SerialNumber", c.lss_serial_number, 0xFFFFFFFFu);
  eds_.comissioning = c;
}

// ---- object lists ----------------------------------------------------------
void Builder::object_list(ObjectList list) {
  // The lists only say where an object belongs (python-canopen reads every
  // [xxxx] section): every defect here is a warning, every entry is read.
  const RawSection* s = section(object_list_name(list));
  if (s == nullptr) return;
  eds_.list_lines[static_cast<int>(list)] = s->line;
  const RawKey* count_key = s->get("SupportedObjects");
  unsigned count = 0;
  bool counted = false;
  if (count_key == nullptr) {
    warning(s->line, fmt::format("[{}] has no SupportedObjects (the number of entries)", s->name));
  } else {
    counted = number(*s, *count_key, count, 0xFFFF);
  }
  std::vector<bool> seen(count + 1, false);
  for (const RawKey& k : s->keys) {
    if (&k == count_key) continue;
    const Number n = parse_number(k.name);
    if (!n.ok || n.negative || n.base != 10 || n.magnitude == 0) {
      warning(k.line, fmt::format("[{}] {}: expected SupportedObjects or an entry number 1 .. {} (ignored)", s->name,
                                  k.name, count));
      continue;
    }
    if (counted && n.magnitude > count)
      warning(k.line, fmt::format("[{}] entry {} is beyond SupportedObjects={}", s->name, k.name, count));
    else if (counted)
      seen[n.magnitude] = true;
    std::uint16_t index = 0;
    if (!number(*s, k, index, 0xFFFF)) continue;
    auto [it, fresh] = listed_.emplace(index, Listed{list, k.line});
    if (!fresh) {
      warning(k.line, fmt::format("[{}] 0x{:04X} is listed again (first in [{}] at line {})", s->name, index,
                                  object_list_name(it->second.list), it->second.line));
    }
  }
  if (counted)
    for (unsigned i = 1; i <= count; ++i)
      if (!seen[i])
        warning(count_key->line, fmt::format("[{}] SupportedObjects={} but entry {} is missing", s->name, count, i));
}

}  // namespace canmotion::eds
