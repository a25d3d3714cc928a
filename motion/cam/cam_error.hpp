#pragma once
/// \file
/// Logix .ERR codes used by the cam code (MCCP, and the profile checks MATC /
/// MAPC make before camming).
///
/// The numbers are the Logix numbers (shared/reference/logix-motion.md §3.1,
/// ICS CommandResultDescriptor; 13 is confirmed in RM002H p.255). They are
/// defined here, locally, because the cam library is self-contained; the
/// motion-core error enum should carry the same numbers, and this enum
/// converts to it with a plain static_cast of the underlying value.
#include <cstdint>
#include <string_view>

namespace canmotion::motion::cam {

/// Motion instruction ERR values that cam code can produce (Logix numbers).
enum class CamError : std::int16_t {
  None = 0,
  ParameterOutOfRange = 13,        ///< PARAMETER_OUT_OF_RANGE; EXERR = operand index
  IllegalCamLength = 26,           ///< Length < 2, or Cam index + Length past the CAM array
  IllegalCamProfileLength = 27,    ///< CAM_PROFILE array has fewer elements than Length
  IllegalCamType = 28,             ///< SegmentType not 0 (linear) or 1 (cubic)
  IllegalCamOrder = 29,            ///< Master values not strictly increasing
  CamProfileBeingCalculated = 30,  ///< CamProfile[0].Status == 1
  CamProfileBeingUsed = 31,        ///< CamProfile[0].Status > 2 (in use by a cam)
  CamProfileNotCalculated = 32,    ///< camming with Status 0 or 1
};

/// Logix-style name of a cam error ("ILLEGAL_CAM_ORDER", ...). Realtime-safe.
[[nodiscard]] constexpr std::string_view to_string(CamError e) noexcept {
  switch (e) {
    case CamError::None: return "NO_ERROR";
    case CamError::ParameterOutOfRange: return "PARAMETER_OUT_OF_RANGE";
    case CamError::IllegalCamLength: return "ILLEGAL_CAM_LENGTH";
    case CamError::IllegalCamProfileLength: return "ILLEGAL_CAM_PROFILE_LENGTH";
    case CamError::IllegalCamType: return "ILLEGAL_CAM_TYPE";
    case CamError::IllegalCamOrder: return "ILLEGAL_CAM_ORDER";
    case CamError::CamProfileBeingCalculated: return "CAM_PROFILE_BEING_CALCULATED";
    case CamError::CamProfileBeingUsed: return "CAM_PROFILE_BEING_USED";
    case CamError::CamProfileNotCalculated: return "CAM_PROFILE_NOT_CALCULATED";
  }
  return "UNKNOWN_CAM_ERROR";
}

/// The .ERR number of a cam error. Realtime-safe.
[[nodiscard]] constexpr std::int16_t err_code(CamError e) noexcept {
  return static_cast<std::int16_t>(e);
}

}  // namespace canmotion::motion::cam
