// The drive boot as data (boot_plan.hpp): kBootPlan, one row per object the
// master writes or reads at boot, and its expansion into one drive's SDO
// transfers. Set-up time, apart from boot_plan(), write_hint_key() and
// boot_note() (realtime-safe).
#include "fieldbus/cia402/boot_plan.hpp"

#include <array>
#include <iterator>
#include <string_view>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

namespace {

// ---- the sentences after a refusal (Failure::describe) ------------------------
constexpr BootHint kModeHint{"; the mode comes from %s (csp: 0x6060 = 8; ip: 0x6060 = 7 and 0x60C0 = 0, linear "
                             "interpolation): the drive must accept it",
                             "; canmotiond runs every drive in a cyclic synchronous mode (0x6060 = 8, 9 or 10) "
                             "or, with drive.mode: ip, in interpolated position mode (0x6060 = 7, 0x60C0 = 0 linear): "
                             "the drive must accept it"};
constexpr BootHint kPeriodHint{"; 0x60C2 is the cycle period, %s: the drive must accept it in cyclic synchronous modes",
                               "; 0x60C2 is the cycle period: the drive must accept it in cyclic synchronous modes"};
constexpr BootHint kPdoHint{"; the PDO mapping comes from %s: the drive must accept it (see fieldbus/README.md, PDO mapping)",
                            "; the PDO mapping comes from the drive's PDO profile: the drive must accept it (see "
                            "fieldbus/README.md, PDO mapping)"};
constexpr BootHint kUnusedPdoHint{"; canmotiond writes the PDOs it does not use invalid (a drive without that PDO may "
                                  "answer 0x06020000 or 0x06090011, which is accepted)",
                                  "; canmotiond writes the PDOs it does not use invalid (a drive without that PDO may "
                                  "answer 0x06020000 or 0x06090011, which is accepted)"};
constexpr BootHint kProducerHeartbeatHint{"; the drive's heartbeat period comes from %s",
                                          "; the drive's heartbeat period comes from the drive configuration"};
constexpr BootHint kConsumerHeartbeatHint{
    "; to leave this write out (the drive then does not watch the master's heartbeat) set %s: 0",
    "; set the drive's consumer_heartbeat_ms to 0 to leave this write out"};
constexpr BootHint kExtraHint{"; the write comes from %s: correct or remove it",
                              "; the write comes from the extra configuration writes: correct or remove it"};
constexpr BootHint kCheckHint{"; canmotiond reads it at boot to check the drive (CiA 301 mandatory object)",
                              "; canmotiond reads it at boot to check the drive (CiA 301 mandatory object)"};
constexpr BootHint kSyncPeriodHint{
    "; canmotiond writes 0x1006 = 0 before 0x1019 (CiA 301 allows a 0x1019 change only while 0x1006 is 0), and the "
    "SYNC period after it when %s is true (false leaves that write out)",
    "; canmotiond writes 0x1006 = 0 before 0x1019 (CiA 301 allows a 0x1019 change only while 0x1006 is 0), and the "
    "SYNC period after it when the drive's sync_watch is true (false leaves that write out)"};
constexpr BootHint kSyncCounterHint{
    "; 0x1019 must match the SYNC the master sends (a drive drops SYNCs of another length, EMCY 8240h): it comes "
    "from %s",
    "; 0x1019 must match the SYNC the master sends (a drive drops SYNCs of another length, EMCY 8240h): it comes "
    "from the master's SYNC counter overflow"};

// ---- what the master does instead (describe_notice) -------------------------------
constexpr const char* kNoSyncCounter =
    "the drive has no SYNC counter setting: it must take the master's SYNC as it is (buses[].sync_counter_overflow)";
constexpr const char* kNoSlat = "the drive has no SLAT: MDS runs without it (direct_control.slat is not set)";

// ---- answers to aborts ------------------------------------------------------------
constexpr OnAbort kAbsentSaid{.absent = Then::kNotice};
constexpr OnAbort kAbsentQuiet{.absent = Then::kQuiet};

// ---- values -------------------------------------------------------------------------
bool read_units(const BootInputs& b) { return b.drive.units.read_at_boot; }
InterpolationPeriod period(const BootInputs& b) { return *encode_interpolation_period(b.drive.cycle_ns); }
std::uint8_t mode_byte(Mode m) { return static_cast<std::uint8_t>(static_cast<std::int8_t>(m)); }

/// The CiA 301 procedure for a PDO the master uses: COB-ID invalid (bit 31),
/// mapping count 0, the entries, the count, the transmission type, COB-ID valid.
void pdo_procedure(const canopen::PdoMap& m, std::vector<SdoWrite>& out) {
  const std::uint32_t cob = m.cob_id & 0x7FFu;
  out.push_back({m.comm_index(), 1, 4, cob | canopen::kPdoInvalid});
  out.push_back({m.map_index(), 0, 1, 0});
  for (std::uint8_t i = 0; i < m.count; ++i)
    out.push_back({m.map_index(), static_cast<std::uint8_t>(i + 1), 4, m.entries[i].raw()});
  out.push_back({m.map_index(), 0, 1, m.count});
  out.push_back({m.comm_index(), 2, 1, m.transmission_type});
  out.push_back({m.comm_index(), 1, 4, cob});
}

/// The PDOs the master uses (RPDOs with `rx`, else TPDOs): their procedures.
void used_pdos(bool rx, const BootInputs& b, std::vector<SdoWrite>& out) {
  const std::uint8_t used = rx ? b.pdos.rpdo_count : b.pdos.tpdo_count;
  for (std::uint8_t n = 0; n < used; ++n) pdo_procedure(rx ? b.pdos.rpdo[n] : b.pdos.tpdo[n], out);
}

/// The PDOs 1..4 a drive may have and the master does not use: COB-ID invalid.
void unused_pdos(bool rx, const BootInputs& b, std::vector<SdoWrite>& out) {
  const std::uint8_t used = rx ? b.pdos.rpdo_count : b.pdos.tpdo_count;
  for (std::uint8_t n = static_cast<std::uint8_t>(used + 1); n <= 4; ++n) {
    const std::uint32_t cob = rx ? canopen::cob::rpdo(n, b.drive.node) : canopen::cob::tpdo(n, b.drive.node);
    out.push_back({static_cast<std::uint16_t>((rx ? 0x1400 : 0x1800) + n - 1), 1, 4, cob | canopen::kPdoInvalid});
  }
}

// clang-format off
/// The boot, in order. Reads first (nothing is written before they pass):
/// the device type (mandatory in CiA 301), the identity the configuration
/// expects (0x1018:2/3 are optional: read only when expected), the supported
/// modes. Then the writes; the mode the drive runs is read back last.
constexpr BootRow kBootPlan[] = {
    {.origin = WriteOrigin::kCheck, .index = obj::kDeviceType, .check = BootCheck::kDeviceType, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = obj::kIdentity, .sub = 1, .check = BootCheck::kVendorId,
     .applies = [](const BootInputs& b) { return b.drive.identity.has_vendor_id; }, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = obj::kIdentity, .sub = 2, .check = BootCheck::kProductCode,
     .applies = [](const BootInputs& b) { return b.drive.identity.has_product_code; }, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = obj::kIdentity, .sub = 3, .check = BootCheck::kRevision,
     .applies = [](const BootInputs& b) { return b.drive.identity.has_revision; }, .hint = kCheckHint},
    // 0x6502 is optional: a drive without it is not checked.
    {.origin = WriteOrigin::kCheck, .index = obj::kSupportedDriveModes, .check = BootCheck::kSupportedModes,
     .need = Need::kOptional, .on_abort = kAbsentSaid, .hint = kCheckHint,
     .notes = {.absent = "the modes the configuration needs are not checked"}},
    {.origin = WriteOrigin::kMode, .index = obj::kModesOfOperation, .size = 1,
     .value = [](const BootInputs& b) -> std::uint32_t { return mode_byte(b.drive.mode); }, .key = &WriteHints::mode,
     .hint = kModeHint},
    // IP (mode 7): sub-mode 0 = linear interpolation. 0x60C0 is optional
    // (CiA 402): a drive without it interpolates linearly by default.
    {.origin = WriteOrigin::kMode, .index = obj::kInterpolationSubModeSelect, .size = 2, .need = Need::kOptional,
     .on_abort = kAbsentSaid, .applies = [](const BootInputs& b) { return b.drive.mode == Mode::kInterpolatedPosition; },
     .key = &WriteHints::mode, .hint = kModeHint,
     .notes = {.absent = "the drive has no interpolation sub-mode select (0x60C0): its default, linear interpolation, "
                         "is taken"}},
    {.origin = WriteOrigin::kInterpolationPeriod, .index = obj::kInterpolationTimePeriod, .sub = 1, .size = 1,
     .value = [](const BootInputs& b) -> std::uint32_t { return period(b).value; },
     .key = &WriteHints::interpolation_period, .hint = kPeriodHint},
    // 0x60C2:2 may be read-only (a drive that takes periods in one unit only)
    // or absent: then its index is read and 0x60C2:1 written again in that
    // unit; a period the drive's unit cannot express fails the boot. Read-only
    // in the EDS: not written, the fallback runs at once; absent from the EDS:
    // neither written nor read (the drive keeps its own unit; config/eds_check warns).
    {.origin = WriteOrigin::kInterpolationPeriod, .index = obj::kInterpolationTimePeriod, .sub = 2, .size = 1,
     .gate = EdsGate::kWritable, .on_abort = {.absent = Then::kFallBack, .read_only = Then::kFallBack},
     .value = [](const BootInputs& b) -> std::uint32_t { return static_cast<std::uint8_t>(period(b).index); },
     .key = &WriteHints::interpolation_period, .hint = kPeriodHint},
    {.origin = WriteOrigin::kCheck, .index = obj::kInterpolationTimePeriod, .sub = 2, .size = 1,
     .check = BootCheck::kInterpolationIndex, .need = Need::kOptional, .on_abort = kAbsentSaid, .falls_back_from = -1,
     .hint = kCheckHint,
     .notes = {.absent = "0x60C2:1 written with the master's value; the unit is the drive's own",
               .held = "0x60C2:1 written in the drive's unit 10^%d s"}},
    {.origin = WriteOrigin::kInterpolationPeriod, .index = obj::kInterpolationTimePeriod, .sub = 1, .size = 1,
     .falls_back_from = -2, .value_from_check = true,
     .value = [](const BootInputs& b) -> std::uint32_t { return period(b).value; },
     .key = &WriteHints::interpolation_period, .hint = kPeriodHint},
    // The SYNC consumer (CiA 301): 0x1019 may change only while 0x1006 is 0
    // (abort 0x08000022 otherwise; CANopenNode's CO_ODF_1019 too), so 0x1006
    // is written 0 first, then 0x1019 = the master's counter overflow value
    // (0: its SYNC carries no counter; a drive whose 0x1019 does not match
    // drops every SYNC, EMCY 8240h), then with sync_watch 0x1006 = the period
    // in us (the drive then watches the SYNC; asked for: required). A drive
    // without 0x1006 / 0x1019 is fine, as is a read-only 0x1006; a 0x1019
    // refused otherwise is read: it must already hold the master's value.
    {.origin = WriteOrigin::kSyncPeriod, .index = obj::kCommunicationCyclePeriod, .size = 4, .need = Need::kOptional,
     .on_abort = {.absent = Then::kNotice, .read_only = Then::kNotice}, .key = &WriteHints::sync_watch,
     .hint = kSyncPeriodHint,
     .notes = {.absent = "the drive has no SYNC watch period (0x1006) to set",
               .read_only = "the drive keeps its own SYNC watch period"}},
    {.origin = WriteOrigin::kSyncCounter, .index = obj::kSyncCounterOverflow, .size = 1, .need = Need::kOptional,
     .on_abort = {.absent = Then::kNotice, .read_only = Then::kFallBack, .other = Then::kFallBack},
     .value = [](const BootInputs& b) -> std::uint32_t {
       return b.master.sync_counter_overflow >= 2 ? b.master.sync_counter_overflow : 0;
     },
     .key = &WriteHints::sync_counter, .hint = kSyncCounterHint, .notes = {.absent = kNoSyncCounter}},
    {.origin = WriteOrigin::kCheck, .index = obj::kSyncCounterOverflow, .size = 1, .check = BootCheck::kSyncCounter,
     .need = Need::kOptional,
     .on_abort = {.absent = Then::kNotice, .read_only = Then::kFailAsTrigger, .other = Then::kFailAsTrigger,
                  .timeout = Then::kFailAsTrigger},
     .falls_back_from = -1, .hint = kCheckHint,
     .notes = {.absent = kNoSyncCounter, .held = "it already holds %d, the master's SYNC counter overflow value"}},
    {.origin = WriteOrigin::kSyncPeriod, .index = obj::kCommunicationCyclePeriod, .size = 4,
     .applies = [](const BootInputs& b) { return b.drive.sync_watch; },
     .value = [](const BootInputs& b) { return static_cast<std::uint32_t>(b.drive.cycle_ns / 1000); },
     .key = &WriteHints::sync_watch, .hint = kSyncPeriodHint},
    // PDOs: the CiA 301 procedure for the used ones, COB-ID invalid for the
    // others of 1..4 (a drive without that PDO is fine).
    {.origin = WriteOrigin::kPdo,
     .expand = [](const BootInputs& b, std::vector<SdoWrite>& out) { used_pdos(true, b, out); },
     .key = &WriteHints::pdo, .hint = kPdoHint},
    {.origin = WriteOrigin::kUnusedPdo, .need = Need::kOptional, .on_abort = kAbsentQuiet,
     .expand = [](const BootInputs& b, std::vector<SdoWrite>& out) { unused_pdos(true, b, out); },
     .hint = kUnusedPdoHint},
    {.origin = WriteOrigin::kPdo,
     .expand = [](const BootInputs& b, std::vector<SdoWrite>& out) { used_pdos(false, b, out); },
     .key = &WriteHints::pdo, .hint = kPdoHint},
    {.origin = WriteOrigin::kUnusedPdo, .need = Need::kOptional, .on_abort = kAbsentQuiet,
     .expand = [](const BootInputs& b, std::vector<SdoWrite>& out) { unused_pdos(false, b, out); },
     .hint = kUnusedPdoHint},
    {.origin = WriteOrigin::kProducerHeartbeat, .index = 0x1017, .size = 2,
     .value = [](const BootInputs& b) -> std::uint32_t { return b.drive.producer_heartbeat_ms; },
     .key = &WriteHints::producer_heartbeat, .hint = kProducerHeartbeatHint},
    // 0x1016 is optional (CiA 301): written only when the drive is to watch
    // the master's heartbeat; required when the configuration asks for it.
    {.origin = WriteOrigin::kConsumerHeartbeat, .index = 0x1016, .sub = 1, .size = 4, .need = Need::kConfigured,
     .on_abort = kAbsentSaid, .applies = [](const BootInputs& b) { return b.drive.consumer_heartbeat_ms > 0; },
     .optional_if = [](const BootInputs& b) { return b.drive.consumer_heartbeat_optional; },
     .value = [](const BootInputs& b) {
       return (static_cast<std::uint32_t>(b.master.node_id) << 16) | b.drive.consumer_heartbeat_ms;
     },
     .key = &WriteHints::consumer_heartbeat, .hint = kConsumerHeartbeatHint,
     .notes = {.absent = "the drive does not watch the master's heartbeat (a lost master is not detected by the drive)"}},
    // Drive units (README "Drive units"): `units.velocity` first, then, when
    // the configuration cannot tell them, the factor group is read (every
    // object optional) before the writes whose values are in those units.
    {.origin = WriteOrigin::kExtra, .index = units::kSiUnitVelocity, .size = 4,
     .applies = [](const BootInputs& b) { return b.drive.units.has_write_velocity; },
     .value = [](const BootInputs& b) { return b.drive.units.write_velocity; },
     .key = &WriteHints::velocity_unit, .hint = kExtraHint},
    {.origin = WriteOrigin::kCheck, .index = units::kSiUnitPosition, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kPositionEncoderResolution, .sub = 1, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kPositionEncoderResolution, .sub = 2, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kGearRatio, .sub = 1, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kGearRatio, .sub = 2, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kFeedConstant, .sub = 1, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kFeedConstant, .sub = 2, .check = BootCheck::kUnitFactor,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = read_units, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = units::kSiUnitVelocity, .check = BootCheck::kVelocityUnit,
     .need = Need::kOptional, .on_abort = kAbsentSaid, .applies = read_units, .hint = kCheckHint,
     .notes = {.absent = "its velocity values are taken in increments/s (CiA 402 without the factor group)",
               .held = "its velocity unit 0x%08X is not one canmotiond interprets; nothing configured needs it, "
                       "so velocities of this axis are not shown"}},
    {.origin = WriteOrigin::kCheck, .index = units::kSiUnitAcceleration, .check = BootCheck::kAccelerationUnit,
     .need = Need::kOptional, .on_abort = kAbsentSaid, .applies = read_units, .hint = kCheckHint,
     .notes = {.absent = "its acceleration values are taken in increments/s^2 (CiA 402 without the factor group)",
               .held = "its acceleration unit 0x%08X is not one canmotiond interprets; nothing configured needs it"}},
    // CiA 302 verify configuration: the DCF's values (among the extra
    // writes, SdoWrite::dcf) are left out when 0x1020 shows the DCF's date.
    {.origin = WriteOrigin::kCheck, .index = 0x1020, .sub = 1, .check = BootCheck::kConfigurationDate,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = [](const BootInputs& b) { return b.drive.dcf_dated; },
     .key = &WriteHints::dcf, .hint = kCheckHint},
    {.origin = WriteOrigin::kCheck, .index = 0x1020, .sub = 2, .check = BootCheck::kConfigurationDate,
     .need = Need::kOptional, .on_abort = kAbsentQuiet, .applies = [](const BootInputs& b) { return b.drive.dcf_dated; },
     .key = &WriteHints::dcf, .hint = kCheckHint},
    {.origin = WriteOrigin::kExtra, .need = Need::kConfigured, .on_abort = kAbsentSaid,
     .expand = [](const BootInputs& b, std::vector<SdoWrite>& out) {
       out.insert(out.end(), b.drive.extra_writes.begin(), b.drive.extra_writes.end());
     },
     .keys = &WriteHints::extra, .hint = kExtraHint},
    // Last: the mode the drive runs (0x6061, optional: without it the written
    // mode is taken as the one it runs), read until it shows the written mode.
    {.origin = WriteOrigin::kCheck, .index = obj::kModesOfOperationDisplay, .check = BootCheck::kModeDisplay,
     .need = Need::kOptional, .on_abort = kAbsentSaid, .hint = kCheckHint,
     .notes = {.absent = "the mode written to 0x6060 is taken as the one the drive runs"}},
};
// clang-format on

/// The notes of extra writes, by object (an extra row has none of its own).
struct ObjectNote {
  std::uint16_t index;
  const char* absent;
};
constexpr ObjectNote kExtraNotes[] = {
    {obj::kSlatConfiguration, kNoSlat},
    {obj::kSlatSetPoint, kNoSlat},
    {obj::kSlatTimeDelay, kNoSlat},
};

/// A note's number (NodeEvent::note) holds the row and which of its notes.
constexpr std::size_t kFallbacks = 3;
static_assert(std::size(kBootPlan) * kFallbacks < 256, "NodeEvent::note numbers every row's notes in 8 bits");

/// The rules of the plan, checked at compile time.
constexpr bool plan_is_consistent() {
  const auto n = static_cast<std::ptrdiff_t>(std::size(kBootPlan));
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const BootRow& r = kBootPlan[i];
    // The rows of one origin share its hint (Failure::describe finds it by origin).
    for (std::ptrdiff_t j = 0; j < i; ++j)
      if (kBootPlan[j].origin == r.origin &&
          (std::string_view(kBootPlan[j].hint.with_key) != r.hint.with_key ||
           std::string_view(kBootPlan[j].hint.without_key) != r.hint.without_key))
        return false;
    const bool fails_as_trigger = r.on_abort.absent == Then::kFailAsTrigger || r.on_abort.read_only == Then::kFailAsTrigger ||
                                  r.on_abort.other == Then::kFailAsTrigger || r.on_abort.timeout == Then::kFailAsTrigger;
    if (r.falls_back_from == 0) {
      if (fails_as_trigger || r.value_from_check) return false;  // only a fallback has a trigger / a check before it
      continue;
    }
    const std::ptrdiff_t t = i + r.falls_back_from;
    if (r.falls_back_from > 0 || t < 0) return false;  // it falls back from an earlier row
    const BootRow& trigger = kBootPlan[t];
    const OnAbort& a = trigger.on_abort;
    const bool falls_back = a.absent == Then::kFallBack || a.read_only == Then::kFallBack ||
                            a.other == Then::kFallBack || a.timeout == Then::kFallBack;
    // A trigger is one object (its transfer is found by its row), that falls back.
    if (!falls_back || trigger.expand != nullptr || trigger.falls_back_from != 0) return false;
    if (r.value_from_check && kBootPlan[i - 1].check == BootCheck::kNone) return false;
  }
  return kBootPlan[n - 1].expand == nullptr;
}
static_assert(plan_is_consistent(),
              "kBootPlan: a fallback names an earlier one-object row that falls back; rows of one origin share a hint");

/// The transfers of one row (several for an expanded row).
void transfers_of(const BootRow& row, const BootInputs& in, std::vector<SdoWrite>& out) {
  out.clear();
  if (row.applies != nullptr && !row.applies(in)) return;
  if (row.expand != nullptr) {
    row.expand(in, out);
    return;
  }
  out.push_back({row.index, row.sub, row.size, row.value != nullptr ? row.value(in) : 0u});
}

bool optional_transfer(const BootRow& row, const BootInputs& in, const SdoWrite& w) {
  switch (row.need) {
    case Need::kRequired: return false;
    case Need::kOptional: return true;
    case Need::kConfigured: return row.optional_if != nullptr ? row.optional_if(in) : w.optional;
  }
  return false;
}
}  // namespace

std::span<const BootRow> boot_plan() noexcept { return kBootPlan; }

std::vector<BootWrite> build_boot_transfers(const BootInputs& in) {
  const canopen::DeviceDictionary* eds = in.drive.dictionary.get();
  auto eds_lacks = [eds](const SdoWrite& w) { return eds != nullptr && eds->has(w.index, w.sub) == canopen::Presence::kAbsent; };
  auto eds_read_only = [eds](const SdoWrite& w) {
    const canopen::DeviceDictionary::Entry* e = eds != nullptr ? eds->find(w.index, w.sub) : nullptr;
    return e != nullptr && (e->access == canopen::Access::kRo || e->access == canopen::Access::kConst);
  };
  std::vector<BootWrite> out;
  // Per row: where its (first) transfer is, or kAlways (none) / kAtOnce
  // (left out as read-only in the EDS: its fallbacks run at once).
  std::array<std::int16_t, std::size(kBootPlan)> at{};
  std::vector<SdoWrite> items;
  for (std::size_t i = 0; i < std::size(kBootPlan); ++i) {
    const BootRow& row = kBootPlan[i];
    at[i] = BootWrite::kAlways;
    std::int16_t after = BootWrite::kAlways;
    if (row.falls_back_from != 0) {
      after = at[static_cast<std::size_t>(static_cast<std::ptrdiff_t>(i) + row.falls_back_from)];
      if (after == BootWrite::kAlways) continue;  // its trigger is not made: nor is it
    }
    transfers_of(row, in, items);
    for (std::size_t k = 0; k < items.size(); ++k) {
      SdoWrite w = items[k];
      const bool optional = optional_transfer(row, in, w);
      w.optional = optional;
      if (eds_lacks(w) && (optional || row.gate == EdsGate::kWritable)) continue;
      if (row.gate == EdsGate::kWritable && eds_read_only(w)) {
        at[i] = BootWrite::kAtOnce;
        continue;
      }
      BootWrite bw;
      bw.w = w;
      bw.origin = row.origin;
      bw.item = static_cast<std::uint16_t>(k);
      bw.optional = optional;
      bw.check = row.check;
      bw.on_abort = row.on_abort;
      // Tolerating an absent object is for optional transfers.
      if (!optional && (bw.on_abort.absent == Then::kQuiet || bw.on_abort.absent == Then::kNotice))
        bw.on_abort.absent = Then::kFail;
      bw.after = after;
      bw.row = &row;
      if (k == 0) at[i] = static_cast<std::int16_t>(out.size());
      out.push_back(bw);
    }
  }
  return out;
}

const std::string* write_hint_key(const WriteHints& hints, const BootWrite& w) noexcept {
  if (w.row == nullptr) return nullptr;
  if (w.row->key != nullptr) return &(hints.*(w.row->key));
  if (w.row->keys != nullptr) {
    const std::vector<std::string>& keys = hints.*(w.row->keys);
    return w.item < keys.size() ? &keys[w.item] : nullptr;
  }
  return nullptr;
}

std::uint8_t boot_note_id(const BootWrite& w, Fallback f) noexcept {
  if (w.row == nullptr) return 0;
  const auto row = static_cast<std::size_t>(w.row - kBootPlan);  // its place in the plan
  return static_cast<std::uint8_t>(1 + row * kFallbacks + static_cast<std::size_t>(f));
}

const char* boot_note_text(std::uint8_t id, std::uint16_t index) noexcept {
  if (id == 0 || id > std::size(kBootPlan) * kFallbacks) return nullptr;
  const BootRow& row = kBootPlan[(id - 1u) / kFallbacks];
  switch (static_cast<Fallback>((id - 1u) % kFallbacks)) {
    case Fallback::kAbsent:
      if (row.notes.absent != nullptr) return row.notes.absent;
      if (row.origin == WriteOrigin::kExtra)
        for (const ObjectNote& n : kExtraNotes)
          if (n.index == index) return n.absent;
      return nullptr;
    case Fallback::kReadOnly: return row.notes.read_only;
    case Fallback::kHeld: return row.notes.held;
  }
  return nullptr;
}

bool boot_note_of_read(std::uint8_t id) noexcept {
  if (id == 0 || id > std::size(kBootPlan) * kFallbacks) return false;
  const BootRow& row = kBootPlan[(id - 1u) / kFallbacks];
  return static_cast<Fallback>((id - 1u) % kFallbacks) == Fallback::kHeld && row.check != BootCheck::kNone &&
         row.falls_back_from == 0;
}

const char* boot_note(const BootWrite& w, Fallback f) noexcept { return boot_note_text(boot_note_id(w, f), w.w.index); }

const BootHint& boot_hint(WriteOrigin origin) noexcept {
  for (const BootRow& r : kBootPlan)
    if (r.origin == origin) return r.hint;
  static constexpr BootHint kNone{};
  return kNone;
}

}  // namespace canmotion::cia402
