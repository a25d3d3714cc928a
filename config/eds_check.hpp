#pragma once
/// \file
/// The configuration against the drives' EDS files (`drive.eds:`, CiA 306):
/// before any bus is touched, what the master will write and map for each
/// CIP axis (its boot configuration, built by cia402::DriveProxy itself) is
/// checked with fieldbus/eds's checker. Each refusal names the axis, the
/// object, the EDS file and line, and the YAML key to change.
///
/// Not realtime: set-up only (allocates, reads files).

#include <cstddef>
#include <vector>

#include "config/config.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/eds/check.hpp"

namespace canmotion::config {

/// The boot SDO writes the master makes to CIP axis `a`'s drive, in order
/// (cia402::DriveProxy's own list for drive_config(a, ...)); optional writes
/// to objects the axis's EDS lacks are not in it.
[[nodiscard]] std::vector<cia402::BootWrite> boot_writes(const AxisSettings& a, const BusSettings& bus, double period_s,
                                                         std::size_t axis_index);

/// What the master intends for CIP axis `a`'s drive, for eds::check(): every
/// boot write (optional ones marked so), every mapped object, the PDO
/// counts, the modes it needs in 0x6502 (optional: an EDS without 0x6502 is
/// not refused for it). Keys are the YAML keys (DriveConfig::hints).
[[nodiscard]] eds::Requirements drive_requirements(const AxisSettings& a, const BusSettings& bus, double period_s,
                                                   std::size_t axis_index);

/// Load each CIP axis's `drive.eds` (each file once), fill eds_data and
/// dictionary, and check drive_requirements() against it: refusals and
/// unreadable files are errors, optional objects left out (0x1016, 0x6502)
/// warnings, appended to `diags`. Called by load_file / load_string once
/// the configuration has no other error.
void check_drive_descriptions(Config& cfg, std::vector<Diagnostic>& diags);

/// The MDS objects (`direct_control:`) against axis `a`'s EDS, before its
/// requirements are built: an object whose address holds another object in
/// the file (another name at the project's default 0x2010..0x2022, or a
/// non-integer type anywhere) is marked DriveSettings::mds_not_in_eds, so it
/// is not written. A write the configuration asks for (ramp objects, SLAT
/// with `slat:`) is then an error naming the direct_control key and the
/// drive.mds_objects key that places the object; the SLAT-disabled writes
/// made without `slat:` are left out with a warning. `who` names the axis.
/// `drive.dcf` (README "DCF download"): fills DriveSettings::dcf.writes from
/// the DCF's ParameterValues of writable objects, leaving out what the
/// master configures itself; a value on an object the master writes with
/// another value is an error naming the DCF line and the master's key.
/// Called before the requirements are checked (the writes are among them).
void dcf_download(const Config& cfg, AxisSettings& a, std::size_t ai, const BusSettings& bus, const std::string& who,
                  std::vector<Diagnostic>& diags);

void check_mds_objects_in_eds(const Config& cfg, AxisSettings& a, std::size_t ai, const std::string& who,
                              std::vector<Diagnostic>& diags);

}  // namespace canmotion::config
