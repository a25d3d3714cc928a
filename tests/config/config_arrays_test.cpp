// The `arrays:` section (issue #5): CAM, CAM_PROFILE and REAL array tags,
// their validation messages (file:line:column: key), and the runtime built
// from them (the array tags exist and MCCP runs on them).
#include <gtest/gtest.h>

#include "tests/config/config_errors.hpp"
#include "tests/config/runtime_rig.hpp"

#include <string>

#include "config/config.hpp"
#include "config/runtime.hpp"

namespace canmotion::config {
namespace {

const std::string kHead = R"(axes:
  - name: X
    type: AXIS_VIRTUAL
    max_speed: 100
cams:
  - name: ref
    points: [[0, 0, cubic], [1, 2, cubic], [2, 0]]
)";

std::string errors_of(const std::string& yaml) { return test::errors_of(yaml, "arr.yaml"); }

TEST(ConfigArrays, LoadsTheThreeTypesWithInitialValues) {
  const Config c = load_string(kHead + R"(arrays:
  - name: pts
    type: CAM
    size: 100
    values: [[0, 0, cubic], [1, 2], [2, 0, linear]]
  - {name: prof, type: cam_profile, size: 100}
  - {name: ed, type: REAL, size: 4, values: [0, 2.5]}
)", "arr.yaml");
  ASSERT_EQ(c.arrays.size(), 3u);
  EXPECT_EQ(c.arrays[0].type, ArraySettings::Type::kCam);
  EXPECT_EQ(c.arrays[0].size, 100u);
  ASSERT_EQ(c.arrays[0].cam_values.size(), 3u);
  EXPECT_TRUE(c.arrays[0].cam_values[0].cubic);
  EXPECT_FALSE(c.arrays[0].cam_values[1].cubic);
  EXPECT_EQ(c.arrays[1].type, ArraySettings::Type::kCamProfile);
  EXPECT_EQ(c.arrays[2].real_values, (std::vector<double>{0, 2.5}));
}

TEST(ConfigArrays, ErrorsNameFileLineColumnAndKey) {
  struct Case {
    std::string yaml;
    std::string want;
  };
  const Case cases[] = {
      {"arrays:\n  - {name: a, type: CAM}\n", "arr.yaml:9:5: error: arrays[0].size: missing: the number of elements, 1 .. 4096"},
      {"arrays:\n  - {name: a, type: CAM, size: 4097}\n", "arrays[0].size: must be 1 .. 4096 elements, got 4097"},
      {"arrays:\n  - {name: a, type: INT, size: 3}\n", "arrays[0].type: 'INT' is not one of: CAM (0), CAM_PROFILE (1), REAL (2)"},
      {"arrays:\n  - {name: a, type: REAL, size: 2, values: [1, 2, 3]}\n", "arrays[0].values: 3 values do not fit in size 2"},
      {"arrays:\n  - {name: a, type: REAL, size: 2, values: [1, x]}\n", "arrays[0].values[1]: must be a finite number, got 'x'"},
      {"arrays:\n  - {name: a, type: CAM, size: 2, values: [[0, 1, spline]]}\n",
       "arrays[0].values[0]: segment type must be linear (0) or cubic (1), got 'spline'"},
      {"arrays:\n  - {name: a, type: CAM_PROFILE, size: 2, values: [1]}\n",
       "arrays[0].values: a CAM_PROFILE array has no initial values: MCCP calculates it"},
      {"arrays:\n  - {name: ref, type: CAM, size: 2}\n", "arrays[0].name: tag name 'ref' is already used at line 6"},
      {"arrays:\n  - {name: X, type: CAM, size: 2}\n", "arrays[0].name: tag name 'X' is already used at line 2"},
      {"arrays:\n  - {name: 'a.b', type: REAL, size: 2}\n", "arrays[0].name: 'a.b' is not a tag name"},
      {"arrays:\n  - {name: 'a-b', type: REAL, size: 2}\n",
       "arrays[0].name: 'a-b' is not a tag name (a letter or '_', then letters, digits or '_')"},
      {"arrays:\n  - {name: 2a, type: REAL, size: 2}\n", "arrays[0].name: '2a' is not a tag name"},
      {"arrays:\n  - {name: a, type: REAL, size: 1000}\n  - {name: b, type: REAL, size: 25}\n",
       "arrays[1].size: REAL arrays may hold 1024 elements together; this one brings the total to 1025"},
      {"arrays:\n  - {name: a, type: REAL, size: 2, sise: 3}\n", "arrays[0].sise: unknown key 'sise'; did you mean 'size'?"},
      {"arrays: {name: a}\n", "arrays: must be a list of {name, type, size, values}"},
  };
  for (const Case& k : cases) {
    const std::string e = errors_of(kHead + k.yaml);
    EXPECT_NE(e.find(k.want), std::string::npos) << "want: " << k.want << "\ngot: " << e;
  }
}

TEST(ConfigArrays, RealElementBoundIsTheControllers) {
  // One bound (rt::kMaxRealElements): what the loader accepts, the Controller
  // builds; one element more is refused at load, naming the bound.
  const std::size_t max = rt::kMaxRealElements;
  auto reals = [](std::size_t a, std::size_t b) {
    return kHead + "arrays:\n  - {name: a, type: REAL, size: " + std::to_string(a) + "}\n  - {name: b, type: REAL, size: " +
           std::to_string(b) + "}\n";
  };
  const Runtime rt = simulated_runtime(load_string(reals(max - 1, 1), "arr.yaml"));
  ASSERT_NE(rt.controller, nullptr);
  std::string e = errors_of(reals(max, 1));
  EXPECT_NE(e.find("arrays[1].size: REAL arrays may hold " + std::to_string(max) + " elements together; this one "
                   "brings the total to " + std::to_string(max + 1)),
            std::string::npos)
      << e;
  e = errors_of(reals(max + 1, 1));
  EXPECT_NE(e.find("arrays[0].size: must be 1 .. " + std::to_string(max) + " elements, got " + std::to_string(max + 1)),
            std::string::npos)
      << e;
}

TEST(ConfigArrays, RuntimeHasTheArrayTagsAndMccpRunsOnThem) {
  test::RuntimeRig r(load_string(kHead + R"(arrays:
  - {name: pts, type: CAM, size: 10, values: [[0, 0, cubic], [1, 2, cubic], [2, 0]]}
  - {name: prof, type: CAM_PROFILE, size: 10}
  - {name: ed, type: REAL, size: 2, values: [0.5, 1]}
)", "arr.yaml"));
  r.cycle();
  EXPECT_EQ(r.read("pts[1].Slave"), 2.0);
  EXPECT_EQ(r.read("ed[0]"), 0.5);
  EXPECT_EQ(r.read("prof[0].Status"), 0.0);
  EXPECT_EQ(r.read("ref[0].Status"), 2.0);
  ASSERT_TRUE(r.execute("MCCP(mc, pts[0], 3, 0, 0, prof[0])"));
  r.cycle();
  ASSERT_TRUE(r.host.settled());
  EXPECT_EQ(r.read("mc.DN"), 1.0);
  EXPECT_EQ(r.read("prof[0].Status"), 2.0);
}

}  // namespace
}  // namespace canmotion::config
