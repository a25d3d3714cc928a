// The checker (fieldbus/eds/check.hpp): what the master intends to use
// against an EDS, each refusal with its kind, the EDS file and line, and
// the configuration key.
#include <gtest/gtest.h>

#include "fieldbus/cia402/cia402.hpp"
#include "fieldbus/eds/check.hpp"
#include "tests/eds/eds_test_util.hpp"

using namespace canmotion;
using eds::RefusalKind;
using eds::Usage;
using eds::test::eds_text;
using eds::test::line_of;

namespace {

// A small drive: 1 RPDO and 1 TPDO objects (NrOfRXPDO/NrOfTXPDO say 2),
// a few CiA 402 objects with each access type, limits and 0x6502.
const std::string kBody =
    "[1400]\nParameterName=RPDO1 communication parameter\nObjectType=0x9\nSubNumber=2\n\n"
    "[1400sub0]\nParameterName=Highest sub-index supported\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\n"
    "[1400sub1]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nDefaultValue=$NODEID+0x200\n\n"
    "[1600]\nParameterName=RPDO1 mapping parameter\nObjectType=0x9\nSubNumber=2\n\n"
    "[1600sub0]\nParameterName=Number of mapped objects\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n\n"
    "[1600sub1]\nParameterName=Mapped object 1\nDataType=0x0007\nAccessType=rw\nDefaultValue=0\n\n"
    "[1800]\nParameterName=TPDO1 communication parameter\nObjectType=0x9\nSubNumber=2\n\n"
    "[1800sub0]\nParameterName=Highest sub-index supported\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\n"
    "[1800sub1]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nDefaultValue=$NODEID+0x180\n\n"
    "[1A00]\nParameterName=TPDO1 mapping parameter\nObjectType=0x9\nSubNumber=2\n\n"
    "[1A00sub0]\nParameterName=Number of mapped objects\nDataType=0x0005\nAccessType=rw\nDefaultValue=0\n\n"
    "[1A00sub1]\nParameterName=Mapped object 1\nDataType=0x0007\nAccessType=rw\nDefaultValue=0\n\n"
    "[6040]\nParameterName=Controlword\nDataType=0x0006\nAccessType=rww\nPDOMapping=1\nDefaultValue=0\n\n"
    "[6041]\nParameterName=Statusword\nDataType=0x0006\nAccessType=ro\nPDOMapping=1\n\n"
    "[6060]\nParameterName=Modes of operation\nDataType=0x0002\nAccessType=rw\nPDOMapping=0\nLowLimit=-1\nHighLimit=10\n\n"
    "[6064]\nParameterName=Position actual value\nDataType=0x0004\nAccessType=ro\nPDOMapping=1\n\n"
    "[6065]\nParameterName=Following error window\nDataType=0x0007\nAccessType=wo\nHighLimit=$NODEID+100\n\n"
    "[607A]\nParameterName=Target position\nDataType=0x0004\nAccessType=rww\nPDOMapping=1\n\n"
    "[6502]\nParameterName=Supported drive modes\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x00000080\n\n"
    "[6503]\nParameterName=No default\nDataType=0x0007\nAccessType=const\n\n";
const std::vector<std::uint16_t> kOptional = {0x1400, 0x1600, 0x1800, 0x1A00, 0x6040, 0x6041,
                                              0x6060, 0x6064, 0x6065, 0x607A, 0x6502, 0x6503};

eds::Use use(std::uint16_t index, std::uint8_t sub, Usage u, std::uint8_t size, std::string key) {
  eds::Use x;
  x.index = index;
  x.sub = sub;
  x.usage = u;
  x.size = size;
  x.key = std::move(key);
  return x;
}

}  // namespace

TEST(EdsCheck, WhatTheDriveHasIsAccepted) {
  const eds::Eds e = eds::parse(eds_text(kBody, {}, kOptional), "drive.eds");
  eds::Requirements req;
  req.rpdos = 1;
  req.tpdos = 1;
  req.uses = {use(0x1400, 1, Usage::kWrite, 4, "pdo"),       use(0x1600, 0, Usage::kWrite, 1, "pdo"),
              use(0x1600, 1, Usage::kWrite, 4, "pdo"),       use(0x6040, 0, Usage::kMapRpdo, 2, "pdo"),
              use(0x607A, 0, Usage::kMapRpdo, 4, "pdo"),     use(0x6041, 0, Usage::kMapTpdo, 2, "pdo"),
              use(0x6064, 0, Usage::kMapTpdo, 0, "pdo"),     use(0x6502, 0, Usage::kRead, 4, "modes"),
              use(0x6060, 0, Usage::kWrite, 1, "mode")};
  req.uses.back().value = 8;
  req.uses[7].required_bits = cia402::supported_mode_bit(cia402::Mode::kCsp);
  const eds::CheckResult r = eds::check(e, req);
  EXPECT_TRUE(r.ok()) << r.refusals.front().to_string();
  EXPECT_TRUE(r.skipped.empty());
}

TEST(EdsCheck, MissingObjectsAndSubIndices) {
  const std::string text = eds_text(kBody, {}, kOptional);
  const eds::Eds e = eds::parse(text, "drive.eds");
  eds::Requirements req;
  req.uses = {use(0x1016, 1, Usage::kWrite, 4, "drives.master_heartbeat_timeout_ms"),
              use(0x1400, 2, Usage::kWrite, 1, "drives.pdo"), use(0x2010, 1, Usage::kWrite, 4, "axes[0].direct_control")};
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.refusals.size(), 3u);
  EXPECT_EQ(r.refusals[0].kind, RefusalKind::kMissingObject);
  EXPECT_EQ(r.refusals[0].index, 0x1016);
  EXPECT_EQ(r.refusals[0].sub, 1);
  EXPECT_EQ(r.refusals[0].to_string(),
            fmt::format("drive.eds:{}: 0x1016:01 (Consumer heartbeat time) is not in the EDS ([OptionalObjects] does "
                        "not list 0x1016); the master would write it (set by drives.master_heartbeat_timeout_ms)",
                        line_of(text, "[OptionalObjects]")));
  EXPECT_EQ(r.refusals[1].kind, RefusalKind::kMissingSubIndex);
  EXPECT_EQ(r.refusals[1].to_string(),
            fmt::format("drive.eds:{}: 0x1400 (RPDO1 communication parameter) has no sub-index 2 (it has sub-indices "
                        "0 .. 1); the master would write it (set by drives.pdo)",
                        line_of(text, "[1400]")));
  // No [ManufacturerObjects] list at all: the whole file is meant.
  EXPECT_EQ(r.refusals[2].line, 0);
  EXPECT_EQ(r.refusals[2].to_string(),
            "drive.eds: 0x2010:01 (Ramp velocity - positive) is not in the EDS (no section [2010]); the master would "
            "write it (set by axes[0].direct_control)");
}

TEST(EdsCheck, OptionalUsesAreSkippedWhenAbsentButStillChecked) {
  const eds::Eds e = eds::parse(eds_text(kBody, {}, kOptional), "drive.eds");
  eds::Requirements req;
  req.uses = {use(0x1016, 1, Usage::kWrite, 4, "hb"), use(0x1400, 5, Usage::kWrite, 2, "inhibit"),
              use(0x6041, 0, Usage::kWrite, 2, "sw")};
  for (auto& u : req.uses) u.optional = true;
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.skipped.size(), 2u);
  EXPECT_EQ(r.skipped[0].index, 0x1016);
  EXPECT_EQ(r.skipped[1].index, 0x1400);
  EXPECT_EQ(r.skipped[1].sub, 5);
  ASSERT_EQ(r.refusals.size(), 1u);  // present but read-only: refused even though optional
  EXPECT_EQ(r.refusals[0].kind, RefusalKind::kNotWritable);
}

TEST(EdsCheck, AccessDirectionMappingAndSize) {
  const std::string text = eds_text(kBody, {}, kOptional);
  const eds::Eds e = eds::parse(text, "drive.eds");
  eds::Requirements req;
  req.uses = {use(0x6041, 0, Usage::kWrite, 2, "a"),    use(0x6503, 0, Usage::kWrite, 4, "b"),
              use(0x6065, 0, Usage::kRead, 4, "c"),     use(0x6060, 0, Usage::kMapRpdo, 1, "d"),
              use(0x6041, 0, Usage::kMapRpdo, 2, "e"),  use(0x6040, 0, Usage::kMapTpdo, 2, "f"),
              use(0x607A, 0, Usage::kMapRpdo, 2, "g"),  use(0x6040, 0, Usage::kWrite, 4, "h")};
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.refusals.size(), 8u);
  const std::vector<RefusalKind> kinds = {RefusalKind::kNotWritable, RefusalKind::kNotWritable, RefusalKind::kNotReadable,
                                          RefusalKind::kNotMappable, RefusalKind::kNotMappable, RefusalKind::kNotMappable,
                                          RefusalKind::kWrongSize,   RefusalKind::kWrongSize};
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    EXPECT_EQ(r.refusals[i].kind, kinds[i]) << i << ": " << r.refusals[i].to_string();
    EXPECT_EQ(r.refusals[i].key, req.uses[i].key);
    EXPECT_EQ(r.refusals[i].line, line_of(text, fmt::format("[{:04X}]", req.uses[i].index)));
  }
  EXPECT_EQ(r.refusals[0].message, "0x6041:00 (Statusword) is AccessType=ro, the master writes it");
  EXPECT_EQ(r.refusals[1].message, "0x6503:00 (No default) is AccessType=const, the master writes it");
  EXPECT_EQ(r.refusals[2].message, "0x6065:00 (Following error window) is AccessType=wo, the master reads it");
  EXPECT_EQ(r.refusals[3].message, "0x6060:00 (Modes of operation) has PDOMapping=0, the master would map it into an RPDO");
  EXPECT_EQ(r.refusals[4].message,
            "0x6041:00 (Statusword) is AccessType=ro: it can be mapped into TPDOs only, the master would map it into an RPDO");
  EXPECT_EQ(r.refusals[5].message,
            "0x6040:00 (Controlword) is AccessType=rww: it can be mapped into RPDOs only, the master would map it into a TPDO");
  EXPECT_EQ(r.refusals[6].message, "0x607A:00 (Target position) is INTEGER32 (4 bytes), the master's RPDO mapping is 2 bytes");
  EXPECT_EQ(r.refusals[7].message, "0x6040:00 (Controlword) is UNSIGNED16 (2 bytes), the master's write is 4 bytes");
  EXPECT_EQ(eds::refusal_kind_name(RefusalKind::kWrongSize), "wrong size");
}

TEST(EdsCheck, GranularityZeroMeansAFixedMapping) {
  std::string text = eds_text(kBody, {}, kOptional);
  text.replace(text.find("Granularity=8"), 13, "Granularity=0");
  const eds::Eds e = eds::parse(text, "fixed.eds");
  eds::Requirements req;
  req.uses = {use(0x607A, 0, Usage::kMapRpdo, 4, "drives.pdo")};
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.refusals.size(), 1u);
  EXPECT_EQ(r.refusals[0].kind, RefusalKind::kNotMappable);
  EXPECT_EQ(r.refusals[0].to_string(),
            fmt::format("fixed.eds:{}: Granularity=0: the device's PDO mapping cannot be changed, the master would map "
                        "0x607A:00 (Target position) (set by drives.pdo)",
                        line_of(text, "Granularity=0")));
}

TEST(EdsCheck, ValuesAgainstTypeAndLimits) {
  const std::string text = eds_text(kBody, {}, kOptional) + "[DeviceComissioning]\nNodeId=5\n";
  const eds::Eds e = eds::parse(text, "drive.dcf");
  eds::Requirements req;
  const auto write = [&](std::uint16_t index, std::int64_t v) {
    auto u = use(index, 0, Usage::kWrite, 0, "v");
    u.value = v;
    req.uses.push_back(u);
  };
  write(0x6060, 10);    // = HighLimit: fine
  write(0x6060, 11);    // above HighLimit=10
  write(0x6060, -2);    // below LowLimit=-1
  write(0x6060, 200);   // not an INTEGER8
  write(0x6065, 105);   // HighLimit=$NODEID+100 = 105 with the DCF's NodeId=5: fine
  write(0x6065, 106);   // above
  write(0x6065, -1);    // not an UNSIGNED32
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.refusals.size(), 5u);
  for (const auto& x : r.refusals) EXPECT_EQ(x.kind, RefusalKind::kOutOfRange) << x.to_string();
  EXPECT_EQ(r.refusals[0].message, "0x6060:00 (Modes of operation): the master writes 11, above HighLimit=10");
  EXPECT_EQ(r.refusals[1].message, "0x6060:00 (Modes of operation): the master writes -2, below LowLimit=-1");
  EXPECT_EQ(r.refusals[2].message, "0x6060:00 (Modes of operation) is INTEGER8, the master writes 200, which does not fit");
  EXPECT_EQ(r.refusals[3].message,
            "0x6065:00 (Following error window): the master writes 106, above HighLimit=$NODEID+100");
  EXPECT_EQ(r.refusals[4].message,
            "0x6065:00 (Following error window) is UNSIGNED32, the master writes -1, which does not fit");
  // Requirements::node_id wins over the DCF's.
  req.node_id = 6;
  const eds::CheckResult r6 = eds::check(e, req);
  EXPECT_EQ(r6.refusals.size(), 4u);  // 106 is now within $NODEID+100
}

TEST(EdsCheck, RequiredBitsOfSupportedDriveModes) {
  const std::string text = eds_text(kBody, {}, kOptional);
  const eds::Eds e = eds::parse(text, "drive.eds");
  eds::Requirements req;
  auto modes = use(0x6502, 0, Usage::kRead, 4, "axes[1].direct_control.mode");
  modes.required_bits = cia402::supported_mode_bit(cia402::Mode::kCsp) | cia402::supported_mode_bit(cia402::Mode::kCsv) |
                        cia402::supported_mode_bit(cia402::Mode::kCst);
  auto none = use(0x6503, 0, Usage::kRead, 4, "x");
  none.required_bits = 1;
  req.uses = {modes, none};
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.refusals.size(), 1u);
  EXPECT_EQ(r.refusals[0].kind, RefusalKind::kMissingBits);
  EXPECT_EQ(r.refusals[0].to_string(),
            fmt::format("drive.eds:{}: 0x6502:00 (Supported drive modes) is 0x00000080 (DefaultValue), it lacks bits "
                        "0x300, which the master needs (set by axes[1].direct_control.mode)",
                        line_of(text, "[6502]")));
  // No value in the file: left to the boot, which reads the object from the
  // drive (issue 29: a DCF's 0x6502 without DefaultValue is not refused).
  ASSERT_EQ(r.deferred.size(), 1u);
  EXPECT_EQ(r.deferred[0].index, 0x6503);
}

TEST(EdsCheck, NotEnoughPdos) {
  const std::string text = eds_text(kBody, {}, kOptional);
  const eds::Eds e = eds::parse(text, "drive.eds");
  eds::Requirements req;
  req.pdo_key = "drives.pdo";
  req.rpdos = 3;  // NrOfRXPDO=2
  req.tpdos = 2;  // NrOfTXPDO=2, but only 0x1800/0x1A00 are in the file
  const eds::CheckResult r = eds::check(e, req);
  ASSERT_EQ(r.refusals.size(), 3u);
  EXPECT_EQ(r.refusals[0].kind, RefusalKind::kTooFewRpdos);
  EXPECT_EQ(r.refusals[0].to_string(),
            fmt::format("drive.eds:{}: the master uses 3 RPDOs, the EDS has NrOfRXPDO=2 (set by drives.pdo)",
                        line_of(text, "NrOfRXPDO")));
  EXPECT_EQ(r.refusals[1].kind, RefusalKind::kTooFewTpdos);
  EXPECT_EQ(r.refusals[1].index, 0x1801);
  EXPECT_EQ(r.refusals[1].message, "TPDO 2 needs 0x1801 (TPDO communication parameter), which is not in the EDS");
  EXPECT_EQ(r.refusals[1].line, line_of(text, "[OptionalObjects]"));
  EXPECT_EQ(r.refusals[2].index, 0x1A01);
  EXPECT_EQ(r.refusals[2].message, "TPDO 2 needs 0x1A01 (TPDO mapping parameter), which is not in the EDS");
}
