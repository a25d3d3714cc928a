#include "fieldbus/cia402/units.hpp"

namespace canmotion::cia402::units {

namespace {
struct Parts {
  int prefix;
  std::uint8_t num;
  std::uint8_t den;
  std::uint8_t reserved;
};
constexpr Parts split(std::uint32_t si) noexcept {
  return {static_cast<std::int8_t>(si >> 24), static_cast<std::uint8_t>(si >> 16), static_cast<std::uint8_t>(si >> 8),
          static_cast<std::uint8_t>(si)};
}
double pow10(int p) noexcept {
  double r = 1.0;
  for (int i = 0; i < (p < 0 ? -p : p); ++i) r *= 10.0;
  return p < 0 ? 1.0 / r : r;
}
}  // namespace

std::optional<double> counts_per_unit(std::uint32_t si, const EncoderResolution& res, bool acceleration) noexcept {
  const Parts p = split(si);
  if (p.reserved != 0 || p.prefix < -9 || p.prefix > 9) return std::nullopt;
  double counts = 0;
  if (p.num == 0xB5) {
    counts = 1.0;
  } else if (p.num == 0xB4) {
    if (!res.known()) return std::nullopt;
    counts = static_cast<double>(res.increments) / static_cast<double>(res.revolutions);
  } else {
    return std::nullopt;
  }
  double seconds = 0;  // of the denominator
  if (!acceleration && p.den == 0x03) seconds = 1.0;
  else if (!acceleration && p.den == 0x47) seconds = 60.0;
  else if (acceleration && p.den == 0x57) seconds = 1.0;
  else return std::nullopt;
  return pow10(p.prefix) * counts / seconds;
}

std::string_view unknown_reason(std::uint32_t si, const EncoderResolution& res, bool acceleration) noexcept {
  const Parts p = split(si);
  if (p.reserved != 0 || p.prefix < -9 || p.prefix > 9) return "not a unit code (byte 0 must be 0, the prefix -9 .. 9)";
  if (p.num != 0xB5 && p.num != 0xB4) return "its numerator is neither increments (0xB5) nor revolutions (0xB4)";
  if (p.num == 0xB4 && !res.known())
    return "revolutions need the counts per motor revolution, and 0x608F (position encoder resolution) gives none "
           "(no value, absent, or behind a 0x6091 gear ratio other than 1:1)";
  if (acceleration) return "its denominator is not s^2 (0x57)";
  return "its denominator is neither s (0x03) nor min (0x47)";
}

std::optional<std::uint32_t> velocity_unit_code(std::string_view name) noexcept {
  if (name == "inc/s") return kIncPerSecond;
  if (name == "rpm") return kRpm;
  return std::nullopt;
}

}  // namespace canmotion::cia402::units
