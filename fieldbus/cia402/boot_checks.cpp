// The checks of the values the boot reads (boot_plan.hpp: BootCheck): per
// check, its verdict on the value (realtime-safe) and the sentence of its
// failure (Failure::describe, snprintf: from a non-RT thread).
#include <array>
#include <cinttypes>
#include <cstdio>
#include <limits>

#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/boot_plan.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

namespace {

using Is = CheckVerdict::Is;

std::uint32_t mode_value(Mode m) noexcept { return static_cast<std::uint8_t>(static_cast<std::int8_t>(m)); }

/// The drive's EDS name of index:sub (`d`: its dictionary, may be null),
/// else `standard` (CiA 301/402's). Realtime-safe.
const char* eds_name_or(const canopen::DeviceDictionary* d, std::uint16_t index, std::uint8_t sub,
                        const char* standard) noexcept {
  const char* n = d != nullptr ? d->name(index, sub) : nullptr;
  return n != nullptr ? n : standard;
}

/// Failure::hint when set, else `otherwise`.
const char* key_or(const Failure& f, const char* otherwise) noexcept {
  return f.hint != nullptr && f.hint[0] != '\0' ? f.hint : otherwise;
}

/// The value must be `want` (a configured identity), naming drive.identity.
CheckVerdict equals(const CheckInput& in, std::uint32_t want) noexcept {
  CheckVerdict c;
  c.expected = want;
  c.key = &in.drive.hints.identity;
  if (in.value != want) c.is = Is::kFail;
  return c;
}

// ---- 0x1000 device type -------------------------------------------------------
CheckVerdict verify_device_type(const CheckInput& in) noexcept {
  if (in.drive.identity.has_device_type) return equals(in, in.drive.identity.device_type);
  CheckVerdict c;
  c.expected = kDeviceProfile402;
  if ((in.value & 0xFFFFu) != kDeviceProfile402) c.is = Is::kFail;
  return c;
}

int describe_device_type(const Failure& f, std::span<char> out, double) noexcept {
  const char* name = eds_name_or(f.dictionary, obj::kDeviceType, 0, "Device type");
  if (f.hint != nullptr && f.hint[0] != '\0')
    return std::snprintf(out.data(), out.size(), "node %u: 0x1000 (%s) is 0x%08" PRIX32 ", %s expects 0x%08" PRIX32,
                         f.node, name, f.read_value, f.hint, f.expected);
  return std::snprintf(out.data(), out.size(),
                       "node %u: 0x1000 (%s) is 0x%08" PRIX32 ": device profile %" PRIu32
                       ", not 402 (CiA 402 drive); canmotiond drives CiA 402 drives only",
                       f.node, name, f.read_value, f.read_value & 0xFFFFu);
}

// ---- 0x1018:1..3 identity -----------------------------------------------------
CheckVerdict verify_vendor_id(const CheckInput& in) noexcept { return equals(in, in.drive.identity.vendor_id); }
CheckVerdict verify_product_code(const CheckInput& in) noexcept { return equals(in, in.drive.identity.product_code); }
CheckVerdict verify_revision(const CheckInput& in) noexcept { return equals(in, in.drive.identity.revision); }

int describe_identity(const Failure& f, std::span<char> out, double) noexcept {
  const std::uint8_t si = f.check == BootCheck::kVendorId ? 1 : f.check == BootCheck::kProductCode ? 2 : 3;
  const char* what = eds_name_or(f.dictionary, obj::kIdentity, si,
                                 si == 1 ? "Vendor-ID" : si == 2 ? "Product code" : "Revision number");
  const char* sub = si == 1 ? "vendor_id" : si == 2 ? "product_code" : "revision";
  return std::snprintf(out.data(), out.size(),
                       "node %u: identity 0x1018:%u (%s) is 0x%08" PRIX32 ", the configuration expects 0x%08" PRIX32
                       " (%s%s%s): another drive than configured is on this node",
                       f.node, si, what, f.read_value, f.expected, key_or(f, "drive.identity"), ".", sub);
}

// ---- 0x6502 supported drive modes -------------------------------------------------
CheckVerdict verify_supported_modes(const CheckInput& in) noexcept {
  CheckVerdict c;
  if ((in.value & supported_mode_bit(in.drive.mode)) == 0) {
    c.is = Is::kFail;
    c.expected = mode_value(in.drive.mode);
    if (!in.drive.hints.mode.empty()) c.key = &in.drive.hints.mode;
    return c;
  }
  for (const ModeNeed& m : in.drive.needed_modes) {
    if ((in.value & supported_mode_bit(m.mode)) != 0) continue;
    c.is = Is::kFail;
    c.expected = mode_value(m.mode);
    c.key = &m.key;
    break;
  }
  return c;
}

int describe_supported_modes(const Failure& f, std::span<char> out, double) noexcept {
  const auto mn = mode_name(static_cast<std::int8_t>(f.expected));
  return std::snprintf(out.data(), out.size(),
                       "node %u: the drive does not support mode %d (%.*s): 0x6502 (%s) is 0x%08" PRIX32
                       "; the mode is needed by %s",
                       f.node, static_cast<int>(static_cast<std::int8_t>(f.expected)), static_cast<int>(mn.size()),
                       mn.data(), eds_name_or(f.dictionary, obj::kSupportedDriveModes, 0, "Supported drive modes"),
                       f.read_value, key_or(f, "the drive's configured mode"));
}

// ---- 0x6061 modes of operation display ----------------------------------------------
CheckVerdict verify_mode_display(const CheckInput& in) noexcept {
  CheckVerdict c;
  const auto shown = static_cast<std::int8_t>(in.value & 0xFFu);
  c.expected = mode_value(in.drive.mode);
  if (shown == static_cast<std::int8_t>(in.drive.mode)) {
    if (in.mode_display != nullptr) *in.mode_display = shown;  // confirmed by the drive
    return c;
  }
  // The switch takes effect asynchronously (CiA 402): read it again.
  c.is = Is::kAgain;
  c.timeout_ns = in.drive.mode_switch_timeout_ns;
  c.key = &in.drive.hints.mode_switch_timeout;
  return c;
}

int describe_mode_display(const Failure& f, std::span<char> out, double waited_ms) noexcept {
  const auto rq = mode_name(static_cast<std::int8_t>(f.expected));
  const auto sh = mode_name(static_cast<std::int8_t>(f.read_value));
  return std::snprintf(out.data(), out.size(),
                       "node %u: 0x6060 = %d (%.*s) written, but 0x6061 (%s) still shows %d (%.*s) "
                       "after %.1f ms (%s): the drive does not run the mode it accepted",
                       f.node, static_cast<int>(static_cast<std::int8_t>(f.expected)), static_cast<int>(rq.size()),
                       rq.data(), eds_name_or(f.dictionary, obj::kModesOfOperationDisplay, 0, "Modes of operation display"),
                       static_cast<int>(static_cast<std::int8_t>(f.read_value)), static_cast<int>(sh.size()), sh.data(),
                       waited_ms, key_or(f, "mode switch timeout"));
}

// ---- 0x60C2:2 interpolation time index, after the drive refused it -------------------
CheckVerdict verify_interpolation_index(const CheckInput& in) noexcept {
  // The drive keeps its own unit 10^idx s: 0x60C2:1 (the next transfer) is
  // written in it when the period is a whole number 1..255 of it.
  CheckVerdict c;
  const auto idx = static_cast<std::int8_t>(in.value & 0xFFu);
  const std::int64_t unit = interpolation_period_ns(InterpolationPeriod{1, idx});
  const std::int64_t cycle = in.drive.cycle_ns;
  if (unit > 0 && cycle % unit == 0 && cycle / unit >= 1 && cycle / unit <= 255) {
    c.held = true;
    c.detail = idx;
    c.has_next = true;
    c.next_value = static_cast<std::uint32_t>(cycle / unit);
    return c;
  }
  c.is = Is::kFail;
  c.expected = static_cast<std::uint32_t>(cycle);
  c.key = &in.drive.hints.interpolation_period;
  return c;
}

int describe_interpolation_index(const Failure& f, std::span<char> out, double) noexcept {
  const auto idx = static_cast<int>(static_cast<std::int8_t>(f.read_value & 0xFFu));
  return std::snprintf(out.data(), out.size(),
                       "node %u: 0x60C2:2 (%s) is read-only at %d (periods in units of "
                       "10^%d s) and the cycle period %.6g ms (%s) is not a whole number 1..255 of that unit: "
                       "choose a period the drive can take",
                       f.node, eds_name_or(f.dictionary, obj::kInterpolationTimePeriod, 2, "Interpolation time index"),
                       idx, idx, static_cast<double>(f.expected) / 1e6, key_or(f, "the cycle period"));
}

// ---- 0x1019 synchronous counter overflow, after the drive refused it -----------------
CheckVerdict verify_sync_counter(const CheckInput& in) noexcept {
  // Fine when the drive already holds the master's value (the refused write's).
  CheckVerdict c;
  const std::uint32_t held = in.value & 0xFFu;
  if (held == in.written) {
    c.held = true;
    c.detail = static_cast<std::int32_t>(held);
    return c;
  }
  c.is = Is::kFail;
  c.expected = in.written;
  c.key = &in.drive.hints.sync_counter;
  return c;
}

int describe_sync_counter(const Failure& f, std::span<char> out, double) noexcept {
  const auto text = canopen::sdo_abort_text(f.sdo_abort);
  char why[160];
  if (f.expected == 0)
    std::snprintf(why, sizeof why, "the drive expects SYNCs with a counter (up to %" PRIu32
                  ") and would drop every SYNC of the master, which has none (EMCY 8240h)", f.read_value);
  else if (f.read_value == 0)
    std::snprintf(why, sizeof why, "the drive takes SYNCs without a counter and would drop every SYNC of the "
                  "master, which carries one (EMCY 8240h)");
  else
    std::snprintf(why, sizeof why, "the drive counts SYNCs up to %" PRIu32 ", the master up to %" PRIu32,
                  f.read_value, f.expected);
  return std::snprintf(out.data(), out.size(),
                       "node %u: 0x1019:0 (%s) refused the write of %" PRIu32
                       " (SDO abort 0x%08" PRIX32 " %.*s) and holds %" PRIu32 ": %s; set %s: %" PRIu32
                       ", or give the drive's 0x1019 the value %" PRIu32,
                       f.node, eds_name_or(f.dictionary, obj::kSyncCounterOverflow, 0, "Synchronous counter overflow value"),
                       f.expected, f.sdo_abort, static_cast<int>(text.size()), text.data(), f.read_value, why,
                       key_or(f, "the master's SYNC counter overflow"), f.read_value, f.expected);
}

// ---- 0x1020 verify configuration (CiA 302) -------------------------------------
CheckVerdict verify_configuration_date(const CheckInput& in) noexcept {
  const std::uint32_t expected = in.sub == 1 ? in.drive.dcf_date : in.drive.dcf_time;
  if (in.dcf_same != nullptr && in.value == expected) ++*in.dcf_same;
  return {};
}

// ---- the factor group, read when the configuration cannot tell the units ----------------
CheckVerdict verify_unit_factor(const CheckInput& in) noexcept {
  if (in.units == nullptr) return {};
  units::FactorGroup& f = in.units->factors;
  switch (in.index) {
    case units::kSiUnitPosition: f.position = in.value; break;
    case units::kPositionEncoderResolution: (in.sub == 1 ? f.res.increments : f.res.revolutions) = in.value; break;
    case units::kGearRatio: (in.sub == 1 ? f.gear_motor : f.gear_shaft) = in.value; break;
    case units::kFeedConstant: (in.sub == 1 ? f.feed : f.feed_shaft) = in.value; break;
    default: break;
  }
  return {};
}

/// 0x60A9 / 0x60AA as read: the counts per unit, or (not interpretable) a
/// failure when the configuration needs the unit, else NaN and said once.
CheckVerdict unit(const CheckInput& in, bool acceleration) noexcept {
  CheckVerdict c;
  if (in.units == nullptr) return c;
  const auto counts = units::counts_per_unit(in.value, in.units->factors, acceleration);
  double& kept = acceleration ? in.units->acceleration_counts : in.units->velocity_counts;
  if (counts) {
    kept = *counts;
    return c;
  }
  kept = std::numeric_limits<double>::quiet_NaN();
  const std::string& needed = acceleration ? in.drive.units.acceleration_needed_by : in.drive.units.velocity_needed_by;
  if (!needed.empty()) {
    c.is = Is::kFail;
    c.key = &needed;
    return c;
  }
  c.held = true;  // nothing needs it: said once (BootNotes::held)
  c.detail = static_cast<std::int32_t>(in.value);
  return c;
}
CheckVerdict verify_velocity_unit(const CheckInput& in) noexcept { return unit(in, false); }
CheckVerdict verify_acceleration_unit(const CheckInput& in) noexcept { return unit(in, true); }

int describe_unit(const Failure& f, std::span<char> out, double) noexcept {
  const bool acc = f.check == BootCheck::kAccelerationUnit;
  const auto why = units::unknown_reason(f.read_value, f.unit_factors, acc);
  return std::snprintf(out.data(), out.size(),
                       "node %u: 0x%04X (%s) is 0x%08" PRIX32 ": %.*s; the drive's %s unit is needed by %s, and "
                       "nothing is guessed: give the drive a unit canmotiond interprets (README \"Drive units\")%s",
                       f.node, acc ? units::kSiUnitAcceleration : units::kSiUnitVelocity,
                       eds_name_or(f.dictionary, acc ? units::kSiUnitAcceleration : units::kSiUnitVelocity, 0,
                                   acc ? "SI unit acceleration" : "SI unit velocity"),
                       f.read_value, static_cast<int>(why.size()), why.data(), acc ? "acceleration" : "velocity",
                       key_or(f, "the configuration"), acc ? "" : ", or set drive.units.velocity (a writable 0x60A9)");
}

// ---- no check ------------------------------------------------------------------------
CheckVerdict verify_nothing(const CheckInput&) noexcept { return {}; }
int describe_nothing(const Failure& f, std::span<char> out, double) noexcept {
  return std::snprintf(out.data(), out.size(), "node %u: boot check failed", f.node);
}

/// Indexed by BootCheck.
constexpr std::array<BootCheckRule, 13> kRules{{
    {verify_nothing, describe_nothing},                               // kNone
    {verify_device_type, describe_device_type},                       // kDeviceType
    {verify_vendor_id, describe_identity},                            // kVendorId
    {verify_product_code, describe_identity},                         // kProductCode
    {verify_revision, describe_identity},                             // kRevision
    {verify_supported_modes, describe_supported_modes},               // kSupportedModes
    {verify_mode_display, describe_mode_display},                     // kModeDisplay
    {verify_interpolation_index, describe_interpolation_index},       // kInterpolationIndex
    {verify_sync_counter, describe_sync_counter},                     // kSyncCounter
    {verify_unit_factor, describe_nothing},                           // kUnitFactor (always passes)
    {verify_velocity_unit, describe_unit},                            // kVelocityUnit
    {verify_acceleration_unit, describe_unit},                        // kAccelerationUnit
    {verify_configuration_date, describe_nothing},                    // kConfigurationDate (always passes)
}};
static_assert(kRules.size() == static_cast<std::size_t>(BootCheck::kConfigurationDate) + 1, "one rule per BootCheck");

}  // namespace

const BootCheckRule& boot_check_rule(BootCheck c) noexcept {
  const auto i = static_cast<std::size_t>(c);
  return kRules[i < kRules.size() ? i : 0];
}

}  // namespace canmotion::cia402
