// Byte-identity of the EDS/DCF reader and the DCF writer (issue 27: the
// reader was split into files by concern): every field the reader fills,
// every warning and every error of the seed corpus and the shipped EDS files,
// and format_dcf's text, against outputs recorded before the split
// (tests/eds/expected/). EDS_UPDATE_GOLDEN=1 rewrites them after a
// deliberate change (review the diff before committing).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "fieldbus/eds/dcf.hpp"
#include "fieldbus/eds/eds.hpp"
#include "tests/eds/eds_test_util.hpp"

using namespace canmotion;

namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Compare `got` with expected/NAME, or write it with EDS_UPDATE_GOLDEN=1.
void golden(const std::string& name, const std::string& got) {
  const fs::path p = fs::path(CANMOTION_EDS_EXPECTED_DIR) / name;
  const char* update = std::getenv("EDS_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    std::ofstream(p, std::ios::binary) << got;
    return;
  }
  ASSERT_TRUE(fs::exists(p)) << p << " missing (EDS_UPDATE_GOLDEN=1 records it)";
  const std::string want = read(p);
  EXPECT_EQ(want, got) << name << " differs (EDS_UPDATE_GOLDEN=1 accepts a deliberate change)";
}

std::string value(const std::optional<eds::Value>& v) {
  if (!v) return "-";
  std::string data;
  for (unsigned char c : v->data) data += fmt::format("{:02X}", c);
  return fmt::format("'{}' rel={} bits=0x{:X} data={}", v->text, v->node_id_relative ? 1 : 0, v->bits, data);
}

std::string dump(const eds::Eds& e) {
  std::string s;
  const auto& fi = e.file_info;
  s += fmt::format("FileInfo: '{}' '{}' '{}' '{}' '{}' '{}' '{}'\n", fi.file_name, fi.file_version, fi.file_revision,
                   fi.eds_version, fi.description, fi.created_by, fi.modified_by);
  const auto& d = e.device_info;
  s += fmt::format("DeviceInfo @{}: '{}' 0x{:X} '{}' 0x{:X} rev 0x{:X} '{}' rates", d.line, d.vendor_name,
                   d.vendor_number, d.product_name, d.product_number, d.revision_number, d.order_code);
  for (auto r : d.baud_rates) s += fmt::format(" {}", r);
  s += fmt::format(" boot {}{} gran {}@{} dyn {} group {} rx {}@{} tx {}@{} lss {}\n", d.simple_boot_up_master,
                   d.simple_boot_up_slave, d.granularity, d.granularity_line, d.dynamic_channels_supported,
                   d.group_messaging, d.nr_of_rxpdo, d.nr_of_rxpdo_line, d.nr_of_txpdo, d.nr_of_txpdo_line,
                   d.lss_supported);
  if (e.comissioning) {
    const auto& c = *e.comissioning;
    s += fmt::format("Comissioning @{}: node {} baud {} '{}' net {} '{}' manager {} lss 0x{:X}\n", c.line, c.node_id,
                     c.baudrate, c.node_name, c.net_number, c.network_name, c.canopen_manager, c.lss_serial_number);
  }
  s += fmt::format("dummy 0x{:X} lists {} {} {} dcf {}\n", e.dummy_usage, e.list_lines[1], e.list_lines[2],
                   e.list_lines[3], e.is_dcf());
  for (const eds::Object& o : e.objects) {
    s += fmt::format("[{:04X}] @{} '{}' {} {} subnum {} compact {} flags 0x{:X} den '{}'\n", o.index, o.line, o.name,
                     eds::object_code_name(o.code), eds::object_list_name(o.list), o.sub_number, o.compact_sub_obj,
                     o.obj_flags, o.denotation);
    for (const eds::SubObject& v : o.subs) {
      s += fmt::format("  sub {} @{} '{}' type 0x{:04X} {} pdo {} flags 0x{:X} den '{}'\n", v.sub, v.line, v.name,
                       static_cast<unsigned>(v.type), eds::access_type_name(v.access), v.pdo_mapping, v.obj_flags,
                       v.denotation);
      s += fmt::format("    default {}\n    low {}\n    high {}\n    param {}\n", value(v.default_value),
                       value(v.low_limit), value(v.high_limit), value(v.parameter_value));
    }
  }
  for (const eds::Diagnostic& w : e.warnings) s += "warning: " + w.to_string() + "\n";
  return s;
}

/// The reader's view of one file: its model and warnings, or its errors.
std::string read_eds(const fs::path& p) {
  try {
    return dump(eds::parse(read(p), p.filename().string()));
  } catch (const eds::ParseError& e) {
    std::string s;
    for (const eds::Diagnostic& d : e.errors()) s += "error: " + d.to_string() + "\n";
    return s;
  }
}

TEST(EdsGolden, CorpusAndShippedFilesReadAsRecorded) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(CANMOTION_EDS_CORPUS_DIR)) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  files.push_back(fs::path(CANMOTION_EXAMPLES_DIR) / "cia402-emu.eds");
  files.push_back(fs::path(CANMOTION_EXAMPLES_DIR) / "minimal-drive.eds");
  files.push_back(fs::path(CANMOTION_PEERS_DIR) / "csp-drive.eds");
  for (const fs::path& p : files) golden(p.filename().string() + ".txt", read_eds(p));
}

/// eds::test::dcf_spec() and more writes: a second mapping entry and the
/// final 0x1600:0, a TPDO mapping, a VAR with its key, a 3-byte value.
eds::DcfSpec boot_writes() {
  eds::DcfSpec s = eds::test::dcf_spec();
  s.writes.insert(s.writes.end(), {{0x1600, 2, 4, 0x607A0020u, "axes[0].drive.pdo"},
                                   {0x1600, 0, 1, 2, "axes[0].drive.pdo"},
                                   {0x1A00, 1, 4, 0x60410010u, "axes[0].drive.pdo"},
                                   {0x1017, 0, 2, 100, "drive.heartbeat_ms"},
                                   {0x4000, 0, 3, 0xABCDEF, ""}});
  return s;
}

TEST(DcfGolden, TextWithoutAndWithTheNodesEds) {
  golden("boot.dcf", eds::format_dcf(boot_writes()));
  const eds::Eds vendor = eds::load(fs::path(CANMOTION_EXAMPLES_DIR) / "cia402-emu.eds");
  eds::DcfSpec s = boot_writes();
  s.eds = &vendor;
  s.node_name = "";
  s.created_by = "test";
  golden("boot-cia402-emu.dcf", eds::format_dcf(s));
}

}  // namespace
