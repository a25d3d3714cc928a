// EDS/DCF reader (fieldbus/eds): every CiA 301 basic data type and CiA 306
// access type, values ($NODEID, hex, octal, limits), objects and
// sub-indices (SubNumber, CompactSubObj), [DeviceInfo], object lists, DCF
// data; malformed files each refused with file:line and what is wrong.
#include <gtest/gtest.h>

#include <bit>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "fieldbus/canopen/pdo.hpp"
#include "fieldbus/eds/eds.hpp"
#include "tests/eds/eds_test_util.hpp"

using namespace canmotion;
using canopen::DataType;
using eds::AccessType;
using eds::test::eds_text;
using eds::test::error_text;
using eds::test::errors_of;
using eds::test::line_of;
using eds::test::warning_text;
using eds::test::warnings_of;

namespace {

struct TypeCase {
  DataType type;
  const char* default_value;
  std::uint64_t bits;  // numbers
  std::string data;    // strings and bytes
};

/// One VAR at `index` of `type` with `default_value` (and more keys).
std::string var_section(std::uint16_t index, DataType type, std::string_view default_value, std::string_view access = "rw",
                        std::string_view extra = "") {
  return fmt::format("[{:04X}]\nParameterName=Object {:04X}\nObjectType=0x7\nDataType=0x{:04X}\nAccessType={}\n"
                     "DefaultValue={}\nPDOMapping=0\n{}\n",
                     index, index, static_cast<unsigned>(type), access, default_value, extra);
}

}  // namespace

TEST(EdsParse, EveryBasicDataTypeWithItsDefault) {
  const std::vector<TypeCase> cases = {
      {DataType::kBoolean, "1", 1, {}},
      {DataType::kInteger8, "-128", 0x80, {}},
      {DataType::kInteger16, "0x8000", 0x8000, {}},  // hex: the bit pattern (-32768)
      {DataType::kInteger24, "-1", 0xFFFFFF, {}},
      {DataType::kInteger32, "-2147483648", 0x80000000u, {}},
      {DataType::kInteger40, "-0x10", 0xFFFFFFFFF0ull, {}},
      {DataType::kInteger48, "0777", 0777, {}},  // octal
      {DataType::kInteger56, "36028797018963967", 0x7FFFFFFFFFFFFFull, {}},
      {DataType::kInteger64, "-9223372036854775808", 0x8000000000000000ull, {}},
      {DataType::kUnsigned8, "255", 255, {}},
      {DataType::kUnsigned16, "0xFFFF", 0xFFFF, {}},
      {DataType::kUnsigned24, "0xFFFFFF", 0xFFFFFF, {}},
      {DataType::kUnsigned32, "4294967295", 0xFFFFFFFFu, {}},
      {DataType::kUnsigned40, "0xFFFFFFFFFF", 0xFFFFFFFFFFull, {}},
      {DataType::kUnsigned48, "281474976710655", 0xFFFFFFFFFFFFull, {}},
      {DataType::kUnsigned56, "0xFFFFFFFFFFFFFF", 0xFFFFFFFFFFFFFFull, {}},
      {DataType::kUnsigned64, "18446744073709551615", ~0ull, {}},
      {DataType::kReal32, "1.5", std::bit_cast<std::uint32_t>(1.5f), {}},
      {DataType::kReal64, "-0.25", std::bit_cast<std::uint64_t>(-0.25), {}},
      {DataType::kVisibleString, "hello, world", 0, "hello, world"},
      {DataType::kOctetString, "01 02 AB", 0, std::string("\x01\x02\xAB", 3)},
      {DataType::kUnicodeString, "h\xC3\xA9llo", 0, "h\xC3\xA9llo"},
      {DataType::kTimeOfDay, "0x123456789ABC", 0x123456789ABCull, {}},
      {DataType::kTimeDifference, "1000", 1000, {}},
      {DataType::kDomain, "DEADBEEF", 0, std::string("\xDE\xAD\xBE\xEF", 4)},
  };
  // Every type of canopen's one table is covered.
  ASSERT_EQ(cases.size(), std::size(canopen::kAllDataTypes));
  std::string body;
  std::vector<std::uint16_t> list;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto index = static_cast<std::uint16_t>(0x2001 + i);
    body += var_section(index, cases[i].type, cases[i].default_value);
    list.push_back(index);
  }
  const std::string text = eds_text(body, list);
  const eds::Eds e = eds::parse(text, "types.eds");
  EXPECT_TRUE(e.warnings.empty()) << e.warnings.front().to_string();
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto index = static_cast<std::uint16_t>(0x2001 + i);
    SCOPED_TRACE(canopen::data_type_name(cases[i].type));
    const eds::SubObject* s = e.find(index, 0);
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->type, cases[i].type);
    EXPECT_EQ(s->size(), canopen::data_type_size(cases[i].type));
    EXPECT_EQ(s->line, line_of(text, fmt::format("[{:04X}]", index)));
    ASSERT_TRUE(s->default_value.has_value());
    EXPECT_EQ(s->default_value->text, cases[i].default_value);
    EXPECT_EQ(s->default_value->bits, cases[i].bits);
    EXPECT_EQ(s->default_value->data, cases[i].data);
    EXPECT_FALSE(s->default_value->node_id_relative);
  }
  // Sign: the INTEGERn bit patterns read back as the numbers written.
  EXPECT_EQ(canopen::sign_extend(e.find(0x2002, 0)->default_value->bits, 8), -128);
  EXPECT_EQ(canopen::sign_extend(e.find(0x2006, 0)->default_value->bits, 40), -16);
  EXPECT_EQ(eds::format_number(DataType::kInteger16, 0x8000), "-32768");
  EXPECT_EQ(eds::format_number(DataType::kReal32, std::bit_cast<std::uint32_t>(1.5f)), "1.5");
}

TEST(EdsParse, IntegerTypesAcceptTheirRangeAndRefuseOneBeyond) {
  for (DataType t : canopen::kAllDataTypes) {
    const std::size_t bytes = canopen::data_type_size(t);
    const bool integer = bytes != 0 && t != DataType::kReal32 && t != DataType::kReal64;
    if (!integer) continue;
    SCOPED_TRACE(canopen::data_type_name(t));
    const unsigned bits = t == DataType::kBoolean ? 1 : static_cast<unsigned>(8 * bytes);
    std::string why;
    if (canopen::data_type_signed(t)) {
      const std::uint64_t half = std::uint64_t{1} << (bits - 1);  // |min|; max = half - 1
      const std::string lo = "-" + std::to_string(half);
      const std::string hi = std::to_string(half - 1);
      EXPECT_TRUE(eds::parse_value(lo, t, why)) << why;
      EXPECT_TRUE(eds::parse_value(hi, t, why)) << why;
      EXPECT_FALSE(eds::parse_value("-" + std::to_string(half + 1), t, why)) << lo;
      EXPECT_NE(why.find("does not fit"), std::string::npos) << why;
      EXPECT_FALSE(eds::parse_value(std::to_string(half), t, why)) << hi;
      EXPECT_NE(why.find(canopen::data_type_name(t)), std::string::npos) << why;
    } else {
      const std::uint64_t hi = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
      EXPECT_TRUE(eds::parse_value(std::to_string(hi), t, why)) << why;
      EXPECT_TRUE(eds::parse_value("0", t, why)) << why;
      EXPECT_FALSE(eds::parse_value("-1", t, why));
      EXPECT_NE(why.find("negative"), std::string::npos) << why;
      EXPECT_FALSE(eds::parse_value(bits >= 64 ? std::string("18446744073709551616") : std::to_string(hi + 1), t, why));
      if (bits < 64) {
        EXPECT_NE(why.find("does not fit"), std::string::npos) << why;
      }
    }
  }
}

TEST(EdsParse, NodeIdRelativeValues) {
  std::string why;
  for (const char* text : {"$NODEID+0x180", "0x180+$NODEID", "$nodeid + 0x180", "$NODEID+384"}) {
    const auto v = eds::parse_value(text, DataType::kUnsigned32, why);
    ASSERT_TRUE(v) << text << ": " << why;
    EXPECT_TRUE(v->node_id_relative);
    EXPECT_EQ(v->bits, 0x180u);
    EXPECT_EQ(v->resolve(5, 4), 0x185u);
  }
  const auto bare = eds::parse_value("$NODEID", DataType::kUnsigned8, why);
  ASSERT_TRUE(bare);
  EXPECT_EQ(bare->resolve(127, 1), 127u);
  EXPECT_FALSE(eds::parse_value("$NODEID-1", DataType::kUnsigned32, why));
  EXPECT_NE(why.find("$NODEID+<number>"), std::string::npos) << why;
  EXPECT_FALSE(eds::parse_value("$NODEID+1", DataType::kInteger32, why));
  EXPECT_NE(why.find("only allowed for UNSIGNED"), std::string::npos) << why;
  EXPECT_FALSE(eds::parse_value("08", DataType::kUnsigned8, why));  // a leading 0 is octal
  EXPECT_NE(why.find("not a number"), std::string::npos) << why;
}

TEST(EdsParse, EveryAccessTypeAndPdoDirection) {
  struct C {
    const char* text;
    AccessType access;
    bool readable, writable, rpdo, tpdo;
    canopen::Access co;
  };
  const C cases[] = {
      {"ro", AccessType::kRo, true, false, false, true, canopen::Access::kRo},
      {"wo", AccessType::kWo, false, true, true, false, canopen::Access::kWo},
      {"RW", AccessType::kRw, true, true, true, true, canopen::Access::kRw},  // case-insensitive
      {"rwr", AccessType::kRwr, true, true, false, true, canopen::Access::kRw},
      {"rww", AccessType::kRww, true, true, true, false, canopen::Access::kRw},
      {"Const", AccessType::kConst, true, false, false, true, canopen::Access::kConst},
  };
  std::string body;
  std::vector<std::uint16_t> list;
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const auto mapped = static_cast<std::uint16_t>(0x2100 + i);
    const auto unmapped = static_cast<std::uint16_t>(0x2200 + i);
    body += fmt::format("[{:04X}]\nParameterName=m\nDataType=0x0006\nAccessType={}\nPDOMapping=1\n\n", mapped, cases[i].text);
    body += fmt::format("[{:04X}]\nParameterName=u\nDataType=0x0006\nAccessType={}\nPDOMapping=0\n\n", unmapped, cases[i].text);
    list.push_back(mapped);
    list.push_back(unmapped);
  }
  std::sort(list.begin(), list.end());
  const eds::Eds e = eds::parse(eds_text(body, list));
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    SCOPED_TRACE(cases[i].text);
    const eds::SubObject& m = *e.find(static_cast<std::uint16_t>(0x2100 + i), 0);
    const eds::SubObject& u = *e.find(static_cast<std::uint16_t>(0x2200 + i), 0);
    EXPECT_EQ(e.find(static_cast<std::uint16_t>(0x2100 + i))->code, eds::ObjectCode::kVar);  // ObjectType left out
    EXPECT_EQ(m.access, cases[i].access);
    std::string lower = cases[i].text;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    EXPECT_EQ(eds::access_type_name(m.access), lower);
    EXPECT_EQ(eds::readable(m.access), cases[i].readable);
    EXPECT_EQ(eds::writable(m.access), cases[i].writable);
    EXPECT_EQ(eds::to_canopen(m.access), cases[i].co);
    EXPECT_EQ(m.rpdo_mappable(), cases[i].rpdo);
    EXPECT_EQ(m.tpdo_mappable(), cases[i].tpdo);
    EXPECT_FALSE(u.rpdo_mappable());
    EXPECT_FALSE(u.tpdo_mappable());
    EXPECT_EQ(u.pdo_direction(), canopen::PdoMappable::kNo);
  }
  EXPECT_EQ(e.find(0x2102, 0)->pdo_direction(), canopen::PdoMappable::kBoth);
  EXPECT_EQ(e.find(0x2104, 0)->pdo_direction(), canopen::PdoMappable::kRpdo);
  EXPECT_EQ(e.find(0x2100, 0)->pdo_direction(), canopen::PdoMappable::kTpdo);
}

TEST(EdsParse, DeviceInfoAndFileInfo) {
  const eds::Eds e = eds::parse(eds_text(""), "info.eds");
  EXPECT_EQ(e.file, "info.eds");
  EXPECT_EQ(e.file_info.file_name, "test.eds");
  EXPECT_EQ(e.file_info.eds_version, "4.0");
  const eds::DeviceInfo& d = e.device_info;
  EXPECT_EQ(d.vendor_name, "test");
  EXPECT_EQ(d.vendor_number, 0x12345678u);
  EXPECT_EQ(d.product_name, "test drive");
  EXPECT_EQ(d.product_number, 0x402u);
  EXPECT_EQ(d.revision_number, 0x00020001u);
  EXPECT_EQ(d.baud_rates, (std::vector<std::uint16_t>{500, 1000}));
  EXPECT_EQ(d.granularity, 8);
  EXPECT_EQ(d.nr_of_rxpdo, 2);
  EXPECT_EQ(d.nr_of_txpdo, 2);
  const std::string text = eds_text("");
  EXPECT_EQ(d.line, line_of(text, "[DeviceInfo]"));
  EXPECT_EQ(d.nr_of_rxpdo_line, line_of(text, "NrOfRXPDO"));
  EXPECT_EQ(d.nr_of_txpdo_line, line_of(text, "NrOfTXPDO"));
  EXPECT_EQ(d.granularity_line, line_of(text, "Granularity"));
  EXPECT_EQ(e.list_lines[static_cast<int>(eds::ObjectList::kMandatory)], line_of(text, "[MandatoryObjects]"));
  EXPECT_EQ(e.list_lines[static_cast<int>(eds::ObjectList::kOptional)], 0);
  EXPECT_FALSE(e.is_dcf());
  const eds::Object& o = *e.find(0x1000);
  EXPECT_EQ(o.list, eds::ObjectList::kMandatory);
  EXPECT_EQ(o.name, "Device type");
  EXPECT_EQ(o.line, line_of(text, "[1000]"));
}

TEST(EdsParse, RecordWithSubNumberAndArrayWithCompactSubObj) {
  const std::string body =
      "[1018]\nParameterName=Identity object\nObjectType=0x9\nSubNumber=3\nObjFlags=1\n\n"
      "[1018sub0]\nParameterName=Highest sub-index supported\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\n\n"
      "[1018Sub1]\nParameterName=Vendor-ID\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x12345678\n\n"
      "[1018SUB2]\nParameterName=Product code\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x402\n\n"
      "[1016]\nParameterName=Consumer heartbeat time\nObjectType=0x8\nCompactSubObj=3\nDataType=0x0007\n"
      "AccessType=rw\nDefaultValue=0\nPDOMapping=0\n\n"
      "[1016Name]\nNrOfEntries=2\n1=Watch the master\n3=Watch node 3\n\n"
      "[1016Value]\nNrOfEntries=1\n1=0x007F012C\n\n"
      "[1F50]\nParameterName=Program data\nObjectType=0x2\n\n";
  const std::string text = eds_text(body, {}, {0x1016, 0x1018, 0x1F50});
  const eds::Eds e = eds::parse(text);
  const eds::Object& id = *e.find(0x1018);
  EXPECT_EQ(id.code, eds::ObjectCode::kRecord);
  EXPECT_EQ(id.sub_number, 3);
  EXPECT_EQ(id.obj_flags, 1u);
  ASSERT_EQ(id.subs.size(), 3u);
  EXPECT_EQ(id.subs[1].name, "Vendor-ID");
  EXPECT_EQ(id.subs[1].default_value->bits, 0x12345678u);
  EXPECT_EQ(id.subs[2].line, line_of(text, "[1018SUB2]"));
  EXPECT_EQ(e.find(0x1018, 3), nullptr);

  const eds::Object& hb = *e.find(0x1016);
  EXPECT_EQ(hb.code, eds::ObjectCode::kArray);
  EXPECT_EQ(hb.compact_sub_obj, 3);
  ASSERT_EQ(hb.subs.size(), 4u);
  EXPECT_EQ(hb.subs[0].type, DataType::kUnsigned8);
  EXPECT_EQ(hb.subs[0].access, AccessType::kRo);
  EXPECT_EQ(hb.subs[0].default_value->bits, 3u);
  EXPECT_EQ(hb.subs[1].name, "Watch the master");
  EXPECT_EQ(hb.subs[1].default_value->bits, 0x007F012Cu);  // from [1016Value]
  EXPECT_EQ(hb.subs[2].name, "Consumer heartbeat timesub2");  // no name given: ParameterName + "sub" + n
  EXPECT_EQ(hb.subs[2].default_value->bits, 0u);               // the object's DefaultValue
  EXPECT_EQ(hb.subs[3].name, "Watch node 3");
  for (const auto& s : hb.subs) EXPECT_EQ(s.line, line_of(text, "[1016]"));
  EXPECT_EQ(hb.subs[3].type, DataType::kUnsigned32);
  EXPECT_EQ(hb.subs[3].access, AccessType::kRw);

  const eds::SubObject& dom = *e.find(0x1F50, 0);  // DOMAIN: DataType and AccessType may be left out
  EXPECT_EQ(e.find(0x1F50)->code, eds::ObjectCode::kDomain);
  EXPECT_EQ(dom.type, DataType::kDomain);
  EXPECT_EQ(dom.access, AccessType::kRw);
}

TEST(EdsParse, LimitsObjFlagsAndDcfData) {
  const std::string body =
      "[2000]\nParameterName=Limited\nDataType=0x0003\nAccessType=rw\nDefaultValue=-5\nLowLimit=-10\nHighLimit=0x0064\n"
      "ObjFlags=0x3\nParameterValue=42\nDenotation=Axis X offset\n\n";
  const std::string text =
      eds_text(body, {0x2000}) + "[DeviceComissioning]\nNodeId=0x10\nNodeName=axis x\nBaudrate=500\nNetNumber=1\n"
                                 "NetworkName=machine\nCANopenManager=0\nLSS_SerialNumber=77\n";
  const eds::Eds e = eds::parse(text, "x.dcf");
  const eds::SubObject& s = *e.find(0x2000, 0);
  EXPECT_EQ(canopen::sign_extend(s.low_limit->bits, 16), -10);
  EXPECT_EQ(s.high_limit->bits, 100u);
  EXPECT_EQ(s.obj_flags, 3u);
  EXPECT_EQ(e.find(0x2000)->obj_flags, 3u);  // a VAR: the object's flags are its sub-index 0's
  ASSERT_TRUE(s.parameter_value);
  EXPECT_EQ(s.parameter_value->bits, 42u);
  EXPECT_EQ(s.denotation, "Axis X offset");
  EXPECT_TRUE(e.is_dcf());
  ASSERT_TRUE(e.comissioning);
  EXPECT_EQ(e.comissioning->node_id, 0x10);
  EXPECT_EQ(e.comissioning->baudrate, 500);
  EXPECT_EQ(e.comissioning->node_name, "axis x");
  EXPECT_EQ(e.comissioning->net_number, 1u);
  EXPECT_EQ(e.comissioning->network_name, "machine");
  EXPECT_EQ(e.comissioning->lss_serial_number, 77u);
  EXPECT_EQ(e.comissioning->line, line_of(text, "[DeviceComissioning]"));
  EXPECT_EQ(eds::compare_values(DataType::kInteger16, s.low_limit->bits, s.high_limit->bits), -1);
}

TEST(EdsParse, IniDetailsCommentsCrLfBomCaseAndDummies) {
  std::string text = "\xEF\xBB\xBF; a comment line\r\n# another\r\n" +
                     eds_text("[2000]\r\nparametername=x ; an inline comment\r\nDATATYPE=0x0005\r\naccesstype=RO\r\n\r\n"
                              "[DummyUsage]\nDummy0001=0\nDummy0002=1\nDummy0005=1\n",
                              {0x2000});
  const eds::Eds e = eds::parse(text);
  const eds::SubObject& s = *e.find(0x2000, 0);
  EXPECT_EQ(s.name, "x");
  EXPECT_EQ(s.type, DataType::kUnsigned8);
  EXPECT_EQ(s.access, AccessType::kRo);
  EXPECT_EQ(s.line, line_of(text, "[2000]"));
  EXPECT_EQ(e.dummy_usage, (1u << 2) | (1u << 5));
}

TEST(EdsParse, UnlistedObjectAndOddDomainAreWarnings) {
  const std::string body = "[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n\n"
                           "[2001]\nParameterName=blob\nDataType=0x000F\nAccessType=rw\nDefaultValue=not hex\n\n";
  const std::string text = eds_text(body, {0x2001});
  const eds::Eds e = eds::parse(text, "w.eds");
  ASSERT_EQ(e.warnings.size(), 2u);
  EXPECT_EQ(e.warnings[0].to_string(),
            fmt::format("w.eds:{}: [2000] is not in [MandatoryObjects], [OptionalObjects] or [ManufacturerObjects] "
                        "(CiA 306: it belongs in [ManufacturerObjects])",
                        line_of(text, "[2000]")));
  EXPECT_EQ(e.warnings[1].line, line_of(text, "DefaultValue=not hex"));
  EXPECT_NE(e.warnings[1].message.find("not hex bytes"), std::string::npos);
  EXPECT_NE(e.find(0x2000), nullptr);  // still loaded
  EXPECT_EQ(e.find(0x2001, 0)->default_value->text, "not hex");
}

TEST(EdsParse, LoadReadsAFileAndNamesIt) {
  const auto path = std::filesystem::temp_directory_path() / fmt::format("canmotion-eds-{}.eds", ::getpid());
  {
    std::ofstream out(path);
    out << eds_text("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\nnot a key\n", {0x2000});
  }
  try {
    (void)eds::load(path);
    ADD_FAILURE() << "accepted";
  } catch (const eds::ParseError& e) {
    ASSERT_EQ(e.errors().size(), 1u);
    EXPECT_EQ(e.errors()[0].file, path.string());
    EXPECT_EQ(std::string(e.what()),
              fmt::format("{}:{}: not a [section] header or a key=value line", path.string(), e.errors()[0].line));
  }
  std::filesystem::remove(path);
  try {
    (void)eds::load("/nonexistent/drive.eds");
    ADD_FAILURE() << "accepted";
  } catch (const eds::ParseError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/drive.eds: cannot be read (no such file, or no permission)");
  }
}

// ---- defects of vendor files: a warning with file:line, the file is read on
// (as python-canopen reads it); a defect that makes an object unusable is
// kept with the object (SubObject::defects) for the checker to refuse a use.

namespace {
/// The defects of index:sub as "file:line: message" lines.
std::string defects_of(const eds::Eds& e, std::uint16_t index, std::uint8_t sub) {
  const eds::SubObject* s = e.find(index, sub);
  if (s == nullptr) return "(absent)";
  std::string out;
  for (const eds::Diagnostic& d : s->defects) out += (out.empty() ? "" : "\n") + d.to_string();
  return out;
}
}  // namespace

TEST(EdsWarnings, BadNumber) {
  const std::string text = eds_text("[2000]\nParameterName=x\nDataType=0x00G7\nAccessType=ro\n", {0x2000});
  const std::string want = fmt::format("bad.eds:{}: [2000] DataType=0x00G7 is not a number (decimal, 0x hex or 0 "
                                       "octal; the object cannot be used)",
                                       line_of(text, "DataType=0x00G7"));
  EXPECT_EQ(warning_text(text), want);
  EXPECT_EQ(defects_of(eds::parse(text, "bad.eds"), 0x2000, 0), want);
}

TEST(EdsWarnings, UnknownDataType) {
  const std::string text = eds_text("[2000]\nParameterName=x\nDataType=0x0040\nAccessType=ro\n", {0x2000});
  EXPECT_EQ(warning_text(text), fmt::format("bad.eds:{}: [2000] DataType=0x0040: unknown data type 0x0040 (the CiA 301 "
                                            "basic types are 0x0001 BOOLEAN .. 0x001B UNSIGNED64, without 0x000E and "
                                            "0x0017; the object cannot be used)",
                                            line_of(text, "DataType=0x0040")));
  EXPECT_FALSE(eds::parse(text, "bad.eds").find(0x2000, 0)->defects.empty());
  const std::string reserved = eds_text("[2000]\nParameterName=x\nDataType=0x0017\nAccessType=ro\n", {0x2000});
  EXPECT_NE(warning_text(reserved).find("unknown data type 0x0017"), std::string::npos);
}

TEST(EdsWarnings, BadAccessTypeAndMissingKeys) {
  const std::string text = eds_text(
      "[2000]\nParameterName=x\nDataType=0x0005\nAccessType=rx\n\n"
      "[2001]\nDataType=0x0005\nAccessType=ro\n\n"
      "[2002]\nParameterName=y\nAccessType=ro\n\n"
      "[2003]\nParameterName=z\nDataType=0x0005\n\n",
      {0x2000, 0x2001, 0x2002, 0x2003});
  const auto e = warnings_of(text);
  ASSERT_EQ(e.size(), 4u) << warning_text(text);
  EXPECT_EQ(e[0].to_string(), fmt::format("bad.eds:{}: [2000] AccessType=rx: expected ro, wo, rw, rwr, rww or const "
                                          "(the object cannot be used)",
                                          line_of(text, "AccessType=rx")));
  EXPECT_EQ(e[1].to_string(), fmt::format("bad.eds:{}: [2001] has no ParameterName", line_of(text, "[2001]")));
  EXPECT_EQ(e[2].to_string(), fmt::format("bad.eds:{}: [2002] has no DataType (the object cannot be used)",
                                          line_of(text, "[2002]")));
  EXPECT_EQ(e[3].to_string(), fmt::format("bad.eds:{}: [2003] has no AccessType (the object cannot be used)",
                                          line_of(text, "[2003]")));
  const eds::Eds d = eds::parse(text, "bad.eds");
  EXPECT_TRUE(d.find(0x2001, 0)->defects.empty()) << "a missing name does not make an object unusable";
  for (const std::uint16_t i : {std::uint16_t{0x2000}, std::uint16_t{0x2002}, std::uint16_t{0x2003}}) EXPECT_EQ(d.find(i, 0)->defects.size(), 1u) << i;
}

TEST(EdsWarnings, ValueDoesNotFitItsTypeOrLimits) {
  const std::string text = eds_text(
      "[2000]\nParameterName=x\nDataType=0x0002\nAccessType=rw\nDefaultValue=200\n\n"
      "[2001]\nParameterName=y\nDataType=0x0006\nAccessType=rw\nDefaultValue=5\nLowLimit=10\nHighLimit=2\n\n"
      "[2002]\nParameterName=z\nDataType=0x0004\nAccessType=rw\nDefaultValue=-20\nLowLimit=-10\nParameterValue=11\n"
      "HighLimit=10\n\n"
      "[2003]\nParameterName=w\nDataType=0x0004\nAccessType=rw\nDefaultValue=$NODEID+1\n\n"
      "[2004]\nParameterName=v\nDataType=0x0008\nAccessType=rw\nDefaultValue=1e39\n\n"
      "[2005]\nParameterName=u\nDataType=0x000A\nAccessType=rw\nDefaultValue=ABC\n\n",
      {0x2000, 0x2001, 0x2002, 0x2003, 0x2004, 0x2005});
  const auto e = warnings_of(text);
  ASSERT_EQ(e.size(), 7u) << warning_text(text);
  EXPECT_EQ(e[0].to_string(), fmt::format("bad.eds:{}: [2000] DefaultValue: 200 does not fit INTEGER8 (-128 .. 127) "
                                          "(the value is unknown)",
                                          line_of(text, "DefaultValue=200")));
  EXPECT_EQ(e[1].to_string(), fmt::format("bad.eds:{}: [2001] HighLimit=2 is below LowLimit=10 (both are ignored)",
                                          line_of(text, "HighLimit=2")));
  EXPECT_EQ(e[2].to_string(), fmt::format("bad.eds:{}: [2002] DefaultValue=-20 is below LowLimit=-10",
                                          line_of(text, "DefaultValue=-20")));
  EXPECT_EQ(e[3].to_string(), fmt::format("bad.eds:{}: [2002] ParameterValue=11 is above HighLimit=10",
                                          line_of(text, "ParameterValue=11")));
  EXPECT_EQ(e[4].to_string(), fmt::format("bad.eds:{}: [2003] DefaultValue: '$NODEID+1': $NODEID is only allowed for "
                                          "UNSIGNED types, not INTEGER32 (the value is unknown)",
                                          line_of(text, "DefaultValue=$NODEID+1")));
  EXPECT_EQ(e[5].to_string(), fmt::format("bad.eds:{}: [2004] DefaultValue: 1e39 does not fit REAL32 (the value is "
                                          "unknown)",
                                          line_of(text, "DefaultValue=1e39")));
  EXPECT_EQ(e[6].to_string(), fmt::format("bad.eds:{}: [2005] DefaultValue: 'ABC' is not hex bytes (two hex digits "
                                          "per byte) for OCTET_STRING (the value is unknown)",
                                          line_of(text, "DefaultValue=ABC")));
  const eds::Eds d = eds::parse(text, "bad.eds");
  EXPECT_FALSE(d.find(0x2001, 0)->low_limit.has_value());  // contradicting limits: both left out
  EXPECT_FALSE(d.find(0x2001, 0)->high_limit.has_value());
  EXPECT_TRUE(d.find(0x2001, 0)->defects.empty());
  EXPECT_TRUE(d.find(0x2002, 0)->defects.empty()) << "a value outside the limits is kept";
  EXPECT_EQ(d.find(0x2002, 0)->value()->text, "11");  // the ParameterValue
  EXPECT_FALSE(d.find(0x2000, 0)->default_value.has_value());
  EXPECT_EQ(d.find(0x2000, 0)->defects.size(), 1u) << "an unreadable value of an object the master uses is refused";
}

TEST(EdsWarnings, SubNumberNotCountingTheSubIndexSections) {
  const std::string text = eds_text(
      "[1018]\nParameterName=Identity object\nObjectType=0x9\nSubNumber=3\nObjFlags=1\n\n"
      "[1018sub0]\nParameterName=n\nDataType=0x0005\nAccessType=ro\nDefaultValue=2\n\n"
      "[1018sub2]\nParameterName=Product code\nDataType=0x0007\nAccessType=ro\n\n",
      {}, {0x1018});
  EXPECT_EQ(warning_text(text), fmt::format("bad.eds:{}: [1018] SubNumber=3 but there are 2 sub-index sections "
                                            "([1018subN], N = 0, 2; those are read)",
                                            line_of(text, "SubNumber=3")));
  EXPECT_NE(eds::parse(text, "bad.eds").find(0x1018, 2), nullptr);
  const std::string too_many = eds_text(
      "[2000]\nParameterName=a\nObjectType=0x8\nSubNumber=1\n\n"
      "[2000sub0]\nParameterName=n\nDataType=0x0005\nAccessType=ro\n\n"
      "[2000sub1]\nParameterName=e\nDataType=0x0005\nAccessType=ro\n\n",
      {0x2000});
  EXPECT_EQ(warning_text(too_many), fmt::format("bad.eds:{}: [2000] SubNumber=1 but there are 2 sub-index sections "
                                                "([2000subN], N = 0, 1; those are read)",
                                                line_of(too_many, "SubNumber=1")));
  EXPECT_NE(eds::parse(too_many, "bad.eds").find(0x2000, 1), nullptr);
}

TEST(EdsWarnings, StructureOfArraysAndRecords) {
  const std::string text = eds_text(
      "[2000]\nParameterName=no count\nObjectType=0x9\n\n"                                                  // no SubNumber
      "[2001]\nParameterName=no sub 0\nObjectType=0x8\nSubNumber=1\n\n"
      "[2001sub1]\nParameterName=e\nDataType=0x0005\nAccessType=ro\n\n"
      "[2002]\nParameterName=var\nDataType=0x0005\nAccessType=ro\n\n"
      "[2002sub1]\nParameterName=e\nDataType=0x0005\nAccessType=ro\n\n"                                  // VAR with a sub
      "[2003sub0]\nParameterName=orphan\nDataType=0x0005\nAccessType=ro\n\n"                             // no [2003]
      "[2004]\nParameterName=bad code\nObjectType=0x3\nDataType=0x0005\nAccessType=ro\n\n"
      "[2005]\nParameterName=r\nObjectType=0x9\nSubNumber=1\n\n"
      "[2005sub0]\nParameterName=n\nObjectType=0x9\nDataType=0x0005\nAccessType=ro\n\n"                   // sub not a VAR
      "[2006]\nParameterName=c\nObjectType=0x8\nCompactSubObj=2\nDataType=0x0005\nAccessType=ro\n\n"
      "[2006Name]\nNrOfEntries=3\n1=a\n5=b\n\n",                                                            // count, range
      {0x2000, 0x2001, 0x2002, 0x2004, 0x2005, 0x2006});
  const auto e = warnings_of(text);
  std::vector<std::string> got;
  for (const eds::Diagnostic& d : e) got.push_back(d.to_string());
  const std::vector<std::string> want = {
      fmt::format("bad.eds:{}: [2000] (RECORD) has neither SubNumber nor CompactSubObj (its 0 sub-index sections are "
                  "read)",
                  line_of(text, "[2000]")),
      fmt::format("bad.eds:{}: [2001] has no sub-index 0 ([2001sub0], the highest sub-index supported)",
                  line_of(text, "[2001]")),
      fmt::format("bad.eds:{}: [2002sub1]: 0x2002 is a VAR (ObjectType), it has no sub-indices (ignored)",
                  line_of(text, "[2002sub1]")),
      fmt::format("bad.eds:{}: [2003sub0]: there is no object section [2003] (ignored)", line_of(text, "[2003sub0]")),
      fmt::format("bad.eds:{}: [2004] ObjectType=0x3 is not an object code (0x2 DOMAIN, 0x5 DEFTYPE, 0x6 DEFSTRUCT, "
                  "0x7 VAR, 0x8 ARRAY, 0x9 RECORD; read as a VAR)",
                  line_of(text, "ObjectType=0x3")),
      fmt::format("bad.eds:{}: [2005sub0] ObjectType=0x9: a sub-index is a VAR (0x7; read as one)",
                  line_of(text, "ObjectType=0x9", 3)),
      fmt::format("bad.eds:{}: [2006Name] NrOfEntries=3 but 1 entries are given", line_of(text, "NrOfEntries=3")),
      fmt::format("bad.eds:{}: [2006Name] 5: expected NrOfEntries or a sub-index 1 .. 2 (CompactSubObj of [2006]; "
                  "ignored)",
                  line_of(text, "5=b")),
  };
  EXPECT_EQ(got, want);
  const eds::Eds d = eds::parse(text, "bad.eds");
  ASSERT_NE(d.find(0x2004), nullptr);
  EXPECT_EQ(d.find(0x2004)->code, eds::ObjectCode::kVar);
  EXPECT_EQ(d.find(0x2004)->defects.size(), 1u) << "a use of an object of unknown ObjectType is refused";
  EXPECT_EQ(d.find(0x2002, 1), nullptr);
}

TEST(EdsWarnings, DuplicateSectionsAndKeys) {
  const std::string text = eds_text(
      "[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\nAccessType=rw\n\n"
      "[2000]\nParameterName=again\n\n",
      {0x2000});
  const auto e = warnings_of(text);
  ASSERT_EQ(e.size(), 2u) << warning_text(text);
  EXPECT_EQ(e[0].to_string(), fmt::format("bad.eds:{}: [2000] AccessType is given again (first at line {}, which is "
                                          "read)",
                                          line_of(text, "AccessType=rw"), line_of(text, "AccessType=ro\nAccessType=rw")));
  EXPECT_EQ(e[1].to_string(), fmt::format("bad.eds:{}: section [2000] appears again (first at line {}; this one is "
                                          "ignored)",
                                          line_of(text, "[2000]", 2), line_of(text, "[2000]")));
  const eds::Eds d = eds::parse(text, "bad.eds");
  EXPECT_EQ(d.find(0x2000, 0)->access, eds::AccessType::kRo);
  EXPECT_EQ(d.find(0x2000, 0)->name, "x");
  // An empty duplicate section is seen too, and names are case-insensitive.
  const std::string empty_again = eds_text("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n\n[deviceinfo]\n",
                                           {0x2000});
  EXPECT_EQ(warning_text(empty_again),
            fmt::format("bad.eds:{}: section [deviceinfo] appears again (first at line {}; this one is ignored)",
                        line_of(empty_again, "[deviceinfo]"), line_of(empty_again, "[DeviceInfo]")));
}

TEST(EdsWarnings, ObjectListsThatDoNotMatchTheSections) {
  const std::string text = eds_text("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n\n", {0x2000, 0x2001},
                                    {0x6041});
  const auto e = warnings_of(text);
  ASSERT_EQ(e.size(), 2u) << warning_text(text);
  EXPECT_EQ(e[0].to_string(), fmt::format("bad.eds:{}: [OptionalObjects] lists 0x6041 but there is no section [6041] "
                                          "(the object is taken as absent)",
                                          line_of(text, "1=0x6041")));
  EXPECT_EQ(e[1].to_string(), fmt::format("bad.eds:{}: [ManufacturerObjects] lists 0x2001 but there is no section "
                                          "[2001] (the object is taken as absent)",
                                          line_of(text, "2=0x2001")));

  std::string counts = eds_text("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n\n", {0x2000});
  const std::string list = "[ManufacturerObjects]\nSupportedObjects=1\n1=0x2000\n";
  counts.replace(counts.find(list), list.size(), "[ManufacturerObjects]\nSupportedObjects=3\n1=0x2000\n2=0x1000\n4=0x2000\n");
  const auto c = warnings_of(counts);
  ASSERT_EQ(c.size(), 4u) << warning_text(counts);
  EXPECT_EQ(c[0].to_string(), fmt::format("bad.eds:{}: [ManufacturerObjects] SupportedObjects=3 but entry 3 is missing",
                                          line_of(counts, "SupportedObjects=3")));
  EXPECT_EQ(c[1].to_string(), fmt::format("bad.eds:{}: [ManufacturerObjects] 0x1000 is listed again (first in "
                                          "[MandatoryObjects] at line {})",
                                          line_of(counts, "2=0x1000"), line_of(counts, "1=0x1000")));
  EXPECT_EQ(c[2].to_string(), fmt::format("bad.eds:{}: [ManufacturerObjects] entry 4 is beyond SupportedObjects=3",
                                          line_of(counts, "4=0x2000")));
  EXPECT_EQ(c[3].to_string(), fmt::format("bad.eds:{}: [ManufacturerObjects] 0x2000 is listed again (first in "
                                          "[ManufacturerObjects] at line {})",
                                          line_of(counts, "4=0x2000"), line_of(counts, "1=0x2000")));
}

// Every line inih cannot read is reported, not the first only (in line
// order, with the file's other errors), and a flood of them is cut short.
TEST(EdsErrors, EveryIniSyntaxErrorIsReported) {
  const std::string text = eds_text(
      "[2000]\nParameterName=x\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\n  continued\nPDOMapping=0\n\n"
      "[2001\nno equals sign here\n\n[2002]\nParameterName=y\nObjectType=0x7\nDataType=0x0005\nAccessType=ro\n"
      "PDOMapping=0\nstray words\n",
      {0x2000, 0x2002});
  const auto e = errors_of(text);
  const std::string syntax = "not a [section] header or a key=value line";
  std::vector<std::string> got;
  for (const eds::Diagnostic& d : e)
    if (d.message == syntax) got.push_back(d.to_string());
  const std::vector<std::string> want = {
      fmt::format("bad.eds:{}: {}", line_of(text, "  continued"), syntax),
      fmt::format("bad.eds:{}: {}", line_of(text, "[2001"), syntax),
      fmt::format("bad.eds:{}: {}", line_of(text, "no equals sign"), syntax),
      fmt::format("bad.eds:{}: {}", line_of(text, "stray words"), syntax),
  };
  EXPECT_EQ(got, want) << error_text(text);

  std::string flood = eds_text("");
  for (int i = 0; i < 60; ++i) flood += "junk\n";
  const auto f = errors_of(flood);
  ASSERT_EQ(f.size(), 51u) << error_text(flood);
  EXPECT_EQ(f[0].line, line_of(flood, "junk"));
  EXPECT_EQ(f[49].line, line_of(flood, "junk") + 49);
  EXPECT_EQ(f[50].message,
            "more lines that are not a [section] header or a key=value line (only the first 50 are listed)");
}

TEST(EdsErrors, IniSyntaxAndFileLevelProblems) {
  const std::string text = "ParameterName=before any section\n" +
                           eds_text("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n  continued\n", {0x2000});
  const auto e = errors_of(text);
  ASSERT_EQ(e.size(), 1u) << error_text(text);
  EXPECT_EQ(e[0].to_string(),
            fmt::format("bad.eds:{}: not a [section] header or a key=value line", line_of(text, "  continued")));
  // Without the syntax error: a key before any section is a warning.
  const std::string stray = "ParameterName=before any section\n" +
                            eds_text("[2000]\nParameterName=x\nDataType=0x0005\nAccessType=ro\n", {0x2000});
  EXPECT_EQ(warning_text(stray), "bad.eds:1: 'ParameterName' is outside any [section] (ignored)");

  EXPECT_EQ(warning_text("[FileInfo]\nFileName=x\n"),
            "bad.eds: no [DeviceInfo] section (CiA 306 requires one; the PDO counts are taken from the 0x1400.., "
            "0x1800.. objects)");
  EXPECT_EQ(error_text(eds_text("") + std::string(70000, 'x') + "\n"),
            fmt::format("bad.eds:{}: line is longer than 65536 characters", line_of(eds_text(""), "PDOMapping=0") + 2));
  EXPECT_EQ(error_text(std::string("[DeviceInfo]\nVendorName=a\0b\n", 28)), "bad.eds:2: NUL character (not a text file?)");
  const std::string info = eds_text("");
  std::string bad_info = info;
  bad_info.replace(bad_info.find("NrOfRXPDO=2"), 11, "NrOfRXPDO=600");
  EXPECT_EQ(warning_text(bad_info), fmt::format("bad.eds:{}: [DeviceInfo] NrOfRXPDO=600 is out of range (0 .. 512; "
                                                "ignored)",
                                                line_of(bad_info, "NrOfRXPDO")));
  EXPECT_EQ(eds::parse(bad_info, "bad.eds").device_info.nr_of_rxpdo_line, 0) << "taken as absent";
}

// A commissioning tool's values (NodeId=0, Baudrate=0 for "not set"): the
// master takes node-ID and bit rate from its configuration.
TEST(EdsWarnings, DeviceComissioning) {
  const std::string text = eds_text("") + "[DeviceComissioning]\nNodeId=0\nBaudrate=300\n";
  const auto e = warnings_of(text);
  ASSERT_EQ(e.size(), 2u) << warning_text(text);
  EXPECT_EQ(e[0].to_string(), fmt::format("bad.eds:{}: [DeviceComissioning] NodeId=0 is not a node-ID (1 .. 127; "
                                          "ignored: the configuration gives the node-ID)",
                                          line_of(text, "NodeId=0")));
  EXPECT_EQ(e[1].to_string(), fmt::format("bad.eds:{}: [DeviceComissioning] Baudrate=300 is not a CiA 301 bit rate in "
                                          "kbit/s (10, 20, 50, 125, 250, 500, 800, 1000; ignored: the bus's "
                                          "configuration gives the bit rate)",
                                          line_of(text, "Baudrate=300")));
  const std::string high = eds_text("") + "[DeviceComissioning]\nNodeId=128\n";
  EXPECT_EQ(warning_text(high), fmt::format("bad.eds:{}: [DeviceComissioning] NodeId=128 is not a node-ID (1 .. 127; "
                                            "ignored: the configuration gives the node-ID)",
                                            line_of(high, "NodeId=128")));
  EXPECT_EQ(eds::parse(high, "bad.eds").comissioning->node_id, 0);
}

TEST(EdsErrors, AllErrorsOfAFileInLineOrder) {
  const std::string text = eds_text(
      "[2000]\nParameterName=x\nDataType=0x0040\nAccessType=ro\nfirst bad line\n\n"
      "[2001]\nParameterName=y\nDataType=0x0005\nAccessType=bad\nsecond bad line\n\n",
      {0x2001, 0x2000});
  const auto e = errors_of(text);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_LT(e[0].line, e[1].line);
  EXPECT_EQ(std::string(eds::ParseError(e).what()), e[0].to_string() + "\n" + e[1].to_string());
}

TEST(EdsWarnings, AllWarningsOfAFileInLineOrderEachOnce) {
  const std::string text = eds_text(
      "[2001]\nParameterName=y\nDataType=0x0005\nAccessType=bad\n\n"
      "[2000]\nParameterName=x\nDataType=0x0040\nAccessType=ro\n\n",
      {0x2001, 0x2000});
  const auto e = warnings_of(text);
  ASSERT_EQ(e.size(), 2u) << warning_text(text);
  EXPECT_LT(e[0].line, e[1].line);
}
