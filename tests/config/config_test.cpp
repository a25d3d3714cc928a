// Configuration loading and validation: every message names file, line,
// column and key; nothing is returned when anything is wrong.
#include <gtest/gtest.h>

#include "tests/config/config_errors.hpp"

#include <string>
#include <vector>

#include "config/config.hpp"

namespace canmotion::config {
namespace {

const char* kGood = R"(controller:
  period_ms: 1
  priority: 80
  cpu: 1
buses:
  - name: can0
    interface: sim
    bitrate: 1000000
drives:
  heartbeat_ms: 100
  timeouts: {sdo_ms: 150, boot_ms: 4000}
axes:
  - name: Master
    type: AXIS_VIRTUAL
    units: mm
    max_speed: 500
  - name: X
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
    conversion_constant: 10000
    rotary: true
    unwind: 360
    exception_actions: {position_error: Fault Status Only, node_lost: 5, hard_overtravel_positive: Stop Planner}
    drive:
      pdo: csp_csv_cst
      timeouts: {transition_ms: 250}
      sdo_writes:
        - {index: 0x6065, sub: 0, size: 4, value: 20000}
cams:
  - name: cam1
    points: [[0, 0], [90, 45, cubic], [180, 90, cubic]]
)";

using test::errors_of;

TEST(Config, LoadsAGoodFile) {
  const Config c = load_string(kGood, "good.yaml");
  EXPECT_DOUBLE_EQ(c.controller.period_s, 0.001);
  EXPECT_EQ(c.controller.cpu, 1);
  ASSERT_EQ(c.axes.size(), 2u);
  const AxisSettings& x = c.axes[1];
  EXPECT_EQ(x.axis.type, motion::AxisType::CipDrive);
  EXPECT_EQ(x.node, 2);
  EXPECT_TRUE(x.axis.rotary);
  EXPECT_EQ(x.axis.action(motion::ExceptionKind::PositionError), motion::ExceptionAction::FaultStatusOnly);
  EXPECT_EQ(x.axis.action(motion::ExceptionKind::NodeLost), motion::ExceptionAction::Shutdown);
  EXPECT_EQ(x.axis.action(motion::ExceptionKind::HardOvertravelPos), motion::ExceptionAction::StopPlanner);
  EXPECT_EQ(x.axis.action(motion::ExceptionKind::HardOvertravelNeg), motion::ExceptionAction::StopDrive);
  EXPECT_EQ(x.drive.pdo, cia402::PdoProfile::kCspCsvCst);
  // Defaults from `drives:` with the axis's own override on top.
  EXPECT_EQ(x.drive.timeouts.sdo_ms, 150u);
  EXPECT_EQ(x.drive.timeouts.boot_ms, 4000u);
  EXPECT_EQ(x.drive.timeouts.transition_ms, 250u);
  EXPECT_EQ(x.drive.heartbeat_ms, 100);
  ASSERT_EQ(x.drive.sdo_writes.size(), 1u);
  EXPECT_EQ(x.drive.sdo_writes[0].index, 0x6065);
  EXPECT_EQ(x.drive.sdo_writes[0].where.line, 29);
  ASSERT_EQ(c.cams.size(), 1u);
  EXPECT_TRUE(c.cams[0].points[1].cubic);
  EXPECT_FALSE(c.cams[0].points[0].cubic);
  EXPECT_TRUE(c.warnings.empty());
}

TEST(Config, UnknownKeySuggestsNearestWithLineAndColumn) {
  std::string y = kGood;
  y.replace(y.find("    max_speed: 500"), 18, "    max_sped: 500");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("test.yaml:16:5: error: axes[0].max_sped: unknown key 'max_sped'; did you mean 'max_speed'?"),
            std::string::npos)
      << e;
}

TEST(Config, TypesAndRangesNameTheKey) {
  std::string y = kGood;
  y.replace(y.find("priority: 80"), 12, "priority: 180");
  y.replace(y.find("max_speed: 500"), 14, "max_speed: fast");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("test.yaml:3:13: error: controller.priority: must be 0 .. 99, got 180"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].max_speed: must be a real number in units/s, got 'fast'"), std::string::npos) << e;
}

// controller.cpu_dma_latency_us: the PM QoS request (rt/pm_qos.hpp); 0 by
// default, -1 = do not ask, range checked with file:line:key.
TEST(Config, CpuDmaLatencyDefaultRangeAndPosition) {
  EXPECT_EQ(load_string(kGood, "good.yaml").controller.cpu_dma_latency_us, 0);
  std::string y = kGood;
  y.replace(y.find("  cpu: 1\n"), 9, "  cpu: 1\n  cpu_dma_latency_us: -1\n");
  EXPECT_EQ(load_string(y, "off.yaml").controller.cpu_dma_latency_us, -1);
  y = kGood;
  y.replace(y.find("  cpu: 1\n"), 9, "  cpu: 1\n  cpu_dma_latency_us: 20\n");
  EXPECT_EQ(load_string(y, "twenty.yaml").controller.cpu_dma_latency_us, 20);
  for (const char* bad : {"-2", "3000000000", "fast", "1.5"}) {
    y = kGood;
    y.replace(y.find("  cpu: 1\n"), 9, std::string("  cpu: 1\n  cpu_dma_latency_us: ") + bad + "\n");
    const std::string e = errors_of(y);
    EXPECT_NE(e.find("test.yaml:5:23: error: controller.cpu_dma_latency_us: must be"), std::string::npos) << e;
  }
  y = kGood;
  y.replace(y.find("  cpu: 1\n"), 9, "  cpu: 1\n  cpu_dma_latency: 0\n");
  EXPECT_NE(errors_of(y).find("cpu_dma_latency_us"), std::string::npos) << "the nearest key is suggested";
}

// controller.sync_first (issue 28): false by default; a boolean, and an
// error naming the key otherwise.
TEST(Config, SyncFirstIsABooleanFalseByDefault) {
  EXPECT_FALSE(load_string(kGood, "good.yaml").controller.sync_first);
  std::string y = kGood;
  y.replace(y.find("  cpu: 1\n"), 9, "  cpu: 1\n  sync_first: true\n");
  EXPECT_TRUE(load_string(y, "on.yaml").controller.sync_first);
  for (const char* bad : {"2", "fast", "[true]"}) {
    y = kGood;
    y.replace(y.find("  cpu: 1\n"), 9, std::string("  cpu: 1\n  sync_first: ") + bad + "\n");
    const std::string e = errors_of(y);
    EXPECT_NE(e.find("test.yaml:5:15: error: controller.sync_first: must be"), std::string::npos) << e;
  }
  y = kGood;
  y.replace(y.find("  cpu: 1\n"), 9, "  cpu: 1\n  syncfirst: true\n");
  EXPECT_NE(errors_of(y).find("sync_first"), std::string::npos) << "the nearest key is suggested";
}

// sdo_writes of objects in the one object table (canopen::known_objects())
// take their size from it; a different size, a read-only object or a value
// that does not fit the size is refused, naming the entry.
TEST(Config, SdoWritesAreCheckedAgainstTheObjectTable) {
  auto with_write = [](const std::string& w) {
    std::string y = kGood;
    y.replace(y.find("        - {index: 0x6065, sub: 0, size: 4, value: 20000}"), 56, "        - " + w);
    return y;
  };
  // Size left out: the table's (0x6083 Profile acceleration is UNSIGNED32,
  // 0x6060 Modes of operation INTEGER8); an unknown object keeps 4.
  const Config c = load_string(with_write("{index: 0x6083, value: 1000}\n        - {index: 0x6060, value: -3}\n"
                                          "        - {index: 0x2345, sub: 1, value: 7}"));
  const auto& w = c.axes[1].drive.sdo_writes;
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].size, 4);
  EXPECT_EQ(w[1].size, 1);
  EXPECT_EQ(w[2].size, 4);

  std::string e = errors_of(with_write("{index: 0x6083, sub: 0, size: 2, value: 1000}"));
  EXPECT_NE(e.find("test.yaml:29:41: error: axes[1].drive.sdo_writes[0].size: 0x6083:00 (Profile acceleration) is "
                   "4 bytes, got 2"),
            std::string::npos)
      << e;
  e = errors_of(with_write("{index: 0x6041, value: 0}"));
  EXPECT_NE(e.find("axes[1].drive.sdo_writes[0].index: 0x6041:00 (Statusword) is read-only"), std::string::npos) << e;
  e = errors_of(with_write("{index: 0x6060, value: 200}"));
  EXPECT_NE(e.find("axes[1].drive.sdo_writes[0].value: 200 does not fit in 1 byte (-128 .. 127)"), std::string::npos)
      << e;
  e = errors_of(with_write("{index: 0x6065, value: -1}"));  // UNSIGNED32
  EXPECT_NE(e.find("axes[1].drive.sdo_writes[0].value: -1 does not fit in 4 bytes (0 .. 4294967295)"),
            std::string::npos)
      << e;
  e = errors_of(with_write("{index: 0x2345, size: 2, value: 70000}"));
  EXPECT_NE(e.find("axes[1].drive.sdo_writes[0].value: 70000 does not fit in 2 bytes (-32768 .. 65535)"),
            std::string::npos)
      << e;
}

// `cams:` names are tags (`cam1[0].Status`): the runtime's tag-name rule, as
// for `arrays:`.
TEST(Config, CamNamesAreTagNames) {
  std::string y = kGood;
  y.replace(y.find("- name: cam1"), 12, "- name: cam-1");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("cams[0].name: 'cam-1' is not a tag name (a letter or '_', then letters, digits or '_')"),
            std::string::npos)
      << e;
}

TEST(Config, EnumerationListsValidValues) {
  std::string y = kGood;
  y.replace(y.find("AXIS_VIRTUAL"), 12, "AXIS_VIRTUL");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("axes[0].type: 'AXIS_VIRTUL' is not one of: AXIS_VIRTUAL (0), AXIS_CIP_DRIVE (1)"),
            std::string::npos)
      << e;
}

TEST(Config, DuplicateNamesAndNodes) {
  std::string y = kGood;
  y += R"(  - name: cam1
    points: [[0, 0], [1, 1]]
)";
  const std::string dup_axis = std::string(kGood).replace(std::string(kGood).find("- name: Master"), 14, "- name: X");
  EXPECT_NE(errors_of(y).find("tag name 'cam1' is already used at line 31"), std::string::npos) << errors_of(y);
  EXPECT_NE(errors_of(dup_axis).find("axis name 'X' is already used"), std::string::npos);
  std::string two = kGood;
  two.insert(two.find("cams:"), R"(  - name: Y
    type: AXIS_CIP_DRIVE
    bus: can0
    node: 2
)");
  const std::string e = errors_of(two);
  EXPECT_NE(e.find("node 2 on bus 'can0' is already axis 'X'"), std::string::npos) << e;
  EXPECT_NE(e.find("COB-ID 0x702 of axis 'Y' (node 2) heartbeat clashes with axis 'X' (node 2) heartbeat"),
            std::string::npos)
      << e;
}

TEST(Config, MasterHeartbeatCobIdClash) {
  std::string y = kGood;
  y.replace(y.find("    bitrate: 1000000"), 20, "    bitrate: 1000000\n    master_node: 2");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("COB-ID 0x702 of axis 'X' (node 2) heartbeat clashes with the master's heartbeat (node 2)"),
            std::string::npos)
      << e;
}

TEST(Config, InterpolationPeriodAgainstThePeriod) {
  std::string y = kGood;
  y.replace(y.find("        - {index: 0x6065"), 0, "        - {index: 0x60C2, sub: 1, size: 1, value: 2}\n");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("0x60C2:01 = 2 contradicts the controller period 1 ms (0x60C2 = 1 x 10^-3 s"), std::string::npos)
      << e;
  auto p = interpolation_period(0.0025);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->mantissa, 25);
  EXPECT_EQ(p->exponent, -4);
  p = interpolation_period(0.004);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->mantissa, 4);
  EXPECT_EQ(p->exponent, -3);
  EXPECT_FALSE(interpolation_period(0.0012345));
  std::string bad = kGood;
  bad.replace(bad.find("period_ms: 1"), 12, "period_ms: 1.2345");
  EXPECT_NE(errors_of(bad).find("controller.period_ms: 1.2345 ms cannot be written to 0x60C2"), std::string::npos);
}

TEST(Config, BusBudgetRefusedOver100AndWarnsOver70) {
  auto with_axes = [](int n, const char* period, const char* bitrate) {
    std::string y = std::string("controller: {period_ms: ") + period + "}\nbuses:\n  - {name: can0, bitrate: " + bitrate +
                    "}\naxes:\n";
    for (int i = 1; i <= n; ++i)
      y += "  - {name: A" + std::to_string(i) + ", type: AXIS_CIP_DRIVE, bus: can0, node: " + std::to_string(i) + "}\n";
    return y;
  };
  // Default CSP mapping: 2 x 6-byte PDOs per axis, 115 bits each with worst-case
  // stuffing, plus SYNC (55 bits): 2 axes = 515 bits = 51.5 % of a 1 ms cycle
  // at 1 Mbit/s; 3 axes = 745 bits, plus heartbeats (65-bit frames: 3 drives
  // every 50 ms, the master every 100 ms: 4.55 bits/cycle) = 75.0 % (warning);
  // 8 axes at 250 kbit/s: refused.
  EXPECT_TRUE(load_string(with_axes(2, "1", "1000000")).warnings.empty());
  const std::string e = errors_of(with_axes(8, "1", "250000"));
  EXPECT_NE(e.find("buses[0]: worst-case bus load"), std::string::npos) << e;
  EXPECT_NE(e.find("over 100 % cannot work"), std::string::npos) << e;
  const Config warn = load_string(with_axes(3, "1", "1000000"));
  ASSERT_EQ(warn.warnings.size(), 1u);
  EXPECT_NE(warn.warnings[0].message.find("over 70 %"), std::string::npos) << warn.warnings[0].str();
  EXPECT_NE(warn.warnings[0].message.find("75.0 %"), std::string::npos) << warn.warnings[0].str();
}

TEST(Config, CrossReferencesAndCamPoints) {
  std::string y = kGood;
  y.replace(y.find("bus: can0\n    node: 2"), 9, "bus: cna0");
  y.replace(y.find("[90, 45, cubic]"), 15, "[-5, 45, cubic]");
  const std::string e = errors_of(y);
  EXPECT_NE(e.find("axes[1].bus: no bus named 'cna0'; did you mean 'can0'?"), std::string::npos) << e;
  EXPECT_NE(e.find("cams[0].points[1]: master values must increase: -5 follows 0"), std::string::npos) << e;
}

TEST(Config, ARequiredKeyIsReportedOnce) {
  // Absent: `missing: ...`; present but bad: what is wrong with it, and only that.
  struct Case {
    std::string yaml, key, message;
  };
  const Case cases[] = {
      {"axes:\n  - {type: AXIS_VIRTUAL}\n", "axes[0].name", "missing: every axis needs a name"},
      {"axes:\n  - {name: '', type: AXIS_VIRTUAL}\n", "axes[0].name", "must be a non-empty string"},
      {"axes:\n  - {name: [X], type: AXIS_VIRTUAL}\n", "axes[0].name", "must be a non-empty string"},
      {"axes:\n  - {name: X}\n", "axes[0].type", "missing: AXIS_VIRTUAL or AXIS_CIP_DRIVE"},
      {"buses:\n  - {name: ''}\naxes:\n  - {name: X, type: AXIS_VIRTUAL}\n", "buses[0].name",
       "must be a non-empty string"},
      {"buses:\n  - {name: c}\naxes:\n  - {name: X, type: AXIS_CIP_DRIVE, bus: '', node: 1}\n", "axes[0].bus",
       "must be a non-empty string"},
      {"buses:\n  - {name: c}\naxes:\n  - {name: X, type: AXIS_CIP_DRIVE, bus: c}\n", "axes[0].node",
       "missing: an AXIS_CIP_DRIVE axis needs its drive's node id (1 .. 127)"},
      {"axes:\n  - {name: X, type: AXIS_VIRTUAL}\ncams:\n  - {name: '', points: [[0, 0], [1, 1]]}\n", "cams[0].name",
       "must be a non-empty string"},
      {"axes:\n  - {name: X, type: AXIS_VIRTUAL}\narrays:\n  - {name: '', type: REAL, size: 1}\n", "arrays[0].name",
       "must be a non-empty string"},
      {"axes:\n  - {name: X, type: AXIS_VIRTUAL}\narrays:\n  - {name: a, type: REAL}\n", "arrays[0].size",
       "missing: the number of elements, 1 .. 1024"},
  };
  for (const Case& k : cases) {
    const std::vector<Diagnostic> d = test::diagnostics_of(k.yaml);
    ASSERT_EQ(d.size(), 1u) << k.yaml << ConfigError(d).what();
    EXPECT_EQ(d[0].key, k.key) << k.yaml;
    EXPECT_EQ(d[0].message, k.message) << k.yaml;
  }
}

TEST(Config, VirtualAxisHasNoDrive) {
  std::string y = kGood;
  y.replace(y.find("    max_speed: 500"), 0, "    node: 4\n");
  EXPECT_NE(errors_of(y).find("axes[0].node: only an AXIS_CIP_DRIVE axis has a drive"), std::string::npos);
}

TEST(Config, YamlSyntaxErrorHasPosition) {
  const std::string e = errors_of("axes:\n  - name: [X\n");
  EXPECT_NE(e.find("test.yaml:"), std::string::npos);
  EXPECT_NE(e.find("YAML syntax"), std::string::npos) << e;
}

TEST(Config, MissingFileIsASystemError) {
  EXPECT_THROW((void)load_file("/nonexistent/canmotion.yaml"), std::system_error);
}

TEST(Config, NearestOnlySuggestsPlausibleTypos) {
  EXPECT_EQ(nearest("prioriy", {"priority", "cpu"}), "priority");
  EXPECT_EQ(nearest("zzzzzz", {"priority", "cpu"}), std::nullopt);
}

}  // namespace
}  // namespace canmotion::config
