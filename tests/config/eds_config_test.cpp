// `drive.eds:` (issue 17): the configuration checked against the drive's EDS
// before any bus work; optional boot writes left out for objects the EDS
// lacks; the refusal names the axis, the object, the EDS file:line and the
// YAML key to change.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "config/eds_check.hpp"
#include "config/runtime.hpp"
#include "config_errors.hpp"
#include "fieldbus/eds/eds.hpp"

namespace canmotion::config {
namespace {

const std::string kExamples = CANMOTION_EXAMPLES_DIR;

/// A configuration with one CIP axis using `eds` (a path as written) and the
/// extra drive keys `drive`; the file name puts it in the examples folder,
/// so that a relative `eds:` resolves there.
std::string yaml(const std::string& drive_keys, const std::string& defaults = "") {
  return "controller: {period_ms: 1}\n"
         "buses:\n"
         "  - {name: can0, interface: sim}\n" +
         (defaults.empty() ? std::string() : "drives:\n" + defaults) +
         "axes:\n"
         "  - name: X\n"
         "    type: AXIS_CIP_DRIVE\n"
         "    bus: can0\n"
         "    node: 2\n"
         "    drive:\n" +
         drive_keys;
}
const std::string kFile = kExamples + "/eds-test.yaml";

/// The line of `[section]` in an example EDS file.
int line_of(const std::string& file, const std::string& section) {
  std::ifstream in(kExamples + "/" + file);
  std::string l;
  for (int n = 1; std::getline(in, l); ++n)
    if (l == "[" + section + "]") return n;
  return 0;
}

TEST(EdsConfig, RelativePathResolvesAgainstTheYamlFolderAndFillsTheDictionary) {
  Config c;
  ASSERT_NO_THROW(c = load_string(yaml("      eds: minimal-drive.eds\n"), kFile));
  const DriveSettings& d = c.axes[0].drive;
  EXPECT_EQ(d.eds_path, kExamples + "/minimal-drive.eds");
  EXPECT_EQ(d.eds_key, "axes[0].drive.eds");
  ASSERT_TRUE(d.eds_data && d.dictionary);
  EXPECT_EQ(d.dictionary->has(0x1016, 1), canopen::Presence::kAbsent);
  EXPECT_EQ(d.dictionary->has(0x607A, 0), canopen::Presence::kPresent);
  // The default master_heartbeat_timeout_ms: 0x1016 is optional, left out (a warning says so).
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].message.find("minimal-drive.eds has no 0x1016:01"), std::string::npos) << c.warnings[0].str();
  const Runtime rt = build_runtime(c, true);
  EXPECT_EQ(rt.controller->axis_spec(0).drive.consumer_heartbeat_ms, 0);
}

TEST(EdsConfig, DrivesDefaultAppliesToEveryAxis) {
  Config c;
  ASSERT_NO_THROW(c = load_string(yaml("      heartbeat_ms: 50\n", "  eds: cia402-emu.eds\n"), kFile));
  EXPECT_EQ(c.axes[0].drive.eds_key, "drives.eds");
  ASSERT_TRUE(c.axes[0].drive.dictionary);
  EXPECT_EQ(c.axes[0].drive.dictionary->has(0x1016, 1), canopen::Presence::kPresent);
  EXPECT_TRUE(c.warnings.empty());
}

TEST(EdsConfig, RequiredHeartbeatConsumerMissingIsRefusedWithFileLineAndKey) {
  const std::string e =
      test::errors_of(yaml("      eds: minimal-drive.eds\n      master_heartbeat_timeout_ms: 300\n"), kFile);
  // The axis, the object, the EDS file and line (the list that lacks it), the YAML key.
  const std::string want_where =
      fmt::format("{}/minimal-drive.eds:{}:", kExamples, line_of("minimal-drive.eds", "OptionalObjects"));
  EXPECT_NE(e.find("axis 'X' (node 2)"), std::string::npos) << e;
  EXPECT_NE(e.find(want_where + " 0x1016:01"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].drive.master_heartbeat_timeout_ms (or drives.master_heartbeat_timeout_ms)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("eds-test.yaml:"), std::string::npos) << e;
}

TEST(EdsConfig, CsvCstProfileNeedsObjectsAndPdosTheMinimalDriveLacks) {
  const std::vector<Diagnostic> d = test::diagnostics_of(yaml("      eds: minimal-drive.eds\n      pdo: csp_csv_cst\n"), kFile);
  const std::string e = ConfigError(d).what();
  // 0x60FF and 0x6071 are mapped into RPDO2 in csp_csv_cst; 0x6502 lacks CSV and CST.
  EXPECT_NE(e.find("0x60FF"), std::string::npos) << e;
  EXPECT_NE(e.find("0x6071"), std::string::npos) << e;
  EXPECT_NE(e.find("0x6502"), std::string::npos) << e;
  for (const Diagnostic& x : d) EXPECT_EQ(x.key, "axes[0].drive.pdo (or drives.pdo)") << x.str();
}

TEST(EdsConfig, ExtraWriteToAnAbsentObjectIsRefused) {
  const std::string e = test::errors_of(
      yaml("      eds: minimal-drive.eds\n      sdo_writes:\n        - {index: 0x2100, sub: 0, size: 4, value: 1}\n"),
      kFile);
  EXPECT_NE(e.find("0x2100:00 is not in the EDS"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].drive.sdo_writes[0] (line 12)"), std::string::npos) << e;
}

TEST(EdsConfig, UnreadableOrMalformedEdsIsAnErrorAtTheKey) {
  std::vector<Diagnostic> d = test::diagnostics_of(yaml("      eds: no-such-file.eds\n"), kFile);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].key, "axes[0].drive.eds");
  EXPECT_EQ(d[0].where.line, 10);
  EXPECT_NE(d[0].message.find("no-such-file.eds"), std::string::npos) << d[0].str();
}

TEST(EdsConfig, BootWritesLeaveOutOptionalObjectsTheEdsLacks) {
  Config c;
  ASSERT_NO_THROW(c = load_string(yaml("      eds: minimal-drive.eds\n"), kFile));
  const std::vector<cia402::BootWrite> w = boot_writes(c.axes[0], c.buses[0], c.controller.period_s, 0);
  ASSERT_FALSE(w.empty());
  for (const cia402::BootWrite& b : w)
    EXPECT_EQ(c.axes[0].drive.dictionary->has(b.w.index, b.w.sub), canopen::Presence::kPresent)
        << std::hex << b.w.index << ":" << int(b.w.sub);
  // Without an EDS the same axis writes the unused PDOs 3 and 4, 0x1016,
  // 0x1006 = 0 and 0x1019, all optional.
  Config n;
  ASSERT_NO_THROW(n = load_string(yaml("      heartbeat_ms: 50\n"), kFile));
  const std::vector<cia402::BootWrite> all = boot_writes(n.axes[0], n.buses[0], n.controller.period_s, 0);
  const auto optional = std::count_if(all.begin(), all.end(), [](const cia402::BootWrite& b) { return b.optional && !b.is_read(); });
  // RPDO 2..4 and TPDO 2..4 (csp uses one each way), 0x1016:1, 0x1006 and
  // 0x1019; the minimal drive has RPDO2 and TPDO2, so 3, 4, 0x1016, 0x1006,
  // 0x1019 and the read of 0x1019 made only if the drive refuses it are left out.
  EXPECT_EQ(optional, 9);
  EXPECT_EQ(all.size(), w.size() + 8);
  // The boot's optional reads (0x6502, 0x6061) stay: the minimal drive has
  // both; so does the read of 0x60C2:2 made only if the drive refuses it.
  const auto optional_reads = std::count_if(w.begin(), w.end(), [](const cia402::BootWrite& b) { return b.optional && b.is_read() && !b.ip_fallback; });
  EXPECT_EQ(optional_reads, 2);
  const auto fallback_reads = std::count_if(w.begin(), w.end(), [](const cia402::BootWrite& b) { return b.ip_fallback && b.is_read(); });
  EXPECT_EQ(fallback_reads, 1);
}

}  // namespace
}  // namespace canmotion::config
