// The loader's `cams:` and `arrays:` sections, and the cam point parser
// they share.
#include <optional>

#include "config/load_sections.hpp"
#include "rt/controller/controller.hpp"

namespace canmotion::config::load {

namespace {

/// One cam point, `[master, slave]` or `[master, slave, linear|cubic]` (a
/// Logix CAM element: Master, Slave, SegmentType). The one parser of both
/// `cams[].points[]` and a CAM array's `values[]`: the same rules and the same
/// messages, reported at the offending element. nullopt once reported.
std::optional<CamPoint> cam_point(Reader& r, const YAML::Node& p, const std::string& key) {
  if (!p.IsSequence() || (p.size() != 2 && p.size() != 3)) {
    const std::string got = p.IsSequence() ? fmt::format("{} value{}", p.size(), p.size() == 1 ? "" : "s")
                            : p.IsScalar() ? fmt::format("'{}'", p.Scalar())
                            : p.IsMap()    ? std::string("a mapping")
                                           : std::string("nothing");
    r.error(p, key, fmt::format("must be [master, slave] or [master, slave, linear|cubic], got {}", got));
    return std::nullopt;
  }
  CamPoint cp;
  bool ok = r.finite_number(p[0], key, "master ", cp.master);
  ok = r.finite_number(p[1], key, "slave ", cp.slave) && ok;
  if (p.size() == 3) {
    const std::string t = p[2].IsScalar() ? lower_compact(p[2].Scalar()) : std::string();
    if (t == "cubic" || t == "1") cp.cubic = true;
    else if (t != "linear" && t != "0") {
      r.error(p[2], key, fmt::format("segment type must be linear (0) or cubic (1), got '{}'",
                                     p[2].IsScalar() ? p[2].Scalar() : "<non-scalar>"));
      ok = false;
    }
  }
  if (!ok) return std::nullopt;
  return cp;
}

/// A list of cam points (see cam_point): a `cams:` entry's `points`, or a CAM
/// array's `values`. `increasing`: master values must strictly increase (a
/// `cams:` entry is one cam, computed by MCCP at load). A CAM array's values
/// are not checked for order: one array may hold several cams, each given to
/// MCCP from its own start element, and MCCP checks the points it is given
/// (ERR 29). Every bad point is reported; returns the good ones.
std::vector<CamPoint> cam_points(Reader& r, const YAML::Node& list, const YAML::Node& parent, const std::string& key,
                                 bool increasing) {
  std::vector<CamPoint> out;
  if (!list || !list.IsSequence()) {
    r.error(list ? list : parent, key, "must be a list of [master, slave] or [master, slave, linear|cubic]");
    return out;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string k = fmt::format("{}[{}]", key, i);
    const std::optional<CamPoint> cp = cam_point(r, list[i], k);
    if (!cp) continue;
    if (increasing && !out.empty() && cp->master <= out.back().master)
      r.error(list[i], k, fmt::format("master values must increase: {} follows {}", cp->master, out.back().master));
    out.push_back(*cp);
  }
  return out;
}

}  // namespace

CamSettings cam(Reader& r, const YAML::Node& n, const std::string& path) {
  CamSettings c;
  c.where = r.loc(n);
  if (!r.check_map(n, path, {"name", "points", "start_slope", "end_slope"})) return c;
  if (r.required(n, path, "name", "every cam needs a name")) r.string(n, path, "name", c.name);
  r.scalar(n, path, "start_slope", c.start_slope, -1e12, 1e12);
  r.scalar(n, path, "end_slope", c.end_slope, -1e12, 1e12);
  const YAML::Node pts = n["points"];
  c.points = cam_points(r, pts, n, path + ".points", true);
  if (pts && pts.IsSequence() && c.points.size() < 2)
    r.error(pts, path + ".points", fmt::format("needs at least 2 points, got {}", c.points.size()));
  return c;
}

/// One `arrays:` entry: {name, type: CAM | CAM_PROFILE | REAL, size, values}.
ArraySettings array(Reader& r, const YAML::Node& n, const std::string& path) {
  using T = ArraySettings::Type;
  ArraySettings a;
  a.where = r.loc(n);
  if (!r.check_map(n, path, {"name", "type", "size", "values"})) return a;
  if (r.required(n, path, "name", "every array needs a name")) r.string(n, path, "name", a.name);
  if (r.required(n, path, "type", "CAM, CAM_PROFILE or REAL"))
    r.enumeration(n, path, "type", a.type, {{"CAM", T::kCam}, {"CAM_PROFILE", T::kCamProfile}, {"REAL", T::kReal}});
  const std::size_t max = a.type == T::kReal ? rt::kMaxRealElements : ArraySettings::kMaxCamElements;
  if (r.required(n, path, "size", fmt::format("the number of elements, 1 .. {}", max)))
    r.scalar(n, path, "size", a.size, std::size_t{1}, max, "elements");
  const YAML::Node v = n["values"];
  if (!v) return a;
  const std::string vp = path + ".values";
  if (a.type == T::kCamProfile) {
    r.error(v, vp, "a CAM_PROFILE array has no initial values: MCCP calculates it");
    return a;
  }
  if (v.IsSequence() && a.size > 0 && v.size() > a.size)
    r.error(v, vp, fmt::format("{} values do not fit in size {}", v.size(), a.size));
  if (a.type == T::kCam) {
    a.cam_values = cam_points(r, v, n, vp, false);
    return a;
  }
  if (!v.IsSequence()) {
    r.error(v, vp, "must be a list of numbers");
    return a;
  }
  for (std::size_t i = 0; i < v.size(); ++i) {
    double x = 0;
    r.finite_number(v[i], fmt::format("{}[{}]", vp, i), "", x);
    a.real_values.push_back(x);
  }
  return a;
}

}  // namespace canmotion::config::load
