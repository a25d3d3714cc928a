// EDS/DCF reader (CiA 306). inih (Debian libinih-dev) reads the INI syntax:
// sections, key=value lines, comments, the BOM; it hands every key to
// on_key() with its line number (Debian builds it with INI_HANDLER_LINENO).
// A first pass over the lines records where each [section] header is, so
// that keys are attributed to the right occurrence of a section given twice
// and empty sections are seen too (inih calls back only for keys). The rest
// of this file interprets the sections.
#include "fieldbus/eds/eds.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include <fmt/format.h>

#ifndef INI_HANDLER_LINENO
#error "fieldbus/eds needs INI_HANDLER_LINENO=1 (set in fieldbus/eds/CMakeLists.txt, as Debian's libinih is built)"
#endif
#include <ini.h>

#include "fieldbus/eds/text.hpp"

namespace canmotion::eds {

using canopen::DataType;

// ============================================================================
// Small public helpers
// ============================================================================
std::string_view object_code_name(ObjectCode c) noexcept {
  switch (c) {
    case ObjectCode::kNull: return "NULL";
    case ObjectCode::kDomain: return "DOMAIN";
    case ObjectCode::kDeftype: return "DEFTYPE";
    case ObjectCode::kDefstruct: return "DEFSTRUCT";
    case ObjectCode::kVar: return "VAR";
    case ObjectCode::kArray: return "ARRAY";
    case ObjectCode::kRecord: return "RECORD";
  }
  return "?";
}

std::string_view access_type_name(AccessType a) noexcept {
  switch (a) {
    case AccessType::kRo: return "ro";
    case AccessType::kWo: return "wo";
    case AccessType::kRw: return "rw";
    case AccessType::kRwr: return "rwr";
    case AccessType::kRww: return "rww";
    case AccessType::kConst: return "const";
  }
  return "?";
}

canopen::Access to_canopen(AccessType a) noexcept {
  switch (a) {
    case AccessType::kRo: return canopen::Access::kRo;
    case AccessType::kWo: return canopen::Access::kWo;
    case AccessType::kConst: return canopen::Access::kConst;
    case AccessType::kRw:
    case AccessType::kRwr:
    case AccessType::kRww: return canopen::Access::kRw;
  }
  return canopen::Access::kRo;
}

std::string_view object_list_name(ObjectList l) noexcept {
  switch (l) {
    case ObjectList::kNone: return "";
    case ObjectList::kMandatory: return "MandatoryObjects";
    case ObjectList::kOptional: return "OptionalObjects";
    case ObjectList::kManufacturer: return "ManufacturerObjects";
  }
  return "";
}

bool SubObject::rpdo_mappable() const noexcept {
  return pdo_mapping && (access == AccessType::kWo || access == AccessType::kRw || access == AccessType::kRww);
}
bool SubObject::tpdo_mappable() const noexcept {
  return pdo_mapping && (access == AccessType::kRo || access == AccessType::kRw || access == AccessType::kRwr ||
                         access == AccessType::kConst);
}

canopen::PdoMappable SubObject::pdo_direction() const noexcept {
  const bool rx = rpdo_mappable();
  const bool tx = tpdo_mappable();
  if (rx && tx) return canopen::PdoMappable::kBoth;
  if (rx) return canopen::PdoMappable::kRpdo;
  if (tx) return canopen::PdoMappable::kTpdo;
  return canopen::PdoMappable::kNo;
}

const SubObject* Object::find(std::uint8_t sub) const noexcept {
  auto it = std::lower_bound(subs.begin(), subs.end(), sub, [](const SubObject& s, std::uint8_t k) { return s.sub < k; });
  return it != subs.end() && it->sub == sub ? &*it : nullptr;
}

const Object* Eds::find(std::uint16_t index) const noexcept {
  auto it = std::lower_bound(objects.begin(), objects.end(), index,
                             [](const Object& o, std::uint16_t k) { return o.index < k; });
  return it != objects.end() && it->index == index ? &*it : nullptr;
}

const SubObject* Eds::find(std::uint16_t index, std::uint8_t sub) const noexcept {
  const Object* o = find(index);
  return o != nullptr ? o->find(sub) : nullptr;
}

bool Eds::is_dcf() const noexcept {
  if (comissioning) return true;
  for (const Object& o : objects)
    for (const SubObject& s : o.subs)
      if (s.parameter_value) return true;
  return false;
}

canopen::DeviceDictionary device_dictionary(const Eds& e) {
  std::vector<canopen::DeviceDictionary::Entry> entries;
  for (const Object& o : e.objects)
    for (const SubObject& s : o.subs) entries.push_back({o.index, s.sub, s.type, to_canopen(s.access), s.name});
  return canopen::DeviceDictionary(std::move(entries), e.file);
}

ObjectList Eds::expected_list(std::uint16_t index) noexcept {
  if (index == 0x1000 || index == 0x1001 || index == 0x1018) return ObjectList::kMandatory;
  if (index >= 0x2000 && index <= 0x5FFF) return ObjectList::kManufacturer;
  return ObjectList::kOptional;
}

std::string Diagnostic::to_string() const {
  return line > 0 ? fmt::format("{}:{}: {}", file, line, message) : fmt::format("{}: {}", file, message);
}

namespace {
std::string join(const std::vector<Diagnostic>& d) {
  std::string s;
  for (const Diagnostic& x : d) {
    if (!s.empty()) s += '\n';
    s += x.to_string();
  }
  return s;
}
}  // namespace

ParseError::ParseError(std::vector<Diagnostic> errors) : std::runtime_error(join(errors)), errors_(std::move(errors)) {}

// ============================================================================
// INI layer (inih)
// ============================================================================
namespace {

/// Longest line accepted (a DOMAIN or OCTET_STRING value in hex can be long;
/// inih's heap buffer grows up to this).
constexpr std::size_t kMaxLine = 65536;

struct RawKey {
  std::string name;
  std::string value;
  int line = 0;
};

struct RawSection {
  std::string name;
  int line = 0;
  std::vector<RawKey> keys;
  [[nodiscard]] const RawKey* get(std::string_view k) const {
    for (const RawKey& x : keys)
      if (iequals(x.name, k)) return &x;
    return nullptr;
  }
};

struct Collector {
  std::vector<RawSection> sections;  // in file order, one per header line
  std::vector<int> header_lines;     // sections[i].line, ascending
  std::vector<std::pair<int, std::string>> outside;  // keys before the first header
  bool out_of_memory = false;
};

int on_key(void* user, const char* /*section*/, const char* name, const char* value, int lineno) noexcept {
  auto& c = *static_cast<Collector*>(user);
  if (name == nullptr) return 1;  // a new-section call, if the library makes them
  try {
    auto it = std::upper_bound(c.header_lines.begin(), c.header_lines.end(), lineno);
    if (it == c.header_lines.begin()) {
      c.outside.emplace_back(lineno, name);
      return 1;
    }
    c.sections[static_cast<std::size_t>(it - c.header_lines.begin() - 1)].keys.push_back(
        RawKey{name, value != nullptr ? value : "", lineno});
  } catch (...) {  // bad_alloc: must not cross the C library
    c.out_of_memory = true;
    return 0;
  }
  return 1;
}

/// Syntax errors listed at most (then one more line says there are more):
/// each costs inih one more pass over the text (syntax_errors()).
constexpr int kMaxSyntaxErrors = 50;

int ignore_key(void*, const char*, const char*, const char*, int) noexcept { return 1; }

/// Every INI syntax error of `text` after the one inih reported at `first`
/// (its line), in line order, `first` included. inih goes on after an error
/// (ini_stop_on_first_error is off: the keys are all collected) but returns
/// the first error's line only: each further one is found by parsing again
/// with the lines reported so far blanked (line numbers kept).
std::vector<int> syntax_errors(std::string text, int first) {
  std::vector<int> lines;
  std::size_t from = 0;  // where line `at` starts (errors come in ascending line order)
  int at = 1;
  for (int line = first; line > 0;) {
    lines.push_back(line);
    if (lines.size() > static_cast<std::size_t>(kMaxSyntaxErrors)) break;  // the caller says there are more
    for (; at < line && from != std::string::npos; ++at) {
      from = text.find('\n', from);
      if (from != std::string::npos) ++from;
    }
    if (from == std::string::npos) break;
    const std::size_t end = std::min(text.find('\n', from), text.size());
    std::fill(text.begin() + static_cast<std::ptrdiff_t>(from), text.begin() + static_cast<std::ptrdiff_t>(end), ' ');
    line = ini_parse_string(text.c_str(), ignore_key, nullptr);
    if (line == -2) throw std::bad_alloc();
  }
  return lines;
}

int probe_key(void* user, const char*, const char* name, const char*, int lineno) noexcept {
  if (name != nullptr) *static_cast<int*>(user) = lineno;
  return 1;
}

/// inih's process-wide settings, once: heap line buffer growing to kMaxLine,
/// no multi-line values (an indented line is an error, not a continuation),
/// ';' comments (also after a blank, as Python's configparser reads EDS
/// files). Then a probe that the library passes line numbers.
bool configure_inih() {
  static std::once_flag once;
  static bool lineno_ok = false;
  std::call_once(once, [] {
    ini_use_stack = false;
    ini_allow_realloc = true;
    ini_max_line = static_cast<int>(kMaxLine + 3);
    ini_allow_multiline = false;
    ini_allow_no_value = false;
    ini_stop_on_first_error = false;
    ini_allow_bom = true;
    ini_allow_inline_comments = true;
    int seen = 0;
    ini_parse_string("\n\n[s]\nk=v\n", probe_key, &seen);
    lineno_ok = seen == 4;
  });
  return lineno_ok;
}

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// ============================================================================
// Interpretation
// ============================================================================
bool is_hex4(std::string_view s) {
  return s.size() >= 4 && std::all_of(s.begin(), s.begin() + 4, [](char c) { return std::isxdigit(static_cast<unsigned char>(c)); });
}
std::uint16_t hex4(std::string_view s) {
  return static_cast<std::uint16_t>(std::stoul(std::string(s.substr(0, 4)), nullptr, 16));
}

/// The sections that describe one object.
struct ObjectSections {
  const RawSection* main = nullptr;
  std::map<unsigned, const RawSection*> subs;  // [xxxxsubN]
  const RawSection* names = nullptr;           // [xxxxName]
  const RawSection* values = nullptr;          // [xxxxValue]
  const RawSection* denotations = nullptr;     // [xxxxDenotation]
};

struct Listed {
  ObjectList list = ObjectList::kNone;
  int line = 0;
};

class Builder {
 public:
  explicit Builder(std::string file) { eds_.file = std::move(file); }

  Eds build(const Collector& c) {
    for (const auto& [line, name] : c.outside) error(line, fmt::format("'{}' is outside any [section]", name));
    index_sections(c);
    if (const RawSection* s = section("FileInfo")) file_info(*s);
    if (const RawSection* s = section("DeviceInfo")) {
      device_info(*s);
    } else {
      error(0, "no [DeviceInfo] section (CiA 306 requires one: vendor, product, PDO counts, baud rates)");
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
    return std::move(eds_);
  }

  void error(int line, std::string msg) { errors_.push_back(Diagnostic{eds_.file, line, std::move(msg)}); }
  void warning(int line, std::string msg) { eds_.warnings.push_back(Diagnostic{eds_.file, line, std::move(msg)}); }
  [[nodiscard]] bool failed() const { return !errors_.empty(); }

 private:
  // ---- sections ----------------------------------------------------------
  void index_sections(const Collector& c) {
    for (const RawSection& s : c.sections) {
      const std::string key = to_lower(s.name);
      auto [it, fresh] = by_name_.emplace(key, &s);
      if (!fresh) {
        error(s.line, fmt::format("section [{}] appears again (first at line {})", s.name, it->second->line));
        continue;
      }
      // Keys given twice.
      for (std::size_t i = 0; i < s.keys.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
          if (iequals(s.keys[i].name, s.keys[j].name)) {
            error(s.keys[i].line, fmt::format("[{}] {} is given again (first at line {})", s.name, s.keys[i].name,
                                              s.keys[j].line));
            break;
          }
    }
  }

  const RawSection* section(std::string_view name) const {
    auto it = by_name_.find(to_lower(name));
    return it != by_name_.end() ? it->second : nullptr;
  }

  // ---- numbers -----------------------------------------------------------
  /// An unsigned number key in [0, max]; false (and an error) when malformed.
  template <typename T>
  bool number(const RawSection& s, const RawKey& k, T& out, std::uint64_t max) {
    const Number n = parse_number(trim(k.value));
    if (!n.ok || n.negative) {
      error(k.line, fmt::format("[{}] {}={} is not a number (decimal, 0x hex or 0 octal)", s.name, k.name, k.value));
      return false;
    }
    if (n.magnitude > max) {
      error(k.line, fmt::format("[{}] {}={} is out of range (0 .. {})", s.name, k.name, k.value, max));
      return false;
    }
    out = static_cast<T>(n.magnitude);
    return true;
  }
  template <typename T>
  bool number(const RawSection& s, std::string_view key, T& out, std::uint64_t max, int* line = nullptr) {
    const RawKey* k = s.get(key);
    if (k == nullptr) return false;
    if (line != nullptr) *line = k->line;
    return number(s, *k, out, max);
  }
  bool flag(const RawSection& s, std::string_view key, bool& out) {
    unsigned v = 0;
    if (!number(s, key, v, 1)) return false;
    out = v != 0;
    return true;
  }
  static void text(const RawSection& s, std::string_view key, std::string& out) {
    if (const RawKey* k = s.get(key)) out = k->value;
  }

  // ---- [FileInfo], [DeviceInfo], [DummyUsage], [DeviceComissioning] -------
  void file_info(const RawSection& s) {
    FileInfo& f = eds_.file_info;
    text(s, "FileName", f.file_name);
    text(s, "FileVersion", f.file_version);
    text(s, "FileRevision", f.file_revision);
    text(s, "EDSVersion", f.eds_version);
    text(s, "Description", f.description);
    text(s, "CreatedBy", f.created_by);
    text(s, "ModifiedBy", f.modified_by);
  }

  void device_info(const RawSection& s) {
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

  void dummy_usage(const RawSection& s) {
    for (const RawKey& k : s.keys) {
      const std::string_view n = k.name;
      if (n.size() != 9 || !iequals(n.substr(0, 5), "Dummy") || !is_hex4(n.substr(5))) {
        error(k.line, fmt::format("[DummyUsage] {}: expected Dummy0001 .. Dummy0007", k.name));
        continue;
      }
      const std::uint16_t type = hex4(n.substr(5));
      unsigned on = 0;
      if (!number(s, k, on, 1)) continue;
      if (type == 0 || type > 0x1F) {
        error(k.line, fmt::format("[DummyUsage] {}: not a data type index (0x0001 .. 0x001F)", k.name));
        continue;
      }
      if (on != 0) eds_.dummy_usage |= std::uint32_t{1} << type;
    }
  }

  void comissioning(const RawSection& s) {
    DeviceComissioning c;
    c.line = s.line;
    if (const RawKey* k = s.get("NodeId")) {
      if (number(s, *k, c.node_id, 127) && c.node_id == 0)
        error(k->line, fmt::format("[{}] NodeId=0 is not a node-ID (1 .. 127)", s.name));
    }
    if (const RawKey* k = s.get("Baudrate")) {
      if (number(s, *k, c.baudrate, 1000)) {
        static constexpr std::uint16_t kRates[] = {10, 20, 50, 125, 250, 500, 800, 1000};
        if (std::find(std::begin(kRates), std::end(kRates), c.baudrate) == std::end(kRates))
          error(k->line, fmt::format("[{}] Baudrate={} is not a CiA 301 bit rate in kbit/s (10, 20, 50, 125, 250, "
                                     "500, 800, 1000)",
                                     s.name, k->value));
      }
    }
    text(s, "NodeName", c.node_name);
    text(s, "NetworkName", c.network_name);
    number(s, "NetNumber", c.net_number, 0xFFFFFFFFu);
    flag(s, "CANopenManager", c.canopen_manager);
    number(s, "LSS_SerialNumber", c.lss_serial_number, 0xFFFFFFFFu);
    eds_.comissioning = c;
  }

  // ---- object lists ------------------------------------------------------
  void object_list(ObjectList list) {
    const RawSection* s = section(object_list_name(list));
    if (s == nullptr) return;
    eds_.list_lines[static_cast<int>(list)] = s->line;
    const RawKey* count_key = s->get("SupportedObjects");
    if (count_key == nullptr) {
      error(s->line, fmt::format("[{}] has no SupportedObjects (the number of entries)", s->name));
      return;
    }
    unsigned count = 0;
    if (!number(*s, *count_key, count, 0xFFFF)) return;
    std::vector<bool> seen(count + 1, false);
    for (const RawKey& k : s->keys) {
      if (&k == count_key) continue;
      const Number n = parse_number(k.name);
      if (!n.ok || n.negative || n.base != 10 || n.magnitude == 0) {
        error(k.line, fmt::format("[{}] {}: expected SupportedObjects or an entry number 1 .. {}", s->name, k.name, count));
        continue;
      }
      if (n.magnitude > count) {
        error(k.line, fmt::format("[{}] entry {} is beyond SupportedObjects={}", s->name, k.name, count));
        continue;
      }
      seen[n.magnitude] = true;
      std::uint16_t index = 0;
      if (!number(*s, k, index, 0xFFFF)) continue;
      auto [it, fresh] = listed_.emplace(index, Listed{list, k.line});
      if (!fresh) {
        error(k.line, fmt::format("[{}] 0x{:04X} is listed again (first in [{}] at line {})", s->name, index,
                                  object_list_name(it->second.list), it->second.line));
      }
    }
    for (unsigned i = 1; i <= count; ++i)
      if (!seen[i])
        error(count_key->line,
              fmt::format("[{}] SupportedObjects={} but entry {} is missing", s->name, count, i));
  }

  // ---- objects -----------------------------------------------------------
  void objects() {
    std::map<std::uint16_t, ObjectSections> by_index;
    for (const auto& [lname, sec] : by_name_) {
      if (!is_hex4(lname)) continue;
      const std::uint16_t index = hex4(lname);
      const std::string_view rest = std::string_view(lname).substr(4);
      ObjectSections& o = by_index[index];
      if (rest.empty()) {
        o.main = sec;
      } else if (rest.size() > 3 && rest.substr(0, 3) == "sub") {
        const std::string_view sub = rest.substr(3);
        const Number n = parse_number(std::string("0x").append(sub));
        if (sub.size() > 2 || !n.ok) {
          error(sec->line, fmt::format("[{}]: the sub-index after 'sub' must be hex 0 .. FF", sec->name));
          continue;
        }
        o.subs[static_cast<unsigned>(n.magnitude)] = sec;
      } else if (rest == "name") {
        o.names = sec;
      } else if (rest == "value") {
        o.values = sec;
      } else if (rest == "denotation") {
        o.denotations = sec;
      } else if (rest == "objectlinks") {
        // Informative (which objects an object refers to); not needed here.
      } else {
        warning(sec->line, fmt::format("[{}]: unknown section (ignored)", sec->name));
      }
    }
    for (const auto& [index, listed] : listed_) {
      auto it = by_index.find(index);
      if (it == by_index.end() || it->second.main == nullptr)
        error(listed.line, fmt::format("[{}] lists 0x{:04X} but there is no section [{:04X}]",
                                       object_list_name(listed.list), index, index));
    }
    for (auto& [index, secs] : by_index) {
      if (secs.main == nullptr) {
        for (const RawSection* r : {secs.names, secs.values, secs.denotations})
          if (r != nullptr) error(r->line, fmt::format("[{}]: there is no object section [{:04X}]", r->name, index));
        for (const auto& [sub, r] : secs.subs)
          error(r->line, fmt::format("[{}]: there is no object section [{:04X}]", r->name, index));
        continue;
      }
      object(index, secs);
    }
  }

  /// DataType, AccessType, PDOMapping, ObjFlags, values of one VAR or
  /// sub-index section. `code` is the object's (a DOMAIN may leave out
  /// DataType and AccessType).
  bool variable(const RawSection& s, ObjectCode code, SubObject& v) {
    bool ok = true;
    v.line = s.line;
    if (const RawKey* k = s.get("ParameterName")) {
      v.name = k->value;
    } else {
      error(s.line, fmt::format("[{}] has no ParameterName", s.name));
      ok = false;
    }
    if (const RawKey* k = s.get("DataType")) {
      std::uint16_t code_number = 0;
      if (number(s, *k, code_number, 0xFFFF)) {
        if (const auto t = canopen::data_type_of(code_number)) {
          v.type = *t;
        } else {
          error(k->line, fmt::format("[{}] DataType={}: unknown data type 0x{:04X} (the CiA 301 basic types are "
                                     "0x0001 BOOLEAN .. 0x001B UNSIGNED64, without 0x000E and 0x0017)",
                                     s.name, k->value, code_number));
          ok = false;
        }
      } else {
        ok = false;
      }
    } else if (code == ObjectCode::kDomain) {
      v.type = DataType::kDomain;
    } else {
      error(s.line, fmt::format("[{}] has no DataType", s.name));
      ok = false;
    }
    if (const RawKey* k = s.get("AccessType")) {
      const std::string a = to_lower(trim(k->value));
      static constexpr std::pair<std::string_view, AccessType> kAccess[] = {
          {"ro", AccessType::kRo},   {"wo", AccessType::kWo},   {"rw", AccessType::kRw},
          {"rwr", AccessType::kRwr}, {"rww", AccessType::kRww}, {"const", AccessType::kConst}};
      const auto* it = std::find_if(std::begin(kAccess), std::end(kAccess), [&](const auto& p) { return p.first == a; });
      if (it != std::end(kAccess)) {
        v.access = it->second;
      } else {
        error(k->line, fmt::format("[{}] AccessType={}: expected ro, wo, rw, rwr, rww or const", s.name, k->value));
        ok = false;
      }
    } else if (code == ObjectCode::kDomain) {
      v.access = AccessType::kRw;
    } else {
      error(s.line, fmt::format("[{}] has no AccessType", s.name));
      ok = false;
    }
    if (const RawKey* k = s.get("PDOMapping")) {
      unsigned m = 0;
      if (number(s, *k, m, 1)) {
        v.pdo_mapping = m != 0;
      } else {
        ok = false;
      }
    }
    if (const RawKey* k = s.get("ObjFlags")) ok = number(s, *k, v.obj_flags, 0xFFFFFFFFu) && ok;
    if (const RawKey* k = s.get("Denotation")) v.denotation = k->value;
    if (!ok) return false;  // the values need the data type
    value(s, "DefaultValue", v, v.default_value);
    value(s, "LowLimit", v, v.low_limit);
    value(s, "HighLimit", v, v.high_limit);
    value(s, "ParameterValue", v, v.parameter_value);
    limits(s, v);
    return true;
  }

  void value(const RawSection& s, std::string_view key, const SubObject& v, std::optional<Value>& out) {
    const RawKey* k = s.get(key);
    if (k == nullptr) return;
    out = value_text(s, *k, v.type);
  }

  std::optional<Value> value_text(const RawSection& s, const RawKey& k, DataType t) {
    const bool numeric = canopen::data_type_size(t) != 0;
    if (numeric && trim(k.value).empty()) return std::nullopt;  // "DefaultValue=" : none
    std::string why;
    auto v = parse_value(k.value, t, why);
    if (!v) {
      if (t == DataType::kDomain) {  // vendors put anything there; the master never uses it
        warning(k.line, fmt::format("[{}] {}: {} (kept as text)", s.name, k.name, why));
        Value raw;
        raw.text = k.value;
        return raw;
      }
      error(k.line, fmt::format("[{}] {}: {}", s.name, k.name, why));
    }
    return v;
  }

  /// LowLimit <= HighLimit, and DefaultValue / ParameterValue within them.
  void limits(const RawSection& s, const SubObject& v) {
    if (canopen::data_type_size(v.type) == 0) return;
    const auto num = [](const std::optional<Value>& x) { return x && !x->node_id_relative; };
    if (num(v.low_limit) && num(v.high_limit) && compare_values(v.type, v.low_limit->bits, v.high_limit->bits) > 0) {
      error(s.get("HighLimit")->line, fmt::format("[{}] HighLimit={} is below LowLimit={}", s.name, v.high_limit->text,
                                                  v.low_limit->text));
      return;  // the values cannot be judged against limits that contradict each other
    }
    for (const auto& [key, val] : {std::pair{"DefaultValue", &v.default_value}, std::pair{"ParameterValue", &v.parameter_value}}) {
      if (!num(*val)) continue;
      if (num(v.low_limit) && compare_values(v.type, (*val)->bits, v.low_limit->bits) < 0)
        error(s.get(key)->line, fmt::format("[{}] {}={} is below LowLimit={}", s.name, key, (*val)->text, v.low_limit->text));
      if (num(v.high_limit) && compare_values(v.type, (*val)->bits, v.high_limit->bits) > 0)
        error(s.get(key)->line,
              fmt::format("[{}] {}={} is above HighLimit={}", s.name, key, (*val)->text, v.high_limit->text));
    }
  }

  void object(std::uint16_t index, const ObjectSections& secs) {
    const RawSection& m = *secs.main;
    Object o;
    o.index = index;
    o.line = m.line;
    if (auto it = listed_.find(index); it != listed_.end()) {
      o.list = it->second.list;
    } else {
      warning(m.line, fmt::format("[{}] is not in [MandatoryObjects], [OptionalObjects] or [ManufacturerObjects] "
                                  "(CiA 306: it belongs in [{}])",
                                  m.name, object_list_name(Eds::expected_list(index))));
    }
    if (const RawKey* k = m.get("ParameterName")) o.name = k->value;
    if (const RawKey* k = m.get("Denotation")) o.denotation = k->value;
    if (const RawKey* k = m.get("ObjectType")) {
      unsigned c = 0;
      if (!number(m, *k, c, 0xFF)) return;
      if (c != 0x2 && c != 0x5 && c != 0x6 && c != 0x7 && c != 0x8 && c != 0x9) {
        error(k->line, fmt::format("[{}] ObjectType={} is not an object code (0x2 DOMAIN, 0x5 DEFTYPE, 0x6 DEFSTRUCT, "
                                   "0x7 VAR, 0x8 ARRAY, 0x9 RECORD)",
                                   m.name, k->value));
        return;
      }
      o.code = static_cast<ObjectCode>(c);
    }
    const RawKey* compact_key = m.get("CompactSubObj");
    if (compact_key != nullptr) number(m, *compact_key, o.compact_sub_obj, 0xFE);
    const RawKey* subnum_key = m.get("SubNumber");
    if (subnum_key != nullptr) number(m, *subnum_key, o.sub_number, 0x100);

    const bool structured = o.code == ObjectCode::kArray || o.code == ObjectCode::kRecord || o.code == ObjectCode::kDefstruct;
    if (!structured) {
      if (!secs.subs.empty())
        error(secs.subs.begin()->second->line,
              fmt::format("[{}]: 0x{:04X} is a {} (ObjectType), it has no sub-indices", secs.subs.begin()->second->name,
                          index, object_code_name(o.code)));
      if (o.sub_number != 0 && subnum_key != nullptr)
        error(subnum_key->line, fmt::format("[{}] SubNumber={}: only an ARRAY or RECORD has sub-indices", m.name,
                                            subnum_key->value));
      if (o.compact_sub_obj != 0 && compact_key != nullptr)
        error(compact_key->line, fmt::format("[{}] CompactSubObj={}: only an ARRAY has compact sub-indices", m.name,
                                             compact_key->value));
      SubObject v;
      if (variable(m, o.code, v)) {
        o.obj_flags = v.obj_flags;  // one section: the object's flags are its sub-index 0's
        o.subs.push_back(std::move(v));
      }
    } else if (o.compact_sub_obj != 0) {
      compact(o, secs);
    } else {
      subs(o, secs, subnum_key);
    }
    if (structured && o.compact_sub_obj == 0) {  // (a compact array's main section was read by variable())
      if (const RawKey* k = m.get("ObjFlags")) number(m, *k, o.obj_flags, 0xFFFFFFFFu);
    }
    eds_.objects.push_back(std::move(o));
  }

  /// ARRAY with CompactSubObj=N: sub 0 (UNSIGNED8 ro = N) and subs 1..N of the
  /// main section's type; names from [xxxxName], defaults from [xxxxValue].
  void compact(Object& o, const ObjectSections& secs) {
    const RawSection& m = *secs.main;
    if (!secs.subs.empty())
      error(secs.subs.begin()->second->line,
            fmt::format("[{}]: 0x{:04X} has CompactSubObj={}, its sub-indices have no sections of their own",
                        secs.subs.begin()->second->name, o.index, o.compact_sub_obj));
    SubObject proto;
    if (!variable(m, ObjectCode::kVar, proto)) return;
    o.obj_flags = proto.obj_flags;
    SubObject s0;
    s0.sub = 0;
    s0.name = "Highest sub-index supported";
    s0.type = DataType::kUnsigned8;
    s0.access = AccessType::kRo;
    s0.default_value = Value{std::to_string(o.compact_sub_obj), false, o.compact_sub_obj, {}};
    s0.line = m.line;
    o.subs.push_back(std::move(s0));
    for (unsigned i = 1; i <= o.compact_sub_obj; ++i) {
      SubObject s = proto;
      s.sub = static_cast<std::uint8_t>(i);
      s.name = fmt::format("{}sub{}", proto.name, i);
      o.subs.push_back(std::move(s));
    }
    const auto entries = [&](const RawSection* r, auto apply) {
      if (r == nullptr) return;
      const RawKey* nk = r->get("NrOfEntries");
      unsigned count = 0;
      if (nk == nullptr) {
        error(r->line, fmt::format("[{}] has no NrOfEntries", r->name));
      } else {
        number(*r, *nk, count, 0xFE);
      }
      unsigned given = 0;
      for (const RawKey& k : r->keys) {
        if (&k == nk) continue;
        const Number n = parse_number(k.name);
        if (!n.ok || n.negative || n.magnitude == 0 || n.magnitude > o.compact_sub_obj) {
          error(k.line, fmt::format("[{}] {}: expected NrOfEntries or a sub-index 1 .. {} (CompactSubObj of [{}])",
                                    r->name, k.name, o.compact_sub_obj, m.name));
          continue;
        }
        ++given;
        apply(o.subs[n.magnitude], k, *r);
      }
      if (nk != nullptr && count != given)
        error(nk->line, fmt::format("[{}] NrOfEntries={} but {} entries are given", r->name, nk->value, given));
    };
    entries(secs.names, [](SubObject& s, const RawKey& k, const RawSection&) { s.name = k.value; });
    entries(secs.values, [this](SubObject& s, const RawKey& k, const RawSection& r) {
      s.default_value = value_text(r, k, s.type);
    });
    entries(secs.denotations, [](SubObject& s, const RawKey& k, const RawSection&) { s.denotation = k.value; });
  }

  /// ARRAY/RECORD with SubNumber sub-index sections.
  void subs(Object& o, const ObjectSections& secs, const RawKey* subnum_key) {
    const RawSection& m = *secs.main;
    if (subnum_key == nullptr) {
      error(m.line, fmt::format("[{}] ({}) has neither SubNumber nor CompactSubObj", m.name,
                                object_code_name(o.code)));
    } else if (o.sub_number != secs.subs.size() && !failed_number(*subnum_key)) {
      std::string found;
      for (const auto& [sub, r] : secs.subs) found += fmt::format("{}{}", found.empty() ? "" : ", ", sub);
      if (o.sub_number > secs.subs.size()) {
        error(subnum_key->line,
              fmt::format("[{}] SubNumber={} but only {} sub-index section{} ([{:04X}subN], N = {}): a sub-index is "
                          "missing",
                          m.name, subnum_key->value, secs.subs.size(), secs.subs.size() == 1 ? "" : "s", o.index,
                          found.empty() ? "none" : found));
      } else {
        error(subnum_key->line, fmt::format("[{}] SubNumber={} but there are {} sub-index sections (N = {})", m.name,
                                            subnum_key->value, secs.subs.size(), found));
      }
    }
    if (!secs.subs.empty() && !secs.subs.contains(0))
      error(m.line, fmt::format("[{}] has no sub-index 0 ([{:04X}sub0], the highest sub-index supported)", m.name, o.index));
    for (const RawSection* r : {secs.names, secs.values, secs.denotations})
      if (r != nullptr)
        error(r->line, fmt::format("[{}]: 0x{:04X} has no CompactSubObj", r->name, o.index));
    for (const auto& [sub, r] : secs.subs) {
      if (const RawKey* k = r->get("ObjectType")) {
        unsigned c = 0;
        if (number(*r, *k, c, 0xFF) && c != 0x7 && c != 0x2)
          error(k->line, fmt::format("[{}] ObjectType={}: a sub-index is a VAR (0x7)", r->name, k->value));
      }
      SubObject v;
      v.sub = static_cast<std::uint8_t>(sub);
      if (variable(*r, ObjectCode::kVar, v)) o.subs.push_back(std::move(v));
    }
  }

  bool failed_number(const RawKey& k) const {
    const Number n = parse_number(trim(k.value));
    return !n.ok || n.negative || n.magnitude > 0x100;
  }

  Eds eds_;
  std::vector<Diagnostic> errors_;
  std::map<std::string, const RawSection*> by_name_;  // lower-case name -> first occurrence
  std::map<std::uint16_t, Listed> listed_;
};

}  // namespace

Eds parse(std::string_view text, std::string file) {
  Builder b(file);
  if (!configure_inih())
    throw ParseError({Diagnostic{file, 0, "libinih does not pass line numbers (it must be built with INI_HANDLER_LINENO=1)"}});
  // First pass: the lines (length, NUL) and where each [section] header is.
  Collector c;
  std::vector<Diagnostic> early;
  int line = 0;
  for (std::size_t pos = 0; pos <= text.size();) {
    ++line;
    const std::size_t nl = text.find('\n', pos);
    std::string_view l = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    if (l.size() > kMaxLine)
      early.push_back(Diagnostic{file, line, fmt::format("line is longer than {} characters", kMaxLine)});
    if (l.find('\0') != std::string_view::npos)
      early.push_back(Diagnostic{file, line, "NUL character (not a text file?)"});
    if (line == 1 && l.starts_with("\xEF\xBB\xBF")) l.remove_prefix(3);
    l = trim(l);
    if (!l.empty() && l.front() == '[') {
      const std::size_t e = l.find(']');
      if (e != std::string_view::npos) {
        c.sections.push_back(RawSection{std::string(trim(l.substr(1, e - 1))), line, {}});
        c.header_lines.push_back(line);
      }
    }
    if (nl == std::string_view::npos) break;
    pos = nl + 1;
  }
  if (!early.empty()) throw ParseError(std::move(early));
  const std::string z(text);  // inih reads a NUL-terminated string
  const int r = ini_parse_string(z.c_str(), on_key, &c);
  if (c.out_of_memory || r == -2) throw std::bad_alloc();
  if (r > 0) {
    const std::vector<int> lines = syntax_errors(z, r);
    for (std::size_t i = 0; i < lines.size(); ++i)
      b.error(lines[i], i < static_cast<std::size_t>(kMaxSyntaxErrors)
                            ? std::string("not a [section] header or a key=value line")
                            : fmt::format("more lines that are not a [section] header or a key=value line (only the "
                                          "first {} are listed)",
                                          kMaxSyntaxErrors));
  }
  return b.build(c);
}

Eds load(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError({Diagnostic{path.string(), 0, "cannot be read (no such file, or no permission)"}});
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw ParseError({Diagnostic{path.string(), 0, "read error"}});
  return parse(ss.str(), path.string());
}

}  // namespace canmotion::eds
