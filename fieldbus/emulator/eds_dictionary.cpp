// The emulated drive's object set from an EDS (EmulatorConfig::served): a
// thin layer over the emulator's own dictionary, kept out of emulator.cpp.
#include "fieldbus/emulator/eds_dictionary.hpp"

#include <algorithm>

namespace canmotion::emulator {

std::vector<ServedObject> served_objects(const eds::Eds& e, std::uint8_t node) {
  std::vector<ServedObject> out;
  for (const eds::Object& o : e.objects) {
    for (const eds::SubObject& s : o.subs) {
      ServedObject x;
      x.index = o.index;
      x.sub = s.sub;
      x.type = s.type;
      x.access = eds::to_canopen(s.access);
      x.pdo = s.pdo_direction();
      const std::size_t size = s.size();
      // A DCF's ParameterValue is what the integrator set: it wins over the default.
      const std::optional<eds::Value>& v = s.parameter_value ? s.parameter_value : s.default_value;
      if (v && size > 0 && size <= 8) {
        x.has_default = true;
        x.default_value = v->resolve(node, size);
      }
      out.push_back(x);
    }
  }
  return out;
}

void Emulator::apply_served() {
  std::sort(od_.begin(), od_.end(), [](const Entry& a, const Entry& b) { return a.key < b.key; });
  std::vector<ServedObject> list = cfg_.served;
  std::sort(list.begin(), list.end(),
            [](const ServedObject& a, const ServedObject& b) { return key(a.index, a.sub) < key(b.index, b.sub); });
  auto listed = [&list](std::uint32_t k) {
    const auto it = std::lower_bound(list.begin(), list.end(), k,
                                     [](const ServedObject& o, std::uint32_t kk) { return key(o.index, o.sub) < kk; });
    return it != list.end() && key(it->index, it->sub) == k ? &*it : nullptr;
  };
  for (Entry& en : od_) {
    const ServedObject* o = listed(en.key);
    en.hidden = o == nullptr;
    if (o == nullptr) continue;
    en.access = o->access;
    en.pdo = o->pdo;
    if (o->has_default && en.text == nullptr) en.value = en.default_value = o->default_value & en.mask;
  }
  // Numbers the file lists that the emulator does not know: plain storage.
  const std::size_t own = od_.size();
  for (const ServedObject& o : list) {
    const std::size_t size = canopen::data_type_size(o.type);
    if (size == 0 || size > 8) continue;
    const std::uint32_t k = key(o.index, o.sub);
    const auto end = od_.begin() + static_cast<std::ptrdiff_t>(own);
    const auto it = std::lower_bound(od_.begin(), end, k, [](const Entry& en, std::uint32_t kk) { return en.key < kk; });
    if (it != end && it->key == k) continue;
    Entry en{k, o.type, o.access, o.pdo, 0, 0, nullptr, 0, 0, false};
    set_type(en, o.type);
    en.value = en.default_value = o.has_default ? o.default_value & en.mask : 0;
    od_.push_back(en);
  }
}

const Emulator::Entry* Emulator::served(std::uint16_t index, std::uint8_t sub) const noexcept {
  const Entry* e = find(index, sub);
  return e != nullptr && !e->hidden ? e : nullptr;
}

}  // namespace canmotion::emulator
