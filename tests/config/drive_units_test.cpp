// Drive units (issue 29 part 2, README "Drive units"): the same MDS speed and
// homing speed in user units give the same shaft speed on an emulated drive
// in inc/s and on one in rpm (tests/units/*.eds: 0x60A9 with 0x608F); a
// drive whose velocity unit cannot be known is refused for MDS, CSV and
// homing by the configuration check, before any frame; the factor decoding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>
#include <unistd.h>
#include <sstream>
#include <fstream>
#include <filesystem>

#include "config/runtime.hpp"
#include "fieldbus/cia402/units.hpp"
#include "tests/config/runtime_rig.hpp"

namespace canmotion::config {
namespace {

const std::string kFile = std::string(CANMOTION_UNITS_DIR) + "/units.yaml";

// 4096 counts per user unit (one motor revolution): 15 units/s = 61440 counts/s
// = 900 rpm exactly, 5 units/s = 300 rpm.
// An empty `eds` leaves `drive:` out (the units are then read at boot).
std::string yaml(const std::string& eds_a, const std::string& eds_b,
                 const std::string& direct = "{mode: velocity}") {
  auto axis = [&](const char* name, const char* bus, const std::string& eds) {
    return std::string("  - name: ") + name + "\n    type: AXIS_CIP_DRIVE\n    bus: " + bus +
           "\n    node: 2\n    conversion_constant: 4096\n    max_speed: 100\n    max_accel: 1000\n    max_decel: 1000\n"
           "    homing: {mode: Active, sequence: Switch, method: 19, speed_search: 5, speed_zero: 1, accel: 200}\n"
           "    direct_control: " + direct + "\n" + (eds.empty() ? std::string() : "    drive: {eds: " + eds + "}\n");
  };
  return "controller: {period_ms: 1}\nbuses:\n  - {name: can0, interface: sim}\n  - {name: can1, interface: sim}\n"
         "drives:\n  pdo: csp_csv_cst\naxes:\n" +
         axis("A", "can0", eds_a) + axis("B", "can1", eds_b);
}

TEST(DriveUnits, Decoding) {
  namespace u = cia402::units;
  u::FactorGroup res;  // position in increments, 4096 per motor revolution
  res.res = {4096, 1};
  const u::FactorGroup none;
  u::FactorGroup r3;
  r3.res = {10000, 3};
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kIncPerSecond, none, false), 1.0);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kRpm, res, false), 4096.0 / 60.0);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(0xFFB44700u, res, false), 4096.0 / 600.0);  // 0.1 rpm
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(0x00B44700u, r3, false), 10000.0 / 3.0 / 60.0);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kIncPerSecond2, none, true), 1.0);
  EXPECT_FALSE(u::counts_per_unit(u::kRpm, none, false));             // revolutions without 0x608F
  EXPECT_FALSE(u::counts_per_unit(u::kIncPerSecond, none, true));     // a velocity code is no acceleration
  EXPECT_FALSE(u::counts_per_unit(0xFD010300u, res, false));          // mm/s with the position in increments
  EXPECT_FALSE(u::counts_per_unit(0x00B50301u, res, false));          // byte 0 not 0
  u::FactorGroup geared = res;  // a 3:1 gear: revolutions of which shaft?
  geared.gear_motor = 3;
  geared.gear_shaft = 1;
  EXPECT_FALSE(u::counts_per_unit(u::kRpm, geared, false));
  EXPECT_NE(u::unknown_reason(u::kRpm, geared, false).find("0x6091"), std::string_view::npos);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kIncPerSecond, geared, false), 1.0);  // increments are the encoder's
  // Position in 0.1 degree (0x60A8 = 0xFF410000, Nanotec's default) with the
  // feed constant 3600 per driving shaft revolution (0x6092) and no gear:
  // rpm = 3600 / 60 = 60 position units/s; 1 degree/s = 10; inc/s = 3600/4096.
  u::FactorGroup deg;
  deg.position = 0xFF410000u;
  deg.res = {4096, 1};
  deg.feed = 3600;
  deg.feed_shaft = 1;
  EXPECT_FALSE(deg.position_in_increments());
  EXPECT_DOUBLE_EQ(*deg.per_motor_revolution(), 3600.0);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kRpm, deg, false), 60.0);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(0x00410300u, deg, false), 10.0);  // degree/s
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kIncPerSecond, deg, false), 3600.0 / 4096.0);
  deg.gear_motor = 2;  // 2 motor revolutions per driving shaft revolution: 1800 per motor revolution
  deg.gear_shaft = 1;
  EXPECT_DOUBLE_EQ(*deg.per_motor_revolution(), 1800.0);
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(u::kIncPerSecond, deg, false), 1800.0 / 4096.0);
  EXPECT_FALSE(u::counts_per_unit(u::kRpm, deg, false));
  u::FactorGroup mm;  // position in mm, velocity in m/s: 1000 mm/s per unit, no mechanics needed
  mm.position = 0xFD010000u;
  EXPECT_DOUBLE_EQ(*u::counts_per_unit(0x00010300u, mm, false), 1000.0);
  EXPECT_FALSE(u::counts_per_unit(u::kRpm, mm, false));  // no feed constant
  EXPECT_NE(u::unknown_reason(u::kRpm, mm, false).find("0x6092"), std::string_view::npos);
  EXPECT_EQ(*u::velocity_unit_code("rpm"), u::kRpm);
  EXPECT_FALSE(u::velocity_unit_code("rps"));
}

struct Rig : test::RuntimeRig {
  explicit Rig(const Config& c) : RuntimeRig(c) { rt.sim->power_on(0); }
  emulator::Emulator& emu(std::size_t bus) { return *rt.sim->find_drive(bus, 2); }
  void exec(const std::string& call) {
    ASSERT_TRUE(execute(call));
    cycle();
  }
};

/// The master runs `master` (no EDS: it knows nothing of the drives' units)
/// while the emulated drives are those of `drives` (each from its EDS): the
/// default drives are detached and the described ones put in their place.
struct ReadAtBootRig : test::RuntimeRig {
  ReadAtBootRig(const Config& master, const Config& drives) : RuntimeRig(master) {
    const std::size_t n = rt.sim->drive_count();
    for (std::size_t i = 0; i < n; ++i) rt.sim->disconnect(i);
    for (std::size_t i = 0; i < drives.axes.size(); ++i) rt.sim->add_drive(i, emulator_config(drives.axes[i]));
    first = n;
    rt.sim->power_on(0);
  }
  emulator::Emulator& emu(std::size_t bus) { return rt.sim->drive(first + bus); }
  const cia402::DriveProxy& proxy(std::size_t bus) { return *ctl().network(bus).drive(2); }
  void exec(const std::string& call) {
    ASSERT_TRUE(execute(call));
    cycle();
  }
  std::size_t first = 0;
};

TEST(DriveUnits, ReadAtBootWithoutAnEds) {
  // The same axes without `drive.eds`: the master reads 0x608F, 0x6091, 0x60A9
  // and 0x60AA at boot and sends every velocity in the unit the drive has.
  const std::string direct = "{mode: velocity, ramp: {acceleration: 100, deceleration: 100, velocity_positive: 50}}";
  const Config master = load_string(yaml("", "", direct), kFile);
  EXPECT_TRUE(master.axes[1].drive.units_at_boot);
  EXPECT_FALSE(master.axes[1].drive.velocity_counts);
  const Config drives = load_string(yaml("incs-drive.eds", "rpm-drive.eds", direct), kFile);
  ReadAtBootRig r(master, drives);
  r.cycles(300);
  ASSERT_EQ(r.proxy(0).phase(), cia402::Phase::kOperational) << r.proxy(0).failure().to_string();
  ASSERT_EQ(r.proxy(1).phase(), cia402::Phase::kOperational) << r.proxy(1).failure().to_string();
  EXPECT_DOUBLE_EQ(r.proxy(0).velocity_counts(), 1.0);
  EXPECT_DOUBLE_EQ(r.proxy(1).velocity_counts(), 4096.0 / 60.0);
  EXPECT_EQ(r.proxy(1).unit_readings().factors.res.increments, 4096u);
  // The boot writes in the drive's unit: 50 units/s = 204800 counts/s = 3000 rpm.
  EXPECT_EQ(r.emu(0).read_int(0x2010, 1), 204800);
  EXPECT_EQ(r.emu(1).read_int(0x2010, 1), 3000);
  EXPECT_EQ(r.emu(0).read_int(0x6083), 409600);  // neither has 0x60AA: inc/s^2
  EXPECT_EQ(r.emu(1).read_int(0x6083), 409600);
  r.exec("MDS(A, ma, 15, UnitsPerSec)");
  r.exec("MDS(B, mb, 15, UnitsPerSec)");
  r.cycles(2000);
  ASSERT_EQ(r.read("mb.IP"), 1.0) << r.read("mb.ERR");
  EXPECT_EQ(r.emu(0).read_int(0x60FF), 61440);
  EXPECT_EQ(r.emu(1).read_int(0x60FF), 900);
  EXPECT_DOUBLE_EQ(r.emu(0).velocity(), 61440.0);  // the same shaft speed
  EXPECT_DOUBLE_EQ(r.emu(1).velocity(), 61440.0);
  EXPECT_NEAR(r.read("B.ActualVelocity"), 15.0, 1e-9);
  r.exec("MAS(B, sb, All, No, 0, UnitsPerSec2, No, 0, UnitsPerSec3)");
  r.cycles(500);
  r.exec("MSO(B, ob)");
  r.cycles(300);
  r.exec("MAH(B, hb)");
  r.cycles(200);
  EXPECT_EQ(r.emu(1).read_int(0x6099, 1), 300);  // 5 units/s in rpm
  EXPECT_EQ(r.emu(1).read_int(0x6099, 2), 60);
}

/// `y` with axis B's homing and direct_control left out (B is the last axis):
/// nothing of it needs the drive's velocity unit.
std::string without_b_motion(std::string y) {
  const auto at = y.find("    homing:", y.find("name: B"));
  const auto end = y.find("    drive:", at);
  y.erase(at, end == std::string::npos ? std::string::npos : end - at);
  return y;
}

TEST(DriveUnits, UnitUnknownAtBootFailsTheBootNamingTheObject) {
  // The drive says rpm and has no 0x608F: its counts per revolution cannot be
  // known. MDS and homing need the unit: the boot fails naming 0x60A9 and the
  // keys, before NMT start (no PDO, no motion). Nothing is guessed.
  const Config drives = load_string(without_b_motion(yaml("incs-drive.eds", "unknown-velocity-drive.eds")), kFile);
  ReadAtBootRig r(load_string(yaml("", ""), kFile), drives);
  r.cycles(400);
  const cia402::DriveProxy& p = r.proxy(1);
  ASSERT_TRUE(p.failed());
  EXPECT_EQ(p.failure().kind, cia402::FailureKind::kBootCheck);
  const std::string why = p.failure().to_string();
  for (const char* part : {"node 2: 0x60A9", "is 0x00B44700", "0x608F", "axes[1].direct_control (MDS in CSV)",
                           "axes[1].homing (speeds, 0x6099)", "nothing is guessed"})
    EXPECT_NE(why.find(part), std::string::npos) << part << " in: " << why;
  EXPECT_EQ(r.emu(1).counters().rpdos, 0u);
  EXPECT_EQ(r.emu(1).nmt_state(), canopen::NmtState::kPreOperational);
  EXPECT_EQ(r.proxy(0).phase(), cia402::Phase::kOperational);  // the other drive is fine
  // MSO on it is refused with the drive's failure.
  r.exec("MSO(B, ob)");
  r.cycles(5);
  EXPECT_EQ(r.read("ob.ER"), 1.0);
  // Without MDS and homing nothing needs the unit: the drive boots and runs
  // on positions, its velocity not known (0x606C not read, 0x60FF sent 0).
  ReadAtBootRig c(load_string(without_b_motion(yaml("", "")), kFile), drives);
  c.cycles(400);
  ASSERT_EQ(c.proxy(1).phase(), cia402::Phase::kOperational) << c.proxy(1).failure().to_string();
  EXPECT_TRUE(std::isnan(c.proxy(1).velocity_counts()));
  c.exec("MSO(B, ob)");
  c.cycles(300);
  ASSERT_EQ(c.read("ob.DN"), 1.0) << c.read("ob.ERR");
  c.exec("MAJ(B, jb, Forward, 2, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, Trapezoidal, 0, 0, UnitsPerSec3, Disabled, Programmed, 0, None)");
  c.cycles(200);
  const std::int64_t p0 = c.emu(1).position_counts();
  c.cycles(1000);
  EXPECT_EQ(c.emu(1).read_int(0x60FF), 0);
  EXPECT_NEAR(static_cast<double>(c.emu(1).position_counts() - p0), 2.0 * 4096, 2.0);
}

/// rpm-drive.eds with the DefaultValue of each of `sections` left out (the
/// drive has the object, the file no value), written to a temporary file;
/// returns its path.
std::string rpm_drive_without(const std::string& name, const std::vector<std::string>& sections) {
  std::ifstream in(std::string(CANMOTION_UNITS_DIR) + "/rpm-drive.eds");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string t = ss.str();
  for (const std::string& sec : sections) {
    const std::size_t at = t.find("[" + sec + "]\n");
    EXPECT_NE(at, std::string::npos) << sec;
    const std::size_t v = t.find("DefaultValue=", at);
    t.erase(v, t.find('\n', v) + 1 - v);
  }
  const std::string path =
      (std::filesystem::temp_directory_path() / ("canmotion-" + name + "-" + std::to_string(::getpid()) + ".eds")).string();
  std::ofstream(path) << t;
  return path;
}

TEST(DriveUnits, ValuesTheFileLacksAreReadAtBoot) {
  // 0x60A9 without a value, then 0x608F without values: not refused at load;
  // read from the drive at boot (which has rpm, 4096 increments per revolution).
  const Config drives = load_string(yaml("incs-drive.eds", "rpm-drive.eds"), kFile);
  for (const auto& [name, sections] :
       {std::pair<std::string, std::vector<std::string>>{"no-60a9-value", {"60A9"}},
        {"no-608f-values", {"608Fsub1", "608Fsub2"}}}) {
    SCOPED_TRACE(name);
    const std::string eds = rpm_drive_without(name, sections);
    const Config master = load_string(yaml("incs-drive.eds", eds), kFile);
    EXPECT_FALSE(master.axes[0].drive.units_at_boot);
    EXPECT_TRUE(master.axes[1].drive.units_at_boot);
    ReadAtBootRig r(master, drives);
    r.cycles(300);
    ASSERT_EQ(r.proxy(1).phase(), cia402::Phase::kOperational) << r.proxy(1).failure().to_string();
    r.exec("MDS(B, mb, 15, UnitsPerSec)");
    r.cycles(2000);
    EXPECT_EQ(r.emu(1).read_int(0x60FF), 900);
    EXPECT_DOUBLE_EQ(r.emu(1).velocity(), 61440.0);
    std::filesystem::remove(eds);
  }
}

TEST(DriveUnits, PositionInTenthsOfADegree) {
  // Nanotec's defaults (tests/units/degree-drive.eds): 0x607A/0x6064 in 0.1
  // degree (0x60A8 = 0xFF410000), feed 3600 per revolution (0x6092), velocity
  // in rpm. User unit: degree, conversion_constant 10. 90 degree/s = 15 rpm
  // = 900 position units/s. From the EDS, and read at boot without it.
  std::string y = yaml("degree-drive.eds", "degree-drive.eds");
  for (std::size_t at; (at = y.find("conversion_constant: 4096")) != std::string::npos;)
    y.replace(at, 25, "conversion_constant: 10");
  const Config drives = load_string(y, kFile);
  EXPECT_DOUBLE_EQ(*drives.axes[0].drive.velocity_counts, 60.0);  // position units/s per rpm
  std::string no_eds = y;
  const std::string line = "    drive: {eds: degree-drive.eds}\n";
  no_eds.erase(no_eds.find(line), line.size());  // axis A's
  const Config master = load_string(no_eds, kFile);
  ASSERT_EQ(master.axes[0].drive.eds, "");
  ASSERT_EQ(master.axes[1].drive.eds, "degree-drive.eds");
  ReadAtBootRig r(master, drives);  // A without the EDS (read at boot), B with it
  r.cycles(300);
  ASSERT_EQ(r.proxy(0).phase(), cia402::Phase::kOperational) << r.proxy(0).failure().to_string();
  EXPECT_DOUBLE_EQ(r.proxy(0).velocity_counts(), 60.0);
  EXPECT_EQ(r.proxy(0).unit_readings().factors.position, 0xFF410000u);
  EXPECT_EQ(r.proxy(0).unit_readings().factors.feed, 3600u);
  r.exec("MDS(A, ma, 90, UnitsPerSec)");
  r.exec("MDS(B, mb, 90, UnitsPerSec)");
  r.cycles(2000);
  for (std::size_t bus = 0; bus < 2; ++bus) {
    SCOPED_TRACE(bus);
    EXPECT_EQ(r.emu(bus).read_int(0x60FF), 15);            // rpm
    EXPECT_DOUBLE_EQ(r.emu(bus).velocity(), 900.0);        // 0.1 degree/s
    EXPECT_EQ(r.emu(bus).read_int(0x606C), 15);
  }
  EXPECT_NEAR(r.read("A.ActualVelocity"), 90.0, 1e-9);
  EXPECT_NEAR(r.read("B.ActualVelocity"), 90.0, 1e-9);
}

TEST(DriveUnits, RampThatRoundsToZeroInTheDrivesUnitIsRefused) {
  // 0.005 units/s = 20.48 counts/s fits 0x2010:1 in counts, but is 0.3 rpm:
  // 0 in the rpm drive's unit, which would be a ramp limit of 0.
  try {
    (void)load_string(yaml("incs-drive.eds", "rpm-drive.eds", "{mode: velocity, ramp: {velocity_positive: 0.005}}"),
                      kFile);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("axes[1].direct_control.ramp.velocity_positive"), std::string::npos) << w;
    EXPECT_NE(w.find("= 0 in the drive's velocity unit"), std::string::npos) << w;
    EXPECT_NE(w.find("0x2010:1"), std::string::npos) << w;
    EXPECT_EQ(w.find("axes[0]"), std::string::npos) << w;  // 20 inc/s is fine
  }
}

TEST(DriveUnits, SameShaftSpeedInIncPerSecondAndRpm) {
  const Config c = load_string(yaml("incs-drive.eds", "rpm-drive.eds"), kFile);
  EXPECT_DOUBLE_EQ(*c.axes[0].drive.velocity_counts, 1.0);
  EXPECT_DOUBLE_EQ(*c.axes[1].drive.velocity_counts, 4096.0 / 60.0);
  Rig r(c);
  auto& inc = r.emu(0);
  auto& rpm = r.emu(1);
  r.cycles(300);
  // ---- MDS: 15 units/s on both --------------------------------------------
  r.exec("MDS(A, ma, 15, UnitsPerSec)");
  r.exec("MDS(B, mb, 15, UnitsPerSec)");
  r.cycles(2000);
  ASSERT_EQ(r.read("ma.IP"), 1.0) << r.read("ma.ERR");
  ASSERT_EQ(r.read("mb.IP"), 1.0) << r.read("mb.ERR");
  EXPECT_EQ(inc.read_int(0x60FF), 61440);  // inc/s
  EXPECT_EQ(rpm.read_int(0x60FF), 900);    // rpm
  EXPECT_DOUBLE_EQ(inc.velocity(), 61440.0);  // shaft speed, counts/s
  EXPECT_DOUBLE_EQ(rpm.velocity(), 61440.0);
  EXPECT_EQ(rpm.read_int(0x606C), 900);  // 0x606C in the drive's unit too
  EXPECT_NEAR(r.read("A.ActualVelocity"), 15.0, 1e-9);
  EXPECT_NEAR(r.read("B.ActualVelocity"), 15.0, 1e-9);
  // ---- stop, then home: 0x6099 speeds in each drive's unit -------------------
  r.exec("MAS(A, sa, All, No, 0, UnitsPerSec2, No, 0, UnitsPerSec3)");
  r.exec("MAS(B, sb, All, No, 0, UnitsPerSec2, No, 0, UnitsPerSec3)");
  r.cycles(500);
  r.exec("MSO(A, oa)");
  r.exec("MSO(B, ob)");
  r.cycles(300);
  r.exec("MAH(A, ha)");
  r.exec("MAH(B, hb)");
  double vmax_inc = 0, vmax_rpm = 0;
  for (int i = 0; i < 15000; ++i) {
    r.cycle();
    vmax_inc = std::max(vmax_inc, std::abs(inc.velocity()));
    vmax_rpm = std::max(vmax_rpm, std::abs(rpm.velocity()));
  }
  EXPECT_EQ(inc.read_int(0x6099, 1), 20480);  // 5 units/s
  EXPECT_EQ(rpm.read_int(0x6099, 1), 300);
  EXPECT_EQ(inc.read_int(0x6099, 2), 4096);  // 1 unit/s
  EXPECT_EQ(rpm.read_int(0x6099, 2), 60);
  EXPECT_DOUBLE_EQ(vmax_inc, 20480.0);  // the search at the same shaft speed
  EXPECT_DOUBLE_EQ(vmax_rpm, 20480.0);
  EXPECT_EQ(r.read("ha.PC"), 1.0) << r.read("ha.ERR");
  EXPECT_EQ(r.read("hb.PC"), 1.0) << r.read("hb.ERR");
}

TEST(DriveUnits, UnknownVelocityUnitIsRefusedBeforeAnyFrame) {
  // rpm without 0x608F: the counts per revolution cannot be known. The check
  // refuses the configuration (load_string throws: no runtime, no frame).
  try {
    (void)load_string(yaml("incs-drive.eds", "unknown-velocity-drive.eds"), kFile);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("axes[1].direct_control"), std::string::npos) << w;
    EXPECT_NE(w.find("MDS (axes[1].direct_control, CSV) needs the drive's velocity unit, which cannot be known"),
              std::string::npos) << w;
    EXPECT_NE(w.find("axes[1].homing"), std::string::npos) << w;
    EXPECT_NE(w.find("0x60A9 = 0x00B44700"), std::string::npos) << w;
    EXPECT_NE(w.find("0x608F"), std::string::npos) << w;
    EXPECT_EQ(w.find("axes[0]"), std::string::npos) << w;  // the inc/s drive is fine
  }
}

TEST(DriveUnits, OlderFactorObjectsOtherThanOneToOneAreUnknown) {
  // No 0x60A9, but 0x6094 (velocity encoder factor) 10:1: not interpreted, so
  // the velocity unit is unknown and MDS and homing are refused.
  try {
    (void)load_string(yaml("incs-drive.eds", "older-factor-drive.eds"), kFile);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("axes[1].direct_control"), std::string::npos) << w;
    EXPECT_NE(w.find("0x6094 (velocity encoder factor) = 10:1, not 1:1: the older factor objects are not interpreted"),
              std::string::npos) << w;
  }
}

TEST(DriveUnits, CspOnlyAxisWithUnknownVelocityUnitRunsWithoutVelocity) {
  std::string y = yaml("incs-drive.eds", "unknown-velocity-drive.eds");
  // Axis B without MDS and homing on the drive: position only.
  const auto at = y.find("    homing:", y.find("name: B"));
  y.erase(at, y.find("    drive:", at) - at);
  const Config c = load_string(y, kFile);
  EXPECT_FALSE(c.axes[1].drive.velocity_counts);
  Rig r(c);
  r.cycles(300);
  r.exec("MSO(B, ob)");
  r.cycles(300);
  ASSERT_EQ(r.read("ob.DN"), 1.0) << r.read("ob.ERR");
  r.exec("MAJ(B, jb, Forward, 2, UnitsPerSec, 100, UnitsPerSec2, 100, UnitsPerSec2, Trapezoidal, 0, 0, UnitsPerSec3, Disabled, Programmed, 0, None)");
  r.cycles(200);
  auto& e = r.emu(1);
  const std::int64_t p0 = e.position_counts();
  r.cycles(1000);
  EXPECT_EQ(e.read_int(0x60FF), 0);  // no velocity sent in a unit that is not known
  EXPECT_NEAR(static_cast<double>(e.position_counts() - p0), 2.0 * 4096, 2.0);  // CSP follows the position: 2 units/s
  // Differentiated from 0x6064 (8 or 9 counts a cycle), not read from 0x606C.
  EXPECT_NEAR(r.read("B.ActualVelocity"), 2.0, 0.25);
}

TEST(DriveUnits, ConfiguredVelocityUnitIsWrittenAndUsed) {
  std::string y = yaml("incs-drive.eds", "incs-drive.eds");
  y.replace(y.rfind("drive: {eds: incs-drive.eds}"), 28, "drive: {eds: incs-drive.eds, units: {velocity: rpm}}");
  const Config c = load_string(y, kFile);
  EXPECT_DOUBLE_EQ(*c.axes[1].drive.velocity_counts, 4096.0 / 60.0);
  Rig r(c);
  r.cycles(300);
  EXPECT_EQ(r.emu(1).read_int(0x60A9), 0x00B44700);
  EXPECT_EQ(r.emu(0).read_int(0x60A9), 0x00B50300);
  r.exec("MDS(B, mb, 15, UnitsPerSec)");
  r.cycles(2000);
  EXPECT_EQ(r.emu(1).read_int(0x60FF), 900);
  EXPECT_DOUBLE_EQ(r.emu(1).velocity(), 61440.0);
  // A word that is no unit names the key.
  std::string bad = yaml("incs-drive.eds", "incs-drive.eds");
  bad.replace(bad.rfind("drive: {eds: incs-drive.eds}"), 28, "drive: {eds: incs-drive.eds, units: {velocity: rps}}");
  try {
    (void)load_string(bad, kFile);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("axes[1].drive.units.velocity"), std::string::npos) << e.what();
  }
  // A drive whose 0x60A9 is read-only does not let the master choose.
  std::string ro = yaml("incs-drive.eds", "incs-drive.eds");
  ro.replace(ro.rfind("drive: {eds: incs-drive.eds}"), 28,
             "drive: {eds: unknown-velocity-drive.eds, units: {velocity: inc/s}}");
  try {
    (void)load_string(ro, kFile);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("axes[1].drive.units.velocity"), std::string::npos) << w;
    EXPECT_NE(w.find("0x60A9:00 (SI unit velocity) is AccessType=ro"), std::string::npos) << w;
  }
}

}  // namespace
}  // namespace canmotion::config
