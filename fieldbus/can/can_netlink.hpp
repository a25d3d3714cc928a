#pragma once
/// \file
/// A CAN interface's kernel settings over rtnetlink: restart-ms, bitrate and
/// controller state (IFLA_CAN_* inside IFLA_LINKINFO / IFLA_INFO_DATA), and
/// the manual restart after bus-off (IFLA_CAN_RESTART, what `ip link set
/// can0 type can restart` sends).
///
/// Why: SocketCAN keeps a bus-off controller off until it is restarted, and
/// the kernel's default restart-ms is 0 (never automatically). canmotiond
/// reads restart-ms at start-up and warns when it is 0; on bus-off with
/// restart-ms 0 it restarts the interface itself (CAP_NET_ADMIN) or says
/// what to run.
///
/// Two layers, as the rest of fieldbus/ (DESIGN.md, lely-core style):
/// - sans-IO: build_getlink_request(), build_restart_request() and
///   parse_link_reply() work on byte buffers only (libmnl's attribute
///   helpers, no socket); golden-byte tests in tests/vcan/can_netlink_test.cpp;
///   decide_restart() and the message helpers are pure;
/// - I/O: query_can_link() and restart_can_link() open a NETLINK_ROUTE socket
///   (libmnl), send one request and read its answer. They block for a few
///   microseconds to milliseconds: NOT realtime-safe. Call them at start-up
///   or from a non-RT thread (canmotiond's housekeeping thread handles the
///   bus-off event), never from the cycle.
///
/// Virtual interfaces (vcan, vxcan) have no CAN netlink attributes: their
/// link kind is not "can" and there is no IFLA_INFO_DATA; CanLink::is_can is
/// false and nothing is said about them.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace canmotion::can {

/// What the kernel says about one network interface.
struct CanLink {
  std::string name;            ///< IFLA_IFNAME
  std::string kind;            ///< IFLA_INFO_KIND ("can", "vcan", ... ; "" when absent)
  bool is_can = false;         ///< kind "can" with IFLA_INFO_DATA (a CAN controller: restart-ms applies)
  std::optional<std::uint32_t> restart_ms;  ///< IFLA_CAN_RESTART_MS
  std::optional<std::uint32_t> bitrate;     ///< IFLA_CAN_BITTIMING's bitrate (bit/s)
  std::optional<std::uint32_t> state;       ///< IFLA_CAN_STATE (enum can_state: 0 active .. 3 bus-off, 4 stopped)
};

/// The RTM_GETLINK request for interface index `ifindex` (NLM_F_REQUEST).
[[nodiscard]] std::vector<std::uint8_t> build_getlink_request(std::uint32_t ifindex, std::uint32_t seq);
/// The RTM_NEWLINK request that restarts a bus-off CAN controller:
/// IFLA_LINKINFO { IFLA_INFO_KIND "can", IFLA_INFO_DATA { IFLA_CAN_RESTART = 1 } },
/// NLM_F_REQUEST | NLM_F_ACK (as `ip link set DEV type can restart`).
[[nodiscard]] std::vector<std::uint8_t> build_restart_request(std::uint32_t ifindex, std::uint32_t seq);

/// Parse one RTM_NEWLINK message (the answer to RTM_GETLINK). Returns
/// nullopt and sets `why` when the bytes are not a well-formed RTM_NEWLINK
/// (short, wrong type, attributes overrunning the message). Unknown
/// attributes are skipped. Pure.
[[nodiscard]] std::optional<CanLink> parse_link_reply(std::span<const std::uint8_t> msg, std::string* why = nullptr);
/// The error of an NLMSG_ERROR message: 0 for an ACK, a positive errno
/// otherwise; nullopt when `msg` is not an NLMSG_ERROR. Pure.
[[nodiscard]] std::optional<int> parse_netlink_error(std::span<const std::uint8_t> msg);

/// What canmotiond does about a bus-off on an interface.
enum class BusOffRestart : std::uint8_t {
  kNotCan,      ///< not a CAN controller (vcan): nothing to restart, nothing to say
  kKernel,      ///< restart-ms > 0: the kernel restarts the controller by itself
  kRestartNow,  ///< restart-ms 0: canmotiond restarts it (IFLA_CAN_RESTART)
};
[[nodiscard]] BusOffRestart decide_restart(const CanLink& link) noexcept;

/// Start-up note for `link`: "" when nothing is to be said (not CAN, or
/// restart-ms > 0); with restart-ms 0 the warning and the exact command,
/// `ip link set can0 type can restart-ms 100` (with the link down first).
[[nodiscard]] std::string restart_ms_warning(const CanLink& link);

/// Start-up note when a CAN controller's bitrate differs from `configured`
/// (buses[].bitrate, which the bus budget uses): "" when it matches, the
/// link is not CAN or the kernel gave no bitrate.
[[nodiscard]] std::string bitrate_note(const CanLink& link, std::uint32_t configured);

/// Read `ifname`'s link settings over rtnetlink. nullopt and `why` (naming
/// the interface and the failing step) on failure. Not realtime-safe.
[[nodiscard]] std::optional<CanLink> query_can_link(std::string_view ifname, std::string* why = nullptr);
/// Restart the bus-off CAN controller `ifname` (IFLA_CAN_RESTART). 0 on
/// success, else the errno the kernel (or the socket) gave: EPERM without
/// CAP_NET_ADMIN, EBUSY when the controller is not bus-off, EINVAL when
/// restart-ms is not 0. Not realtime-safe.
[[nodiscard]] int restart_can_link(std::string_view ifname);

/// The whole bus-off reaction of the non-RT side for `ifname`: query the
/// link, restart it when restart-ms is 0, and return one sentence saying
/// which happened ("" for a non-CAN interface such as vcan): the kernel
/// restarts it (restart-ms N), canmotiond restarted it, or the restart
/// failed (errno) and the bus stays off, with the command to run. Not
/// realtime-safe.
[[nodiscard]] std::string handle_bus_off(std::string_view ifname);

}  // namespace canmotion::can
