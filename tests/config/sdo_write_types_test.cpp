// sdo_writes of every CiA 301 type (issue 30): the bytes each type gives
// (little endian, as the SDO carries them), DOMAIN/OCTET_STRING from a file,
// and the errors, each naming the key and the type.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "tests/config/config_errors.hpp"

namespace canmotion::config {
namespace {

std::string with_writes(const std::string& writes) {
  return R"(controller: {period_ms: 1}
buses:
  - {name: can0, interface: sim, bitrate: 1000000}
axes:
  - name: X
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 10000
    drive:
      sdo_writes:
)" + writes;
}

std::vector<std::uint8_t> bytes_of(const std::string& entry) {
  const Config c = load_string(with_writes("        - " + entry + "\n"));
  return c.axes.at(0).drive.sdo_writes.at(0).bytes;
}

using B = std::vector<std::uint8_t>;
using test::errors_of;

TEST(ConfigSdoWriteTypes, BytesOfEveryType) {
  EXPECT_EQ(bytes_of("{index: 0x4000, type: BOOLEAN, value: true}"), B{1});
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER8, value: -2}"), B{0xFE});
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER16, value: -2}"), (B{0xFE, 0xFF}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER24, value: -8388608}"), (B{0x00, 0x00, 0x80}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER32, value: 0x12345678}"), (B{0x78, 0x56, 0x34, 0x12}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER40, value: -1}"), (B{0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER48, value: 1}"), (B{1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER56, value: 2}"), (B{2, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: INTEGER64, value: -9223372036854775808}"),
            (B{0, 0, 0, 0, 0, 0, 0, 0x80}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED8, value: 255}"), B{0xFF});
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED16, value: 0x1234}"), (B{0x34, 0x12}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED24, value: 0xABCDEF}"), (B{0xEF, 0xCD, 0xAB}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED32, value: 4294967295}"), (B{0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED40, value: 0x0102030405}"), (B{5, 4, 3, 2, 1}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED48, value: 0x010203040506}"), (B{6, 5, 4, 3, 2, 1}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED56, value: 0x01020304050607}"), (B{7, 6, 5, 4, 3, 2, 1}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNSIGNED64, value: 18446744073709551615}"), B(8, 0xFF));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: REAL32, value: 1.5}"), (B{0x00, 0x00, 0xC0, 0x3F}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: REAL64, value: -2.0}"), (B{0, 0, 0, 0, 0, 0, 0, 0xC0}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: VISIBLE_STRING, value: \"Axis 1\"}"), (B{'A', 'x', 'i', 's', ' ', '1'}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: OCTET_STRING, value: \"01 a2 FF\"}"), (B{0x01, 0xA2, 0xFF}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: UNICODE_STRING, value: \"A\u00e9\"}"), (B{'A', 0, 0xE9, 0}));
  EXPECT_EQ(bytes_of("{index: 0x4000, type: DOMAIN, value: \"deadbeef\"}"), (B{0xDE, 0xAD, 0xBE, 0xEF}));
  // The object table's type when `type:` is left out (0x1008 is read-only;
  // 0x6065 UNSIGNED32 keeps the integer form, with bytes left empty).
  const Config c = load_string(with_writes("        - {index: 0x6065, value: 7}\n"));
  EXPECT_TRUE(c.axes.at(0).drive.sdo_writes.at(0).bytes.empty());
  EXPECT_EQ(c.axes.at(0).drive.sdo_writes.at(0).size, 4);
}

TEST(ConfigSdoWriteTypes, DomainFromAFile) {
  const auto dir = std::filesystem::temp_directory_path() / ("canmotion_sdo_types_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  B data(300);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 7);
  {
    std::ofstream(dir / "blob.bin", std::ios::binary).write(reinterpret_cast<const char*>(data.data()), 300);
    std::ofstream(dir / "empty.bin", std::ios::binary);
  }
  // Relative to the YAML file's folder.
  const Config c = load_string(with_writes("        - {index: 0x4100, type: DOMAIN, file: blob.bin}\n"),
                               (dir / "drive.yaml").string());
  EXPECT_EQ(c.axes.at(0).drive.sdo_writes.at(0).bytes, data);
  EXPECT_EQ(c.axes.at(0).drive.sdo_writes.at(0).type, "DOMAIN");
  std::string e = errors_of(with_writes("        - {index: 0x4100, file: missing.bin}\n"), (dir / "drive.yaml").string());
  EXPECT_NE(e.find("axes[0].drive.sdo_writes[0].file: cannot read '" + (dir / "missing.bin").string() + "'"),
            std::string::npos) << e;
  e = errors_of(with_writes("        - {index: 0x4100, file: empty.bin}\n"), (dir / "drive.yaml").string());
  EXPECT_NE(e.find("axes[0].drive.sdo_writes[0].file: '" + (dir / "empty.bin").string() + "' is empty"),
            std::string::npos) << e;
  e = errors_of(with_writes("        - {index: 0x4100, type: UNSIGNED32, file: blob.bin}\n"), (dir / "drive.yaml").string());
  EXPECT_NE(e.find("sdo_writes[0].file: a file is for DOMAIN or OCTET_STRING, not UNSIGNED32"), std::string::npos) << e;
  std::filesystem::remove_all(dir);
}

TEST(ConfigSdoWriteTypes, ErrorsNameTheKeyAndTheType) {
  auto err = [](const std::string& entry) { return errors_of(with_writes("        - " + entry + "\n")); };
  std::string e = err("{index: 0x4000, type: INTEGER8, value: 128}");
  EXPECT_NE(e.find("test.yaml:12:"), std::string::npos) << e;
  EXPECT_NE(e.find("sdo_writes[0].value: 128 is out of range (-128 .. 127) for INTEGER8"), std::string::npos) << e;
  e = err("{index: 0x4000, type: UNSIGNED24, value: 16777216}");
  EXPECT_NE(e.find("sdo_writes[0].value: 16777216 is out of range (0 .. 16777215) for UNSIGNED24"), std::string::npos) << e;
  e = err("{index: 0x4000, type: UNSIGNED64, value: -1}");
  EXPECT_NE(e.find("sdo_writes[0].value: -1 is out of range (0 .. 18446744073709551615) for UNSIGNED64"), std::string::npos) << e;
  e = err("{index: 0x4000, type: INTEGER64, value: 9223372036854775808}");
  EXPECT_NE(e.find("sdo_writes[0].value: '9223372036854775808' is not an integer for INTEGER64"), std::string::npos) << e;
  e = err("{index: 0x4000, type: REAL32, value: 1e39}");
  EXPECT_NE(e.find("sdo_writes[0].value: 1e39 is out of range"), std::string::npos) << e;
  EXPECT_NE(e.find("for REAL32"), std::string::npos) << e;
  e = err("{index: 0x4000, type: BOOLEAN, value: 2}");
  EXPECT_NE(e.find("sdo_writes[0].value: '2' is not true or false for BOOLEAN"), std::string::npos) << e;
  e = err("{index: 0x4000, type: OCTET_STRING, value: \"0g\"}");
  EXPECT_NE(e.find("sdo_writes[0].value: '0g' is not hex bytes"), std::string::npos) << e;
  e = err("{index: 0x4000, type: VISIBLE_STRING, value: \"tab\\there\"}");
  EXPECT_NE(e.find("sdo_writes[0].value: only printable ASCII (0x20..0x7E) is allowed for VISIBLE_STRING"), std::string::npos) << e;
  e = err("{index: 0x4000, type: FLOAT, value: 1}");
  EXPECT_NE(e.find("sdo_writes[0].type: unknown type 'FLOAT'"), std::string::npos) << e;
  e = err("{index: 0x6065, type: INTEGER16, value: 1}");
  EXPECT_NE(e.find("sdo_writes[0].type: 0x6065:00 (Following error window) is UNSIGNED32, got INTEGER16"), std::string::npos) << e;
  e = err("{index: 0x4000, type: INTEGER8, size: 1, value: 1}");
  EXPECT_NE(e.find("sdo_writes[0].size: is for the integer form"), std::string::npos) << e;
}

}  // namespace
}  // namespace canmotion::config
