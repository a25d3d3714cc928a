// eds::format_dcf (canmotiond --write-dcf): the DCF of a master's boot writes
// reads back with our own reader, with the last value written per
// sub-object, types from the EDS or the object table, the node-ID and baud rate.
#include <gtest/gtest.h>

#include "fieldbus/eds/dcf.hpp"
#include "fieldbus/eds/eds.hpp"
#include "tests/eds/eds_test_util.hpp"

using namespace canmotion;

namespace {

TEST(Dcf, ReadsBackWithTheLastValues) {
  const std::string text = eds::format_dcf(eds::test::dcf_spec());
  eds::Eds e;
  ASSERT_NO_THROW(e = eds::parse(text, "X.dcf")) << text;
  EXPECT_TRUE(e.is_dcf());
  ASSERT_TRUE(e.comissioning);
  EXPECT_EQ(e.comissioning->node_id, 5);
  EXPECT_EQ(e.comissioning->baudrate, 500);
  EXPECT_EQ(e.comissioning->node_name, "X");
  const auto value = [&](std::uint16_t i, std::uint8_t s) -> std::uint64_t {
    const eds::SubObject* o = e.find(i, s);
    if (o == nullptr || !o->parameter_value) {
      ADD_FAILURE() << std::hex << i << ":" << int(s) << " missing\n" << text;
      return ~0ull;
    }
    return o->parameter_value->bits;
  };
  EXPECT_EQ(value(0x6060, 0), 8u);
  EXPECT_EQ(e.find(0x6060, 0)->type, canopen::DataType::kInteger8);  // the object table's type
  EXPECT_EQ(value(0x60C2, 2), 0xFDu);
  EXPECT_EQ(value(0x1400, 1), 0x205u);  // the last write: valid
  EXPECT_EQ(value(0x1600, 0), 1u);
  EXPECT_EQ(value(0x1600, 1), 0x60400010u);
  EXPECT_EQ(value(0x2100, 3), 0x1234u);
  EXPECT_EQ(e.find(0x2100, 3)->type, canopen::DataType::kUnsigned16);  // unknown: UNSIGNEDn of the size
  EXPECT_EQ(e.objects.size(), 5u);
  EXPECT_TRUE(e.warnings.empty()) << e.warnings[0].to_string();
  // The configuration key is a comment above its value.
  EXPECT_NE(text.find("; axes[0].drive.sdo_writes[0] (line 9)\n[2100sub3]"), std::string::npos) << text;
}

TEST(Dcf, TypesAndNamesFromTheEds) {
  const eds::Eds vendor = eds::parse(R"([DeviceInfo]
VendorName=ACME
ProductName=Servo
NrOfRXPDO=1
NrOfTXPDO=1

[ManufacturerObjects]
SupportedObjects=1
1=0x2100

[2100]
ParameterName=Tuning
ObjectType=0x9
SubNumber=2

[2100sub0]
ParameterName=Highest sub-index supported
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=3

[2100sub3]
ParameterName=Gain
ObjectType=0x7
DataType=0x0003
AccessType=rww
PDOMapping=1
)",
                                     "acme.eds");
  eds::DcfSpec s = eds::test::dcf_spec();
  s.eds = &vendor;
  const eds::Eds e = eds::parse(eds::format_dcf(s), "X.dcf");
  EXPECT_EQ(e.device_info.vendor_name, "ACME");
  const eds::SubObject* g = e.find(0x2100, 3);
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->name, "Gain");
  EXPECT_EQ(g->type, canopen::DataType::kInteger16);
  EXPECT_EQ(g->access, eds::AccessType::kRww);
  EXPECT_TRUE(g->pdo_mapping);
  EXPECT_EQ(e.find(0x2100)->name, "Tuning");
}

}  // namespace
