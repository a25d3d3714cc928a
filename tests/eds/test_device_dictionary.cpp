// canopen::DeviceDictionary, the master's "does the drive have it?" query,
// built from an EDS (eds::device_dictionary) or standing for "no EDS".
#include <gtest/gtest.h>

#include <string>

#include "fieldbus/canopen/device_dictionary.hpp"
#include "fieldbus/eds/eds.hpp"

using namespace canmotion;

namespace {

const char* kEds = R"([DeviceInfo]
NrOfRXPDO=0
NrOfTXPDO=0

[MandatoryObjects]
SupportedObjects=1
1=0x1000

[OptionalObjects]
SupportedObjects=1
1=0x1018

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020192

[1018]
ParameterName=Identity
ObjectType=0x9
SubNumber=2

[1018sub0]
ParameterName=Highest sub-index
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=1

[1018sub1]
ParameterName=Vendor-ID of the vendor
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0
)";

TEST(DeviceDictionary, WithoutADescriptionEverythingIsUnknown) {
  const canopen::DeviceDictionary d;
  EXPECT_FALSE(d.described());
  EXPECT_EQ(d.has(0x1016, 1), canopen::Presence::kUnknown);
  EXPECT_EQ(d.has(0x1016), canopen::Presence::kUnknown);
  EXPECT_EQ(d.find(0x1000, 0), nullptr);
  EXPECT_EQ(d.name(0x1000, 0), nullptr);
  EXPECT_EQ(d.name_or_standard(0x6041, 0), "Statusword");  // canopen's table
}

TEST(DeviceDictionary, FromAnEdsAnswersPresentAbsentAndTheVendorsNames) {
  const canopen::DeviceDictionary d = eds::device_dictionary(eds::parse(kEds, "v.eds"));
  EXPECT_TRUE(d.described());
  EXPECT_EQ(d.source(), "v.eds");
  EXPECT_EQ(d.has(0x1000, 0), canopen::Presence::kPresent);
  EXPECT_EQ(d.has(0x1018, 1), canopen::Presence::kPresent);
  EXPECT_EQ(d.has(0x1018, 2), canopen::Presence::kAbsent);  // the index exists, the sub-index does not
  EXPECT_EQ(d.has(0x1018), canopen::Presence::kPresent);
  EXPECT_EQ(d.has(0x1016), canopen::Presence::kAbsent);
  ASSERT_NE(d.find(0x1018, 1), nullptr);
  EXPECT_EQ(d.find(0x1018, 1)->type, canopen::DataType::kUnsigned32);
  EXPECT_EQ(d.find(0x1018, 1)->access, canopen::Access::kRo);
  EXPECT_STREQ(d.name(0x1018, 1), "Vendor-ID of the vendor");
  EXPECT_EQ(d.name_or_standard(0x1018, 1), "Vendor-ID of the vendor");
  EXPECT_EQ(d.name_or_standard(0x6041, 0), "Statusword");  // not in the file: the standard's name
  ASSERT_EQ(d.entries().size(), 3u);
  EXPECT_EQ(d.entries()[0].index, 0x1000);
  EXPECT_EQ(d.entries()[2].sub, 1);
}

TEST(DeviceDictionary, APairGivenTwiceKeepsTheFirst) {
  const canopen::DeviceDictionary d({{0x2000, 0, canopen::DataType::kUnsigned8, canopen::Access::kRw, "b"},
                                     {0x1000, 0, canopen::DataType::kUnsigned32, canopen::Access::kRo, "a"},
                                     {0x2000, 0, canopen::DataType::kUnsigned16, canopen::Access::kRo, "c"}},
                                    "x");
  ASSERT_EQ(d.entries().size(), 2u);
  EXPECT_STREQ(d.name(0x2000, 0), "b");
}

}  // namespace
