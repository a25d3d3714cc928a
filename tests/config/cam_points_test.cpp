// One cam-point parser for `cams[].points` and the values of a CAM array in
// `arrays:`: the same bad point gives the same message in both sections, at
// the same element (file, line, column, key), and refuses the whole file
// (nothing half-applied). The one difference is by design: a `cams:` entry is
// one cam (master values must increase), a CAM array may hold several.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/config.hpp"
#include "tests/config/config_errors.hpp"
#include "tests/config/runtime_rig.hpp"

namespace canmotion::config {
namespace {

const std::string kHead = "axes:\n  - {name: X, type: AXIS_VIRTUAL, max_speed: 100}\n";
constexpr int kLine = 4;  // the line of the `cams:` / `arrays:` entry below

std::string in_cams(const std::string& point) {
  return kHead + "cams:\n  - {name: c, points: [[0, 0], " + point + ", [9, 9]]}\n";
}
std::string in_arrays(const std::string& point) {
  return kHead + "arrays:\n  - {name: c, type: CAM, size: 3, values: [[0, 0], " + point + ", [9, 9]]}\n";
}

std::vector<Diagnostic> refused(const std::string& yaml) { return test::diagnostics_of(yaml, "pts.yaml"); }

/// 1-based column of `what` in line `line` (1-based) of `yaml`, searched
/// after the first point `[0, 0]`.
int column_of(const std::string& yaml, int line, const std::string& what) {
  std::size_t start = 0;
  for (int l = 1; l < line; ++l) start = yaml.find('\n', start) + 1;
  const std::string text = yaml.substr(start, yaml.find('\n', start) - start);
  const std::size_t at = text.find(what, text.find("[0, 0]") + 6);
  EXPECT_NE(at, std::string::npos) << what << " in " << text;
  return static_cast<int>(at) + 1;
}

struct BadPoint {
  std::string point;  // the second point of the list
  std::string at;     // the element the error points at
  std::string want;   // the message
};

const BadPoint kBadPoints[] = {
    {"[1]", "[1]", "must be [master, slave] or [master, slave, linear|cubic], got 1 value"},
    {"[]", "[]", "must be [master, slave] or [master, slave, linear|cubic], got 0 values"},
    {"[1, 2, cubic, 4]", "[1, 2, cubic, 4]", "must be [master, slave] or [master, slave, linear|cubic], got 4 values"},
    {"7", "7", "must be [master, slave] or [master, slave, linear|cubic], got '7'"},
    {"{master: 1, slave: 2}", "{master", "must be [master, slave] or [master, slave, linear|cubic], got a mapping"},
    {"[x, 2]", "x", "master must be a finite number, got 'x'"},
    {"[1, .nan]", ".nan", "slave must be a finite number, got '.nan'"},
    {"[1, [2]]", "[2]", "slave must be a finite number, got '<non-scalar>'"},
    {"[1, 2, spline]", "spline", "segment type must be linear (0) or cubic (1), got 'spline'"},
    {"[1, 2, 3]", "3", "segment type must be linear (0) or cubic (1), got '3'"},
};

TEST(ConfigCamPoints, SameBadPointSameErrorInCamsAndArrays) {
  for (const BadPoint& b : kBadPoints) {
    SCOPED_TRACE(b.point);
    const std::string yc = in_cams(b.point), ya = in_arrays(b.point);
    const std::vector<Diagnostic> dc = refused(yc), da = refused(ya);
    // Exactly the one error: no follow-up error from the dropped point (the
    // cam keeps 2 good points), nothing else in the file is blamed.
    ASSERT_EQ(dc.size(), 1u) << ConfigError(dc).what();
    ASSERT_EQ(da.size(), 1u) << ConfigError(da).what();
    EXPECT_EQ(dc[0].message, b.want);
    EXPECT_EQ(da[0].message, dc[0].message);
    EXPECT_EQ(dc[0].key, "cams[0].points[1]");
    EXPECT_EQ(da[0].key, "arrays[0].values[1]");
    EXPECT_EQ(dc[0].file, "pts.yaml");
    EXPECT_EQ(dc[0].where.line, kLine);
    EXPECT_EQ(da[0].where.line, kLine);
    EXPECT_EQ(dc[0].where.column, column_of(yc, kLine, b.at)) << dc[0].str();
    EXPECT_EQ(da[0].where.column, column_of(ya, kLine, b.at)) << da[0].str();
    EXPECT_EQ(dc[0].str(), "pts.yaml:4:" + std::to_string(dc[0].where.column) + ": error: cams[0].points[1]: " + b.want);
  }
}

TEST(ConfigCamPoints, EveryBadPointIsReportedAndTheFileIsRefused) {
  // Two bad points in each section: all four are reported, and the load throws
  // (no Config comes back: neither the cam, nor the array, nor anything else
  // of the file is applied).
  auto file = [](const std::string& p1, const std::string& p3) {
    const std::string pts = "[[0, 0], " + p1 + ", [2, 2], " + p3 + "]";
    return kHead + "cams:\n  - {name: c, points: " + pts + "}\n" +
           "arrays:\n  - {name: a, type: CAM, size: 4, values: " + pts + "}\n";
  };
  const std::string y = file("[1]", "[3, 3, spline]");
  EXPECT_THROW((void)load_string(y), ConfigError);
  const std::vector<Diagnostic> d = refused(y);
  ASSERT_EQ(d.size(), 4u) << ConfigError(d).what();
  EXPECT_EQ(d[0].key, "cams[0].points[1]");
  EXPECT_EQ(d[1].key, "cams[0].points[3]");
  EXPECT_EQ(d[2].key, "arrays[0].values[1]");
  EXPECT_EQ(d[3].key, "arrays[0].values[3]");
  EXPECT_EQ(d[0].message, d[2].message);
  EXPECT_EQ(d[1].message, d[3].message);
  // The same file with the points fixed loads, with every point.
  const std::string good = file("[1, 1]", "[3, 3, cubic]");
  const Config c = load_string(good);
  ASSERT_EQ(c.cams.size(), 1u);
  ASSERT_EQ(c.arrays.size(), 1u);
  EXPECT_EQ(c.cams[0].points.size(), 4u);
  ASSERT_EQ(c.arrays[0].cam_values.size(), 4u);
  EXPECT_TRUE(c.cams[0].points[3].cubic);
  EXPECT_TRUE(c.arrays[0].cam_values[3].cubic);
}

TEST(ConfigCamPoints, SameErrorForAListThatIsNotAList) {
  const std::vector<Diagnostic> dc = refused(kHead + "cams:\n  - {name: c, points: 3}\n");
  const std::vector<Diagnostic> da = refused(kHead + "arrays:\n  - {name: c, type: CAM, size: 3, values: 3}\n");
  ASSERT_EQ(dc.size(), 1u) << ConfigError(dc).what();
  ASSERT_EQ(da.size(), 1u) << ConfigError(da).what();
  EXPECT_EQ(dc[0].key, "cams[0].points");
  EXPECT_EQ(da[0].key, "arrays[0].values");
  EXPECT_EQ(dc[0].message, "must be a list of [master, slave] or [master, slave, linear|cubic]");
  EXPECT_EQ(da[0].message, dc[0].message);
}

TEST(ConfigCamPoints, MastersMustIncreaseInACamButNotInACamArray) {
  // A `cams:` entry is one cam, computed by MCCP at load: its masters must increase.
  const std::vector<Diagnostic> d = refused(in_cams("[0, 5]"));
  ASSERT_EQ(d.size(), 1u) << ConfigError(d).what();
  EXPECT_EQ(d[0].key, "cams[0].points[1]");
  EXPECT_EQ(d[0].message, "master values must increase: 0 follows 0");
  // A CAM array may hold several cams, each given to MCCP from its own start
  // element: its values load in any order, and MCCP checks what it is given.
  test::RuntimeRig r(load_string(kHead + R"(arrays:
  - {name: pts, type: CAM, size: 6, values: [[0, 0], [1, 1], [2, 0], [0, 0], [1, 2, cubic], [2, 0]]}
  - {name: prof, type: CAM_PROFILE, size: 6}
)"));
  r.cycle();
  EXPECT_EQ(r.read("pts[3].Master"), 0.0);
  EXPECT_EQ(r.read("pts[4].Slave"), 2.0);
  EXPECT_EQ(r.read("pts[4].SegmentType"), 1.0);  // cubic
  EXPECT_EQ(r.read("pts[5].SegmentType"), 0.0);  // linear
  ASSERT_TRUE(r.execute("MCCP(mc, pts[3], 3, 0, 0, prof[0])"));
  r.cycle();
  ASSERT_TRUE(r.host.settled());
  EXPECT_EQ(r.read("mc.DN"), 1.0);
  EXPECT_EQ(r.read("prof[0].Status"), 2.0);
  // The whole array is not one cam: MCCP refuses it (ERR 29, illegal cam order).
  ASSERT_TRUE(r.execute("MCCP(mc2, pts[0], 6, 0, 0, prof[0])"));
  r.cycle();
  ASSERT_TRUE(r.host.settled());
  EXPECT_EQ(r.read("mc2.ER"), 1.0);
  EXPECT_EQ(r.read("mc2.ERR"), 29.0);
}

}  // namespace
}  // namespace canmotion::config
