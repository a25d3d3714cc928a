#include "fieldbus/can/can_netlink.hpp"

#include <libmnl/libmnl.h>
#include <linux/can/netlink.h>
#include <linux/if_link.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <cerrno>
#include <cstring>

#include "fieldbus/can/socketcan_bus.hpp"

namespace canmotion::can {
namespace {

// A netlink message in 4-byte aligned storage (libmnl reads struct nlmsghdr
// and struct nlattr through pointers into it).
// Longer messages are cut (a link message is a few hundred bytes; netlink
// messages are at most 64 KiB), so the copy has a bound.
constexpr std::size_t kMaxMessage = 65536;
struct Aligned {
  std::vector<std::uint32_t> words;
  explicit Aligned(std::span<const std::uint8_t> bytes) : words(kMaxMessage / 4, 0) {
    const std::size_t n = bytes.size() < kMaxMessage ? bytes.size() : kMaxMessage;
    std::memcpy(words.data(), bytes.data(), n);
    words.resize((n + 3) / 4);
  }
  nlmsghdr* nlh() { return reinterpret_cast<nlmsghdr*>(words.data()); }
};

std::vector<std::uint8_t> to_bytes(const nlmsghdr* nlh) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(nlh);
  return {p, p + nlh->nlmsg_len};
}

// Room for a request: header, ifinfomsg and a few small attributes.
constexpr std::size_t kRequestBytes = 256;

nlmsghdr* put_link_header(std::uint32_t* buf, std::uint16_t type, std::uint16_t flags, std::uint32_t seq,
                          std::uint32_t ifindex) {
  nlmsghdr* nlh = mnl_nlmsg_put_header(buf);
  nlh->nlmsg_type = type;
  nlh->nlmsg_flags = flags;
  nlh->nlmsg_seq = seq;
  auto* ifi = static_cast<ifinfomsg*>(mnl_nlmsg_put_extra_header(nlh, sizeof(ifinfomsg)));
  ifi->ifi_family = AF_UNSPEC;
  ifi->ifi_index = static_cast<int>(ifindex);
  return nlh;
}

struct ParseState {
  CanLink link;
  const nlattr* info_data = nullptr;  // into the message being parsed
  bool bad = false;
};

int can_data_attr(const nlattr* attr, void* data) {
  auto& st = *static_cast<ParseState*>(data);
  switch (mnl_attr_get_type(attr)) {
    case IFLA_CAN_RESTART_MS:
      if (mnl_attr_validate(attr, MNL_TYPE_U32) < 0) { st.bad = true; return MNL_CB_ERROR; }
      st.link.restart_ms = mnl_attr_get_u32(attr);
      break;
    case IFLA_CAN_STATE:
      if (mnl_attr_validate(attr, MNL_TYPE_U32) < 0) { st.bad = true; return MNL_CB_ERROR; }
      st.link.state = mnl_attr_get_u32(attr);
      break;
    case IFLA_CAN_BITTIMING:
      // struct can_bittiming starts with the bitrate (__u32).
      if (mnl_attr_get_payload_len(attr) < sizeof(can_bittiming)) { st.bad = true; return MNL_CB_ERROR; }
      {
        can_bittiming bt{};
        std::memcpy(&bt, mnl_attr_get_payload(attr), sizeof bt);
        st.link.bitrate = bt.bitrate;
      }
      break;
    default: break;
  }
  return MNL_CB_OK;
}

int link_info_attr(const nlattr* attr, void* data) {
  auto& st = *static_cast<ParseState*>(data);
  switch (mnl_attr_get_type(attr)) {
    case IFLA_INFO_KIND:
      if (mnl_attr_validate(attr, MNL_TYPE_STRING) < 0) { st.bad = true; return MNL_CB_ERROR; }
      st.link.kind = mnl_attr_get_str(attr);
      break;
    case IFLA_INFO_DATA:
      // Parsed once the kind is known (another kind's data, e.g. vxcan's
      // peer, reuses the same attribute numbers).
      st.info_data = attr;
      break;
    default: break;
  }
  return MNL_CB_OK;
}

int link_attr(const nlattr* attr, void* data) {
  auto& st = *static_cast<ParseState*>(data);
  switch (mnl_attr_get_type(attr)) {
    case IFLA_IFNAME:
      if (mnl_attr_validate(attr, MNL_TYPE_STRING) < 0) { st.bad = true; return MNL_CB_ERROR; }
      st.link.name = mnl_attr_get_str(attr);
      break;
    case IFLA_LINKINFO:
      if (mnl_attr_parse_nested(attr, link_info_attr, data) < 0) { st.bad = true; return MNL_CB_ERROR; }
      if (st.link.kind == "can" && st.info_data != nullptr) {
        st.link.is_can = true;
        if (mnl_attr_parse_nested(st.info_data, can_data_attr, data) < 0) { st.bad = true; return MNL_CB_ERROR; }
      }
      break;
    default: break;
  }
  return MNL_CB_OK;
}

void set_why(std::string* why, std::string s) {
  if (why != nullptr) *why = std::move(s);
}

// One request/answer exchange on a fresh NETLINK_ROUTE socket. `on_msg` is
// called for each message of the answer; returns 0 or an errno.
int exchange(const std::vector<std::uint8_t>& request, mnl_cb_t on_msg, void* data, std::string* step) {
  mnl_socket* nl = mnl_socket_open(NETLINK_ROUTE);
  if (nl == nullptr) { *step = "socket(NETLINK_ROUTE)"; return errno; }
  struct Closer {
    mnl_socket* s;
    ~Closer() { mnl_socket_close(s); }
  } closer{nl};
  if (mnl_socket_bind(nl, 0, MNL_SOCKET_AUTOPID) < 0) { *step = "bind"; return errno; }
  // The kernel answers at once; the bound keeps a lost answer from hanging the caller.
  timeval tv{1, 0};
  (void)setsockopt(mnl_socket_get_fd(nl), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (mnl_socket_sendto(nl, request.data(), request.size()) < 0) { *step = "sendto"; return errno; }
  const auto* req = reinterpret_cast<const nlmsghdr*>(request.data());
  const std::uint32_t portid = mnl_socket_get_portid(nl);
  std::vector<std::uint32_t> buf(MNL_SOCKET_BUFFER_SIZE / 4);
  for (;;) {
    const ssize_t n = mnl_socket_recvfrom(nl, buf.data(), buf.size() * 4);
    if (n < 0) { *step = "recv"; return errno; }
    const int r = mnl_cb_run(buf.data(), static_cast<std::size_t>(n), req->nlmsg_seq, portid, on_msg, data);
    if (r == MNL_CB_ERROR) { *step = "the kernel's answer"; return errno != 0 ? errno : EPROTO; }
    if (r == MNL_CB_STOP) return 0;
  }
}

}  // namespace

std::vector<std::uint8_t> build_getlink_request(std::uint32_t ifindex, std::uint32_t seq) {
  std::uint32_t buf[kRequestBytes / 4] = {};
  return to_bytes(put_link_header(buf, RTM_GETLINK, NLM_F_REQUEST, seq, ifindex));
}

std::vector<std::uint8_t> build_restart_request(std::uint32_t ifindex, std::uint32_t seq) {
  std::uint32_t buf[kRequestBytes / 4] = {};
  nlmsghdr* nlh = put_link_header(buf, RTM_NEWLINK, NLM_F_REQUEST | NLM_F_ACK, seq, ifindex);
  nlattr* info = mnl_attr_nest_start(nlh, IFLA_LINKINFO);
  mnl_attr_put_strz(nlh, IFLA_INFO_KIND, "can");
  nlattr* d = mnl_attr_nest_start(nlh, IFLA_INFO_DATA);
  mnl_attr_put_u32(nlh, IFLA_CAN_RESTART, 1);
  mnl_attr_nest_end(nlh, d);
  mnl_attr_nest_end(nlh, info);
  return to_bytes(nlh);
}

std::optional<CanLink> parse_link_reply(std::span<const std::uint8_t> msg, std::string* why) {
  if (msg.size() < sizeof(nlmsghdr) + sizeof(ifinfomsg)) {
    set_why(why, "netlink message too short for RTM_NEWLINK (" + std::to_string(msg.size()) + " bytes)");
    return std::nullopt;
  }
  Aligned a(msg);
  nlmsghdr* nlh = a.nlh();
  if (!mnl_nlmsg_ok(nlh, static_cast<int>(msg.size())) || nlh->nlmsg_len < sizeof(nlmsghdr) + sizeof(ifinfomsg)) {
    set_why(why, "netlink length " + std::to_string(nlh->nlmsg_len) + " does not fit the " +
                     std::to_string(msg.size()) + " bytes");
    return std::nullopt;
  }
  if (nlh->nlmsg_type != RTM_NEWLINK) {
    set_why(why, "netlink message type " + std::to_string(nlh->nlmsg_type) + " is not RTM_NEWLINK");
    return std::nullopt;
  }
  ParseState st;
  if (mnl_attr_parse(nlh, sizeof(ifinfomsg), link_attr, &st) < 0 || st.bad) {
    set_why(why, "malformed link attributes");
    return std::nullopt;
  }
  return st.link;
}

std::optional<int> parse_netlink_error(std::span<const std::uint8_t> msg) {
  if (msg.size() < sizeof(nlmsghdr) + sizeof(nlmsgerr)) return std::nullopt;
  Aligned a(msg);
  const nlmsghdr* nlh = a.nlh();
  if (nlh->nlmsg_type != NLMSG_ERROR || nlh->nlmsg_len < sizeof(nlmsghdr) + sizeof(nlmsgerr)) return std::nullopt;
  const auto* e = static_cast<const nlmsgerr*>(mnl_nlmsg_get_payload(nlh));
  return -e->error;
}

BusOffRestart decide_restart(const CanLink& link) noexcept {
  if (!link.is_can) return BusOffRestart::kNotCan;
  // A CAN link without IFLA_CAN_RESTART_MS (not seen from the kernel's can-dev,
  // which always sends it) is treated as restart-ms 0: restarting is harmless.
  return link.restart_ms.value_or(0) > 0 ? BusOffRestart::kKernel : BusOffRestart::kRestartNow;
}

std::string restart_ms_warning(const CanLink& link) {
  if (decide_restart(link) != BusOffRestart::kRestartNow) return {};
  const std::string& i = link.name;
  return "interface " + i +
         " has restart-ms 0 (the kernel's default): after a bus-off it stays off until restarted; canmotiond "
         "will try to restart it (needs CAP_NET_ADMIN). For automatic restarts run `ip link set " +
         i + " down && ip link set " + i + " type can restart-ms 100 && ip link set " + i + " up`";
}

std::string bitrate_note(const CanLink& link, std::uint32_t configured) {
  if (!link.is_can || !link.bitrate || *link.bitrate == configured) return {};
  return "interface " + link.name + " runs at " + std::to_string(*link.bitrate) + " bit/s but buses[].bitrate is " +
         std::to_string(configured) + " (the bus budget was checked with " + std::to_string(configured) +
         "): set buses[].bitrate to " + std::to_string(*link.bitrate) + ", or the interface with `ip link set " +
         link.name + " down && ip link set " + link.name + " type can bitrate " + std::to_string(configured) +
         " && ip link set " + link.name + " up`";
}

std::optional<CanLink> query_can_link(std::string_view ifname, std::string* why) {
  const std::string name(ifname);
  const unsigned idx = if_nametoindex(name.c_str());
  if (idx == 0) {
    set_why(why, "interface '" + name + "': if_nametoindex failed: " + std::strerror(errno));
    return std::nullopt;
  }
  struct Got {
    std::optional<CanLink> link;
    std::string why;
  } got;
  auto on_msg = [](const nlmsghdr* nlh, void* data) -> int {
    auto& g = *static_cast<Got*>(data);
    const auto* p = reinterpret_cast<const std::uint8_t*>(nlh);
    g.link = parse_link_reply({p, nlh->nlmsg_len}, &g.why);
    return MNL_CB_STOP;
  };
  std::string step;
  if (const int err = exchange(build_getlink_request(idx, 1), on_msg, &got, &step); err != 0) {
    set_why(why, "interface '" + name + "': rtnetlink RTM_GETLINK: " + step + " failed: " + std::strerror(err));
    return std::nullopt;
  }
  if (!got.link) set_why(why, "interface '" + name + "': rtnetlink answer: " + got.why);
  return got.link;
}

int restart_can_link(std::string_view ifname) {
  const std::string name(ifname);
  const unsigned idx = if_nametoindex(name.c_str());
  if (idx == 0) return errno;
  std::string step;
  // An ACK ends the exchange with MNL_CB_STOP; an error with its errno.
  return exchange(build_restart_request(idx, 1), nullptr, nullptr, &step);
}

std::string handle_bus_off(std::string_view ifname) {
  const std::string i(ifname);
  std::string why;
  const std::optional<CanLink> link = query_can_link(ifname, &why);
  if (!link) return "could not read the settings of " + i + " (" + why + "): " + SocketCanBus::bus_off_advice(ifname);
  switch (decide_restart(*link)) {
    case BusOffRestart::kNotCan: return {};
    case BusOffRestart::kKernel:
      return "the kernel restarts " + i + " by itself after restart-ms " + std::to_string(*link->restart_ms) +
             " ms; canmotiond re-boots the drives when the bus is back, then MASR and MSO";
    case BusOffRestart::kRestartNow: break;
  }
  if (const int err = restart_can_link(ifname); err != 0) {
    return "restart-ms of " + i + " is 0 and canmotiond could not restart it (" + std::strerror(err) +
           (err == EPERM ? ": canmotiond lacks CAP_NET_ADMIN" : "") + "): the bus stays off. " +
           SocketCanBus::bus_off_advice(ifname);
  }
  return "restart-ms of " + i + " is 0: canmotiond restarted it (as `ip link set " + i +
         " type can restart`); it re-boots the drives when the bus is back, then MASR and MSO";
}

}  // namespace canmotion::can
