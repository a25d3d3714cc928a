// The texts of the drive proxy's failures and notices (DESIGN.md: a failure
// explains itself): Failure::describe, describe_notice and what a refused
// boot write is for. snprintf into the caller's buffer: call them from a
// non-RT thread (write_hint_key is realtime-safe).
#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <string>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

namespace {

/// The sentence that follows a refused write in Failure::describe: where its
/// value comes from (`key`, may be null) and what to do.
int write_hint(char* out, std::size_t size, WriteOrigin origin, const char* key) noexcept {
  const bool k = key != nullptr && key[0] != '\0';
  switch (origin) {
    case WriteOrigin::kMode:
      return std::snprintf(out, size, "; canmotiond runs every drive in a cyclic synchronous mode (0x6060 = 8, 9 or 10): "
                                      "the drive must accept it");
    case WriteOrigin::kInterpolationPeriod:
      return std::snprintf(out, size, "; 0x60C2 is the cycle period%s%s: the drive must accept it in cyclic synchronous modes",
                           k ? ", " : "", k ? key : "");
    case WriteOrigin::kPdo:
      return std::snprintf(out, size, "; the PDO mapping comes from %s: the drive must accept it (see fieldbus/README.md, PDO mapping)",
                           k ? key : "the drive's PDO profile");
    case WriteOrigin::kUnusedPdo:
      return std::snprintf(out, size, "; canmotiond writes the PDOs it does not use invalid (a drive without that PDO may "
                                      "answer 0x06020000 or 0x06090011, which is accepted)");
    case WriteOrigin::kProducerHeartbeat:
      return std::snprintf(out, size, "; the drive's heartbeat period comes from %s", k ? key : "the drive configuration");
    case WriteOrigin::kConsumerHeartbeat:
      return k ? std::snprintf(out, size, "; to leave this write out (the drive then does not watch the master's heartbeat) set %s: 0", key)
               : std::snprintf(out, size, "; set the drive's consumer_heartbeat_ms to 0 to leave this write out");
    case WriteOrigin::kExtra:
      return std::snprintf(out, size, "; the write comes from %s: correct or remove it", k ? key : "the extra configuration writes");
    case WriteOrigin::kCheck:
      return std::snprintf(out, size, "; canmotiond reads it at boot to check the drive (CiA 301 mandatory object)");
    case WriteOrigin::kSyncPeriod:
      return std::snprintf(out, size, "; canmotiond writes 0x1006 = 0 before 0x1019 (CiA 301 allows a 0x1019 change only "
                                      "while 0x1006 is 0), and the SYNC period after it when %s is true (false leaves "
                                      "that write out)",
                           k ? key : "the drive's sync_watch");
    case WriteOrigin::kSyncCounter:
      return std::snprintf(out, size, "; 0x1019 must match the SYNC the master sends (a drive drops SYNCs of another "
                                      "length, EMCY 8240h): it comes from %s",
                           k ? key : "the master's SYNC counter overflow");
  }
  return 0;
}

/// The drive's EDS name of index:sub (`d`: its dictionary, may be null),
/// else `standard` (CiA 301/402's). Realtime-safe.
const char* eds_name_or(const canopen::DeviceDictionary* d, std::uint16_t index, std::uint8_t sub,
                        const char* standard) noexcept {
  const char* n = d != nullptr ? d->name(index, sub) : nullptr;
  return n != nullptr ? n : standard;
}
}  // namespace

const std::string* write_hint_key(const WriteHints& hints, const BootWrite& w) noexcept {
  switch (w.origin) {
    case WriteOrigin::kInterpolationPeriod: return &hints.interpolation_period;
    case WriteOrigin::kPdo: return &hints.pdo;
    case WriteOrigin::kProducerHeartbeat: return &hints.producer_heartbeat;
    case WriteOrigin::kConsumerHeartbeat: return &hints.consumer_heartbeat;
    case WriteOrigin::kExtra: return w.extra < hints.extra.size() ? &hints.extra[w.extra] : nullptr;
    case WriteOrigin::kSyncPeriod: return &hints.sync_watch;
    case WriteOrigin::kSyncCounter: return &hints.sync_counter;
    case WriteOrigin::kMode:
    case WriteOrigin::kUnusedPdo:
    case WriteOrigin::kCheck: return nullptr;
  }
  return nullptr;
}

std::string describe_notice(const canopen::NodeEvent& e, const canopen::DeviceDictionary* dictionary) {
  const std::string_view name =
      dictionary != nullptr ? dictionary->name_or_standard(e.index, e.sub) : canopen::object_name(e.index, e.sub);
  const char* fallback = "not written; the drive keeps its own setting";
  char buf[160];
  if (e.index == 0x1016) {
    fallback = "the drive does not watch the master's heartbeat (a lost master is not detected by the drive)";
  } else if (e.index == obj::kInterpolationTimePeriod && e.detail != 0) {
    std::snprintf(buf, sizeof buf, "0x60C2:1 written in the drive's unit 10^%d s", static_cast<int>(e.detail));
    fallback = buf;
  } else if (e.index == obj::kInterpolationTimePeriod) {
    fallback = "0x60C2:1 written with the master's value; the unit is the drive's own";
  } else if (e.index == obj::kSupportedDriveModes) {
    fallback = "the modes the configuration needs are not checked";
  } else if (e.index == obj::kModesOfOperationDisplay) {
    fallback = "the mode written to 0x6060 is taken as the one the drive runs";
  } else if (e.index == obj::kSlatConfiguration || e.index == obj::kSlatSetPoint || e.index == obj::kSlatTimeDelay) {
    fallback = "the drive has no SLAT: MDS runs without it (direct_control.slat is not set)";
  } else if (e.index == obj::kCommunicationCyclePeriod) {
    fallback = e.abort == static_cast<std::uint32_t>(canopen::SdoAbort::kReadOnly)
                   ? "the drive keeps its own SYNC watch period"
                   : "the drive has no SYNC watch period (0x1006) to set";
  } else if (e.index == obj::kSyncCounterOverflow &&
             canopen::object_absent(static_cast<canopen::SdoAbort>(e.abort))) {
    fallback = "the drive has no SYNC counter setting: it must take the master's SYNC as it is (buses[].sync_counter_overflow)";
  } else if (e.index == obj::kSyncCounterOverflow) {
    std::snprintf(buf, sizeof buf, "it already holds %d, the master's SYNC counter overflow value", static_cast<int>(e.detail));
    fallback = buf;
  }
  char out[512];
  if (e.abort == 0) {  // no transfer: the drive's EDS has it read-only (DriveProxy leaves the write out)
    std::snprintf(out, sizeof out, "node %u: optional object 0x%04X:%u (%.*s) read-only in the drive's EDS (not written): %s",
                  e.node, e.index, e.sub, static_cast<int>(name.size()), name.data(), fallback);
    return out;
  }
  const char* what = e.abort == static_cast<std::uint32_t>(canopen::SdoAbort::kReadOnly) ? "read-only"
                     : canopen::object_absent(static_cast<canopen::SdoAbort>(e.abort)) || e.abort == 0 ? "absent"
                                                                                                       : "refused";
  std::snprintf(out, sizeof out, "node %u: optional object 0x%04X:%u (%.*s) %s (SDO abort 0x%08" PRIX32 " %.*s): %s",
                e.node, e.index, e.sub, static_cast<int>(name.size()), name.data(), what, e.abort,
                static_cast<int>(canopen::sdo_abort_text(e.abort).size()), canopen::sdo_abort_text(e.abort).data(),
                fallback);
  return out;
}

// ============================================================================
// Failure
// ============================================================================
int Failure::describe_sdo_abort(std::span<char> out, double waited_ms) const noexcept {
  auto name = dictionary != nullptr ? dictionary->name_or_standard(sdo_index, sdo_sub)
                                    : canopen::object_name(sdo_index, sdo_sub);
  if (name.empty()) name = "an object canmotion does not know";
  const auto text = canopen::sdo_abort_text(sdo_abort);
  char why[320] = "";
  write_hint(why, sizeof why, sdo_origin, hint);
  return std::snprintf(out.data(), out.size(),
                       "node %u: configuration %s 0x%04X:%u (%.*s) aborted with 0x%08" PRIX32 " (%.*s) after %.1f ms: %s%s",
                       node, sdo_origin == WriteOrigin::kCheck ? "read of" : "write to", sdo_index, sdo_sub, static_cast<int>(name.size()), name.data(), sdo_abort,
                       static_cast<int>(text.size()), text.data(), waited_ms,
                       sdo_abort == static_cast<std::uint32_t>(canopen::SdoAbort::kTimeout) ? "the drive did not answer"
                                                                                            : "the drive refused it",
                       why);
}

int Failure::describe_transition(std::span<char> out, double waited_ms, const char* emcy) const noexcept {
  const auto sn = state_name(reached);
  const auto wn = state_name(wanted);
  const auto from = transition < kTransitions.size() ? state_name(kTransitions[transition].from) : "?";
  const auto to = transition < kTransitions.size() ? state_name(kTransitions[transition].to) : wn;
  return std::snprintf(out.data(), out.size(),
                       "node %u: transition %u (%.*s -> %.*s) towards %.*s timed out after %.1f ms: drive is in %.*s, "
                       "statusword 0x%04X%s%s",
                       node, transition, static_cast<int>(from.size()), from.data(), static_cast<int>(to.size()),
                       to.data(), static_cast<int>(wn.size()), wn.data(), waited_ms, static_cast<int>(sn.size()),
                       sn.data(), statusword, emcy,
                       // Statusword bit 9 (remote) clear: the drive ignores the controlword.
                       (statusword & sw::kRemote) == 0 && reached != State::kUnknown && reached != State::kNotReadyToSwitchOn
                           ? "; the drive is under local control (statusword bit 9 remote = 0: it does not process "
                             "the controlword): switch it to bus/remote control on the drive"
                           : "");
}

int Failure::describe_boot_check(std::span<char> out, double waited_ms) const noexcept {
  int n = 0;
  const bool k = hint != nullptr && hint[0] != '\0';
  switch (check) {
    case BootCheck::kDeviceType:
      n = k ? std::snprintf(out.data(), out.size(), "node %u: 0x1000 (%s) is 0x%08" PRIX32 ", %s expects 0x%08" PRIX32,
                            node, eds_name_or(dictionary, 0x1000, 0, "Device type"), read_value, hint, expected)
            : std::snprintf(out.data(), out.size(),
                            "node %u: 0x1000 (%s) is 0x%08" PRIX32 ": device profile %" PRIu32
                            ", not 402 (CiA 402 drive); canmotiond drives CiA 402 drives only",
                            node, eds_name_or(dictionary, 0x1000, 0, "Device type"), read_value,
                            read_value & 0xFFFFu);
      break;
    case BootCheck::kVendorId:
    case BootCheck::kProductCode:
    case BootCheck::kRevision: {
      const std::uint8_t si = check == BootCheck::kVendorId ? 1 : check == BootCheck::kProductCode ? 2 : 3;
      const char* what = eds_name_or(dictionary, obj::kIdentity, si,
                                     si == 1 ? "Vendor-ID" : si == 2 ? "Product code" : "Revision number");
      const char* sub = check == BootCheck::kVendorId ? "vendor_id" : check == BootCheck::kProductCode ? "product_code" : "revision";
      n = std::snprintf(out.data(), out.size(),
                        "node %u: identity 0x1018:%u (%s) is 0x%08" PRIX32 ", the configuration expects 0x%08" PRIX32
                        " (%s%s%s): another drive than configured is on this node",
                        node, si, what, read_value, expected, k ? hint : "drive.identity", ".", sub);
      break;
    }
    case BootCheck::kSupportedModes: {
      const auto mn = mode_name(static_cast<std::int8_t>(expected));
      n = std::snprintf(out.data(), out.size(),
                        "node %u: the drive does not support mode %d (%.*s): 0x6502 (%s) is 0x%08" PRIX32
                        "; the mode is needed by %s",
                        node, static_cast<int>(static_cast<std::int8_t>(expected)), static_cast<int>(mn.size()), mn.data(),
                        eds_name_or(dictionary, obj::kSupportedDriveModes, 0, "Supported drive modes"), read_value,
                        k ? hint : "the drive's configured mode");
      break;
    }
    case BootCheck::kModeDisplay: {
      const auto rq = mode_name(static_cast<std::int8_t>(expected));
      const auto sh = mode_name(static_cast<std::int8_t>(read_value));
      n = std::snprintf(out.data(), out.size(),
                        "node %u: 0x6060 = %d (%.*s) written, but 0x6061 (%s) still shows %d (%.*s) "
                        "after %.1f ms (%s): the drive does not run the mode it accepted",
                        node, static_cast<int>(static_cast<std::int8_t>(expected)), static_cast<int>(rq.size()), rq.data(),
                        eds_name_or(dictionary, obj::kModesOfOperationDisplay, 0, "Modes of operation display"),
                        static_cast<int>(static_cast<std::int8_t>(read_value)), static_cast<int>(sh.size()), sh.data(),
                        waited_ms, k ? hint : "mode switch timeout");
      break;
    }
    case BootCheck::kInterpolationIndex: {
      const auto idx = static_cast<int>(static_cast<std::int8_t>(read_value & 0xFFu));
      n = std::snprintf(out.data(), out.size(),
                        "node %u: 0x60C2:2 (%s) is read-only at %d (periods in units of "
                        "10^%d s) and the cycle period %.6g ms (%s) is not a whole number 1..255 of that unit: "
                        "choose a period the drive can take",
                        node, eds_name_or(dictionary, obj::kInterpolationTimePeriod, 2, "Interpolation time index"), idx, idx, static_cast<double>(expected) / 1e6, k ? hint : "the cycle period");
      break;
    }
    case BootCheck::kSyncCounter: {
      const auto text = canopen::sdo_abort_text(sdo_abort);
      char why[160];
      if (expected == 0)
        std::snprintf(why, sizeof why, "the drive expects SYNCs with a counter (up to %" PRIu32
                      ") and would drop every SYNC of the master, which has none (EMCY 8240h)", read_value);
      else if (read_value == 0)
        std::snprintf(why, sizeof why, "the drive takes SYNCs without a counter and would drop every SYNC of the "
                      "master, which carries one (EMCY 8240h)");
      else
        std::snprintf(why, sizeof why, "the drive counts SYNCs up to %" PRIu32 ", the master up to %" PRIu32,
                      read_value, expected);
      n = std::snprintf(out.data(), out.size(),
                        "node %u: 0x1019:0 (%s) refused the write of %" PRIu32
                        " (SDO abort 0x%08" PRIX32 " %.*s) and holds %" PRIu32 ": %s; set %s: %" PRIu32
                        ", or give the drive's 0x1019 the value %" PRIu32,
                        node, eds_name_or(dictionary, obj::kSyncCounterOverflow, 0, "Synchronous counter overflow value"),
                        expected, sdo_abort, static_cast<int>(text.size()), text.data(), read_value, why,
                        k ? hint : "the master's SYNC counter overflow", read_value, expected);
      break;
    }
    case BootCheck::kNone: n = std::snprintf(out.data(), out.size(), "node %u: boot check failed", node); break;
  }
  return n;
}

int Failure::describe_nmt_state(std::span<char> out, const char* emcy) const noexcept {
  const auto sn = state_name(reached);
  const auto st = canopen::nmt_state_name(nmt_state);
  // What the drive's CiA 402 state is: read over SDO (Pre-operational
  // answers SDO), or only its last TPDO's from before it left.
  char drive[192];
  if (statusword_read) {
    std::snprintf(drive, sizeof drive, "; the drive is in %.*s (statusword 0x%04X, read over SDO)",
                  static_cast<int>(sn.size()), sn.data(), statusword);
  } else if (nmt_state == canopen::NmtState::kStopped) {
    std::snprintf(drive, sizeof drive,
                  "; a stopped node answers no SDO: its CiA 402 state is not known (its last TPDO showed %.*s, "
                  "statusword 0x%04X)",
                  static_cast<int>(sn.size()), sn.data(), statusword);
  } else {
    std::snprintf(drive, sizeof drive, "; its last TPDO showed %.*s (statusword 0x%04X)", static_cast<int>(sn.size()),
                  sn.data(), statusword);
  }
  return std::snprintf(out.data(), out.size(),
                       "node %u: left NMT operational: its heartbeat shows %.*s (no PDOs are exchanged; many drives do "
                       "this on a communication error, CiA 301 0x1029)%s%s",
                       node, static_cast<int>(st.size()), st.data(), drive, emcy);
}

std::size_t Failure::describe(std::span<char> out) const noexcept {
  if (out.empty()) return 0;
  char emcy[96] = "";
  if (has_emcy) {
    std::snprintf(emcy, sizeof emcy, ", last EMCY 0x%04X (%.*s)", emcy_code,
                  static_cast<int>(canopen::emcy_code_text(emcy_code).size()), canopen::emcy_code_text(emcy_code).data());
  }
  const double waited_ms = static_cast<double>(waited_ns) / 1e6;
  const auto sn = state_name(reached);
  int n = 0;
  switch (kind) {
    case FailureKind::kNone:
      n = std::snprintf(out.data(), out.size(), "node %u: no failure", node);
      break;
    case FailureKind::kBootTimeout:
      n = std::snprintf(out.data(), out.size(),
                        "node %u: no boot-up or heartbeat within %.1f ms, even after NMT reset node (timeout %.1f ms)",
                        node, waited_ms, static_cast<double>(timeout_ns) / 1e6);
      break;
    case FailureKind::kSdoAbort: n = describe_sdo_abort(out, waited_ms); break;
    case FailureKind::kSdoQueueFull:
      n = std::snprintf(out.data(), out.size(), "node %u: SDO queue full while configuring", node);
      break;
    case FailureKind::kStartTimeout:
      n = std::snprintf(out.data(), out.size(), "node %u: no TPDO within %.1f ms after NMT start%s", node,
                        static_cast<double>(timeout_ns) / 1e6, emcy);
      break;
    case FailureKind::kTransitionTimeout: n = describe_transition(out, waited_ms, emcy); break;
    case FailureKind::kDriveFault:
      n = std::snprintf(out.data(), out.size(), "node %u: drive entered %.*s (statusword 0x%04X)%s", node,
                        static_cast<int>(sn.size()), sn.data(), statusword, emcy);
      break;
    case FailureKind::kHeartbeatLost:
      n = std::snprintf(out.data(), out.size(),
                        "node %u: heartbeat lost (none for %.1f ms; drive was in %.*s, statusword 0x%04X)%s", node,
                        static_cast<double>(timeout_ns) / 1e6, static_cast<int>(sn.size()), sn.data(), statusword, emcy);
      break;
    case FailureKind::kModeSwitchTimeout: {
      const auto rq = mode_name(mode_requested);
      const auto sh = mode_name(mode_shown);
      n = std::snprintf(out.data(), out.size(),
                        "node %u: mode switch to %d (%.*s) not shown in 0x6061 within %.1f ms: drive still shows %d "
                        "(%.*s), statusword 0x%04X%s",
                        node, mode_requested, static_cast<int>(rq.size()), rq.data(), static_cast<double>(timeout_ns) / 1e6,
                        mode_shown, static_cast<int>(sh.size()), sh.data(), statusword, emcy);
      break;
    }
    case FailureKind::kUnexpectedBootUp:
      n = std::snprintf(out.data(), out.size(),
                        "node %u: unexpected boot-up while %.*s (the drive reset itself or was power-cycled; it is "
                        "configured again)%s",
                        node, static_cast<int>(phase_name(phase).size()), phase_name(phase).data(), emcy);
      break;
    case FailureKind::kBootCheck: n = describe_boot_check(out, waited_ms); break;
    case FailureKind::kNmtState: n = describe_nmt_state(out, emcy); break;
  }
  if (n < 0) {
    out[0] = '\0';
    return 0;
  }
  return std::min<std::size_t>(static_cast<std::size_t>(n), out.size() - 1);
}

std::string Failure::to_string() const {
  char buf[512];
  const std::size_t n = describe(buf);
  return std::string(buf, n);
}

}  // namespace canmotion::cia402
