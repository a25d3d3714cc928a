#include "fieldbus/canopen/pdo.hpp"

namespace canmotion::canopen {

bool queue_pdo_configuration(const PdoMap& map, SdoClient& sdo, std::uint32_t tag) noexcept {
  const std::uint32_t cob = map.cob_id & 0x7FFu;
  bool ok = sdo.download_value<std::uint32_t>(map.comm_index(), 1, cob | kPdoInvalid, tag);
  ok = ok && sdo.download_value<std::uint8_t>(map.map_index(), 0, 0, tag);
  for (std::uint8_t i = 0; i < map.count && ok; ++i)
    ok = sdo.download_value<std::uint32_t>(map.map_index(), static_cast<std::uint8_t>(i + 1), map.entries[i].raw(), tag);
  ok = ok && sdo.download_value<std::uint8_t>(map.map_index(), 0, map.count, tag);
  ok = ok && sdo.download_value<std::uint8_t>(map.comm_index(), 2, map.transmission_type, tag);
  ok = ok && sdo.download_value<std::uint32_t>(map.comm_index(), 1, cob, tag);
  return ok;
}

bool queue_pdo_disable(PdoDir dir, std::uint8_t number, std::uint8_t node, SdoClient& sdo, std::uint32_t tag) noexcept {
  const auto index = static_cast<std::uint16_t>((dir == PdoDir::kRpdo ? 0x1400 : 0x1800) + number - 1);
  const std::uint32_t cob = dir == PdoDir::kRpdo ? cob::rpdo(number, node) : cob::tpdo(number, node);
  return sdo.download_value<std::uint32_t>(index, 1, cob | kPdoInvalid, tag);
}

}  // namespace canmotion::canopen
