#pragma once
/// \file
/// The interpretation of an EDS/DCF's sections (internal to fieldbus/eds):
/// the Builder turns the INI sections read by ini.hpp into an Eds, with an
/// error or a warning (file:line) for what CiA 306 does not allow.
/// builder.cpp reads the file's header sections ([FileInfo], [DeviceInfo],
/// [DummyUsage], [DeviceComissioning]) and the object lists; objects.cpp
/// reads the object sections. Set-up only (allocates, throws).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "fieldbus/eds/eds.hpp"
#include "fieldbus/eds/ini.hpp"
#include "fieldbus/eds/text.hpp"

namespace canmotion::eds {

/// The sections that describe one object.
struct ObjectSections {
  const RawSection* main = nullptr;
  std::map<unsigned, const RawSection*> subs;  // [xxxxsubN]
  const RawSection* names = nullptr;           // [xxxxName]
  const RawSection* values = nullptr;          // [xxxxValue]
  const RawSection* denotations = nullptr;     // [xxxxDenotation]
};

/// Where an index is listed ([MandatoryObjects], ...).
struct Listed {
  ObjectList list = ObjectList::kNone;
  int line = 0;
};

class Builder {
 public:
  explicit Builder(std::string file) { eds_.file = std::move(file); }

  /// The Eds of `ini`, its warnings sorted by line; throws ParseError with
  /// every error (the INI syntax errors first), sorted by line.
  Eds build(const IniFile& ini);

  void error(int line, std::string msg) { errors_.push_back(Diagnostic{eds_.file, line, std::move(msg)}); }
  void warning(int line, std::string msg) { eds_.warnings.push_back(Diagnostic{eds_.file, line, std::move(msg)}); }
  /// A warning that is also a defect of an object when `defects` is given.
  void warn(int line, std::string msg, std::vector<Diagnostic>* defects) {
    if (defects != nullptr) defects->push_back(Diagnostic{eds_.file, line, msg});
    warning(line, std::move(msg));
  }
  [[nodiscard]] bool failed() const { return !errors_.empty(); }

 private:
  // ---- sections (builder.cpp) ----------------------------------------------
  void index_sections(const IniFile& ini);
  const RawSection* section(std::string_view name) const;

  // ---- numbers -------------------------------------------------------------
  /// An unsigned number key in [0, max]; false (and a warning, also put in
  /// `defects` when given) when malformed or out of range.
  template <typename T>
  bool number(const RawSection& s, const RawKey& k, T& out, std::uint64_t max,
              std::vector<Diagnostic>* defects = nullptr, std::string_view then = "ignored") {
    const Number n = parse_number(trim(k.value));
    if (!n.ok || n.negative) {
      warn(k.line, fmt::format("[{}] {}={} is not a number (decimal, 0x hex or 0 octal; {})", s.name, k.name, k.value, then),
           defects);
      return false;
    }
    if (n.magnitude > max) {
      warn(k.line, fmt::format("[{}] {}={} is out of range (0 .. {}; {})", s.name, k.name, k.value, max, then), defects);
      return false;
    }
    out = static_cast<T>(n.magnitude);
    return true;
  }
  template <typename T>
  bool number(const RawSection& s, std::string_view key, T& out, std::uint64_t max, int* line = nullptr) {
    const RawKey* k = s.get(key);
    if (k == nullptr) return false;
    if (!number(s, *k, out, max)) return false;
    if (line != nullptr) *line = k->line;
    return true;
  }
  bool flag(const RawSection& s, std::string_view key, bool& out);
  static void text(const RawSection& s, std::string_view key, std::string& out);

  // ---- [FileInfo], [DeviceInfo], [DummyUsage], [DeviceComissioning] (builder.cpp)
  void file_info(const RawSection& s);
  void device_info(const RawSection& s);
  void dummy_usage(const RawSection& s);
  void comissioning(const RawSection& s);

  // ---- object lists (builder.cpp) ------------------------------------------
  void object_list(ObjectList list);

  // ---- objects (objects.cpp) -----------------------------------------------
  void objects();
  void object(std::uint16_t index, const ObjectSections& secs);
  /// DataType, AccessType, PDOMapping, ObjFlags, values of one VAR or
  /// sub-index section. `code` is the object's (a DOMAIN may leave out
  /// DataType and AccessType).
  /// A defect (unknown type, access ...) is kept in v.defects, and v is
  /// read on without its values.
  void variable(const RawSection& s, ObjectCode code, SubObject& v);
  void value(const RawSection& s, std::string_view key, SubObject& v, std::optional<Value>& out);
  /// `defects`: where an unreadable value is a defect (DefaultValue,
  /// ParameterValue); null for limits (read past with a warning).
  std::optional<Value> value_text(const RawSection& s, const RawKey& k, canopen::DataType t,
                                  std::vector<Diagnostic>* defects);
  /// LowLimit <= HighLimit (else both are dropped, with a warning), and
  /// DefaultValue / ParameterValue within them (else a warning).
  void limits(const RawSection& s, SubObject& v);
  /// ARRAY with CompactSubObj=N: sub 0 (UNSIGNED8 ro = N) and subs 1..N of the
  /// main section's type; names from [xxxxName], defaults from [xxxxValue].
  void compact(Object& o, const ObjectSections& secs);
  /// ARRAY/RECORD with SubNumber sub-index sections.
  void subs(Object& o, const ObjectSections& secs, const RawKey* subnum_key);

  Eds eds_;
  std::vector<Diagnostic> errors_;
  std::map<std::string, const RawSection*> by_name_;  // lower-case name -> first occurrence
  std::map<std::uint16_t, Listed> listed_;
};

}  // namespace canmotion::eds
