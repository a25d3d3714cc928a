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

bool FactorGroup::position_in_increments() const noexcept {
  const Parts p = split(position);
  return position == 0 || (p.num == kIncrements && p.den == 0 && p.reserved == 0 && p.prefix == 0);
}

std::optional<double> FactorGroup::per_motor_revolution() const noexcept {
  if (position_in_increments()) {
    if (!res.known()) return std::nullopt;
    return static_cast<double>(res.increments) / static_cast<double>(res.revolutions);
  }
  if (feed == 0 || feed_shaft == 0) return std::nullopt;  // no feed constant: the mechanics are not known
  if ((gear_motor == 0) != (gear_shaft == 0)) return std::nullopt;
  const double shaft_per_motor = gear_motor == 0 ? 1.0 : static_cast<double>(gear_shaft) / gear_motor;
  return static_cast<double>(feed) / static_cast<double>(feed_shaft) * shaft_per_motor;
}

namespace {
/// Seconds of a denominator, 0 when it does not fit.
double seconds_of(std::uint8_t den, bool acceleration) noexcept {
  if (!acceleration && den == 0x03) return 1.0;
  if (!acceleration && den == 0x47) return 60.0;
  if (acceleration && den == 0x57) return 1.0;
  return 0.0;
}
bool valid(const Parts& p) noexcept { return p.reserved == 0 && p.prefix >= -9 && p.prefix <= 9; }
}  // namespace

std::optional<double> counts_per_unit(std::uint32_t si, const FactorGroup& f, bool acceleration) noexcept {
  const Parts p = split(si);
  const Parts pos = split(f.position);
  const double seconds = seconds_of(p.den, acceleration);
  if (!valid(p) || seconds == 0.0) return std::nullopt;
  if (f.position != 0 && (!valid(pos) || pos.den != 0)) return std::nullopt;  // 0x60A8 not a position unit
  double per = 0;  // position units per numerator unit (with its prefix)
  if (f.position_in_increments() ? p.num == kIncrements : (p.num == pos.num && p.num != kRevolutions)) {
    per = pow10(p.prefix - (f.position == 0 ? 0 : pos.prefix));  // the same base unit
  } else if (p.num == kIncrements) {  // increments, the position in another unit
    const auto rev = f.per_motor_revolution();
    if (!rev || !f.res.known()) return std::nullopt;
    per = pow10(p.prefix) * *rev * static_cast<double>(f.res.revolutions) / static_cast<double>(f.res.increments);
  } else if (p.num == kRevolutions) {
    const auto rev = f.per_motor_revolution();
    if (!rev || f.gear_other()) return std::nullopt;
    per = pow10(p.prefix) * *rev;
  } else {
    return std::nullopt;
  }
  return per / seconds;
}

std::string_view unknown_reason(std::uint32_t si, const FactorGroup& f, bool acceleration) noexcept {
  const Parts p = split(si);
  const Parts pos = split(f.position);
  if (!valid(p)) return "not a unit code (byte 0 must be 0, the prefix -9 .. 9)";
  if (seconds_of(p.den, acceleration) == 0.0)
    return acceleration ? "its denominator is not s^2 (0x57)" : "its denominator is neither s (0x03) nor min (0x47)";
  if (f.position != 0 && (!valid(pos) || pos.den != 0)) return "0x60A8 (SI unit position) is not a position unit code";
  if (p.num != kIncrements && p.num != kRevolutions && (f.position_in_increments() || p.num != pos.num))
    return "its numerator is neither increments (0xB5), revolutions (0xB4) nor the position unit's (0x60A8)";
  if (p.num == kRevolutions && f.gear_other())
    return "a 0x6091 gear ratio other than 1:1 stands between motor and load: revolutions of which shaft is not known";
  if (f.position_in_increments())
    return "revolutions need the counts per motor revolution, and 0x608F (position encoder resolution) gives none "
           "(no value, or absent)";
  if (p.num == kIncrements && !f.res.known())
    return "increments with a position unit other than increments (0x60A8) need 0x608F (position encoder "
           "resolution), which gives none";
  return "the position unit (0x60A8) is not increments, and 0x6092 (feed constant) gives no position units per "
         "revolution (no value, or absent)";
}

std::optional<std::uint32_t> velocity_unit_code(std::string_view name) noexcept {
  if (name == "inc/s") return kIncPerSecond;
  if (name == "rpm") return kRpm;
  return std::nullopt;
}

}  // namespace canmotion::cia402::units
