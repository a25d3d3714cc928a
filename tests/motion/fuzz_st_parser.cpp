// libFuzzer target for the ST call parser and binder (canmotion_fuzz).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "motion/planner.hpp"
#include "motion/st_parser.hpp"

using namespace canmotion::motion;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Symbols sym = [] {
    Symbols s;
    s.axes["x"] = 0;
    s.axes["y"] = 1;
    s.controls["c"] = 0;
    s.groups["g"] = 0;
    s.cams["cam"] = 0;
    s.cam_profiles["prof"] = 0;
    s.numeric_tags["t"] = 1.0;
    return s;
  }();
  static Planner* planner = [] {
    auto* p = new Planner(0.001);
    AxisConfig c;
    p->configure_axis(0, c);
    p->configure_axis(1, c);
    return p;
  }();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ParseResult r = parse_st_call(text);
  if (r.ok()) {
    Request q;
    if (!bind_call(*r.call, sym, q)) planner->execute(q);  // whatever parses must execute without UB
  }
  return 0;
}
