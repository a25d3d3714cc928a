#include "fieldbus/cia402/drive_pdos.hpp"

#include "fieldbus/cia402/cia402.hpp"

namespace canmotion::cia402 {

DrivePdoSet default_drive_pdos(PdoProfile profile, std::uint8_t node, Mode mode) noexcept {
  using canopen::PdoDir;
  using canopen::PdoMap;
  namespace cob = canopen::cob;
  DrivePdoSet s;
  PdoMap r1{PdoDir::kRpdo, 1, cob::rpdo(1, node)};
  r1.add(obj::kControlword, 0, 16);
  if (mode == Mode::kInterpolatedPosition) r1.add(obj::kInterpolationDataRecord, obj::kInterpolationDataPositionSub, 32);
  else r1.add(obj::kTargetPosition, 0, 32);
  r1.finalize();
  PdoMap t1{PdoDir::kTpdo, 1, cob::tpdo(1, node)};
  t1.add(obj::kStatusword, 0, 16);
  t1.add(obj::kPositionActualValue, 0, 32);
  t1.finalize();
  s.rpdo[s.rpdo_count++] = r1;
  s.tpdo[s.tpdo_count++] = t1;
  if (profile == PdoProfile::kCspCsvCst) {
    PdoMap r2{PdoDir::kRpdo, 2, cob::rpdo(2, node)};
    r2.add(obj::kTargetVelocity, 0, 32);
    r2.add(obj::kTargetTorque, 0, 16);
    r2.add(obj::kModesOfOperation, 0, 8);
    r2.finalize();
    PdoMap t2{PdoDir::kTpdo, 2, cob::tpdo(2, node)};
    t2.add(obj::kVelocityActualValue, 0, 32);
    t2.add(obj::kTorqueActualValue, 0, 16);
    t2.add(obj::kModesOfOperationDisplay, 0, 8);
    t2.finalize();
    s.rpdo[s.rpdo_count++] = r2;
    s.tpdo[s.tpdo_count++] = t2;
  }
  return s;
}

canopen::NodeTraffic node_traffic(PdoProfile profile, std::uint32_t heartbeat_ms) noexcept {
  const DrivePdoSet s = default_drive_pdos(profile, 1);
  canopen::NodeTraffic t;
  for (std::uint8_t i = 0; i < s.rpdo_count && i < 4; ++i) t.rpdo_bytes[t.rpdo_count++] = s.rpdo[i].size_bytes;
  for (std::uint8_t i = 0; i < s.tpdo_count && i < 4; ++i) t.tpdo_bytes[t.tpdo_count++] = s.tpdo[i].size_bytes;
  t.heartbeat_ms = heartbeat_ms;
  return t;
}

}  // namespace canmotion::cia402
