// `drive.mds_objects` (issue 15 item 6): where a drive keeps the MDS objects
// CiA 402 lacks (ramp velocity limits, ramp jerk, SLAT), per drive or under
// `drives:`; the project's 0x2010..0x2022 by default. Validated (INDEX:SUB,
// area, no clash with each other, with the CiA 402 objects the master uses,
// with a standard object of another size or with drive.sdo_writes) with
// file:line:column:key messages; the boot writes go to the configured
// indices; a drive EDS must have them. Also `drive.sync_watch` and the keys
// named for 0x1006 / 0x1019 (item 5).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "config/eds_check.hpp"
#include "config/runtime.hpp"
#include "fieldbus/cia402/cia402.hpp"
#include "tests/config/config_errors.hpp"

namespace canmotion::config {
namespace {

using cia402::MdsObject;
using cia402::ObjectAddress;

/// One velocity axis with ramps and one torque axis with SLAT; `drives` and
/// `t_drive` are put under `drives:` and under T's `drive:`.
std::string yaml(const std::string& drives, const std::string& t_drive = "") {
  return "controller: {period_ms: 2}\n"
         "buses:\n"
         "  - {name: can0, interface: sim}\n"
         "drives:\n"
         "  pdo: csp_csv_cst\n" +
         drives +
         "axes:\n"
         "  - name: V\n"
         "    type: AXIS_CIP_DRIVE\n"
         "    bus: can0\n"
         "    node: 2\n"
         "    conversion_constant: 1000\n"
         "    direct_control:\n"
         "      mode: velocity\n"
         "      ramp: {acceleration: 50, velocity_positive: 60, velocity_negative: 40, jerk_control: 25}\n"
         "  - name: T\n"
         "    type: AXIS_CIP_DRIVE\n"
         "    bus: can0\n"
         "    node: 3\n"
         "    conversion_constant: 1000\n"
         "    direct_control:\n"
         "      mode: torque\n"
         "      slat: {configuration: 1, set_point: 2, time_delay_ms: 5}\n" +
         (t_drive.empty() ? std::string() : "    drive:\n" + t_drive);
}

const std::string kRelocated =
    "  mds_objects:\n"
    "    ramp_velocity_positive: 0x3000:1\n"
    "    ramp_velocity_negative: \"0x3000:2\"\n"
    "    ramp_jerk_control: 0x3001\n"
    "    slat_configuration: 0x3010:0\n"
    "    slat_set_point: 12305\n"                // 0x3011, decimal
    "    slat_time_delay: 0x3012:0x00\n";

struct W {
  std::uint16_t index;
  std::uint8_t sub;
  std::uint8_t size;
  std::uint32_t value;
  friend bool operator==(const W&, const W&) = default;
};
std::vector<W> writes(const AxisSettings& a) {
  std::vector<W> out;
  for (const cia402::SdoWrite& w : direct_control_writes(a)) out.push_back({w.index, w.sub, w.size, w.value});
  return out;
}

TEST(MdsObjectsConfig, DefaultsAreTheProjectsOwnIndices) {
  const Config c = load_string(yaml(""), "mds.yaml");
  EXPECT_EQ(c.axes[0].drive.mds_objects, cia402::MdsObjects{});
  const std::vector<W> v = {{0x6083, 0, 4, 50'000}, {0x2010, 1, 4, 60'000}, {0x2010, 2, 4, 40'000},
                            {0x2011, 0, 1, 25},     {0x2020, 0, 1, 0},      {0x2021, 0, 4, 0},
                            {0x2022, 0, 2, 0}};
  EXPECT_EQ(writes(c.axes[0]), v);
}

TEST(MdsObjectsConfig, RelocatedUnderDrivesTheWritesGoThereOnly) {
  const Config c = load_string(yaml(kRelocated), "mds.yaml");
  for (const AxisSettings& a : c.axes) {
    const cia402::MdsObjects& m = a.drive.mds_objects;
    EXPECT_EQ(m[MdsObject::kRampVelocityPositive], (ObjectAddress{0x3000, 1}));
    EXPECT_EQ(m[MdsObject::kRampVelocityNegative], (ObjectAddress{0x3000, 2}));
    EXPECT_EQ(m[MdsObject::kRampJerkControl], (ObjectAddress{0x3001, 0}));
    EXPECT_EQ(m[MdsObject::kSlatConfiguration], (ObjectAddress{0x3010, 0}));
    EXPECT_EQ(m[MdsObject::kSlatSetPoint], (ObjectAddress{0x3011, 0}));
    EXPECT_EQ(m[MdsObject::kSlatTimeDelay], (ObjectAddress{0x3012, 0}));
    EXPECT_EQ(a.drive.mds_object_keys[0], "drives.mds_objects.ramp_velocity_positive");
  }
  const std::vector<W> v = {{0x6083, 0, 4, 50'000}, {0x3000, 1, 4, 60'000}, {0x3000, 2, 4, 40'000},
                            {0x3001, 0, 1, 25},     {0x3010, 0, 1, 0},      {0x3011, 0, 4, 0},
                            {0x3012, 0, 2, 0}};
  EXPECT_EQ(writes(c.axes[0]), v);
  const std::vector<W> t = {{0x3010, 0, 1, 1}, {0x3011, 0, 4, 2'000}, {0x3012, 0, 2, 5}};
  EXPECT_EQ(writes(c.axes[1]), t);
  // The hint of a relocated write names both keys (the message of a refusal at boot).
  const cia402::DriveConfig d = drive_config(c.axes[1], c.buses[0], 0.002, 1);
  ASSERT_EQ(d.hints.extra.size(), 3u);
  EXPECT_EQ(d.hints.extra[0],
            "axes[1].direct_control.slat.configuration (written to 0x3010:0, placed by "
            "drives.mds_objects.slat_configuration)");
  // The simulated drive keeps them there too.
  EXPECT_EQ(emulator_config(c.axes[1]).mds_objects, c.axes[1].drive.mds_objects);
  // Nothing goes to the project's indices.
  for (const AxisSettings& a : c.axes)
    for (const cia402::BootWrite& b : boot_writes(a, c.buses[0], c.controller.period_s, 0))
      EXPECT_TRUE(b.w.index < 0x2010 || b.w.index > 0x2022) << std::hex << b.w.index;
}

TEST(MdsObjectsConfig, AnAxisOverridesOneObjectOfTheDefaults) {
  const Config c = load_string(yaml(kRelocated, "      mds_objects: {slat_set_point: 0x4000:7}\n"), "mds.yaml");
  EXPECT_EQ(c.axes[0].drive.mds_objects[MdsObject::kSlatSetPoint], (ObjectAddress{0x3011, 0}));
  EXPECT_EQ(c.axes[1].drive.mds_objects[MdsObject::kSlatSetPoint], (ObjectAddress{0x4000, 7}));
  EXPECT_EQ(c.axes[1].drive.mds_objects[MdsObject::kSlatConfiguration], (ObjectAddress{0x3010, 0}));
  EXPECT_EQ(c.axes[1].drive.mds_object_keys[4], "axes[1].drive.mds_objects.slat_set_point");
}

/// The one diagnostic of loading `y` (a test failure unless exactly one).
Diagnostic one_error(const std::string& y) {
  const std::vector<Diagnostic> d = test::diagnostics_of(y, "mds.yaml");
  EXPECT_EQ(d.size(), 1u) << ConfigError(d).what();
  return d.empty() ? Diagnostic{} : d[0];
}

TEST(MdsObjectsConfig, BadAddressesNameFileLineAndKey) {
  {
    const Diagnostic d = one_error(yaml("  mds_objects: {ramp_jerk_control: \"0x2011:x\"}\n"));
    EXPECT_EQ(d.key, "drives.mds_objects.ramp_jerk_control");
    EXPECT_EQ(d.where.line, 6);
    EXPECT_NE(d.message.find("'0x2011:x' is not an object INDEX:SUB"), std::string::npos) << d.str();
    EXPECT_NE(d.str().find("mds.yaml:6:"), std::string::npos) << d.str();
  }
  {
    const Diagnostic d = one_error(yaml("  mds_objects: {slat_set_point: 0x1010:1}\n"));
    EXPECT_EQ(d.key, "drives.mds_objects.slat_set_point");
    EXPECT_NE(d.message.find("0x1010:1 is outside the manufacturer-specific (0x2000 .. 0x5FFF) and device profile"),
              std::string::npos)
        << d.str();
  }
  {
    const Diagnostic d = one_error(yaml("  mds_objects: {slat_time_delay: 0x3012:255}\n"));
    EXPECT_NE(d.message.find("sub-index 0 .. 254"), std::string::npos) << d.str();
  }
  {
    const Diagnostic d = one_error(yaml("  mds_objects: {slat_timedelay: 0x3012}\n"));
    EXPECT_EQ(d.key, "drives.mds_objects.slat_timedelay");
    EXPECT_NE(d.message.find("did you mean 'slat_time_delay'?"), std::string::npos) << d.str();
  }
}

TEST(MdsObjectsConfig, ClashesAreRefusedAtTheKeyThatPlacedTheObject) {
  {
    // With one of the defaults (ramp_velocity_positive stays at 0x2010:1).
    const Diagnostic d = one_error(yaml("", "      mds_objects: {slat_set_point: 0x2010:1}\n"));
    EXPECT_EQ(d.key, "axes[1].drive.mds_objects.slat_set_point");
    EXPECT_EQ(d.where.line, 24);
    EXPECT_NE(d.message.find("0x2010:1 is also ramp_velocity_positive (the default)"), std::string::npos) << d.str();
  }
  {
    // Two placed at one address: said once, at the second.
    const Diagnostic d = one_error(yaml("  mds_objects: {slat_configuration: 0x3000, slat_time_delay: 0x3000}\n"));
    EXPECT_EQ(d.key, "drives.mds_objects.slat_time_delay");
    EXPECT_NE(d.message.find("0x3000:0 is also drives.mds_objects.slat_configuration"), std::string::npos) << d.str();
  }
  {
    // Sub-index 0 of a record whose sub-index 1 holds another.
    const Diagnostic d = one_error(yaml("  mds_objects: {ramp_velocity_positive: 0x3000:1, ramp_jerk_control: 0x3000}\n"));
    EXPECT_EQ(d.key, "drives.mds_objects.ramp_jerk_control");
    EXPECT_NE(d.message.find("sub-index 0 of a record whose sub-index 1 is drives.mds_objects.ramp_velocity_positive"),
              std::string::npos)
        << d.str();
  }
  {
    // A CiA 402 object the master writes itself.
    const Diagnostic d = one_error(yaml("  mds_objects: {ramp_velocity_positive: 0x6083}\n"));
    EXPECT_NE(d.message.find("0x6083:0 is 0x6083 (Profile acceleration), which the master itself writes, maps or reads"),
              std::string::npos)
        << d.str();
  }
  {
    // A standard object of another size: 0x6086 motion profile type is INTEGER16, jerk control 1 byte.
    const Diagnostic d = one_error(yaml("  mds_objects: {ramp_jerk_control: 0x6086}\n"));
    EXPECT_NE(d.message.find("0x6086:0 is Motion profile type (2 bytes), but ramp_jerk_control is 1 byte"),
              std::string::npos)
        << d.str();
  }
  {
    // Written twice: by direct_control and by the drive's own sdo_writes.
    const Diagnostic d = one_error(yaml("", "      mds_objects: {slat_set_point: 0x3011}\n"
                                            "      sdo_writes: [{index: 0x3011, size: 4, value: 5}]\n"));
    EXPECT_EQ(d.key, "axes[1].drive.mds_objects.slat_set_point");
    EXPECT_NE(d.message.find("also written by sdo_writes[0] (line 25) of axis 'T'"), std::string::npos) << d.str();
  }
  {
    // A bad default is said once, not once per axis.
    const std::vector<Diagnostic> d = test::diagnostics_of(yaml("  mds_objects: {slat_set_point: 0x6040}\n"), "mds.yaml");
    EXPECT_EQ(d.size(), 1u) << ConfigError(d).what();
  }
}

TEST(MdsObjectsConfig, DriveEdsMustHaveTheRelocatedObjects) {
  // cia402-emu.eds has the project's 0x2010..0x2022 and nothing at 0x3000.
  const std::string examples = CANMOTION_EXAMPLES_DIR;
  const std::string e = test::errors_of(yaml("  eds: cia402-emu.eds\n" + kRelocated), examples + "/mds-test.yaml");
  EXPECT_NE(e.find("0x3000:01 is not in the EDS"), std::string::npos) << e;
  EXPECT_NE(e.find("axes[0].direct_control.ramp.velocity_positive (written to 0x3000:1, placed by "
                   "drives.mds_objects.ramp_velocity_positive)"),
            std::string::npos)
      << e;
  // At the defaults the same file is fine.
  EXPECT_NO_THROW((void)load_string(yaml("  eds: cia402-emu.eds\n"), examples + "/mds-test.yaml"));
}

/// cia402-emu.eds with each (from, to) replaced once, written beside the
/// examples' folder copy under a temporary folder; its path.
std::string eds_variant(const std::string& name, const std::vector<std::pair<std::string, std::string>>& edits) {
  std::ifstream in(std::string(CANMOTION_EXAMPLES_DIR) + "/cia402-emu.eds");
  std::string t((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const auto& [from, to] : edits) {
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) t.replace(at, from.size(), to);
  }
  const std::string path = ::testing::TempDir() + std::to_string(::getpid()) + "-" + name;
  std::ofstream(path) << t;
  return path;
}

TEST(MdsObjectsConfig, AVendorObjectAtTheDefaultAddressIsNeverWritten) {
  // Ingenia's 0x2020 is "Enable alternative frequency PWM", UNSIGNED8 rw: the
  // same size as SLAT configuration and writable. Without `slat:` the
  // SLAT-disabled writes are left out with a warning at the mds_objects key.
  const std::string eds = eds_variant("vendor-2020.eds", {{"ParameterName=SLAT configuration",
                                                           "ParameterName=Enable alternative frequency PWM"}});
  const std::string v_only =
      "controller: {period_ms: 2}\n"
      "buses:\n"
      "  - {name: can0, interface: sim}\n"
      "axes:\n"
      "  - name: V\n"
      "    type: AXIS_CIP_DRIVE\n"
      "    bus: can0\n"
      "    node: 2\n"
      "    conversion_constant: 1000\n"
      "    direct_control: {mode: velocity}\n"
      "    drive: {pdo: csp_csv_cst, eds: " + eds + "}\n";
  const Config c = load_string(v_only, "vendor.yaml");
  EXPECT_TRUE(writes(c.axes[0]).empty());  // nothing to 0x2020..0x2022 (set point and delay alone mean nothing)
  ASSERT_EQ(c.warnings.size(), 1u);
  const std::string w = c.warnings[0].message;
  EXPECT_EQ(c.warnings[0].key, "axes[0].drive.mds_objects.slat_configuration");
  std::ifstream in(eds);
  int line = 0, section = 0;
  for (std::string l; section == 0 && std::getline(in, l);) section = ++line * (l == "[2020]");
  EXPECT_NE(w.find(fmt::format(":{}: 0x2020:00 is 'Enable alternative frequency PWM' (UNSIGNED8), not slat_configuration",
                               section)),
            std::string::npos)
      << w;
  EXPECT_NE(w.find("the SLAT-disabled writes are left out"), std::string::npos) << w;
  // The project's own file: written as before, without a word.
  const std::string own = std::string(CANMOTION_EXAMPLES_DIR) + "/cia402-emu.eds";
  std::string y = v_only;
  y.replace(y.find(eds), eds.size(), own);
  const Config o = load_string(y, "vendor.yaml");
  EXPECT_EQ(writes(o.axes[0]).size(), 3u);
  EXPECT_TRUE(o.warnings.empty()) << o.warnings[0].message;
  // With `slat:` the write is asked for: refused at the slat key, naming the
  // mds_objects key that would place it, and not the read-only/size checks.
  std::string s = v_only;
  s.replace(s.find("{mode: velocity}"), 16, "{mode: torque, slat: {configuration: 1, set_point: 2}}");
  const std::string e = test::errors_of(s, "vendor.yaml");
  EXPECT_NE(e.find("axes[0].direct_control.slat.configuration: axis 'V' (node 2): "), std::string::npos) << e;
  EXPECT_NE(e.find("set axes[0].drive.mds_objects.slat_configuration to where this drive keeps it, or remove "
                   "axes[0].direct_control.slat.configuration"),
            std::string::npos)
      << e;
  EXPECT_EQ(e.find("slat.set_point"), std::string::npos) << e;  // 0x2021 is the project's own in this file
}

TEST(MdsObjectsConfig, APlacedObjectOfANonIntegerTypeIsRefused) {
  // SCHUNK's 0x2021 is REAL32: the master writes an integer there.
  const std::string eds = eds_variant(
      "real-2021.eds", {{"ParameterName=SLAT set point\nObjectType=0x7\nDataType=0x0007",
                         "ParameterName=SLAT set point\nObjectType=0x7\nDataType=0x0008"}});
  const std::string e = test::errors_of(yaml("  eds: " + eds + "\n"), "real.yaml");
  EXPECT_NE(e.find("axes[1].direct_control.slat.set_point: axis 'T' (node 3): "), std::string::npos) << e;
  EXPECT_NE(e.find("0x2021:00 is 'SLAT set point' (REAL32), not slat_set_point"), std::string::npos) << e;
}

TEST(SyncConfig, SyncWatchAndTheKeysNamedFor1006And1019) {
  const std::string y =
      "controller: {period_ms: 4}\n"
      "buses:\n"
      "  - {name: can0, interface: sim, sync_counter_overflow: 12}\n"
      "drives: {sync_watch: true}\n"
      "axes:\n"
      "  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2}\n"
      "  - {name: Y, type: AXIS_CIP_DRIVE, bus: can0, node: 3, drive: {sync_watch: false}}\n";
  const Config c = load_string(y, "sync.yaml");
  EXPECT_TRUE(c.axes[0].drive.sync_watch);
  EXPECT_FALSE(c.axes[1].drive.sync_watch);
  const cia402::DriveConfig d = drive_config(c.axes[0], c.buses[0], c.controller.period_s, 0);
  EXPECT_TRUE(d.sync_watch);
  EXPECT_EQ(d.hints.sync_watch, "axes[0].drive.sync_watch (or drives.sync_watch)");
  EXPECT_EQ(d.hints.sync_counter, "buses[].sync_counter_overflow of bus 'can0' (line 3)");
  // The boot writes: 0x1006 = 0, 0x1019 = 12, (the read of 0x1019 if refused), 0x1006 = 4000 us.
  std::vector<std::string> sync;
  for (const cia402::BootWrite& b : boot_writes(c.axes[0], c.buses[0], c.controller.period_s, 0))
    if (b.w.index == 0x1006 || b.w.index == 0x1019)
      sync.push_back(fmt::format("{}{:04X}={}", b.is_read() ? "read " : "", b.w.index, b.w.value));
  EXPECT_EQ(sync, (std::vector<std::string>{"1006=0", "1019=12", "read 1019=0", "1006=4000"}));
  sync.clear();
  for (const cia402::BootWrite& b : boot_writes(c.axes[1], c.buses[0], c.controller.period_s, 1))
    if (!b.is_read() && (b.w.index == 0x1006 || b.w.index == 0x1019))
      sync.push_back(fmt::format("{:04X}={}", b.w.index, b.w.value));
  EXPECT_EQ(sync, (std::vector<std::string>{"1006=0", "1019=12"}));
  const Diagnostic bad = one_error(
      "axes:\n  - {name: X, type: AXIS_CIP_DRIVE, bus: can0, node: 2, drive: {sync_watch: sometimes}}\n"
      "buses: [{name: can0}]\n");
  EXPECT_EQ(bad.key, "axes[0].drive.sync_watch");
  EXPECT_NE(bad.message.find("must be true or false, got 'sometimes'"), std::string::npos) << bad.str();
}

}  // namespace
}  // namespace canmotion::config
