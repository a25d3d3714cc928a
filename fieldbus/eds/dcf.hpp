#pragma once
/// \file
/// A DCF (device configuration file in CiA 306's INI text format, an EDS
/// with the values to configure) of what a master writes to one node at
/// boot: only the written sub-objects, not the device's whole dictionary.
/// It is not a "concise DCF" (CiA 302-3, object 0x1F22: a binary list of
/// index, sub-index, size and data). For a commissioning engineer to review:
/// [DeviceComissioning] (node-ID, baud rate, name), the [DeviceInfo] of the
/// node's EDS when there is one, and one section per written sub-object
/// with its ParameterValue (the last value written: the PDO procedure
/// writes some objects twice). Data and access types come from the EDS,
/// else from canopen's object table, else UNSIGNEDn of the write's size.
/// A comment above each value names the configuration key behind it.
///
/// Pure (no I/O); set-up only (allocates). eds::parse() reads it back.

#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/eds/eds.hpp"

namespace canmotion::eds {

/// One SDO write of the master (expedited: 1..4 bytes).
struct DcfWrite {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t size = 4;
  std::uint32_t value = 0;
  std::string key;  ///< the configuration key behind it ("" when none)
};

struct DcfSpec {
  std::uint8_t node_id = 1;
  std::uint16_t baudrate_kbit = 1000;
  std::string node_name;     ///< e.g. the axis name
  const Eds* eds = nullptr;  ///< the node's EDS, or null
  std::string created_by = "canmotiond --write-dcf";
  std::vector<DcfWrite> writes;  ///< in the order the master makes them
};

/// The DCF text.
[[nodiscard]] std::string format_dcf(const DcfSpec& spec);

}  // namespace canmotion::eds
