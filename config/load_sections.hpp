#pragma once
// Internal to config/: the loader's sections, one file each. Each reads its
// part of the document into the data model of config.hpp, reporting through
// the Reader (yaml_reader.hpp); cross_check() then checks the parts against
// each other. loader.cpp walks the document and calls them.

#include <map>
#include <string>

#include "config/config.hpp"
#include "config/yaml_reader.hpp"

#include "fieldbus/canopen/object_names.hpp"

namespace canmotion::config::load {

// load_controller.cpp
/// `controller:`.
[[nodiscard]] ControllerSettings controller(Reader& r, const YAML::Node& n);
/// One `buses:` entry at `path` (`buses[i]`).
[[nodiscard]] BusSettings bus(Reader& r, const YAML::Node& n, const std::string& path);

// load_drive.cpp
/// A `drive:` block (of `drives:` at `path` "drives", or of an axis) over `d`:
/// the keys present override the defaults already in `d`.
void drive(Reader& r, const YAML::Node& n, const std::string& path, DriveSettings& d);
/// An `sdo_writes` entry with `type:` (or `file:`, or an object whose table
/// type is a string, domain, 64-bit or real type): fills s.type and s.bytes
/// (prepared at load) and returns true, errors reported naming the key and
/// the type; false when the entry takes the integer path (size/value).
bool typed_sdo_write(Reader& r, const YAML::Node& e, const std::string& p, const canopen::ObjectInfo* known,
                     SdoWrite& s);
/// UTF-8 -> UTF-16LE code units (UNICODE_STRING on the wire); nullopt on invalid UTF-8.
[[nodiscard]] std::optional<std::vector<std::uint8_t>> utf16le(const std::string& s);

// load_axis.cpp
/// One `axes:` entry at `path`, its drive settings starting from `defaults` (`drives:`).
[[nodiscard]] AxisSettings axis(Reader& r, const YAML::Node& n, const std::string& path, const DriveSettings& defaults);

// load_cams.cpp
/// One `cams:` entry.
[[nodiscard]] CamSettings cam(Reader& r, const YAML::Node& n, const std::string& path);
/// One `arrays:` entry: {name, type: CAM | CAM_PROFILE | REAL, size, values}.
[[nodiscard]] ArraySettings array(Reader& r, const YAML::Node& n, const std::string& path);

// load_coordinate_systems.cpp
/// One `coordinate_systems:` entry.
[[nodiscard]] CoordinateSystemSettings coordinate_system(Reader& r, const YAML::Node& n, const std::string& path);

// cross_check.cpp
/// The parts against each other: unique names, tag names, registry
/// capacities, coordinate system members, MDS object placement, the period
/// against 0x60C2, per bus the COB-IDs, heartbeats and the bus budget, each
/// CIP axis's bus and node.
void cross_check(Reader& r, const Config& cfg);

}  // namespace canmotion::config::load
