// Vendor files read the way python-canopen reads them (issue 29 part 1): one
// test file per class of defect found in public vendor EDS/DCF files
// (tests/eds/corpus/defect-*.eds, *.dcf: canmotion's own, no vendor file).
// A defect that does not change what the master needs is a warning naming
// file:line, and the master's use of the file is accepted; a defect in an
// object the master uses refuses that use, naming file:line and the object.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "fieldbus/eds/check.hpp"
#include "fieldbus/eds/eds.hpp"
#include "eds_test_util.hpp"

using namespace canmotion;
using namespace canmotion::eds;
using canmotion::eds::test::line_of;

namespace {

const std::string kCorpus = CANMOTION_EDS_CORPUS_DIR;

struct File {
  std::string name;  // as the diagnostics name it (the path given to load())
  std::string text;
  Eds eds;
};

File load_corpus(const std::string& name) {
  const std::string path = kCorpus + "/" + name;
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return File{path, ss.str(), load(path)};  // a ParseError fails the test
}

/// The line of `what` at the start of a line of `f` (the comments above
/// the sections quote the keys too); `nth` > 1 for later ones.
int at(const File& f, const std::string& what, int nth = 1) { return line_of(f.text, "\n" + what, nth) + 1; }

/// The one warning at `line` whose message holds `what`; its to_string()
/// starts with "file:line: ".
std::string warning_at(const File& f, int line, std::string_view what) {
  int found = 0;
  std::string got;
  for (const Diagnostic& w : f.eds.warnings)
    if (w.line == line && w.message.find(what) != std::string::npos) {
      ++found;
      got = w.to_string();
    }
  std::string all;
  for (const Diagnostic& w : f.eds.warnings) all += w.to_string() + "\n";
  EXPECT_EQ(found, 1) << "no single warning at line " << line << " with '" << what << "'; warnings:\n" << all;
  const std::string prefix = line > 0 ? fmt::format("{}:{}: ", f.name, line) : f.name + ": ";
  EXPECT_EQ(got.rfind(prefix, 0), 0u) << got;
  return got;
}

Use use(std::uint16_t index, std::uint8_t sub, Usage u, std::uint8_t size, std::string key,
        std::optional<std::int64_t> value = std::nullopt) {
  Use x;
  x.index = index;
  x.sub = sub;
  x.usage = u;
  x.size = size;
  x.key = std::move(key);
  x.value = value;
  return x;
}

/// What a CSP master does with the objects every corpus file has: 0x1000
/// read, 0x6040 and 0x607A mapped into RPDO1 (the PDO objects themselves
/// are not in these small files: no PDO counts asked).
Requirements csp_uses() {
  Requirements r;
  r.uses = {use(0x1000, 0, Usage::kRead, 4, "drive.identity"), use(0x6040, 0, Usage::kMapRpdo, 2, "drives.pdo"),
            use(0x607A, 0, Usage::kMapRpdo, 4, "drives.pdo")};
  return r;
}

std::string refusals(const CheckResult& r) {
  std::string s;
  for (const Refusal& x : r.refusals) s += x.to_string() + "\n";
  return s;
}

}  // namespace

// maxon's commissioning tool writes Baudrate=0 and NodeId=0 for "not set".
TEST(EdsDefects, CommissioningValuesAreWarnings) {
  const File f = load_corpus("defect-commissioning.dcf");
  EXPECT_EQ(warning_at(f, at(f, "Baudrate=0"), "Baudrate=0 is not a CiA 301 bit rate"),
            fmt::format("{}:{}: [DeviceComissioning] Baudrate=0 is not a CiA 301 bit rate in kbit/s (10, 20, 50, 125, "
                        "250, 500, 800, 1000; ignored: the bus's configuration gives the bit rate)",
                        f.name, at(f, "Baudrate=0")));
  warning_at(f, at(f, "NodeId=0"), "NodeId=0 is not a node-ID");
  ASSERT_TRUE(f.eds.comissioning.has_value());
  EXPECT_EQ(f.eds.comissioning->node_id, 0);
  EXPECT_EQ(f.eds.comissioning->baudrate, 0);
  EXPECT_TRUE(f.eds.is_dcf());
  const CheckResult r = check(f.eds, csp_uses());
  EXPECT_TRUE(r.ok()) << refusals(r);
}

// HighLimit=65536 on an UNSIGNED16, LowLimit=-1 on an UNSIGNED32: the limit
// is left out, the type's range applies.
TEST(EdsDefects, LimitsOutsideTheTypeAreWarningsAndLeftOut) {
  const File f = load_corpus("defect-limit-range.eds");
  warning_at(f, at(f, "HighLimit=65536"), "65536 does not fit UNSIGNED16 (0 .. 65535) (the limit is ignored)");
  warning_at(f, at(f, "LowLimit=-1"), "-1 is negative, UNSIGNED32 is unsigned");
  const SubObject* torque = f.eds.find(0x6072, 0);
  ASSERT_NE(torque, nullptr);
  EXPECT_FALSE(torque->high_limit.has_value());
  ASSERT_TRUE(torque->low_limit.has_value());
  Requirements req = csp_uses();
  req.uses.push_back(use(0x6072, 0, Usage::kWrite, 2, "axes[0].max_torque", 65535));
  req.uses.push_back(use(0x6080, 0, Usage::kWrite, 4, "axes[0].max_motor_speed", 5000));
  EXPECT_TRUE(check(f.eds, req).ok()) << refusals(check(f.eds, req));
  // The type itself still bounds what the master writes.
  req.uses.push_back(use(0x6072, 0, Usage::kWrite, 2, "axes[0].max_torque", 70000));
  const CheckResult r = check(f.eds, req);
  ASSERT_EQ(r.refusals.size(), 1u) << refusals(r);
  EXPECT_EQ(r.refusals[0].kind, RefusalKind::kOutOfRange);
}

// 0xFF80 for an INTEGER16 and 0xFFFFFF80 (32 bits) for an INTEGER8: read as
// two's complement (-128), as python-canopen's _signed_int_from_hex does.
TEST(EdsDefects, SignedLimitsInTwosComplementHexAreWarnings) {
  const File f = load_corpus("defect-signed-hex.eds");
  EXPECT_EQ(warning_at(f, at(f, "LowLimit=0xFF80"), "two's-complement hex"),
            fmt::format("{}:{}: [6071] LowLimit=0xFF80: a signed limit in two's-complement hex, read as -128 (INTEGER16)",
                        f.name, at(f, "LowLimit=0xFF80")));
  warning_at(f, at(f, "LowLimit=0xFFFFFF80"), "two's complement of more bits than INTEGER8, read as -128");
  const SubObject* ip = f.eds.find(0x60C2, 2);
  ASSERT_NE(ip, nullptr);
  ASSERT_TRUE(ip->low_limit.has_value());
  EXPECT_EQ(format_number(ip->type, ip->low_limit->bits), "-128");
  Requirements req = csp_uses();
  req.uses.push_back(use(0x6071, 0, Usage::kMapRpdo, 2, "drives.pdo"));
  req.uses.push_back(use(0x60C2, 2, Usage::kWrite, 1, "controller.period_ms", -3));
  EXPECT_TRUE(check(f.eds, req).ok()) << refusals(check(f.eds, req));
  // The limits are read as signed: -129 is below 0xFF80.
  req.uses.push_back(use(0x6071, 0, Usage::kWrite, 2, "x", -129));
  const CheckResult r = check(f.eds, req);
  ASSERT_EQ(r.refusals.size(), 1u) << refusals(r);
  EXPECT_NE(r.refusals[0].message.find("below LowLimit=0xFF80"), std::string::npos) << refusals(r);
}

// python-canopen reads the sub-index sections there are.
TEST(EdsDefects, SubNumberMismatchesAreWarnings) {
  const File f = load_corpus("defect-subnumber.eds");
  warning_at(f, at(f, "SubNumber=5"), "SubNumber=5 but there are 2 sub-index sections");
  warning_at(f, at(f, "[60C2]\n"), "has neither SubNumber nor CompactSubObj (its 3 sub-index sections are read)");
  ASSERT_NE(f.eds.find(0x60C2, 2), nullptr);
  Requirements req = csp_uses();
  req.uses.push_back(use(0x1018, 1, Usage::kRead, 4, "drive.identity"));
  req.uses.push_back(use(0x60C2, 1, Usage::kWrite, 1, "controller.period_ms", 1));
  req.uses.push_back(use(0x60C2, 2, Usage::kWrite, 1, "controller.period_ms", -3));
  EXPECT_TRUE(check(f.eds, req).ok()) << refusals(check(f.eds, req));
}

// The first occurrence of a key or a section is read, as configparser's
// first-seen value; later ones are warnings.
TEST(EdsDefects, DuplicateAndStrayKeysAreWarnings) {
  const File f = load_corpus("defect-duplicates.eds");
  warning_at(f, 1, "'StrayKey' is outside any [section] (ignored)");
  warning_at(f, at(f, "3=0x6040"), "0x6040 is listed again");
  warning_at(f, at(f, "DefaultValue=5"), "[607A] DefaultValue is given again (first at line");
  warning_at(f, at(f, "[6040]", 2), "section [6040] appears again");
  const SubObject* target = f.eds.find(0x607A, 0);
  ASSERT_NE(target, nullptr);
  ASSERT_TRUE(target->default_value.has_value());
  EXPECT_EQ(target->default_value->text, "0");
  EXPECT_EQ(f.eds.find(0x6040, 0)->name, "Controlword");
  const CheckResult r = check(f.eds, csp_uses());
  EXPECT_TRUE(r.ok()) << refusals(r);
}

// No [FileInfo] and no [DeviceInfo] (PDO counts from the 0x1400.. objects),
// a list without SupportedObjects, an object that no list names, a listed
// object without its section.
TEST(EdsDefects, MissingSectionsAndListDefectsAreWarnings) {
  const File f = load_corpus("defect-lists.eds");
  warning_at(f, 0, "no [DeviceInfo] section");
  warning_at(f, at(f, "[OptionalObjects]"), "has no SupportedObjects");
  warning_at(f, at(f, "5=0x6099"), "lists 0x6099 but there is no section [6099]");
  warning_at(f, at(f, "[6064]"), "[6064] is not in [MandatoryObjects], [OptionalObjects]");
  Requirements req = csp_uses();
  req.rpdos = 1;  // 0x1400 and 0x1600 are there
  req.pdo_key = "drives.pdo";
  req.uses.push_back(use(0x6064, 0, Usage::kMapTpdo, 4, "drives.pdo"));
  EXPECT_TRUE(check(f.eds, req).ok()) << refusals(check(f.eds, req));
  // A TPDO is not there: each missing object is named.
  req.tpdos = 1;
  const CheckResult r = check(f.eds, req);
  ASSERT_EQ(r.refusals.size(), 2u) << refusals(r);
  EXPECT_EQ(r.refusals[0].index, 0x1800);
  EXPECT_EQ(r.refusals[1].index, 0x1A00);
  // A listed object without a section is absent: a use of it is refused.
  req.tpdos = 0;
  req.uses.push_back(use(0x6099, 1, Usage::kWrite, 4, "axes[0].homing.speed"));
  const CheckResult r2 = check(f.eds, req);
  ASSERT_EQ(r2.refusals.size(), 1u) << refusals(r2);
  EXPECT_EQ(r2.refusals[0].kind, RefusalKind::kMissingObject);
}

// A DCF's ParameterValue is what the device holds: it wins over the
// DefaultValue for 0x6502's mode bits and 0x60C2:2's unit.
TEST(EdsDefects, ParameterValueWinsOverDefaultValue) {
  const File f = load_corpus("parameter-value.dcf");
  EXPECT_TRUE(f.eds.warnings.empty()) << f.eds.warnings.front().to_string();
  const SubObject* modes = f.eds.find(0x6502, 0);
  ASSERT_NE(modes, nullptr);
  ASSERT_NE(modes->value(), nullptr);
  EXPECT_EQ(modes->value()->text, "0x000003A1");
  EXPECT_EQ(f.eds.find(0x60C2, 2)->value()->text, "-3");
  Requirements req = csp_uses();
  Use m = use(0x6502, 0, Usage::kRead, 4, "drives.pdo");
  m.required_bits = 0x80 | 0x100 | 0x200;  // CSP, CSV, CST: in the ParameterValue, not in the DefaultValue (0x1)
  req.uses.push_back(m);
  EXPECT_TRUE(check(f.eds, req).ok()) << refusals(check(f.eds, req));
  req.uses.back().required_bits = 0x2;  // velocity mode: in neither
  const CheckResult r = check(f.eds, req);
  ASSERT_EQ(r.refusals.size(), 1u) << refusals(r);
  EXPECT_EQ(r.refusals[0].to_string(),
            fmt::format("{}:{}: 0x6502:00 (Supported drive modes) is 0x000003A1 (ParameterValue), it lacks bit 0x2, "
                        "which the master needs (set by drives.pdo)",
                        f.name, at(f, "[6502]")));
}

// No value at all: the check leaves 0x6502 to the boot, which reads it from
// the drive (tests/fieldbus/test_boot_checks.cpp: refused there, naming 0x6502).
TEST(EdsDefects, SupportedModesWithoutAValueAreLeftToTheBoot) {
  const File f = load_corpus("no-6502-value.dcf");
  EXPECT_TRUE(f.eds.warnings.empty()) << f.eds.warnings.front().to_string();
  Requirements req = csp_uses();
  Use m = use(0x6502, 0, Usage::kRead, 4, "drives.pdo");
  m.required_bits = 0x80;
  req.uses.push_back(m);
  const CheckResult r = check(f.eds, req);
  EXPECT_TRUE(r.ok()) << refusals(r);
  ASSERT_EQ(r.deferred.size(), 1u);
  EXPECT_EQ(r.deferred[0].index, 0x6502);
}

// Defects that make an object unusable: warnings while the master does not
// use the object; a refusal naming file:line and the object when it does.
TEST(EdsDefects, DefectsInObjectsTheMasterUsesAreRefused) {
  const File f = load_corpus("defect-used-objects.eds");
  warning_at(f, at(f, "DataType=0x0040\nAccessType=rw\n"), "[2000] DataType=0x0040: unknown data type");
  warning_at(f, at(f, "AccessType=rx"), "[2001] AccessType=rx: expected ro, wo, rw, rwr, rww or const");
  warning_at(f, at(f, "ObjectType=0x3"), "[2002] ObjectType=0x3 is not an object code");
  warning_at(f, at(f, "DefaultValue=0xZZ"), "[2003] DefaultValue: '0xZZ' is not a number");
  warning_at(f, at(f, "PDOMapping=2"), "[2003] PDOMapping=2 is out of range");
  // The master does not use 0x2000..0x2003: accepted as far as it goes.
  Requirements req;
  req.uses = {use(0x1000, 0, Usage::kRead, 4, "drive.identity")};
  EXPECT_TRUE(check(f.eds, req).ok()) << refusals(check(f.eds, req));
  // It uses 0x6040, 0x607A and 0x6502: each refused, naming file:line and the object.
  req = csp_uses();
  Use m = use(0x6502, 0, Usage::kRead, 4, "drives.pdo");
  m.required_bits = 0x80;
  req.uses.push_back(m);
  const CheckResult r = check(f.eds, req);
  ASSERT_EQ(r.refusals.size(), 3u) << refusals(r);
  for (const Refusal& x : r.refusals) EXPECT_EQ(x.kind, RefusalKind::kDefect) << x.to_string();
  EXPECT_EQ(r.refusals[0].to_string(),
            fmt::format("{}:{}: 0x6040:00 (Controlword) cannot be used, the master would map it into an RPDO: [6040] "
                        "AccessType=readwrite: expected ro, wo, rw, rwr, rww or const (the object cannot be used) "
                        "(set by drives.pdo)",
                        f.name, at(f, "AccessType=readwrite")));
  EXPECT_EQ(r.refusals[1].line, at(f, "DataType=0x0040"));
  EXPECT_NE(r.refusals[1].message.find("0x607A:00 (Target position) cannot be used"), std::string::npos)
      << refusals(r);
  EXPECT_EQ(r.refusals[2].line, at(f, "DefaultValue=CSP|CSV"));
  EXPECT_NE(r.refusals[2].message.find("0x6502:00 (Supported drive modes) cannot be used, the master would read it: "
                                       "[6502] DefaultValue: 'CSP|CSV' is not a number"),
            std::string::npos)
      << refusals(r);
}

// Each diagnostic once: a compact array whose type cannot be read has one
// defect per sub-index, and one warning.
TEST(EdsDefects, EachDiagnosticOnce) {
  const std::string text = test::eds_text(
      "[2100]\nParameterName=table\nObjectType=0x8\nCompactSubObj=3\nDataType=0x0099\nAccessType=rw\n", {0x2100});
  const Eds e = parse(text, "once.eds");
  int n = 0;
  for (const Diagnostic& w : e.warnings) n += w.message.find("unknown data type 0x0099") != std::string::npos;
  EXPECT_EQ(n, 1);
  ASSERT_NE(e.find(0x2100, 3), nullptr);
  EXPECT_FALSE(e.find(0x2100, 3)->defects.empty());
}
