// CAN error frames in words (issue 15 item 3): the classes SocketCAN reports
// (no ACK, protocol, transceiver, controller, ...) and what to do on bus-off.
// Host-side: handle_error_frame() and the texts need no CAN interface.
#include <gtest/gtest.h>

#include <linux/can/error.h>

#include <array>

#include "fieldbus/can/socketcan_bus.hpp"

using canmotion::can::BusEvent;
using canmotion::can::SocketCanBus;

TEST(BusErrors, EachClassIsNamed) {
  EXPECT_EQ(SocketCanBus::error_classes_text(CAN_ERR_ACK),
            "no ACK (no other node acknowledged: all drives off or unplugged, or another bitrate)");
  const std::string both = SocketCanBus::error_classes_text(CAN_ERR_PROT | CAN_ERR_TRX);
  EXPECT_NE(both.find("protocol violation"), std::string::npos) << both;
  EXPECT_NE(both.find("transceiver problem"), std::string::npos) << both;
  EXPECT_NE(SocketCanBus::error_classes_text(CAN_ERR_CRTL).find("controller problem"), std::string::npos);
  EXPECT_EQ(SocketCanBus::error_classes_text(0), "unknown error class");
}

TEST(BusErrors, BusOffAdviceNamesBothCommands) {
  const std::string a = SocketCanBus::bus_off_advice("can1");
  EXPECT_NE(a.find("ip link set can1 type can restart`"), std::string::npos) << a;
  EXPECT_NE(a.find("ip link set can1 type can restart-ms 100"), std::string::npos) << a;
}
