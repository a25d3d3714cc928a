// The Builder's object sections (see builder.hpp): [xxxx], [xxxxsubN], and
// a compact array's [xxxxName], [xxxxValue], [xxxxDenotation].
#include <algorithm>
#include <iterator>

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

bool Builder::variable(const RawSection& s, ObjectCode code, SubObject& v) {
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

void Builder::value(const RawSection& s, std::string_view key, const SubObject& v, std::optional<Value>& out) {
  const RawKey* k = s.get(key);
  if (k == nullptr) return;
  out = value_text(s, *k, v.type);
}

std::optional<Value> Builder::value_text(const RawSection& s, const RawKey& k, DataType t) {
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

void Builder::limits(const RawSection& s, const SubObject& v) {
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

void Builder::compact(Object& o, const ObjectSections& secs) {
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

void Builder::subs(Object& o, const ObjectSections& secs, const RawKey* subnum_key) {
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

bool Builder::failed_number(const RawKey& k) const {
  const Number n = parse_number(trim(k.value));
  return !n.ok || n.negative || n.magnitude > 0x100;
}

}  // namespace canmotion::eds
