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

/// The written sub-objects (index -> sub -> cell, ascending; a sub-object
/// written twice keeps the last value) and the objects' names.
struct Written {
  std::map<std::uint16_t, std::map<std::uint8_t, Cell>> objects;
  std::map<std::uint16_t, std::string> names;
};

/// A cell's type, access, PDO mapping and name: from the EDS, else from the
/// object table, else UNSIGNEDn of the write's size.
Written collect(const DcfSpec& spec) {
  Written r;
  for (const DcfWrite& w : spec.writes) {
    Cell& c = r.objects[w.index][w.sub];
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
      if (const Object* o = spec.eds->find(w.index); o != nullptr && !o->name.empty()) r.names[w.index] = o->name;
    }
    if (!r.names.count(w.index)) {
      const std::string_view n = canopen::object_name(w.index, 0);
      r.names[w.index] = n.empty() ? fmt::format("Object {:04X}", w.index) : std::string(n);
    }
  }
  return r;
}

/// The DCF text, line by line.
struct Text {
  std::string out;
  void line(std::string_view l) {
    out += l;
    out += '\n';
  }
};

void file_info(Text& t, const DcfSpec& spec) {
  t.line(fmt::format("; DCF of what the master writes to node {} ({}) at boot, in CiA 306 form.", spec.node_id,
                     spec.node_name));
  t.line("; One section per written sub-object; ParameterValue is the value after the boot configuration.");
  t.line("");
  t.line("[FileInfo]");
  t.line(fmt::format("FileName={}.dcf", spec.node_name.empty() ? fmt::format("node{}", spec.node_id) : spec.node_name));
  t.line("FileVersion=1");
  t.line("FileRevision=0");
  t.line("EDSVersion=4.0");
  t.line(fmt::format("Description=Boot configuration of node {} by canmotion", spec.node_id));
  t.line(fmt::format("CreatedBy={}", spec.created_by));
}

/// [DeviceInfo] of the node's EDS (empty without one), [DeviceComissioning].
void device_sections(Text& t, const DcfSpec& spec) {
  t.line("");
  t.line("[DeviceInfo]");
  if (spec.eds != nullptr) {
    const DeviceInfo& d = spec.eds->device_info;
    t.line(fmt::format("VendorName={}", d.vendor_name));
    t.line(fmt::format("VendorNumber=0x{:08X}", d.vendor_number));
    t.line(fmt::format("ProductName={}", d.product_name));
    t.line(fmt::format("ProductNumber=0x{:08X}", d.product_number));
    t.line(fmt::format("RevisionNumber=0x{:08X}", d.revision_number));
    t.line(fmt::format("Granularity={}", d.granularity));
    t.line(fmt::format("NrOfRXPDO={}", d.nr_of_rxpdo));
    t.line(fmt::format("NrOfTXPDO={}", d.nr_of_txpdo));
  }
  t.line("");
  t.line("[DeviceComissioning]");
  t.line(fmt::format("NodeId={}", spec.node_id));
  t.line(fmt::format("NodeName={}", spec.node_name));
  t.line(fmt::format("Baudrate={}", spec.baudrate_kbit));
  t.line("CANopenManager=0");
}

/// Object lists, by CiA 306's rule for where an index belongs.
void object_lists(Text& t, const Written& w) {
  for (ObjectList l : {ObjectList::kMandatory, ObjectList::kOptional, ObjectList::kManufacturer}) {
    std::vector<std::uint16_t> in;
    for (const auto& [index, subs] : w.objects)
      if (Eds::expected_list(index) == l) in.push_back(index);
    t.line("");
    t.line(fmt::format("[{}]", object_list_name(l)));
    t.line(fmt::format("SupportedObjects={}", in.size()));
    for (std::size_t i = 0; i < in.size(); ++i) t.line(fmt::format("{}=0x{:04X}", i + 1, in[i]));
  }
}

/// The keys of a VAR section or a sub-index section, with the written value.
void cell_body(Text& t, const Cell& c) {
  t.line(fmt::format("ParameterName={}", c.name));
  t.line("ObjectType=0x7");
  t.line(fmt::format("DataType=0x{:04X}", static_cast<unsigned>(c.type)));
  t.line(fmt::format("AccessType={}", c.access));
  t.line(fmt::format("PDOMapping={}", c.pdo ? 1 : 0));
  t.line(fmt::format("ParameterValue=0x{:0{}X}", c.w->value, 2 * c.w->size));
}

/// A record's sections: [xxxx], [xxxxsub0] when the master did not write
/// it, and one [xxxxsubN] per written sub-index.
void record_sections(Text& t, const DcfSpec& spec, std::uint16_t index, const std::map<std::uint8_t, Cell>& subs,
                     const std::string& name) {
  t.line(fmt::format("[{:04X}]", index));
  t.line(fmt::format("ParameterName={}", name));
  t.line("ObjectType=0x9");
  // Sub-index 0 (highest sub-index supported) is required in a record: the
  // master's own write of it, else the EDS's, else the highest written.
  const bool has_sub0 = subs.begin()->first == 0;
  t.line(fmt::format("SubNumber={}", subs.size() + (has_sub0 ? 0 : 1)));
  if (!has_sub0) {
    const SubObject* s0 = spec.eds != nullptr ? spec.eds->find(index, 0) : nullptr;
    t.line("");
    t.line(fmt::format("[{:04X}sub0]", index));
    t.line("ParameterName=Highest sub-index supported");
    t.line("ObjectType=0x7");
    t.line("DataType=0x0005");
    t.line(fmt::format("AccessType={}", s0 != nullptr ? access_type_name(s0->access) : "ro"));
    t.line(s0 != nullptr && s0->default_value ? fmt::format("DefaultValue={}", s0->default_value->text)
                                             : fmt::format("DefaultValue=0x{:02X}", subs.rbegin()->first));
  }
  for (const auto& [sub, c] : subs) {
    t.line("");
    if (!c.w->key.empty()) t.line(fmt::format("; {}", c.w->key));
    t.line(fmt::format("[{:04X}sub{:X}]", index, sub));
    cell_body(t, c);
  }
}

/// One section per written object: a VAR when only its sub-index 0 is
/// written (PDO parameters are records even then), else a record.
void object_sections(Text& t, const DcfSpec& spec, const Written& w) {
  for (const auto& [index, subs] : w.objects) {
    t.line("");
    const bool var = subs.size() == 1 && subs.begin()->first == 0 && !(index >= 0x1400 && index <= 0x1BFF);
    if (var) {
      const Cell& c = subs.begin()->second;
      if (!c.w->key.empty()) t.line(fmt::format("; {}", c.w->key));
      t.line(fmt::format("[{:04X}]", index));
      cell_body(t, c);
      continue;
    }
    record_sections(t, spec, index, subs, w.names.at(index));
  }
}

}  // namespace

std::string format_dcf(const DcfSpec& spec) {
  const Written w = collect(spec);
  Text t;
  file_info(t, spec);
  device_sections(t, spec);
  object_lists(t, w);
  object_sections(t, spec, w);
  return std::move(t.out);
}

}  // namespace canmotion::eds
