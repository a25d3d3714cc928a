// The texts of the drive proxy's failures and notices (DESIGN.md: a failure
// explains itself): Failure::describe and describe_notice. What a refused
// boot transfer is for, the fallback taken and a failed check's sentence
// come from the boot plan (boot_plan.cpp, boot_checks.cpp). snprintf into
// the caller's buffer: call them from a non-RT thread.
#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <string>

#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"

namespace canmotion::cia402 {

std::string describe_notice(const canopen::NodeEvent& e, const canopen::DeviceDictionary* dictionary) {
  const std::string_view name =
      dictionary != nullptr ? dictionary->name_or_standard(e.index, e.sub) : canopen::object_name(e.index, e.sub);
  // The fallback the proxy took, from the boot plan's row (BootNotes).
  char fallback[160] = "not written; the drive keeps its own setting";
  if (const char* note = boot_note_text(e.note, e.index); note != nullptr)
    std::snprintf(fallback, sizeof fallback, note, static_cast<int>(e.detail));
  char out[512];
  if (e.abort == 0 && boot_note_of_read(e.note)) {  // a read at boot that passed, with something to say
    std::snprintf(out, sizeof out, "node %u: 0x%04X:%u (%.*s) read at boot: %s", e.node, e.index, e.sub,
                  static_cast<int>(name.size()), name.data(), fallback);
    return out;
  }
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
  // What the refused transfer is for and what to do: its boot plan rows' sentence.
  char why[320];
  const BootHint& h = boot_hint(sdo_origin);
  const bool k = hint != nullptr && hint[0] != '\0';
  std::snprintf(why, sizeof why, k ? h.with_key : h.without_key, hint);
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
  if (follow_missing)
    return std::snprintf(out.data(), out.size(),
                         "node %u: transition 4 towards Operation enabled not completed after %.1f ms: the drive shows "
                         "Operation enabled in CSP, but statusword bit 12 (drive follows the command) stayed 0, "
                         "statusword 0x%04X%s: the drive ignores 0x607A (target position); see its manual for what "
                         "holds the command back (e.g. a halt, an interpolation or synchronisation setting)",
                         node, waited_ms, statusword, emcy);
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
    case FailureKind::kBootCheck: n = boot_check_rule(check).describe(*this, out, waited_ms); break;
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
