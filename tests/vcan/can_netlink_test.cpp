// rtnetlink for CAN interfaces (fieldbus/can/can_netlink): golden bytes of
// the two requests canmotiond sends, parsing of RTM_NEWLINK answers for a CAN
// controller (restart-ms 0 and 100), a vcan, a plain link and malformed
// messages, and the restart decision. The CAN answers are assembled here by
// hand from the kernel's layout (linux/rtnetlink.h, linux/if_link.h,
// linux/can/netlink.h; drivers/net/can/dev/netlink.c can_fill_info sends
// BITTIMING, CLOCK, STATE, CTRLMODE, RESTART_MS in that order); no host here
// has a CAN controller. The last test asks the real kernel about vcan0 (in
// the VM run, vcan.can_netlink_unit): not CAN, nothing to say.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "fieldbus/can/can_netlink.hpp"
#include "fieldbus/can/socketcan_bus.hpp"

namespace canmotion::can {
namespace {

std::vector<std::uint8_t> hex(const std::string& s) {
  std::vector<std::uint8_t> out;
  std::string digits;
  for (char c : s)
    if (std::isxdigit(static_cast<unsigned char>(c)) != 0) digits += c;
  for (std::size_t i = 0; i + 1 < digits.size(); i += 2) out.push_back(static_cast<std::uint8_t>(std::stoul(digits.substr(i, 2), nullptr, 16)));
  return out;
}
std::string hex_of(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::uint8_t x : b) {
    std::snprintf(buf, sizeof buf, "%02x", x);
    s += buf;
  }
  return s;
}

// RTM_NEWLINK for can0 (ifindex 3, 500 kbit/s); `restart_ms` and `state` as given (little endian u32 hex).
std::vector<std::uint8_t> can_link_reply(const std::string& restart_ms_le, const std::string& state_le) {
  return hex(
      "8c000000 1000 0000 01000000 00000000"  // nlmsghdr: len 140, RTM_NEWLINK, flags 0, seq 1, pid 0
      "00 00 1801 03000000 c1000000 00000000"  // ifinfomsg: AF_UNSPEC, ARPHRD_CAN (280), index 3, UP|RUNNING|NOARP
      "0900 0300 63616e3000 000000"           // IFLA_IFNAME "can0"
      "0800 0d00 0a000000"                    // IFLA_TXQLEN 10
      "5800 1200"                             // IFLA_LINKINFO, 88 bytes
      "  0800 0100 63616e00"                  //   IFLA_INFO_KIND "can"
      "  4c00 0200"                           //   IFLA_INFO_DATA, 76 bytes
      "    2400 0100 20a10700 6b030000 7d000000 06000000 07000000 02000000 01000000 0a000000"  // BITTIMING 500000 ...
      "    0800 0300 00b4c404"                //     IFLA_CAN_CLOCK 80 MHz
      "    0800 0400 " + state_le +           //     IFLA_CAN_STATE
      "    0c00 0500 00000000 00000000"       //     IFLA_CAN_CTRLMODE
      "    0800 0600 " + restart_ms_le);      //     IFLA_CAN_RESTART_MS
}

TEST(CanNetlink, GetlinkRequestGoldenBytes) {
  EXPECT_EQ(hex_of(build_getlink_request(3, 7)),
            "20000000" "1200" "0100" "07000000" "00000000"  // len 32, RTM_GETLINK, NLM_F_REQUEST, seq 7
            "00" "00" "0000" "03000000" "00000000" "00000000");  // ifinfomsg: index 3
}

TEST(CanNetlink, RestartRequestGoldenBytes) {
  // As `ip link set can0 type can restart` (iproute2 iplink_can.c): IFLA_LINKINFO
  // { IFLA_INFO_KIND "can", IFLA_INFO_DATA { IFLA_CAN_RESTART u32 1 } }; libmnl
  // marks nests with NLA_F_NESTED (0x8000), which the kernel accepts.
  EXPECT_EQ(hex_of(build_restart_request(3, 9)),
            "38000000" "1000" "0500" "09000000" "00000000"  // len 56, RTM_NEWLINK, REQUEST|ACK, seq 9
            "00" "00" "0000" "03000000" "00000000" "00000000"
            "1800" "1280"                                    // IFLA_LINKINFO (nested), 24 bytes
            "0800" "0100" "63616e00"                         //   IFLA_INFO_KIND "can"
            "0c00" "0280"                                    //   IFLA_INFO_DATA (nested), 12 bytes
            "0800" "0700" "01000000");                       //     IFLA_CAN_RESTART 1
}

TEST(CanNetlink, CanLinkWithRestartMsZeroIsRestartedByCanmotion) {
  const auto msg = can_link_reply("00000000", "03000000");
  ASSERT_EQ(msg.size(), 140u);
  std::string why;
  const auto link = parse_link_reply(msg, &why);
  ASSERT_TRUE(link) << why;
  EXPECT_EQ(link->name, "can0");
  EXPECT_EQ(link->kind, "can");
  EXPECT_TRUE(link->is_can);
  EXPECT_EQ(link->restart_ms, 0u);
  EXPECT_EQ(link->bitrate, 500000u);
  EXPECT_EQ(link->state, 3u);  // CAN_STATE_BUS_OFF
  EXPECT_EQ(decide_restart(*link), BusOffRestart::kRestartNow);
  const std::string w = restart_ms_warning(*link);
  EXPECT_NE(w.find("interface can0 has restart-ms 0"), std::string::npos) << w;
  EXPECT_NE(w.find("`ip link set can0 down && ip link set can0 type can restart-ms 100 && ip link set can0 up`"),
            std::string::npos) << w;
}

TEST(CanNetlink, BitrateDifferingFromTheConfigurationIsNoted) {
  const auto link = parse_link_reply(can_link_reply("00000000", "00000000"));
  ASSERT_TRUE(link);
  EXPECT_EQ(bitrate_note(*link, 500000), "");
  const std::string n = bitrate_note(*link, 1000000);
  EXPECT_NE(n.find("interface can0 runs at 500000 bit/s but buses[].bitrate is 1000000"), std::string::npos) << n;
  EXPECT_NE(n.find("`ip link set can0 down && ip link set can0 type can bitrate 1000000 && ip link set can0 up`"),
            std::string::npos) << n;
  CanLink vcan;
  vcan.name = "vcan0";
  vcan.kind = "vcan";
  EXPECT_EQ(bitrate_note(vcan, 1000000), "");
}

TEST(CanNetlink, CanLinkWithRestartMs100IsLeftToTheKernel) {
  const auto link = parse_link_reply(can_link_reply("64000000", "00000000"));
  ASSERT_TRUE(link);
  EXPECT_TRUE(link->is_can);
  EXPECT_EQ(link->restart_ms, 100u);
  EXPECT_EQ(link->state, 0u);
  EXPECT_EQ(decide_restart(*link), BusOffRestart::kKernel);
  EXPECT_EQ(restart_ms_warning(*link), "");
}

TEST(CanNetlink, VcanHasNoCanAttributesAndNothingIsSaid) {
  // What the kernel sends for a vcan: IFLA_LINKINFO { IFLA_INFO_KIND "vcan" }, no IFLA_INFO_DATA.
  const auto msg = hex(
      "3c000000 1000 0000 01000000 00000000"
      "00 00 1801 04000000 c1000000 00000000"
      "0a00 0300 7663616e3000 0000"   // IFLA_IFNAME "vcan0"
      "1000 1200"                     // IFLA_LINKINFO, 16 bytes
      "  0900 0100 7663616e00 000000");  // IFLA_INFO_KIND "vcan"
  std::string why;
  const auto link = parse_link_reply(msg, &why);
  ASSERT_TRUE(link) << why;
  EXPECT_EQ(link->name, "vcan0");
  EXPECT_EQ(link->kind, "vcan");
  EXPECT_FALSE(link->is_can);
  EXPECT_FALSE(link->restart_ms);
  EXPECT_EQ(decide_restart(*link), BusOffRestart::kNotCan);
  EXPECT_EQ(restart_ms_warning(*link), "");
}

TEST(CanNetlink, AnotherKindsDataIsNotReadAsCanData) {
  // A kind with IFLA_INFO_DATA whose attribute 1 is no can_bittiming (vxcan's peer).
  const auto msg = hex(
      "44000000 1000 0000 01000000 00000000"
      "00 00 1801 05000000 c1000000 00000000"
      "1c00 1200"
      "  0a00 0100 766263616e00 0000"  // IFLA_INFO_KIND "vbcan" (6 bytes + pad)
      "  0c00 0200 0800 0600 00000000"  // IFLA_INFO_DATA { attribute 6 = 0 }
      "0800 0d00 0a000000");
  const auto link = parse_link_reply(msg);
  ASSERT_TRUE(link);
  EXPECT_FALSE(link->is_can);
  EXPECT_FALSE(link->restart_ms) << "attribute 6 of another kind read as restart-ms";
  EXPECT_EQ(decide_restart(*link), BusOffRestart::kNotCan);
}

TEST(CanNetlink, LinkWithoutLinkInfoIsNotCan) {
  const auto msg = hex("28000000 1000 0000 01000000 00000000 00 00 0100 01000000 49000000 00000000"
                       "0700 0300 6c6f00 00");  // "lo"
  const auto link = parse_link_reply(msg);
  ASSERT_TRUE(link);
  EXPECT_EQ(link->name, "lo");
  EXPECT_EQ(link->kind, "");
  EXPECT_EQ(decide_restart(*link), BusOffRestart::kNotCan);
}

TEST(CanNetlink, MalformedMessagesAreRefusedWithAReason) {
  std::string why;
  auto msg = can_link_reply("00000000", "00000000");
  EXPECT_FALSE(parse_link_reply(std::span(msg).first(20), &why));
  EXPECT_NE(why.find("too short"), std::string::npos) << why;
  // nlmsg_len larger than the bytes.
  auto longer = msg;
  longer[0] = 0xF0;
  EXPECT_FALSE(parse_link_reply(longer, &why));
  EXPECT_NE(why.find("does not fit"), std::string::npos) << why;
  // Not RTM_NEWLINK.
  auto other = msg;
  other[4] = 0x14;  // RTM_NEWADDR
  EXPECT_FALSE(parse_link_reply(other, &why));
  EXPECT_NE(why.find("not RTM_NEWLINK"), std::string::npos) << why;
  // IFLA_CAN_RESTART_MS with a 2-byte payload.
  auto bad = msg;
  bad[bad.size() - 8] = 0x06;
  EXPECT_FALSE(parse_link_reply(bad, &why));
  EXPECT_EQ(why, "malformed link attributes");
}

TEST(CanNetlink, NetlinkErrorAndAck) {
  // NLMSG_ERROR (2): error 0 = ACK; -1 = EPERM; then the request's header.
  const std::string req_hdr = "38000000 1000 0500 09000000 00000000";
  EXPECT_EQ(parse_netlink_error(hex("24000000 0200 0001 09000000 00000000 00000000" + req_hdr)), 0);
  EXPECT_EQ(parse_netlink_error(hex("24000000 0200 0000 09000000 00000000 ffffffff" + req_hdr)), 1);
  EXPECT_EQ(parse_netlink_error(can_link_reply("00000000", "00000000")), std::nullopt);
}

TEST(CanNetlink, TheKernelsVcanIsNotCanAndBusOffSaysNothing) {
  if (!SocketCanBus::kernel_has_can()) GTEST_SKIP() << "no CAN in this kernel; covered in the vcan test run";
  std::string why;
  const auto link = query_can_link("vcan0", &why);
  if (!link && why.find("if_nametoindex") != std::string::npos) GTEST_SKIP() << why;
  ASSERT_TRUE(link) << why;
  EXPECT_EQ(link->name, "vcan0");
  EXPECT_EQ(link->kind, "vcan");
  EXPECT_FALSE(link->is_can);
  EXPECT_EQ(handle_bus_off("vcan0"), "");
  EXPECT_FALSE(query_can_link("nosuchcan9", &why));
  EXPECT_NE(why.find("interface 'nosuchcan9'"), std::string::npos) << why;
  // A restart of a non-CAN link is refused by the kernel (vcan has no changelink).
  EXPECT_NE(restart_can_link("vcan0"), 0);
}

}  // namespace
}  // namespace canmotion::can
