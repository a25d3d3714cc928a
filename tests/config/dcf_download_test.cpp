// `drive.dcf` (issue 30 part 6, README "DCF download"): the ParameterValues
// of a DCF's writable objects are written at boot, what the master sets
// itself is left out with a warning, a value the configuration also writes
// with another value is refused naming both, 0x1020 (CiA 302 verify
// configuration) goes last and a drive that holds it is not written again,
// and the optional store (0x1010:1 = "save") has its own timeout.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "config/runtime.hpp"
#include "tests/config/config_errors.hpp"
#include "tests/config/runtime_rig.hpp"

namespace canmotion::config {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void replace_once(std::string& s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  s.replace(at, from.size(), to);
}

/// 0x1010 store parameters and 0x1020 verify configuration, which
/// cia402-emu.eds lacks; `values`: with the DCF's ParameterValues.
std::string store_and_verify(bool values, bool string_value = true) {
  auto var = [&](const char* section, const char* name, const char* type, const char* access, const char* def,
                 const char* value) {
    return std::string("[") + section + "]\nParameterName=" + name + "\nObjectType=0x7\nDataType=" + type +
           "\nAccessType=" + access + "\nDefaultValue=" + def + "\nPDOMapping=0\n" +
           (values && value != nullptr ? std::string("ParameterValue=") + value + "\n" : std::string()) + "\n";
  };
  return var("2100", "Axis label", "0x0009", "rw", "none", string_value ? "Spindle 2" : nullptr) +
         var("2101", "Encoder serial", "0x001B", "rw", "0", "0x1122334455667788") +
         "[1010]\nParameterName=Store parameters\nObjectType=0x8\nSubNumber=2\n\n" +
         var("1010sub0", "Highest sub-index supported", "0x0005", "const", "1", nullptr) +
         var("1010sub1", "Save all parameters", "0x0007", "rw", "1", "0x65766173") +
         "[1020]\nParameterName=Verify configuration\nObjectType=0x9\nSubNumber=3\n\n" +
         var("1020sub0", "Highest sub-index supported", "0x0005", "const", "2", nullptr) +
         var("1020sub1", "Configuration date", "0x0007", "rw", "0", "15340") +
         var("1020sub2", "Configuration time", "0x0007", "rw", "0", "36000000");
}

/// 0x1010 and 0x1020 added at the end of [OptionalObjects].
void list_store_and_verify(std::string& t) {
  const std::size_t at = t.find("SupportedObjects=");
  ASSERT_NE(at, std::string::npos);
  const int n = std::stoi(t.substr(at + 17));
  replace_once(t, fmt::format("SupportedObjects={}\n", n), fmt::format("SupportedObjects={}\n", n + 2));
  const std::size_t last = t.find(fmt::format("\n{}=0x", n));
  ASSERT_NE(last, std::string::npos);
  t.insert(t.find('\n', last + 1) + 1, fmt::format("{}=0x1010\n{}=0x1020\n", n + 1, n + 2));
  // 0x2100 and 0x2101 at the end of [ManufacturerObjects].
  const std::size_t m = t.find("[ManufacturerObjects]\nSupportedObjects=");
  ASSERT_NE(m, std::string::npos);
  const int k = std::stoi(t.substr(m + 39));
  replace_once(t, fmt::format("[ManufacturerObjects]\nSupportedObjects={}\n", k),
               fmt::format("[ManufacturerObjects]\nSupportedObjects={}\n", k + 2));
  const std::size_t end = t.find('\n', t.find(fmt::format("\n{}=0x", k), m) + 1);
  t.insert(end + 1, fmt::format("{}=0x2100\n{}=0x2101\n", k + 1, k + 2));
}

/// cia402-emu.eds with 0x1010 and 0x1020; `dcf`: with ParameterValues (the
/// commissioning engineer's), written to a temporary file; its path.
std::string drive_file(bool dcf, const std::string& name, bool string_value = true) {
  std::string t = read_text(std::string(CANMOTION_EXAMPLES_DIR) + "/cia402-emu.eds");
  list_store_and_verify(t);
  if (dcf) {
    // Written: 0x6065 and 0x605A.
    replace_once(t, "AccessType=rww\nDefaultValue=0x000186A0\n", "AccessType=rww\nDefaultValue=0x000186A0\nParameterValue=4321\n");
    replace_once(t, "DataType=0x0003\nAccessType=rw\nDefaultValue=2\n", "DataType=0x0003\nAccessType=rw\nDefaultValue=2\nParameterValue=1\n");
    // The master's own: 0x1017 heartbeat (it writes 50 ms) and a PDO mapping.
    replace_once(t, "DataType=0x0006\nAccessType=rw\nDefaultValue=0\nPDOMapping=0\n\n[1018]",
                 "DataType=0x0006\nAccessType=rw\nDefaultValue=0\nPDOMapping=0\nParameterValue=0\n\n[1018]");
    replace_once(t, "ParameterName=Mapped object 1\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\nDefaultValue=0x60400010\n",
                 "ParameterName=Mapped object 1\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\nDefaultValue=0x60400010\n"
                 "ParameterValue=0x607A0020\n");
    // Refuse write on download (ObjFlags bit 0): not written.
    replace_once(t, "ParameterName=Min position limit\nObjectType=0x7\nDataType=0x0004\nAccessType=rw\n",
                 "ParameterName=Min position limit\nObjectType=0x7\nDataType=0x0004\nAccessType=rw\nObjFlags=0x1\n"
                 "ParameterValue=-1000\n");
  }
  t += "\n" + store_and_verify(dcf, string_value);
  const std::string path = ::testing::TempDir() + std::to_string(::getpid()) + "-" + name;
  std::ofstream(path) << t;
  return path;
}

std::string yaml(const std::string& drive) {
  return "controller: {period_ms: 1}\n"
         "buses:\n"
         "  - {name: can0, interface: sim}\n"
         "axes:\n"
         "  - name: X\n"
         "    type: AXIS_CIP_DRIVE\n"
         "    bus: can0\n"
         "    node: 2\n"
         "    conversion_constant: 1000\n"
         "    drive: " + drive + "\n";
}

struct DcfValueView {
  std::uint16_t index;
  std::uint8_t sub;
  std::uint32_t value;
  friend bool operator==(const DcfValueView&, const DcfValueView&) = default;
};

TEST(DcfDownload, WritableValuesAreTakenAndTheMastersOwnLeftOut) {
  const std::string dcf = drive_file(true, "drive2.dcf");
  const Config c = load_string(yaml("{dcf: " + dcf + "}"), "dcf.yaml");
  const DcfSettings& d = c.axes[0].drive.dcf;
  std::vector<DcfValueView> got;
  for (const DcfValue& v : d.writes) got.push_back({v.index, v.sub, v.value});
  // File order; the ro/const ones, ObjFlags bit 0, the store command, the
  // PDO mapping and 0x1017 are not taken; 0x1020 last.
  const std::vector<DcfValueView> want = {{0x2100, 0, 0x6E697053}, {0x2101, 0, 0x55667788}, {0x605A, 0, 1},
                                         {0x6065, 0, 4321},        {0x1020, 1, 15340},      {0x1020, 2, 36000000}};
  EXPECT_EQ(got, want);
  // A string and a 64-bit value go as their bytes (segmented at boot).
  EXPECT_EQ(d.writes[0].bytes, std::vector<std::uint8_t>({'S', 'p', 'i', 'n', 'd', 'l', 'e', ' ', '2'}));
  EXPECT_EQ(d.writes[1].bytes, std::vector<std::uint8_t>({0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11}));
  EXPECT_TRUE(d.writes[2].bytes.empty());
  EXPECT_TRUE(d.dated);
  EXPECT_EQ(d.date, 15340u);
  EXPECT_EQ(d.time, 36000000u);
  // The DCF is the drive's description too.
  EXPECT_EQ(c.axes[0].drive.eds_key, "axes[0].drive.dcf");
  ASSERT_NE(c.axes[0].drive.eds_data, nullptr);
  std::string warnings;
  for (const Diagnostic& w : c.warnings) warnings += w.message + "\n";
  EXPECT_NE(warnings.find("1 PDO parameter value of the DCF is left out: the master configures the PDOs itself"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("the master sets this object itself (heartbeats, SYNC, mode, interpolation period): the "
                          "DCF's value is left out: 0x1017:00 at :"),
            std::string::npos)
      << warnings;
  // The boot writes: the DCF's first among the extra writes, marked so;
  // with `store:` 0x1010:1 = "save" last, with its own timeout.
  const Config s = load_string(yaml("{dcf: {file: " + dcf + ", store: true, store_timeout_ms: 8000}}"), "dcf.yaml");
  const cia402::DriveConfig dc = drive_config(s.axes[0], s.buses[0], s.controller.period_s, 0);
  ASSERT_GE(dc.extra_writes.size(), 5u);
  EXPECT_TRUE(dc.extra_writes[0].dcf);
  EXPECT_EQ(dc.extra_writes[0].index, 0x2100);
  ASSERT_NE(dc.extra_writes[0].data, nullptr);  // its bytes, referenced
  EXPECT_EQ(dc.extra_writes[0].data_len, 9u);
  EXPECT_EQ(dc.extra_writes[2].index, 0x605A);
  EXPECT_EQ(dc.extra_writes[2].data, nullptr);
  EXPECT_NE(dc.hints.extra[0].find("axes[0].drive.dcf (" + dcf + ":"), std::string::npos) << dc.hints.extra[0];
  const cia402::SdoWrite& store = dc.extra_writes.back();
  EXPECT_EQ(store.index, 0x1010);
  EXPECT_EQ(store.sub, 1);
  EXPECT_EQ(store.value, 0x65766173u);
  EXPECT_EQ(store.timeout_ns, 8'000'000'000);
  EXPECT_TRUE(store.dcf);
  EXPECT_EQ(dc.hints.extra.back(), "axes[0].drive.dcf.store");
  EXPECT_TRUE(dc.dcf_dated);
  EXPECT_EQ(dc.dcf_date, 15340u);
}

TEST(DcfDownload, AValueTheConfigurationAlsoWritesIsRefusedNamingBoth) {
  const std::string dcf = drive_file(true, "drive2-collide.dcf");
  const std::string e = test::errors_of(yaml("{dcf: " + dcf + ", quick_stop_option: 5}"), "dcf.yaml");
  EXPECT_NE(e.find("axes[0].drive.dcf: axis 'X' (node 2): " + dcf + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("0x605A:00 (Quick stop option code) ParameterValue=1 (0x1), but the master writes 5 (0x5) there "
                   "(axes[0].drive.quick_stop_option"),
            std::string::npos)
      << e;
  // The same value is written once, by the master.
  const Config c = load_string(yaml("{dcf: " + dcf + ", quick_stop_option: 1}"), "dcf.yaml");
  for (const DcfValue& v : c.axes[0].drive.dcf.writes) EXPECT_NE(v.index, 0x605A);
}

TEST(DcfDownload, KeyErrorsNameTheKey) {
  const std::string dcf = drive_file(true, "drive2-keys.dcf");
  std::string e = test::errors_of(yaml("{dcf: " + dcf + ", eds: " + dcf + "}"), "dcf.yaml");
  EXPECT_NE(e.find("axes[0].drive.dcf: give axes[0].drive.dcf or axes[0].drive.eds, not both"), std::string::npos) << e;
  e = test::errors_of(yaml("{dcf: {store: true}}"), "dcf.yaml");
  EXPECT_NE(e.find("axes[0].drive.dcf: needs file"), std::string::npos) << e;
  e = test::errors_of(yaml("{dcf: {file: " + dcf + ", stor: true}}"), "dcf.yaml");
  EXPECT_NE(e.find("stor"), std::string::npos) << e;
  e = test::errors_of(yaml("{dcf: /nonexistent/drive.dcf}"), "dcf.yaml");
  EXPECT_NE(e.find("axes[0].drive.dcf"), std::string::npos) << e;
}

/// The master runs the DCF; the emulated drive is the plain file (its
/// defaults), so that the first boot has something to write.
struct Rig : test::RuntimeRig {
  Rig(const Config& master, const Config& drive) : RuntimeRig(master) {
    rt.sim->disconnect(0);
    rt.sim->add_drive(0, emulator_config(drive.axes[0]));
    rt.sim->power_on(0);
  }
  emulator::Emulator& emu() { return rt.sim->drive(1); }
  cia402::DriveProxy& proxy() { return *ctl().network(0).drive(2); }
  std::string why() {
    char b[1024];
    const std::size_t n = proxy().failure().describe(b);
    return std::string(b, n);
  }
  bool boot() {
    for (int i = 0; i < 3000; ++i) {
      cycle();
      if (proxy().phase() == cia402::Phase::kOperational) return true;
    }
    return false;
  }
};

TEST(DcfDownload, WrittenAtTheFirstBootAndNotAgainWhileTheDriveHoldsIt) {
  // Without the store the reset brings the EDS defaults back: written again.
  {
    const Config master = load_string(yaml("{dcf: " + drive_file(true, "drive2-nostore.dcf", false) + "}"), "dcf.yaml");
    const Config drive = load_string(yaml("{eds: " + drive_file(false, "drive2-plain0.eds") + "}"), "eds.yaml");
    Rig rig(master, drive);
    ASSERT_TRUE(rig.boot()) << rig.why();
    EXPECT_EQ(rig.emu().read_int(0x6065), 4321);
    rig.proxy().reboot_node();
    ASSERT_TRUE(rig.boot()) << rig.why();
    EXPECT_EQ(rig.emu().read_int(0x6065), 4321);
    EXPECT_EQ(rig.emu().read_int(0x1020, 1), 15340);
  }
  const Config master = load_string(yaml("{dcf: {file: " + drive_file(true, "drive2-run.dcf", false) + ", store: true}}"), "dcf.yaml");
  const Config drive = load_string(yaml("{eds: " + drive_file(false, "drive2-plain.eds") + "}"), "eds.yaml");
  Rig rig(master, drive);
  EXPECT_EQ(rig.emu().read_int(0x6065), 100000);  // the EDS default before the boot
  const std::uint64_t before = rig.emu().counters().sdo_requests;
  ASSERT_TRUE(rig.boot()) << rig.why();
  const std::uint64_t first = rig.emu().counters().sdo_requests - before;
  EXPECT_EQ(rig.emu().read_int(0x6065), 4321);
  EXPECT_EQ(rig.emu().read_int(0x605A), 1);
  EXPECT_EQ(rig.emu().read_int(0x607D, 1), -2147483648LL);  // ObjFlags bit 0: not written
  EXPECT_EQ(rig.emu().read_int(0x1020, 1), 15340);
  EXPECT_EQ(rig.emu().read_int(0x1020, 2), 36000000);
  EXPECT_EQ(static_cast<std::uint64_t>(rig.emu().read_int(0x2101)), 0x1122334455667788u);  // 8 bytes, segmented
  // Reset (NMT reset node): the drive starts from what the store saved, and
  // 0x1020 shows the DCF's date, so its 5 values and the store are left out.
  rig.proxy().reboot_node();
  const std::uint64_t again_from = rig.emu().counters().sdo_requests;
  ASSERT_TRUE(rig.boot()) << rig.why();
  const std::uint64_t again = rig.emu().counters().sdo_requests - again_from;
  EXPECT_EQ(rig.emu().read_int(0x6065), 4321);
  // (The emulator serves no strings: 0x2100 has no value here. The 8-byte
  // 0x2101 takes 3 requests: initiate and two segments.)
  EXPECT_EQ(first - again, 4u + 1u + 3u) << "first boot " << first << " SDO requests, second " << again;
}

}  // namespace
}  // namespace canmotion::config
