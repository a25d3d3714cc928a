#pragma once
/// \file
/// An emulated drive described by an EDS (cia402-emu --eds FILE): the
/// object set of the file, so that tests can stand in for a vendor's drive.
/// Objects absent from the file abort 0x06020000 (0x06090011 for a missing
/// sub-index), the PDO count follows from the PDO parameter objects the
/// file has, PDO mapping flags, access types and defaults come from it.
///
/// Set-up only (allocates).

#include <cstdint>
#include <vector>

#include "fieldbus/eds/eds.hpp"
#include "fieldbus/emulator/emulator.hpp"

namespace canmotion::emulator {

/// Every sub-object of `e` as the drive with node-ID `node` serves it
/// ($NODEID-relative defaults resolved), for EmulatorConfig::served.
[[nodiscard]] std::vector<ServedObject> served_objects(const eds::Eds& e, std::uint8_t node);

}  // namespace canmotion::emulator
