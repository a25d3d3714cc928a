#include "fieldbus/eds/check.hpp"

#include <fmt/format.h>

#include "fieldbus/canopen/pdo.hpp"  // sign_extend

namespace canmotion::eds {

std::string_view usage_name(Usage u) noexcept {
  switch (u) {
    case Usage::kWrite: return "write";
    case Usage::kRead: return "read";
    case Usage::kMapRpdo: return "RPDO mapping";
    case Usage::kMapTpdo: return "TPDO mapping";
  }
  return "?";
}

std::string_view refusal_kind_name(RefusalKind k) noexcept {
  switch (k) {
    case RefusalKind::kMissingObject: return "object missing";
    case RefusalKind::kMissingSubIndex: return "sub-index missing";
    case RefusalKind::kNotWritable: return "not writable";
    case RefusalKind::kNotReadable: return "not readable";
    case RefusalKind::kNotMappable: return "not mappable";
    case RefusalKind::kWrongSize: return "wrong size";
    case RefusalKind::kOutOfRange: return "out of range";
    case RefusalKind::kMissingBits: return "not supported";
    case RefusalKind::kTooFewRpdos: return "not enough RPDOs";
    case RefusalKind::kTooFewTpdos: return "not enough TPDOs";
    case RefusalKind::kDefect: return "defective";
  }
  return "?";
}

std::string Refusal::to_string() const {
  const std::string where = line > 0 ? fmt::format("{}:{}", file, line) : file;
  return key.empty() ? fmt::format("{}: {}", where, message) : fmt::format("{}: {} (set by {})", where, message, key);
}

namespace {

class Checker {
 public:
  Checker(const Eds& eds, const Requirements& req)
      : eds_(eds), req_(req), node_(req.node_id != 0 ? req.node_id : (eds.comissioning ? eds.comissioning->node_id : 0)) {}

  CheckResult run() {
    pdos(true);
    pdos(false);
    for (const Use& u : req_.uses) use(u);
    return std::move(r_);
  }

 private:
  void refuse(RefusalKind k, std::uint16_t index, std::uint8_t sub, int line, const std::string& key, std::string msg) {
    r_.refusals.push_back(Refusal{k, index, sub, eds_.file, line, key, std::move(msg)});
  }

  /// "0x1016:01 (Consumer heartbeat time)": the EDS's name, else CiA 301/402's.
  std::string label(std::uint16_t index, std::uint8_t sub) const {
    std::string_view name;
    if (const SubObject* s = eds_.find(index, sub)) name = s->name;
    if (name.empty()) name = canopen::object_name(index, sub);
    return name.empty() ? fmt::format("0x{:04X}:{:02X}", index, sub) : fmt::format("0x{:04X}:{:02X} ({})", index, sub, name);
  }

  void pdos(bool rx) {
    const DeviceInfo& d = eds_.device_info;
    const std::uint16_t need = rx ? req_.rpdos : req_.tpdos;
    const int count_line = rx ? d.nr_of_rxpdo_line : d.nr_of_txpdo_line;
    const std::uint16_t have = rx ? d.nr_of_rxpdo : d.nr_of_txpdo;
    const char* what = rx ? "RPDO" : "TPDO";
    const RefusalKind kind = rx ? RefusalKind::kTooFewRpdos : RefusalKind::kTooFewTpdos;
    if (need == 0) return;
    // Without NrOfRXPDO/NrOfTXPDO (or with one that cannot be read), the PDO
    // objects the file has decide: each missing one is named below.
    if (count_line != 0 && have < need) {
      refuse(kind, rx ? 0x1400 : 0x1800, 0, count_line, req_.pdo_key,
             fmt::format("the master uses {} {}{}, the EDS has {}={}", need, what, need == 1 ? "" : "s",
                         rx ? "NrOfRXPDO" : "NrOfTXPDO", have));
      return;
    }
    for (std::uint16_t n = 0; n < need; ++n) {
      const auto comm = static_cast<std::uint16_t>((rx ? 0x1400 : 0x1800) + n);
      const auto map = static_cast<std::uint16_t>((rx ? 0x1600 : 0x1A00) + n);
      for (std::uint16_t index : {comm, map}) {
        if (eds_.find(index) != nullptr) continue;
        refuse(kind, index, 0, missing_line(index), req_.pdo_key,
               fmt::format("{} {} needs 0x{:04X} ({} {} parameter), which is not in the EDS", what, n + 1, index,
                           what, index == comm ? "communication" : "mapping"));
      }
    }
  }

  /// Where an absent object would be: its list's header line (0: no such list).
  int missing_line(std::uint16_t index) const {
    return eds_.list_lines[static_cast<int>(Eds::expected_list(index))];
  }

  void use(const Use& u) {
    const Object* o = eds_.find(u.index);
    if (o == nullptr) {
      if (u.optional) {
        r_.skipped.push_back(u);
        return;
      }
      const ObjectList l = Eds::expected_list(u.index);
      const int line = missing_line(u.index);
      refuse(RefusalKind::kMissingObject, u.index, u.sub, line, u.key,
             fmt::format("{} is not in the EDS ({}); the master would {}", label(u.index, u.sub),
                         line != 0 ? fmt::format("[{}] does not list 0x{:04X}", object_list_name(l), u.index)
                                   : fmt::format("no section [{:04X}]", u.index),
                         usage_verb(u.usage)));
      return;
    }
    const SubObject* s = o->find(u.sub);
    if (s == nullptr) {
      if (u.optional) {
        r_.skipped.push_back(u);
        return;
      }
      refuse(RefusalKind::kMissingSubIndex, u.index, u.sub, o->line, u.key,
             fmt::format("0x{:04X} ({}) has no sub-index {} (it has {}); the master would {}", u.index, o->name, u.sub,
                         sub_list(*o), usage_verb(u.usage)));
      return;
    }
    const std::string what = label(u.index, u.sub);
    // A defect of the object in the file (unknown type, access ...): the
    // master cannot know how to use it.
    for (const std::vector<Diagnostic>* defects : {&o->defects, &s->defects})
      if (!defects->empty()) {
        std::string why;
        for (const Diagnostic& d : *defects) why += fmt::format("{}{}", why.empty() ? "" : "; ", d.message);
        refuse(RefusalKind::kDefect, u.index, u.sub, defects->front().line, u.key,
               fmt::format("{} cannot be used, the master would {}: {}", what, usage_verb(u.usage), why));
        return;
      }
    switch (u.usage) {
      case Usage::kWrite:
        if (!writable(s->access))
          refuse(RefusalKind::kNotWritable, u.index, u.sub, s->line, u.key,
                 fmt::format("{} is AccessType={}, the master writes it", what, access_type_name(s->access)));
        break;
      case Usage::kRead:
        if (!readable(s->access))
          refuse(RefusalKind::kNotReadable, u.index, u.sub, s->line, u.key,
                 fmt::format("{} is AccessType={}, the master reads it", what, access_type_name(s->access)));
        break;
      case Usage::kMapRpdo:
      case Usage::kMapTpdo: mapping(u, *s, what); break;
    }
    const std::size_t type_size = s->size();
    if (u.size != 0 && type_size != 0 && u.size != type_size)
      refuse(RefusalKind::kWrongSize, u.index, u.sub, s->line, u.key,
             fmt::format("{} is {} ({} byte{}), the master's {} is {} byte{}", what, canopen::data_type_name(s->type),
                         type_size, type_size == 1 ? "" : "s", usage_name(u.usage), u.size, u.size == 1 ? "" : "s"));
    if (u.value) range(u, *s, what);
    if (u.required_bits != 0) bits(u, *s, what);
  }

  static std::string_view usage_verb(Usage u) {
    switch (u) {
      case Usage::kWrite: return "write it";
      case Usage::kRead: return "read it";
      case Usage::kMapRpdo: return "map it into an RPDO";
      case Usage::kMapTpdo: return "map it into a TPDO";
    }
    return "use it";
  }

  static std::string sub_list(const Object& o) {
    if (o.subs.empty()) return "none";
    if (o.subs.size() == 1) return fmt::format("only sub-index {}", o.subs.front().sub);
    bool contiguous = o.subs.back().sub - o.subs.front().sub + 1 == static_cast<int>(o.subs.size());
    if (contiguous) return fmt::format("sub-indices {} .. {}", o.subs.front().sub, o.subs.back().sub);
    std::string s = "sub-indices ";
    for (std::size_t i = 0; i < o.subs.size(); ++i) s += fmt::format("{}{}", i == 0 ? "" : ", ", o.subs[i].sub);
    return s;
  }

  void mapping(const Use& u, const SubObject& s, const std::string& what) {
    const bool rx = u.usage == Usage::kMapRpdo;
    const DeviceInfo& d = eds_.device_info;
    if (!s.pdo_mapping) {
      refuse(RefusalKind::kNotMappable, u.index, u.sub, s.line, u.key,
             fmt::format("{} has PDOMapping=0, the master would map it into a{}", what, rx ? "n RPDO" : " TPDO"));
      return;
    }
    if (rx ? !s.rpdo_mappable() : !s.tpdo_mappable()) {
      refuse(RefusalKind::kNotMappable, u.index, u.sub, s.line, u.key,
             fmt::format("{} is AccessType={}: it can be mapped into {} only, the master would map it into a{}", what,
                         access_type_name(s.access), rx ? "TPDOs" : "RPDOs", rx ? "n RPDO" : " TPDO"));
      return;
    }
    if (d.granularity == 0) {
      refuse(RefusalKind::kNotMappable, u.index, u.sub, d.granularity_line != 0 ? d.granularity_line : d.line, u.key,
             fmt::format("Granularity=0: the device's PDO mapping cannot be changed, the master would map {}", what));
      return;
    }
    const std::size_t bytes = u.size != 0 ? u.size : s.size();
    if (bytes != 0 && (8 * bytes) % d.granularity != 0)
      refuse(RefusalKind::kNotMappable, u.index, u.sub, d.granularity_line != 0 ? d.granularity_line : d.line, u.key,
             fmt::format("Granularity={}: {} ({} bits) cannot be mapped", d.granularity, what, 8 * bytes));
  }

  void range(const Use& u, const SubObject& s, const std::string& what) {
    const std::size_t bytes = s.size();
    if (bytes == 0 || s.type == canopen::DataType::kReal32 || s.type == canopen::DataType::kReal64) return;
    const std::int64_t v = *u.value;
    const unsigned nbits = static_cast<unsigned>(8 * bytes);
    const std::uint64_t mask = bytes >= 8 ? ~std::uint64_t{0} : (std::uint64_t{1} << nbits) - 1;
    const bool is_signed = canopen::data_type_signed(s.type);
    const bool fits = is_signed ? canopen::sign_extend(static_cast<std::uint64_t>(v) & mask, nbits) == v
                                : (v >= 0 && (static_cast<std::uint64_t>(v) & ~mask) == 0);
    if (!fits) {
      refuse(RefusalKind::kOutOfRange, u.index, u.sub, s.line, u.key,
             fmt::format("{} is {}, the master writes {}, which does not fit", what, canopen::data_type_name(s.type), v));
      return;
    }
    const std::uint64_t b = static_cast<std::uint64_t>(v) & mask;
    const auto limit = [&](const std::optional<Value>& l) -> std::optional<std::uint64_t> {
      if (!l || canopen::data_type_size(s.type) == 0) return std::nullopt;
      if (l->node_id_relative && node_ == 0) return std::nullopt;
      return l->resolve(node_, bytes);
    };
    if (const auto lo = limit(s.low_limit); lo && compare_values(s.type, b, *lo) < 0)
      refuse(RefusalKind::kOutOfRange, u.index, u.sub, s.line, u.key,
             fmt::format("{}: the master writes {}, below LowLimit={}", what, v, s.low_limit->text));
    if (const auto hi = limit(s.high_limit); hi && compare_values(s.type, b, *hi) > 0)
      refuse(RefusalKind::kOutOfRange, u.index, u.sub, s.line, u.key,
             fmt::format("{}: the master writes {}, above HighLimit={}", what, v, s.high_limit->text));
  }

  void bits(const Use& u, const SubObject& s, const std::string& what) {
    const Value* v = s.value();
    if (v == nullptr || s.size() == 0 || (v->node_id_relative && node_ == 0)) {
      r_.deferred.push_back(u);  // the boot reads the object from the device
      return;
    }
    const std::uint64_t have = v->resolve(node_, s.size());
    const std::uint64_t lacking = u.required_bits & ~have;
    if (lacking != 0)
      refuse(RefusalKind::kMissingBits, u.index, u.sub, s.line, u.key,
             fmt::format("{} is {} ({}), it lacks bit{} 0x{:X}, which the master needs", what, v->text,
                         s.parameter_value ? "ParameterValue" : "DefaultValue", (lacking & (lacking - 1)) != 0 ? "s" : "",
                         lacking));
  }

  const Eds& eds_;
  const Requirements& req_;
  std::uint8_t node_;
  CheckResult r_;
};

}  // namespace

CheckResult check(const Eds& eds, const Requirements& req) { return Checker(eds, req).run(); }

}  // namespace canmotion::eds
