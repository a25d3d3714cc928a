#pragma once
/// \file
/// Drive units (CiA 402 factor group): what one unit of a drive's velocity
/// or acceleration value is in encoder increments (counts). Pure, sans-IO,
/// no allocation: used by the configuration (from the EDS/DCF), by the
/// emulator (from its own dictionary) and by tests.
///
/// 0x60A9 (SI unit velocity) and 0x60AA (SI unit acceleration) are UNSIGNED32
/// in the CiA 402 / DR 303-2 notation: byte 3 the prefix (a signed power of
/// ten), byte 2 the numerator unit, byte 1 the denominator unit, byte 0
/// reserved (0). Examples: 0x00B44700 = rev/min (rpm), 0x00B50300 = inc/s,
/// 0xFFB44700 = 0.1 rpm, 0x00B55700 = inc/s^2.
///
/// 0x60A8 (SI unit position) has the same layout with denominator 0: the
/// drive's position unit, in which 0x607A/0x6064 count (absent: increments).
///
/// Numerators known here: 0xB5 increments, 0xB4 revolutions (of the motor:
/// needs 0x608F position encoder resolution, increments per motor
/// revolutions, for a position in increments, or 0x6092 feed constant for
/// another position unit, and no gear 0x6091 other than 1:1), and the
/// position unit's own numerator (0x01 metre, 0x41 degree, ...: a power of
/// ten apart). Denominators: 0x03 s, 0x47 min, 0x57 s^2 (acceleration).
/// Anything else is unknown: never guessed.

#include <cstdint>
#include <optional>
#include <string_view>

namespace canmotion::cia402::units {

inline constexpr std::uint16_t kSiUnitPosition = 0x60A8;
inline constexpr std::uint16_t kSiUnitVelocity = 0x60A9;
inline constexpr std::uint16_t kSiUnitAcceleration = 0x60AA;
inline constexpr std::uint16_t kPositionEncoderResolution = 0x608F;  ///< :1 encoder increments, :2 motor revolutions
inline constexpr std::uint16_t kGearRatio = 0x6091;                  ///< :1 motor revolutions, :2 shaft revolutions
inline constexpr std::uint16_t kFeedConstant = 0x6092;               ///< :1 feed, :2 shaft revolutions
inline constexpr std::uint16_t kRatedTorque = 0x6076;
inline constexpr std::uint8_t kIncrements = 0xB5;   ///< numerator: increments
inline constexpr std::uint8_t kRevolutions = 0xB4;  ///< numerator: revolutions

inline constexpr std::uint32_t kIncPerSecond = 0x00B50300;
inline constexpr std::uint32_t kRpm = 0x00B44700;
inline constexpr std::uint32_t kIncPerSecond2 = 0x00B55700;

/// The drive's position encoder resolution (0x608F), when known.
struct EncoderResolution {
  std::uint32_t increments = 0;  ///< 0x608F:1
  std::uint32_t revolutions = 0;  ///< 0x608F:2
  [[nodiscard]] constexpr bool known() const noexcept { return increments != 0 && revolutions != 0; }
};

/// The drive's factor group as far as it is known: what its position unit
/// (the unit of 0x607A/0x6064, in which `conversion_constant` counts; the
/// "counts" of this file) is per motor revolution. Every field 0: absent.
struct FactorGroup {
  std::uint32_t position = 0;   ///< 0x60A8 SI unit position (0: absent, increments)
  EncoderResolution res;        ///< 0x608F:1/2
  std::uint32_t gear_motor = 0; ///< 0x6091:1 motor shaft revolutions (0: absent, no gear)
  std::uint32_t gear_shaft = 0; ///< 0x6091:2 driving shaft revolutions
  std::uint32_t feed = 0;       ///< 0x6092:1 feed, in position units (0: absent)
  std::uint32_t feed_shaft = 0; ///< 0x6092:2 driving shaft revolutions
  /// True when the position unit is increments (of the motor's encoder).
  [[nodiscard]] bool position_in_increments() const noexcept;
  /// A gear other than 1:1 (or one half given): motor and driving shaft
  /// revolutions differ, so "revolutions" in a velocity unit is ambiguous.
  [[nodiscard]] constexpr bool gear_other() const noexcept {
    return (gear_motor != 0 || gear_shaft != 0) && gear_motor != gear_shaft;
  }
  /// Position units per motor revolution: 0x608F for increments, else the
  /// feed constant (0x6092) through the gear (0x6091); nothing when unknown.
  [[nodiscard]] std::optional<double> per_motor_revolution() const noexcept;
};

/// Counts (position units) per one unit of a value in `si` (a velocity in
/// counts/s, an acceleration in counts/s^2), or nothing when the code or the
/// factors it needs are unknown. `acceleration` selects which denominators
/// fit. Numerators: increments (0xB5), motor revolutions (0xB4, gear 1:1),
/// or the position unit's own (e.g. 0x01 metre with 0x60A8 in mm).
[[nodiscard]] std::optional<double> counts_per_unit(std::uint32_t si, const FactorGroup& f, bool acceleration) noexcept;

/// Why counts_per_unit() gave nothing, in words (a static string).
[[nodiscard]] std::string_view unknown_reason(std::uint32_t si, const FactorGroup& f, bool acceleration) noexcept;

/// A velocity unit as written in the configuration (`drive.units.velocity`):
/// "inc/s" or "rpm"; nothing for another word.
[[nodiscard]] std::optional<std::uint32_t> velocity_unit_code(std::string_view name) noexcept;

}  // namespace canmotion::cia402::units
