// Unit tests of the shared CANopen / CiA 402 definition headers.
#include <gtest/gtest.h>

#include <set>

#include "fieldbus/canopen/cob_id.hpp"
#include "fieldbus/canopen/emcy.hpp"
#include "fieldbus/canopen/nmt.hpp"
#include "fieldbus/canopen/object_names.hpp"
#include "fieldbus/canopen/sdo_abort.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"
#include "fieldbus/cia402/cia402.hpp"

using namespace canmotion;
using canopen::FrameKind;

TEST(FieldbusCobId, ClassifiesPredefinedConnectionSet) {
  using canopen::classify;
  using canopen::CobInfo;
  EXPECT_EQ(classify(0x000), (CobInfo{FrameKind::kNmt, 0, 0}));
  EXPECT_EQ(classify(0x080), (CobInfo{FrameKind::kSync, 0, 0}));
  EXPECT_EQ(classify(0x082), (CobInfo{FrameKind::kEmcy, 2, 0}));
  EXPECT_EQ(classify(0x100), (CobInfo{FrameKind::kTime, 0, 0}));
  EXPECT_EQ(classify(0x183), (CobInfo{FrameKind::kTpdo, 3, 1}));
  EXPECT_EQ(classify(0x203), (CobInfo{FrameKind::kRpdo, 3, 1}));
  EXPECT_EQ(classify(0x285), (CobInfo{FrameKind::kTpdo, 5, 2}));
  EXPECT_EQ(classify(0x305), (CobInfo{FrameKind::kRpdo, 5, 2}));
  EXPECT_EQ(classify(0x3FF), (CobInfo{FrameKind::kTpdo, 127, 3}));
  EXPECT_EQ(classify(0x401), (CobInfo{FrameKind::kRpdo, 1, 3}));
  EXPECT_EQ(classify(0x481), (CobInfo{FrameKind::kTpdo, 1, 4}));
  EXPECT_EQ(classify(0x501), (CobInfo{FrameKind::kRpdo, 1, 4}));
  EXPECT_EQ(classify(0x582), (CobInfo{FrameKind::kSdoTx, 2, 0}));
  EXPECT_EQ(classify(0x602), (CobInfo{FrameKind::kSdoRx, 2, 0}));
  EXPECT_EQ(classify(0x77F), (CobInfo{FrameKind::kHeartbeat, 127, 0}));
  EXPECT_EQ(classify(0x7E5).kind, FrameKind::kLss);
  EXPECT_EQ(classify(0x180).kind, FrameKind::kUnknown);  // node 0 is not a node
  EXPECT_EQ(classify(0x800).kind, FrameKind::kUnknown);
  for (std::uint8_t n = 1; n <= 127; ++n) {
    for (std::uint8_t p = 1; p <= 4; ++p) {
      EXPECT_EQ(classify(canopen::cob::tpdo(p, n)), (CobInfo{FrameKind::kTpdo, n, p}));
      EXPECT_EQ(classify(canopen::cob::rpdo(p, n)), (CobInfo{FrameKind::kRpdo, n, p}));
    }
  }
}

TEST(FieldbusNmt, FramesAndNames) {
  const auto f = canopen::make_nmt_frame(canopen::NmtCommand::kStart, 2);
  EXPECT_EQ(f, (can::Frame{0x000, {0x01, 0x02}}));
  EXPECT_EQ(canopen::make_heartbeat_frame(3, canopen::NmtState::kPreOperational), (can::Frame{0x703, {0x7F}}));
  EXPECT_EQ(canopen::nmt_state_from_byte(0x85), canopen::NmtState::kOperational);
  EXPECT_EQ(canopen::nmt_command_name(std::uint8_t{0x81}), "reset node");
  EXPECT_EQ(canopen::nmt_command_name(std::uint8_t{0x33}), "unknown");
}

TEST(FieldbusSdoAbort, EveryCodeHasItsOwnText) {
  std::set<std::string_view> texts;
  for (auto a : canopen::kAllSdoAborts) {
    const auto t = canopen::sdo_abort_text(a);
    EXPECT_NE(t, "unknown SDO abort code") << std::hex << static_cast<std::uint32_t>(a);
    texts.insert(t);
  }
  EXPECT_EQ(texts.size(), canopen::kAllSdoAborts.size());
  EXPECT_EQ(canopen::sdo_abort_text(0x06020000u), "object does not exist in the object dictionary");
  EXPECT_EQ(canopen::sdo_abort_text(0x12345678u), "unknown SDO abort code");
}

TEST(FieldbusSdoFrame, DecodesExpeditedAndSegments) {
  using namespace canopen::sdo;
  const auto up = decode(can::Frame{0x582, {0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}}, true);
  EXPECT_EQ(up.kind, SdoFrameKind::kInitiateUploadResponse);
  EXPECT_EQ(up.index, 0x1000);
  EXPECT_EQ(up.data_len, 4);
  EXPECT_EQ(up.data[0], 0x92);
  const auto w = decode(can::Frame{0x602, {0x2B, 0x17, 0x10, 0x00, 0x64, 0x00, 0x00, 0x00}}, false);
  EXPECT_EQ(w.kind, SdoFrameKind::kInitiateDownloadRequest);
  EXPECT_EQ(w.data_len, 2);
  const auto seg = decode(can::Frame{0x582, {0x15, 'a', 'b', 'c', 'd', 'e', 0, 0}}, true);
  EXPECT_EQ(seg.kind, SdoFrameKind::kUploadSegmentResponse);
  EXPECT_TRUE(seg.toggle);
  EXPECT_TRUE(seg.last);
  EXPECT_EQ(seg.data_len, 5);
  const auto ab = decode(can::Frame{0x582, {0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x02, 0x06}}, true);
  EXPECT_EQ(ab.kind, SdoFrameKind::kAbort);
  EXPECT_EQ(ab.abort_code, 0x06020000u);
}

TEST(FieldbusEmcy, DecodeEncodeAndTexts) {
  const can::Frame f{0x082, {0x11, 0x86, 0x20, 1, 2, 3, 4, 5}};
  const auto e = canopen::decode_emcy(f);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->node, 2);
  EXPECT_EQ(e->code, 0x8611);
  EXPECT_EQ(e->error_register, 0x20);
  EXPECT_EQ(e->vendor[4], 5);
  EXPECT_EQ(canopen::make_emcy_frame(*e), f);
  EXPECT_EQ(canopen::emcy_code_text(0x8611), "following error");
  EXPECT_EQ(canopen::emcy_code_text(0x2399), "current, device output side");
  EXPECT_EQ(canopen::emcy_code_text(0x2999), "current");
  EXPECT_EQ(canopen::emcy_code_text(0x8130), "life guard error or heartbeat error");
  EXPECT_EQ(canopen::error_register_bit_name(5), "device profile");
  EXPECT_FALSE(canopen::decode_emcy(can::Frame{0x182, {0, 0}}).has_value());
}

TEST(FieldbusObjectNames, KnownObjectsAndRanges) {
  EXPECT_EQ(canopen::object_name(0x6040, 0), "Controlword");
  EXPECT_EQ(canopen::object_name(0x1A01, 3), "TPDO mapping parameter: mapped object");
  EXPECT_EQ(canopen::object_name(0x1016, 1), "Consumer heartbeat time");
  EXPECT_EQ(canopen::object_name(0x60C2, 2), "Interpolation time period: index");
  EXPECT_EQ(canopen::object_name(0x4444, 0), "");
  const auto* t = canopen::object_info(0x607A, 0);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->type, canopen::DataType::kInteger32);
  EXPECT_EQ(canopen::data_type_size(t->type), 4u);
  EXPECT_EQ(canopen::decode_mapping_entry(0x607A0020u), (canopen::MappingEntry{0x607A, 0, 32}));
  EXPECT_EQ((canopen::MappingEntry{0x6040, 0, 16}).raw(), 0x60400010u);
}

TEST(FieldbusCia402, DecodeStateTable) {
  using cia402::State;
  EXPECT_EQ(cia402::decode_state(0x0000), State::kNotReadyToSwitchOn);
  EXPECT_EQ(cia402::decode_state(0x0040), State::kSwitchOnDisabled);
  EXPECT_EQ(cia402::decode_state(0x0060), State::kSwitchOnDisabled);  // bit 5 ignored
  EXPECT_EQ(cia402::decode_state(0x0021), State::kReadyToSwitchOn);
  EXPECT_EQ(cia402::decode_state(0x0031), State::kReadyToSwitchOn);
  EXPECT_EQ(cia402::decode_state(0x0023), State::kSwitchedOn);
  EXPECT_EQ(cia402::decode_state(0x0237), State::kOperationEnabled);
  EXPECT_EQ(cia402::decode_state(0x0007), State::kQuickStopActive);
  EXPECT_EQ(cia402::decode_state(0x000F), State::kFaultReactionActive);
  EXPECT_EQ(cia402::decode_state(0x0008), State::kFault);
  EXPECT_EQ(cia402::decode_state(0x0028), State::kFault);
  EXPECT_EQ(cia402::decode_state(0x0001), State::kUnknown);
  for (int s = 0; s < 8; ++s) {
    const auto st = static_cast<State>(s);
    EXPECT_EQ(cia402::decode_state(cia402::state_bits(st)), st) << cia402::state_name(st);
  }
}

TEST(FieldbusCia402, CommandsDecodeToThemselves) {
  using cia402::Command;
  for (auto c : {Command::kShutdown, Command::kSwitchOn, Command::kEnableOperation, Command::kDisableVoltage,
                 Command::kQuickStop, Command::kFaultReset}) {
    EXPECT_EQ(cia402::decode_command(cia402::controlword(c)), c) << cia402::command_name(c);
  }
  EXPECT_EQ(cia402::decode_command(cia402::controlword(Command::kDisableOperation)), Command::kSwitchOn);
  EXPECT_EQ(cia402::decode_command(0x000E), Command::kShutdown);  // bit 3 don't care
  EXPECT_EQ(cia402::decode_command(0x000D), Command::kDisableVoltage);
  EXPECT_EQ(cia402::decode_command(0x000B), Command::kQuickStop);
}

TEST(FieldbusCia402, InterpolationPeriod) {
  using cia402::InterpolationPeriod;
  EXPECT_EQ(cia402::encode_interpolation_period(1'000'000), (InterpolationPeriod{1, -3}));
  EXPECT_EQ(cia402::encode_interpolation_period(2'000'000), (InterpolationPeriod{2, -3}));
  EXPECT_EQ(cia402::encode_interpolation_period(250'000), (InterpolationPeriod{25, -5}));
  EXPECT_EQ(cia402::interpolation_period_ns({1, -3}), 1'000'000);
  EXPECT_EQ(cia402::interpolation_period_ns({250, -6}), 250'000);
  EXPECT_FALSE(cia402::encode_interpolation_period(0).has_value());
}
