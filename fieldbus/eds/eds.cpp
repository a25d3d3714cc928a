// EDS/DCF reader (CiA 306): the public helpers of eds.hpp and parse()/load().
// ini.cpp reads the INI syntax (inih); builder.cpp and objects.cpp interpret
// the sections.
#include "fieldbus/eds/eds.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "fieldbus/eds/builder.hpp"
#include "fieldbus/eds/ini.hpp"

namespace canmotion::eds {

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
// Reading a file: the INI layer, then the interpretation of its sections
// ============================================================================
Eds parse(std::string_view text, std::string file) {
  const IniFile ini = read_ini(text, file);
  Builder b(std::move(file));
  return b.build(ini);
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
