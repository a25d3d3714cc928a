// SDO block transfer (CiA 301 §7.2.4.3.9-.16) and the retry after a timeout:
// golden bytes against a scripted server, CRCs computed independently
// (Python's binascii.crc_hqx, CRC-16/XMODEM), a lost segment resent both
// ways, the fallback to segmented transfer on 0x05040001, the retry's times
// on the virtual clock.
#include <gtest/gtest.h>

#include <numeric>
#include <string>
#include <vector>

#include "fieldbus/canopen/sdo_client.hpp"
#include "fieldbus/canopen/sdo_server.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"

using namespace canmotion;
using canopen::SdoAbort;
using canopen::Transfer;
using fbtest::frame;
using fbtest::hex;
using fbtest::VecSink;

namespace {
constexpr std::int64_t kMs = 1'000'000;

/// The client against a script: step() returns what the client sent in one
/// cycle; reply() hands it a server frame.
struct Scripted {
  canopen::SdoClient client{2, 100 * kMs};
  VecSink out;
  std::int64_t t = 0;
  std::vector<std::string> step() {
    t += kMs;
    client.step(t, out);
    std::vector<std::string> sent;
    for (const auto& f : out.frames) sent.push_back(hex(f));
    out.clear();
    return sent;
  }
  void reply(const std::string& s) { client.on_frame(frame(s), t); }
};

std::vector<std::uint8_t> iota_bytes(std::size_t n, std::uint8_t first = 0) {
  std::vector<std::uint8_t> v(n);
  std::iota(v.begin(), v.end(), first);
  return v;
}
using V = std::vector<std::string>;

/// One object of any length behind canopen::SdoServer.
struct Store final : canopen::SdoServerBackend {
  std::vector<std::uint8_t> value;
  SdoAbort sdo_read(std::uint16_t index, std::uint8_t, std::span<std::uint8_t> out, std::size_t& len) noexcept override {
    if (index != 0x2100) return SdoAbort::kNoObject;
    if (value.size() > out.size()) return SdoAbort::kOutOfMemory;
    std::copy(value.begin(), value.end(), out.begin());
    len = value.size();
    return SdoAbort::kNone;
  }
  SdoAbort sdo_write(std::uint16_t index, std::uint8_t, std::span<const std::uint8_t> d) noexcept override {
    if (index != 0x2100) return SdoAbort::kNoObject;
    value.assign(d.begin(), d.end());
    return SdoAbort::kNone;
  }
};

/// Our client against our server, frame by frame; `drop` loses the n-th
/// frame on the wire (1-based, 0 = none).
struct Pair {
  Store store;
  canopen::SdoServer server{2, store};
  canopen::SdoClient client{2, 100 * kMs};
  VecSink to_server, to_client;
  std::vector<std::string> wire;
  int drop = 0;
  canopen::SdoResult run() {
    canopen::SdoResult r;
    for (std::int64_t t = kMs; t < 500 * kMs; t += kMs) {
      client.step(t, to_server);
      for (auto& f : to_server.frames) {
        wire.push_back(hex(f));
        if (static_cast<int>(wire.size()) != drop) server.on_frame(f, t, to_client);
      }
      to_server.clear();
      for (auto& f : to_client.frames) {
        wire.push_back(hex(f));
        if (static_cast<int>(wire.size()) != drop) client.on_frame(f, t);
      }
      to_client.clear();
      if (client.poll(r)) return r;
    }
    ADD_FAILURE() << "transfer did not finish";
    return r;
  }
};
}  // namespace

TEST(FieldbusSdoBlock, Crc16IsCcittXmodem) {
  const std::string check = "123456789";
  EXPECT_EQ(canopen::sdo_crc16({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0x31C3);
  EXPECT_EQ(canopen::sdo_crc16(iota_bytes(20)), 0xACCC);  // binascii.crc_hqx(bytes(range(20)), 0)
  // Continuing from a partial CRC gives the whole one.
  const auto d = iota_bytes(30);
  EXPECT_EQ(canopen::sdo_crc16(std::span(d).subspan(11), canopen::sdo_crc16(std::span(d).first(11))), 0x1F11);
}

TEST(FieldbusSdoBlock, DownloadGoldenBytesWithCrc) {
  Scripted s;
  const auto data = iota_bytes(20);
  ASSERT_TRUE(s.client.download_ref(0x2000, 1, data, 7, 0, Transfer::kBlock));
  EXPECT_EQ(s.step(), V{"602#C600200114000000"});  // ccs 6, cc, s; size 20
  s.reply("582#A40020017F000000");                 // sc, blksize 127
  EXPECT_EQ(s.step(), (V{"602#0100010203040506", "602#02070809" "0A0B0C0D", "602#830E0F10111213" "00"}));
  s.reply("582#A2037F0000000000");                 // ackseq 3
  EXPECT_EQ(s.step(), V{"602#C5CCAC0000000000"});  // n = 1 byte unused in the last segment, CRC 0xACCC
  s.reply("582#A100000000000000");
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  EXPECT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_TRUE(r.block);
  EXPECT_EQ(r.bytes, 20u);
  EXPECT_EQ(r.tag, 7u);
}

TEST(FieldbusSdoBlock, DownloadWithoutServerCrcSendsZero) {
  Scripted s;
  const auto data = iota_bytes(20);
  ASSERT_TRUE(s.client.download_ref(0x2000, 1, data, 0, 0, Transfer::kBlock));
  s.step();
  s.reply("582#A00020017F000000");  // sc = 0: the server has no CRC
  EXPECT_EQ(s.step().size(), 3u);
  s.reply("582#A2037F0000000000");
  EXPECT_EQ(s.step(), V{"602#C500000000000000"});
}

TEST(FieldbusSdoBlock, DownloadResendsFromTheLostSegment) {
  Scripted s;
  const auto data = iota_bytes(30);
  ASSERT_TRUE(s.client.download_ref(0x2000, 0, data, 0, 0, Transfer::kBlock));
  EXPECT_EQ(s.step(), V{"602#C60020001E000000"});
  s.reply("582#A400200004000000");  // blksize 4
  EXPECT_EQ(s.step(), (V{"602#01000102030405" "06", "602#02070809" "0A0B0C0D", "602#030E0F10111213" "14",
                         "602#0415161718191A" "1B"}));
  s.reply("582#A202040000000000");  // segment 3 lost: ack 2, blksize 4
  // The next sub-block starts at byte 14, numbered from 1 again.
  EXPECT_EQ(s.step(), (V{"602#010E0F10111213" "14", "602#0215161718191A" "1B", "602#831C1D0000000000"}));
  s.reply("582#A203040000000000");
  EXPECT_EQ(s.step(), V{"602#D5111F0000000000"});  // n = 5, CRC 0x1F11
  s.reply("582#A100000000000000");
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.bytes, 30u);
}

TEST(FieldbusSdoBlock, UploadGoldenBytesWithCrc) {
  Scripted s;
  std::vector<std::uint8_t> dest(64, 0xEE);
  ASSERT_TRUE(s.client.upload_into(0x2001, 2, dest, 9));
  EXPECT_EQ(s.step(), V{"602#A40120027F000000"});  // ccs 5, cc; blksize 127, pst 0
  s.reply("582#C601200214000000");                 // sc, s; size 20
  EXPECT_EQ(s.step(), V{"602#A300000000000000"});  // start
  s.reply("582#01646566676869" "6A");
  s.reply("582#026B6C6D6E6F70" "71");
  s.reply("582#83727374757677" "00");
  EXPECT_EQ(s.step(), V{"602#A2037F0000000000"});  // ack 3
  s.reply("582#C5109B0000000000");                 // n 1, CRC 0x9B10
  EXPECT_EQ(s.step(), V{"602#A100000000000000"});
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  ASSERT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_TRUE(r.block);
  EXPECT_EQ(r.bytes, 20u);
  EXPECT_EQ(std::vector<std::uint8_t>(dest.begin(), dest.begin() + 20), iota_bytes(20, 100));
  EXPECT_EQ(dest[20], 0xEE);
}

TEST(FieldbusSdoBlock, UploadAcksTheLastInOrderSegmentAndTakesTheResend) {
  Scripted s;
  std::vector<std::uint8_t> dest(64);
  ASSERT_TRUE(s.client.upload_into(0x2001, 2, dest));
  s.step();
  s.reply("582#C601200214000000");
  s.step();
  s.reply("582#01646566676869" "6A");
  s.reply("582#83727374757677" "00");  // segment 2 lost
  EXPECT_EQ(s.step(), V{"602#A2017F0000000000"});  // ack 1: resend from segment 2
  s.reply("582#016B6C6D6E6F70" "71");
  s.reply("582#82727374757677" "00");
  EXPECT_EQ(s.step(), V{"602#A2027F0000000000"});
  s.reply("582#C5109B0000000000");
  EXPECT_EQ(s.step(), V{"602#A100000000000000"});
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  ASSERT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_EQ(std::vector<std::uint8_t>(dest.begin(), dest.begin() + 20), iota_bytes(20, 100));
}

TEST(FieldbusSdoBlock, UploadWithAWrongCrcAbortsWith05040004) {
  Scripted s;
  std::vector<std::uint8_t> dest(64);
  ASSERT_TRUE(s.client.upload_into(0x2001, 2, dest));
  s.step();
  s.reply("582#C601200214000000");
  s.step();
  s.reply("582#01646566676869" "6A");
  s.reply("582#026B6C6D6E6F70" "71");
  s.reply("582#83727374757677" "00");
  s.step();
  s.reply("582#C5119B0000000000");  // CRC off by one
  EXPECT_EQ(s.step(), V{"602#8001200204000405"});
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  EXPECT_EQ(r.abort, SdoAbort::kCrc);
  EXPECT_FALSE(r.aborted_by_server);
}

TEST(FieldbusSdoBlock, UploadLongerThanTheDestinationAbortsWith05040005) {
  Scripted s;
  std::vector<std::uint8_t> dest(16);
  ASSERT_TRUE(s.client.upload_into(0x2001, 2, dest));
  s.step();
  s.reply("582#C601200214000000");  // 20 bytes announced
  EXPECT_EQ(s.step(), V{"602#8001200205000405"});
}

TEST(FieldbusSdoBlock, RefusedBlockFallsBackToSegmentedAndIsNotAskedAgain) {
  Scripted s;
  const auto data = iota_bytes(9);
  ASSERT_TRUE(s.client.download_ref(0x2000, 0, data, 0, 0, Transfer::kBlock));
  EXPECT_EQ(s.step(), V{"602#C600200009000000"});
  s.reply("582#8000200001000405");  // command specifier not valid
  EXPECT_EQ(s.step(), V{"602#2100200009000000"});  // the same transfer, segmented
  s.reply("582#6000200000000000");
  EXPECT_EQ(s.step(), V{"602#00000102030405" "06"});
  s.reply("582#2000000000000000");
  EXPECT_EQ(s.step(), V{"602#1B0708" "0000000000"});
  s.reply("582#3000000000000000");
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.fell_back);
  EXPECT_FALSE(r.block);
  // The next block request to this server goes segmented straight away.
  ASSERT_TRUE(s.client.download_ref(0x2000, 0, data, 0, 0, Transfer::kBlock));
  EXPECT_EQ(s.step(), V{"602#2100200009000000"});
}

TEST(FieldbusSdoBlock, EmulatorWithoutBlockTransferServesTheUploadSegmented) {
  VecSink to_server, to_client;
  emulator::EmulatorConfig c;
  c.node = 2;
  c.behaviour = emulator::EmulatorBehaviour::permissive();
  c.behaviour.sdo_block_refused = true;
  emulator::Emulator emu{c};
  emu.power_on(0, to_client);
  to_client.clear();
  canopen::SdoClient client{2, 100 * kMs};
  std::vector<std::uint8_t> dest(128);
  ASSERT_TRUE(client.upload_into(0x1008, 0, dest));  // kAuto: block first
  canopen::SdoResult r;
  std::vector<std::string> wire;
  for (std::int64_t t = kMs; t < 200 * kMs && !client.poll(r); t += kMs) {
    client.step(t, to_server);
    for (auto& f : to_server.frames) wire.push_back(hex(f)), emu.set_time(t), emu.on_frame(can::TimedFrame{f, t}, to_client);
    to_server.clear();
    for (auto& f : to_client.frames) wire.push_back(hex(f)), client.on_frame(f, t);
    to_client.clear();
  }
  ASSERT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_TRUE(r.fell_back);
  EXPECT_EQ(wire.at(0), "602#A40810007F000000");
  EXPECT_EQ(wire.at(1), "582#8008100001000405");
  EXPECT_EQ(wire.at(2), "602#4008100000000000");
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(dest.data()), r.bytes), emu.config().device_name);
}

TEST(FieldbusSdoBlock, TimeoutIsRetriedOnceFromTheInitiate) {
  Scripted s;  // 100 ms timeout, 1 ms steps; the server never answers
  ASSERT_TRUE(s.client.upload(0x1000, 0));
  EXPECT_EQ(s.step(), V{"602#4000100000000000"});  // t = 1 ms
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(s.step().empty()) << s.t;
  EXPECT_EQ(s.t, 101 * kMs);
  EXPECT_EQ(s.step(), V{"602#8000100000000405"});  // t = 102 ms: the first try aborted
  EXPECT_EQ(s.step(), V{"602#4000100000000000"});  // t = 103 ms: started again
  canopen::SdoResult r;
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(s.step().empty()) << s.t;
  EXPECT_FALSE(s.client.poll(r));
  EXPECT_EQ(s.step(), V{"602#8000100000000405"});  // t = 204 ms: timeout x 2 + the gap
  ASSERT_TRUE(s.client.poll(r));
  EXPECT_EQ(r.abort, SdoAbort::kTimeout);
  EXPECT_TRUE(r.retried);
  EXPECT_EQ(r.started_ns, 1 * kMs);
  EXPECT_EQ(r.finished_ns, 204 * kMs);
}

TEST(FieldbusSdoBlock, RetryThatIsAnsweredSucceeds) {
  Scripted s;
  ASSERT_TRUE(s.client.upload(0x1000, 0));
  s.step();
  while (s.step().empty()) {}
  s.reply("582#4300100092010200");  // a late answer to the first try: ignored
  EXPECT_EQ(s.step(), V{"602#4000100000000000"});
  s.reply("582#4300100092010200");
  canopen::SdoResult r;
  ASSERT_TRUE(s.client.poll(r));
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.retried);
  EXPECT_EQ(r.u32(), 0x00020192u);
}

TEST(FieldbusSdoBlock, OurServerTakesABlockDownloadAndServesItBackWithLostSegments) {
  Pair p;
  p.server.set_block_size(8);  // several sub-blocks
  const auto data = iota_bytes(200, 7);
  p.drop = 5;  // the client's 3rd segment of the first sub-block
  ASSERT_TRUE(p.client.download_ref(0x2100, 0, data));  // kAuto: > 64 bytes goes as a block
  auto r = p.run();
  ASSERT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_TRUE(r.block);
  EXPECT_FALSE(r.fell_back);
  EXPECT_EQ(p.store.value, data);
  EXPECT_EQ(p.wire.at(0), "602#C6002100C8000000");
  EXPECT_EQ(p.wire.at(1), "582#A400210008000000");
  EXPECT_EQ(p.wire.at(10), "582#A202080000000000");  // segments 1..2 in order: ack 2, the rest resent
  EXPECT_EQ(p.wire.at(11), "602#0115161718191A1B");  // the next sub-block starts with byte 14 (value 7 + 14)
  // The end frame: 200 bytes = 28 segments of 7 + 4, n = 3, CRC of the data.
  const std::uint16_t crc = canopen::sdo_crc16(data);
  char end[32];
  std::snprintf(end, sizeof end, "602#CD%02X%02X0000000000", crc & 0xFF, crc >> 8);
  EXPECT_NE(std::find(p.wire.begin(), p.wire.end(), end), p.wire.end()) << end;

  std::vector<std::uint8_t> back(256);
  p.wire.clear();
  p.drop = 4;  // the server's 1st segment
  ASSERT_TRUE(p.client.upload_into(0x2100, 0, back));
  r = p.run();
  ASSERT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_TRUE(r.block);
  ASSERT_EQ(r.bytes, 200u);
  EXPECT_EQ(std::vector<std::uint8_t>(back.begin(), back.begin() + 200), data);
  EXPECT_EQ(p.wire.at(0), "602#A40021007F000000");
  EXPECT_EQ(p.wire.at(1), "582#C6002100C8000000");
  EXPECT_EQ(p.wire.at(2), "602#A300000000000000");
}

TEST(FieldbusSdoBlock, OurServerChecksTheCrc) {
  Store store;
  canopen::SdoServer server{2, store};
  VecSink out;
  server.on_frame(frame("602#C600210014000000"), 0, out);
  EXPECT_EQ(hex(out.frames.at(0)), "582#A40021007F000000");
  server.on_frame(frame("602#0100010203040506"), 0, out);
  server.on_frame(frame("602#020708090A0B0C0D"), 0, out);
  server.on_frame(frame("602#830E0F1011121300"), 0, out);
  EXPECT_EQ(hex(out.frames.at(1)), "582#A2037F0000000000");
  server.on_frame(frame("602#C5CDAC0000000000"), 0, out);  // CRC 0xACCD: one off
  EXPECT_EQ(hex(out.frames.at(2)), "582#8000210004000405");
  EXPECT_TRUE(store.value.empty());
}
