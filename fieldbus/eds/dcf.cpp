#include "fieldbus/eds/dcf.hpp"

#include <map>

#include <fmt/format.h>

namespace canmotion::eds {

namespace {
struct Cell {
  const DcfWrite* w = nullptr;  // the last write of this sub-object
  canopen::DataType type = canopen::DataType::kUnsigned32;
  std::string access = "rw";
  bool pdo = false;
  std::string name;
};

canopen::DataType unsigned_of(std::uint8_t size) {
  switch (size) {
    case 1: return canopen::DataType::kUnsigned8;
    case 2: return canopen::DataType::kUnsigned16;
    case 3: return canopen::DataType::kUnsigned24;
    default: return canopen::DataType::kUnsigned32;
  }
}

std::string_view access_of(canopen::Access a) {
  switch (a) {
    case canopen::Access::kRo: return "ro";
    case canopen::Access::kWo: return "wo";
    case canopen::Access::kConst: return "const";
    case canopen::Access::kRw: return "rw";
  }
  return "rw";
}
}  // namespace

std::string format_dcf(const DcfSpec& spec) {
  // index -> sub -> cell, ascending; a sub-object written twice keeps the last value.
  std::map<std::uint16_t, std::map<std::uint8_t, Cell>> objects;
  std::map<std::uint16_t, std::string> object_names;
  for (const DcfWrite& w : spec.writes) {
    Cell& c = objects[w.index][w.sub];
    c.w = &w;
    c.type = unsigned_of(w.size);
    c.name = fmt::format("Sub-index {}", w.sub);
    if (const canopen::ObjectInfo* info = canopen::object_info(w.index, w.sub)) {
      c.type = info->type;
      c.access = access_of(info->access);
      c.pdo = info->pdo != canopen::PdoMappable::kNo;
      c.name = std::string(canopen::object_name(w.index, w.sub));
    }
    if (spec.eds != nullptr) {
      if (const SubObject* s = spec.eds->find(w.index, w.sub)) {
        c.type = s->type;
        c.access = access_type_name(s->access);
        c.pdo = s->pdo_mapping;
        if (!s->name.empty()) c.name = s->name;
      }
      if (const Object* o = spec.eds->find(w.index); o != nullptr && !o->name.empty()) object_names[w.index] = o->name;
    }
    if (!object_names.count(w.index)) {
      const std::string_view n = canopen::object_name(w.index, 0);
      object_names[w.index] = n.empty() ? fmt::format("Object {:04X}", w.index) : std::string(n);
    }
  }

  std::string out;
  auto line = [&out](std::string_view l) {
    out += l;
    out += '\n';
  };
  line(fmt::format("; DCF of what the master writes to node {} ({}) at boot, in CiA 306 form.", spec.node_id,
                   spec.node_name));
  line("; One section per written sub-object; ParameterValue is the value after the boot configuration.");
  line("");
  line("[FileInfo]");
  line(fmt::format("FileName={}.dcf", spec.node_name.empty() ? fmt::format("node{}", spec.node_id) : spec.node_name));
  line("FileVersion=1");
  line("FileRevision=0");
  line("EDSVersion=4.0");
  line(fmt::format("Description=Boot configuration of node {} by canmotion", spec.node_id));
  line(fmt::format("CreatedBy={}", spec.created_by));
  line("");
  line("[DeviceInfo]");
  if (spec.eds != nullptr) {
    const DeviceInfo& d = spec.eds->device_info;
    line(fmt::format("VendorName={}", d.vendor_name));
    line(fmt::format("VendorNumber=0x{:08X}", d.vendor_number));
    line(fmt::format("ProductName={}", d.product_name));
    line(fmt::format("ProductNumber=0x{:08X}", d.product_number));
    line(fmt::format("RevisionNumber=0x{:08X}", d.revision_number));
    line(fmt::format("Granularity={}", d.granularity));
    line(fmt::format("NrOfRXPDO={}", d.nr_of_rxpdo));
    line(fmt::format("NrOfTXPDO={}", d.nr_of_txpdo));
  }
  line("");
  line("[DeviceComissioning]");
  line(fmt::format("NodeId={}", spec.node_id));
  line(fmt::format("NodeName={}", spec.node_name));
  line(fmt::format("Baudrate={}", spec.baudrate_kbit));
  line("CANopenManager=0");

  // Object lists, by CiA 306's rule for where an index belongs.
  for (ObjectList l : {ObjectList::kMandatory, ObjectList::kOptional, ObjectList::kManufacturer}) {
    std::vector<std::uint16_t> in;
    for (const auto& [index, subs] : objects)
      if (Eds::expected_list(index) == l) in.push_back(index);
    line("");
    line(fmt::format("[{}]", object_list_name(l)));
    line(fmt::format("SupportedObjects={}", in.size()));
    for (std::size_t i = 0; i < in.size(); ++i) line(fmt::format("{}=0x{:04X}", i + 1, in[i]));
  }

  auto body = [&](const Cell& c, std::uint8_t object_type) {
    line(fmt::format("ParameterName={}", c.name));
    line(fmt::format("ObjectType=0x{:X}", object_type));
    line(fmt::format("DataType=0x{:04X}", static_cast<unsigned>(c.type)));
    line(fmt::format("AccessType={}", c.access));
    line(fmt::format("PDOMapping={}", c.pdo ? 1 : 0));
    line(fmt::format("ParameterValue=0x{:0{}X}", c.w->value, 2 * c.w->size));
  };
  for (const auto& [index, subs] : objects) {
    line("");
    const bool var = subs.size() == 1 && subs.begin()->first == 0 && !(index >= 0x1400 && index <= 0x1BFF);
    if (var) {
      const Cell& c = subs.begin()->second;
      if (!c.w->key.empty()) line(fmt::format("; {}", c.w->key));
      line(fmt::format("[{:04X}]", index));
      body(c, 0x7);
      continue;
    }
    line(fmt::format("[{:04X}]", index));
    line(fmt::format("ParameterName={}", object_names[index]));
    line("ObjectType=0x9");
    // Sub-index 0 (highest sub-index supported) is required in a record: the
    // master's own write of it, else the EDS's, else the highest written.
    const bool has_sub0 = subs.begin()->first == 0;
    line(fmt::format("SubNumber={}", subs.size() + (has_sub0 ? 0 : 1)));
    if (!has_sub0) {
      const SubObject* s0 = spec.eds != nullptr ? spec.eds->find(index, 0) : nullptr;
      line("");
      line(fmt::format("[{:04X}sub0]", index));
      line("ParameterName=Highest sub-index supported");
      line("ObjectType=0x7");
      line("DataType=0x0005");
      line(fmt::format("AccessType={}", s0 != nullptr ? access_type_name(s0->access) : "ro"));
      line(s0 != nullptr && s0->default_value ? fmt::format("DefaultValue={}", s0->default_value->text)
                                             : fmt::format("DefaultValue=0x{:02X}", subs.rbegin()->first));
    }
    for (const auto& [sub, c] : subs) {
      line("");
      if (!c.w->key.empty()) line(fmt::format("; {}", c.w->key));
      line(fmt::format("[{:04X}sub{:X}]", index, sub));
      body(c, 0x7);
    }
  }
  return out;
}

}  // namespace canmotion::eds
