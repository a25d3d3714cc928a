// The Builder's object sections (see builder.hpp): [xxxx], [xxxxsubN], and
// a compact array's [xxxxName], [xxxxValue], [xxxxDenotation].
#include <algorithm>
#include <iterator>

#include "fieldbus/canopen/pdo.hpp"  // sign_extend
#include "fieldbus/eds/builder.hpp"

namespace canmotion::eds {

using canopen::DataType;

void Builder::objects() {
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
        warning(sec->line, fmt::format("[{}]: the sub-index after 'sub' must be hex 0 .. FF (ignored)", sec->name));
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
      warning(listed.line, fmt::format("[{}] lists 0x{:04X} but there is no section [{:04X}] (the object is "
                                       "taken as absent)",
                                       object_list_name(listed.list), index, index));
  }
  for (auto& [index, secs] : by_index) {
    if (secs.main == nullptr) {
      for (const RawSection* r : {secs.names, secs.values, secs.denotations})
        if (r != nullptr)
          warning(r->line, fmt::format("[{}]: there is no object section [{:04X}] (ignored)", r->name, index));
      for (const auto& [sub, r] : secs.subs)
        warning(r->line, fmt::format("[{}]: there is no object section [{:04X}] (ignored)", r->name, index));
      continue;
    }
    object(index, secs);
  }
}

void Builder::object(std::uint16_t index, const ObjectSections& secs) {
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
  // An ObjectType that cannot be read: the object is read as a RECORD when
  // it has sub-index sections, else as a VAR, and a use of it is refused.
  const ObjectCode guess = secs.subs.empty() ? ObjectCode::kVar : ObjectCode::kRecord;
  if (const RawKey* k = m.get("ObjectType")) {
    unsigned c = 0;
    const std::string then = fmt::format("read as a {}", object_code_name(guess));
    if (!number(m, *k, c, 0xFF, &o.defects, then)) {
      o.code = guess;
    } else if (c != 0x2 && c != 0x5 && c != 0x6 && c != 0x7 && c != 0x8 && c != 0x9) {
      warn(k->line,
           fmt::format("[{}] ObjectType={} is not an object code (0x2 DOMAIN, 0x5 DEFTYPE, 0x6 DEFSTRUCT, 0x7 VAR, "
                       "0x8 ARRAY, 0x9 RECORD; {})",
                       m.name, k->value, then),
           &o.defects);
      o.code = guess;
    } else {
      o.code = static_cast<ObjectCode>(c);
    }
  }
  const RawKey* compact_key = m.get("CompactSubObj");
  if (compact_key != nullptr && !number(m, *compact_key, o.compact_sub_obj, 0xFE)) compact_key = nullptr;
  const RawKey* subnum_key = m.get("SubNumber");
  if (subnum_key != nullptr && !number(m, *subnum_key, o.sub_number, 0x100)) subnum_key = nullptr;

  const bool structured = o.code == ObjectCode::kArray || o.code == ObjectCode::kRecord || o.code == ObjectCode::kDefstruct;
  if (!structured) {
    for (const auto& [sub, r] : secs.subs)
      warning(r->line, fmt::format("[{}]: 0x{:04X} is a {} (ObjectType), it has no sub-indices (ignored)", r->name,
                                   index, object_code_name(o.code)));
    if (o.sub_number != 0 && subnum_key != nullptr)
      warning(subnum_key->line, fmt::format("[{}] SubNumber={}: only an ARRAY or RECORD has sub-indices (ignored)",
                                            m.name, subnum_key->value));
    if (o.compact_sub_obj != 0 && compact_key != nullptr)
      warning(compact_key->line, fmt::format("[{}] CompactSubObj={}: only an ARRAY has compact sub-indices (ignored)",
                                             m.name, compact_key->value));
    o.sub_number = 0;
    o.compact_sub_obj = 0;
    SubObject v;
    variable(m, o.code, v);
    o.obj_flags = v.obj_flags;  // one section: the object's flags are its sub-index 0's
    o.subs.push_back(std::move(v));
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

void Builder::variable(const RawSection& s, ObjectCode code, SubObject& v) {
  bool typed = true;  // the values need the data type
  v.line = s.line;
  if (const RawKey* k = s.get("ParameterName")) {
    v.name = k->value;
  } else {
    warning(s.line, fmt::format("[{}] has no ParameterName", s.name));
  }
  if (const RawKey* k = s.get("DataType")) {
    std::uint16_t code_number = 0;
    if (number(s, *k, code_number, 0xFFFF, &v.defects, "the object cannot be used")) {
      if (const auto t = canopen::data_type_of(code_number)) {
        v.type = *t;
      } else {
        warn(k->line, fmt::format("[{}] DataType={}: unknown data type 0x{:04X} (the CiA 301 basic types are "
                                  "0x0001 BOOLEAN .. 0x001B UNSIGNED64, without 0x000E and 0x0017; the object cannot "
                                  "be used)",
                                  s.name, k->value, code_number),
             &v.defects);
        typed = false;
      }
    } else {
      typed = false;
    }
  } else if (code == ObjectCode::kDomain) {
    v.type = DataType::kDomain;
  } else {
    warn(s.line, fmt::format("[{}] has no DataType (the object cannot be used)", s.name), &v.defects);
    typed = false;
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
      warn(k->line,
           fmt::format("[{}] AccessType={}: expected ro, wo, rw, rwr, rww or const (the object cannot be used)",
                       s.name, k->value),
           &v.defects);
    }
  } else if (code == ObjectCode::kDomain) {
    v.access = AccessType::kRw;
  } else {
    warn(s.line, fmt::format("[{}] has no AccessType (the object cannot be used)", s.name), &v.defects);
  }
  if (const RawKey* k = s.get("PDOMapping")) {
    unsigned m = 0;
    if (number(s, *k, m, 1, &v.defects, "the object cannot be used")) v.pdo_mapping = m != 0;
  }
  if (const RawKey* k = s.get("ObjFlags")) number(s, *k, v.obj_flags, 0xFFFFFFFFu);
  if (const RawKey* k = s.get("Denotation")) v.denotation = k->value;
  if (!typed) return;
  value(s, "DefaultValue", v, v.default_value);
  value(s, "LowLimit", v, v.low_limit);
  value(s, "HighLimit", v, v.high_limit);
  value(s, "ParameterValue", v, v.parameter_value);
  limits(s, v);
}

void Builder::value(const RawSection& s, std::string_view key, SubObject& v, std::optional<Value>& out) {
  const RawKey* k = s.get(key);
  if (k == nullptr) return;
  const bool limit = &out == &v.low_limit || &out == &v.high_limit;
  out = value_text(s, *k, v.type, limit ? nullptr : &v.defects);
}

namespace {
/// A signed limit or value in hex wider than its type whose sign extension
/// from 16, 32 or 64 bits fits it (0xFFFFFF80 for an INTEGER8 is -128): the
/// two's-complement bits in the type's width, else nullopt.
std::optional<std::uint64_t> wide_twos_complement(std::string_view text, DataType t) {
  if (!canopen::data_type_signed(t)) return std::nullopt;
  const Number n = parse_number(strip_spaces(text));
  if (!n.ok || n.negative || n.base != 16) return std::nullopt;
  const unsigned bits = static_cast<unsigned>(8 * canopen::data_type_size(t));
  for (unsigned from : {16u, 32u, 64u}) {
    if (from <= bits || (from < 64 && n.magnitude >> from != 0)) continue;
    const std::int64_t x = canopen::sign_extend(n.magnitude, from);
    const std::int64_t lo = -(std::int64_t{1} << (bits - 1));
    if (x < 0 && x >= lo) return static_cast<std::uint64_t>(x) & ((std::uint64_t{1} << bits) - 1);
  }
  return std::nullopt;
}
}  // namespace

std::optional<Value> Builder::value_text(const RawSection& s, const RawKey& k, DataType t,
                                         std::vector<Diagnostic>* defects) {
  const bool numeric = canopen::data_type_size(t) != 0;
  if (numeric && trim(k.value).empty()) return std::nullopt;  // "DefaultValue=" : none
  std::string why;
  auto v = parse_value(k.value, t, why);
  if (v && numeric && canopen::data_type_signed(t) && defects == nullptr && !v->node_id_relative) {
    // A signed limit in two's-complement hex (0xFF80 for an INTEGER16): read
    // so, as python-canopen does, and said.
    const Number n = parse_number(strip_spaces(k.value));
    const unsigned bits = static_cast<unsigned>(8 * canopen::data_type_size(t));
    if (n.ok && !n.negative && n.base == 16 && (n.magnitude >> (bits - 1)) != 0)
      warning(k.line, fmt::format("[{}] {}={}: a signed limit in two's-complement hex, read as {} ({})", s.name,
                                  k.name, k.value, format_number(t, v->bits), canopen::data_type_name(t)));
  }
  if (!v) {
    if (const auto b = wide_twos_complement(k.value, t)) {
      warning(k.line, fmt::format("[{}] {}={}: two's complement of more bits than {}, read as {}", s.name, k.name,
                                  k.value, canopen::data_type_name(t), format_number(t, *b)));
      Value w;
      w.text = k.value;
      w.bits = *b;
      return w;
    }
    if (t == DataType::kDomain) {  // vendors put anything there; the master never uses it
      warning(k.line, fmt::format("[{}] {}: {} (kept as text)", s.name, k.name, why));
      Value raw;
      raw.text = k.value;
      return raw;
    }
    if (defects == nullptr)
      warning(k.line, fmt::format("[{}] {}: {} (the limit is ignored)", s.name, k.name, why));
    else
      warn(k.line, fmt::format("[{}] {}: {} (the value is unknown)", s.name, k.name, why), defects);
  }
  return v;
}

void Builder::limits(const RawSection& s, SubObject& v) {
  if (canopen::data_type_size(v.type) == 0) return;
  const auto num = [](const std::optional<Value>& x) { return x && !x->node_id_relative; };
  if (num(v.low_limit) && num(v.high_limit) && compare_values(v.type, v.low_limit->bits, v.high_limit->bits) > 0) {
    warning(s.get("HighLimit")->line, fmt::format("[{}] HighLimit={} is below LowLimit={} (both are ignored)", s.name,
                                                  v.high_limit->text, v.low_limit->text));
    v.low_limit.reset();
    v.high_limit.reset();
    return;  // the values cannot be judged against limits that contradict each other
  }
  for (const auto& [key, val] : {std::pair{"DefaultValue", &v.default_value}, std::pair{"ParameterValue", &v.parameter_value}}) {
    if (!num(*val)) continue;
    if (num(v.low_limit) && compare_values(v.type, (*val)->bits, v.low_limit->bits) < 0)
      warning(s.get(key)->line,
              fmt::format("[{}] {}={} is below LowLimit={}", s.name, key, (*val)->text, v.low_limit->text));
    if (num(v.high_limit) && compare_values(v.type, (*val)->bits, v.high_limit->bits) > 0)
      warning(s.get(key)->line,
              fmt::format("[{}] {}={} is above HighLimit={}", s.name, key, (*val)->text, v.high_limit->text));
  }
}

void Builder::compact(Object& o, const ObjectSections& secs) {
  const RawSection& m = *secs.main;
  for (const auto& [sub, r] : secs.subs)
    warning(r->line, fmt::format("[{}]: 0x{:04X} has CompactSubObj={}, its sub-indices have no sections of their "
                                 "own (ignored)",
                                 r->name, o.index, o.compact_sub_obj));
  SubObject proto;
  variable(m, ObjectCode::kVar, proto);
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
      warning(r->line, fmt::format("[{}] has no NrOfEntries", r->name));
    } else if (!number(*r, *nk, count, 0xFE)) {
      nk = nullptr;
    }
    unsigned given = 0;
    for (const RawKey& k : r->keys) {
      if (&k == nk) continue;
      const Number n = parse_number(k.name);
      if (!n.ok || n.negative || n.magnitude == 0 || n.magnitude > o.compact_sub_obj) {
        warning(k.line, fmt::format("[{}] {}: expected NrOfEntries or a sub-index 1 .. {} (CompactSubObj of [{}]; "
                                    "ignored)",
                                    r->name, k.name, o.compact_sub_obj, m.name));
        continue;
      }
      ++given;
      apply(o.subs[n.magnitude], k, *r);
    }
    if (nk != nullptr && count != given)
      warning(nk->line, fmt::format("[{}] NrOfEntries={} but {} entries are given", r->name, nk->value, given));
  };
  entries(secs.names, [](SubObject& s, const RawKey& k, const RawSection&) { s.name = k.value; });
  entries(secs.values, [this](SubObject& s, const RawKey& k, const RawSection& r) {
    if (s.defects.empty()) s.default_value = value_text(r, k, s.type, &s.defects);
  });
  entries(secs.denotations, [](SubObject& s, const RawKey& k, const RawSection&) { s.denotation = k.value; });
}

void Builder::subs(Object& o, const ObjectSections& secs, const RawKey* subnum_key) {
  // python-canopen reads the sub-index sections there are; SubNumber only
  // says how many there should be.
  const RawSection& m = *secs.main;
  if (subnum_key == nullptr) {
    warning(m.line, fmt::format("[{}] ({}) has neither SubNumber nor CompactSubObj (its {} sub-index section{} {} "
                                "read)",
                                m.name, object_code_name(o.code), secs.subs.size(), secs.subs.size() == 1 ? "" : "s",
                                secs.subs.size() == 1 ? "is" : "are"));
  } else if (o.sub_number != secs.subs.size()) {
    std::string found;
    for (const auto& [sub, r] : secs.subs) found += fmt::format("{}{}", found.empty() ? "" : ", ", sub);
    warning(subnum_key->line,
            fmt::format("[{}] SubNumber={} but there {} {} sub-index section{} ([{:04X}subN], N = {}; {} read)",
                        m.name, subnum_key->value, secs.subs.size() == 1 ? "is" : "are", secs.subs.size(),
                        secs.subs.size() == 1 ? "" : "s", o.index, found.empty() ? "none" : found,
                        secs.subs.size() == 1 ? "it is" : "those are"));
  }
  if (!secs.subs.empty() && !secs.subs.contains(0))
    warning(m.line,
            fmt::format("[{}] has no sub-index 0 ([{:04X}sub0], the highest sub-index supported)", m.name, o.index));
  for (const RawSection* r : {secs.names, secs.values, secs.denotations})
    if (r != nullptr)
      warning(r->line, fmt::format("[{}]: 0x{:04X} has no CompactSubObj (ignored)", r->name, o.index));
  for (const auto& [sub, r] : secs.subs) {
    if (const RawKey* k = r->get("ObjectType")) {
      unsigned c = 0;
      if (number(*r, *k, c, 0xFF) && c != 0x7 && c != 0x2)
        warning(k->line, fmt::format("[{}] ObjectType={}: a sub-index is a VAR (0x7; read as one)", r->name, k->value));
    }
    SubObject v;
    v.sub = static_cast<std::uint8_t>(sub);
    variable(*r, ObjectCode::kVar, v);
    o.subs.push_back(std::move(v));
  }
}

}  // namespace canmotion::eds
