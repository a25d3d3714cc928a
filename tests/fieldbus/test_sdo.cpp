// SDO client and server: golden bytes, segmented transfers, toggle errors,
// every abort path, timeouts on a virtual clock.
#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "fieldbus/canopen/sdo_client.hpp"
#include "fieldbus/canopen/sdo_server.hpp"
#include "fieldbus/canopen/sdo_frame.hpp"
#include "fieldbus/emulator/emulator.hpp"
#include "test_support.hpp"

using namespace canmotion;
using canopen::SdoAbort;
using fbtest::frame;
using fbtest::hex;
using fbtest::VecSink;

namespace {
constexpr std::int64_t kMs = 1'000'000;

/// Runs client <-> server frame by frame (one hop per call).
struct Link {
  canopen::SdoClient client{2, 100 * kMs};
  emulator::Emulator emu{[] {
    emulator::EmulatorConfig c;
    c.node = 2;
    // Permissive: this link hands frames over without stepping the drive's
    // clock, so the strict drive's delayed replies would never go out (the
    // delay itself: EmulatorStrict.SdoReplyNotInTheSameCall).
    c.behaviour = emulator::EmulatorBehaviour::permissive();
    return c;
  }()};
  VecSink to_server, to_client;
  std::int64_t t = 0;
  std::vector<std::string> wire;

  Link() { emu.power_on(0, to_client), to_client.clear(); }
  canopen::SdoResult run(int max_steps = 100) {
    canopen::SdoResult r;
    for (int i = 0; i < max_steps; ++i) {
      t += kMs;
      client.step(t, to_server);
      for (auto& f : to_server.frames) {
        wire.push_back(hex(f));
        emu.set_time(t);
        emu.on_frame(can::TimedFrame{f, t}, to_client);
      }
      to_server.clear();
      for (auto& f : to_client.frames) {
        wire.push_back(hex(f));
        client.on_frame(f, t);
      }
      to_client.clear();
      if (client.poll(r)) return r;
    }
    ADD_FAILURE() << "transfer did not finish";
    return r;
  }
};
}  // namespace

TEST(FieldbusSdo, ExpeditedDownloadGoldenBytes) {
  Link l;
  ASSERT_TRUE(l.client.download_value<std::uint16_t>(0x1017, 0, 100, 5));
  const auto r = l.run();
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.tag, 5u);
  ASSERT_EQ(l.wire.size(), 2u);
  EXPECT_EQ(l.wire[0], "602#2B17100064000000");
  EXPECT_EQ(l.wire[1], "582#6017100000000000");
  EXPECT_EQ(l.emu.read_int(0x1017), 100);
}

TEST(FieldbusSdo, ExpeditedUploadGoldenBytes) {
  Link l;
  ASSERT_TRUE(l.client.upload(0x1000, 0));
  const auto r = l.run();
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.u32(), 0x00020192u);
  EXPECT_EQ(l.wire[0], "602#4000100000000000");
  EXPECT_EQ(l.wire[1], "582#4300100092010200");
  // 1-byte and 4-byte command bytes.
  ASSERT_TRUE(l.client.download_value<std::int8_t>(0x6060, 0, 9));
  ASSERT_TRUE(l.run().ok());
  EXPECT_EQ(l.wire[2], "602#2F60600009000000");
  ASSERT_TRUE(l.client.download_value<std::uint32_t>(0x6065, 0, 0x01020304));
  ASSERT_TRUE(l.run().ok());
  EXPECT_EQ(l.wire[4], "602#2365600004030201");
}

TEST(FieldbusSdo, SegmentedUploadOfDeviceName) {
  Link l;
  ASSERT_TRUE(l.client.upload(0x1008, 0));
  const auto r = l.run();
  ASSERT_TRUE(r.ok()) << canopen::sdo_abort_text(r.abort);
  EXPECT_TRUE(r.segmented);
  const std::string name(reinterpret_cast<const char*>(r.data.data()), r.size);
  EXPECT_EQ(name, l.emu.config().device_name);
  // Initiate with size, then toggling segment requests 60, 70, 60, ...
  EXPECT_EQ(l.wire[0], "602#4008100000000000");
  EXPECT_EQ(l.wire[1].substr(0, 12), "582#41081000");
  EXPECT_EQ(l.wire[2], "602#6000000000000000");
  EXPECT_EQ(l.wire[4], "602#7000000000000000");
  EXPECT_EQ(l.wire[6], "602#6000000000000000");
  // The last segment has the c bit set.
  const auto last = frame(l.wire.back());
  EXPECT_EQ(last.data[0] & 0x01, 0x01);
}

namespace {
/// A backend with a 20-byte domain at 0x3000 for segmented downloads.
struct DomainBackend final : canopen::SdoServerBackend {
  std::vector<std::uint8_t> domain;
  canopen::SdoAbort sdo_read(std::uint16_t index, std::uint8_t, std::span<std::uint8_t> out, std::size_t& len) noexcept override {
    if (index != 0x3000) return SdoAbort::kNoObject;
    len = std::min(out.size(), domain.size());
    std::copy_n(domain.begin(), len, out.begin());
    return SdoAbort::kNone;
  }
  canopen::SdoAbort sdo_write(std::uint16_t index, std::uint8_t, std::span<const std::uint8_t> d) noexcept override {
    if (index != 0x3000) return SdoAbort::kNoObject;
    domain.assign(d.begin(), d.end());
    return SdoAbort::kNone;
  }
};
}  // namespace

TEST(FieldbusSdo, SegmentedDownloadGoldenBytes) {
  DomainBackend be;
  canopen::SdoServer server(2, be);
  canopen::SdoClient client(2, 100 * kMs);
  VecSink a, b;
  std::vector<std::string> wire;
  const std::uint8_t data[10] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  ASSERT_TRUE(client.download(0x3000, 0, data));
  canopen::SdoResult r;
  for (int i = 0; i < 10 && !client.poll(r); ++i) {
    client.step(i, a);
    for (auto& f : a.frames) wire.push_back(hex(f)), server.on_frame(f, i, b);
    for (auto& f : b.frames) wire.push_back(hex(f)), client.on_frame(f, i);
    a.clear(), b.clear();
  }
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(be.domain, std::vector<std::uint8_t>(data, data + 10));
  const std::vector<std::string> expected = {
      "602#210030000A000000",  // initiate, size indicated, 10 bytes
      "582#6000300000000000",
      "602#0001020304050607",  // toggle 0, 7 bytes, more follow
      "582#2000000000000000",
      "602#1908090A00000000",  // toggle 1, n = 4 unused, last
      "582#3000000000000000",
  };
  EXPECT_EQ(wire, expected);
}

TEST(FieldbusSdo, ClientAbortsOnToggleErrorInUpload) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  ASSERT_TRUE(c.upload(0x1008, 0));
  c.step(0, out);
  c.on_frame(frame("582#4108100014000000"), 0);  // segmented, 20 bytes
  c.step(1, out);
  EXPECT_EQ(hex(out.frames.back()), "602#6000000000000000");
  c.on_frame(frame("582#1061626364656667"), 1);  // toggle 1 where 0 was due
  c.step(2, out);
  EXPECT_EQ(hex(out.frames.back()), "602#8008100000000305");
  canopen::SdoResult r;
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.abort, SdoAbort::kToggleBit);
  EXPECT_FALSE(r.aborted_by_server);
}

TEST(FieldbusSdo, ClientAbortsOnToggleErrorInDownload) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  const std::uint8_t data[9] = {};
  ASSERT_TRUE(c.download(0x3000, 1, data));
  c.step(0, out);
  c.on_frame(frame("582#6000300100000000"), 0);
  c.step(1, out);  // first segment, toggle 0
  c.on_frame(frame("582#3000000000000000"), 1);  // server answers with toggle 1
  c.step(2, out);
  EXPECT_EQ(hex(out.frames.back()), "602#8000300100000305");
  canopen::SdoResult r;
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.abort, SdoAbort::kToggleBit);
}

TEST(FieldbusSdo, ServerAbortsOnToggleError) {
  DomainBackend be;
  be.domain.assign(30, 0x55);
  canopen::SdoServer s(2, be);
  VecSink out;
  s.on_frame(frame("602#4000300000000000"), 0, out);
  EXPECT_EQ(hex(out.frames.back()), "582#410030001E000000");
  s.on_frame(frame("602#7000000000000000"), 0, out);  // toggle 1 first: wrong
  EXPECT_EQ(hex(out.frames.back()), "582#8000300000000305");
  // Download segments with a repeated toggle.
  s.on_frame(frame("602#2100300009000000"), 0, out);
  s.on_frame(frame("602#0001020304050607"), 0, out);
  s.on_frame(frame("602#0D08000000000000"), 0, out);  // toggle 0 again
  EXPECT_EQ(hex(out.frames.back()), "582#8000300000000305");
  // A segment with no transfer running.
  s.on_frame(frame("602#6000000000000000"), 0, out);
  EXPECT_EQ(hex(out.frames.back()), "582#8000300001000405");
}

TEST(FieldbusSdo, ClientReportsEveryServerAbortWithItsText) {
  for (const SdoAbort a : canopen::kAllSdoAborts) {
    canopen::SdoClient c(2, 100 * kMs);
    VecSink out;
    ASSERT_TRUE(c.upload(0x6041, 0));
    c.step(0, out);
    can::Frame f = frame("582#8041600000000000");
    const auto code = static_cast<std::uint32_t>(a);
    for (int i = 0; i < 4; ++i) f.data[4 + i] = static_cast<std::uint8_t>(code >> (8 * i));
    c.on_frame(f, 1);
    canopen::SdoResult r;
    ASSERT_TRUE(c.poll(r));
    EXPECT_EQ(r.abort, a);
    EXPECT_TRUE(r.aborted_by_server);
    EXPECT_NE(canopen::sdo_abort_text(r.abort), "unknown SDO abort code");
  }
}

// A server that names another index/sub (or none) in its abort: the transfer
// ends with the real abort code at once (on main it was ignored and became a
// 0x05040000 timeout 100 ms later); what the abort named is kept.
TEST(FieldbusSdo, AbortNamingAnotherObjectEndsTheTransferWithItsCode) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  ASSERT_TRUE(c.download_value<std::int8_t>(0x6060, 0, 8, 7));
  c.step(0, out);
  c.on_frame(frame("582#8000000022000008"), 1 * kMs);  // 0x08000022, index 0x0000 sub 0
  canopen::SdoResult r;
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 7u);
  EXPECT_EQ(r.abort, SdoAbort::kDeviceState);
  EXPECT_TRUE(r.aborted_by_server);
  EXPECT_EQ(r.index, 0x6060);
  EXPECT_EQ(r.abort_index, 0x0000);
  EXPECT_EQ(r.finished_ns, 1 * kMs);
  EXPECT_TRUE(c.idle());
}

// A transfer cancelled (cancel_all(), e.g. a drive proxy restarting the
// node's boot) while the server's answer is on its way: that late answer
// names another object than the next transfer, which keeps waiting for its
// own (before, the late answer aborted it with 0x08000000).
TEST(FieldbusSdo, LateAnswerToACancelledTransferIsIgnored) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  ASSERT_TRUE(c.upload(0x6041, 0, 1));
  c.step(0, out);
  EXPECT_EQ(hex(out.frames.back()), "602#4041600000000000");
  c.cancel_all();
  ASSERT_TRUE(c.upload(0x1000, 0, 2));
  c.step(1 * kMs, out);  // the running upload is aborted
  EXPECT_EQ(hex(out.frames.back()), "602#8041600000000008");
  c.step(2 * kMs, out);  // the next one starts
  EXPECT_EQ(hex(out.frames.back()), "602#4000100000000000");
  canopen::SdoResult r;
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 1u);
  EXPECT_EQ(r.abort, SdoAbort::kGeneral);
  c.on_frame(frame("582#4B41600028020000"), 3 * kMs);  // 0x6041's answer, late
  EXPECT_FALSE(c.poll(r)) << "the late answer ended the next transfer";
  c.on_frame(frame("582#4300100092010200"), 4 * kMs);  // 0x1000's own answer
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 2u);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.u32(), 0x00020192u);
}

TEST(FieldbusSdo, TimeoutOnVirtualClockThenNextTransferRuns) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  ASSERT_TRUE(c.upload(0x1000, 0, 1));
  ASSERT_TRUE(c.upload(0x1001, 0, 2));
  c.step(0, out);
  EXPECT_EQ(out.frames.size(), 1u);
  c.step(100 * kMs, out);  // exactly the timeout: not yet
  canopen::SdoResult r;
  EXPECT_FALSE(c.poll(r));
  EXPECT_EQ(out.frames.size(), 1u);
  c.step(100 * kMs + 1, out);  // the first try is aborted ...
  EXPECT_FALSE(c.poll(r));
  EXPECT_EQ(hex(out.frames.back()), "602#8000100000000405");
  c.step(100 * kMs + 2, out);  // ... and started once more (issue 30: one retry)
  EXPECT_EQ(hex(out.frames.back()), "602#4000100000000000");
  c.step(200 * kMs + 2, out);
  EXPECT_FALSE(c.poll(r));
  c.step(200 * kMs + 3, out);
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 1u);
  EXPECT_EQ(r.abort, SdoAbort::kTimeout);
  EXPECT_TRUE(r.retried);
  EXPECT_EQ(r.finished_ns - r.started_ns, 200 * kMs + 3);  // timeout x 2 + the step between abort and initiate
  EXPECT_EQ(hex(out.frames.back()), "602#8000100000000405");
  c.step(200 * kMs + 4, out);  // the queued upload starts
  EXPECT_EQ(hex(out.frames.back()), "602#4001100000000000");
  c.on_frame(frame("582#4F01100000000000"), 200 * kMs + 5);
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 2u);
  EXPECT_TRUE(r.ok());
}

TEST(FieldbusSdo, ServerTimesOutHangingSegmentedTransfer) {
  DomainBackend be;
  be.domain.assign(30, 1);
  canopen::SdoServer s(2, be);
  s.set_timeout(50 * kMs);
  VecSink out;
  s.on_frame(frame("602#4000300000000000"), 0, out);
  s.step(50 * kMs, out);
  EXPECT_EQ(out.frames.size(), 1u);
  s.step(50 * kMs + 1, out);
  EXPECT_EQ(hex(out.frames.back()), "582#8000300000000405");
}

TEST(FieldbusSdo, QueueCapacityIsEnforced) {
  canopen::SdoClient c(2);
  for (std::size_t i = 0; i < canopen::SdoClient::kQueueCapacity; ++i) ASSERT_TRUE(c.upload(0x1000, 0));
  EXPECT_FALSE(c.upload(0x1000, 0));
  const std::uint8_t big[canopen::kSdoMaxDownload + 1] = {};
  canopen::SdoClient d(2);
  EXPECT_FALSE(d.download(0x3000, 0, big));
}

// ---- every abort path of the emulator's SDO server ---------------------------
namespace {
struct AbortCase {
  const char* name;
  std::vector<std::string> setup;  // requests sent first (must succeed)
  std::string request;
  std::uint32_t abort;
};
}  // namespace

TEST(FieldbusSdo, EmulatorAbortPaths) {
  const std::vector<AbortCase> cases = {
      {"no such object", {}, "602#4044440000000000", 0x06020000},
      {"no such sub-index", {}, "602#4018100900000000", 0x06090011},
      {"write read-only", {}, "602#2300100001000000", 0x06010002},
      {"write const string", {}, "602#2F08100041000000", 0x06010002},
      {"length too high", {}, "602#2317100064000000", 0x06070012},
      {"length too low", {}, "602#2B65600064000000", 0x06070013},
      {"mode out of range", {}, "602#2F60600005000000", 0x06090030},
      {"0x60C2 value 0", {}, "602#2FC2600100000000", 0x06090030},
      {"0x60C2 index too high", {}, "602#2FC2600201000000", 0x06090031},
      {"0x60C2 index too low", {}, "602#2FC26002F6000000", 0x06090032},
      {"mapping while PDO valid", {}, "602#2F00160000000000", 0x08000022},
      {"mapping entry while count != 0", {"602#2300140102020080"}, "602#2300160110004060", 0x08000022},
      {"not mappable (statusword into RPDO)",
       {"602#2300140102020080", "602#2F00160000000000"},
       "602#2300160110004160",
       0x06040041},
      {"mapping of a missing object",
       {"602#2300140102020080", "602#2F00160000000000"},
       "602#2300160110004444",
       0x06020000},
      {"mapping with wrong length",
       {"602#2300140102020080", "602#2F00160000000000"},
       "602#2300160108004060",
       0x06040043},
      {"mapping longer than 64 bits",
       {"602#2300140102020080", "602#2F00160000000000", "602#230016012000FF60", "602#230016022000FF60",
        "602#2300160310004060"},
       "602#2F00160003000000",
       0x06040042},
      {"PDO COB-ID change while valid", {}, "602#2300140103030000", 0x06090030},
      {"TPDO sub-index 4 does not exist", {}, "602#2F00180404000000", 0x06090011},
      {"transmission type 245", {}, "602#2F001402F5000000", 0x06090030},
      {"unknown command specifier", {}, "602#E000100000000000", 0x05040001},
      {"block upload with block size 0", {}, "602#A400100000000000", 0x05040002},
      {"block upload of a missing object", {}, "602#A40044447F000000", 0x06020000},
      {"block download end without transfer", {}, "602#C100000000000000", 0x05040001},
      {"block download larger than the server's buffer", {}, "602#C600200000100000", 0x05040005},
      {"segment without transfer", {}, "602#0000000000000000", 0x05040001},
  };
  for (const auto& c : cases) {
    emulator::EmulatorConfig cfg;
    cfg.node = 2;
    cfg.behaviour = emulator::EmulatorBehaviour::permissive();  // replies in the same call (no clock here)
    emulator::Emulator emu(cfg);
    VecSink out;
    emu.power_on(0, out);
    for (const auto& s : c.setup) {
      out.clear();
      emu.on_frame(can::TimedFrame{frame(s), 0}, out);
      ASSERT_EQ(out.frames.size(), 1u) << c.name;
      ASSERT_NE(out.frames[0].data[0], 0x80) << c.name << ": setup " << s << " aborted: " << hex(out.frames[0]);
    }
    out.clear();
    emu.on_frame(can::TimedFrame{frame(c.request), 0}, out);
    ASSERT_EQ(out.frames.size(), 1u) << c.name;
    const auto s = canopen::sdo::decode(out.frames[0], true);
    EXPECT_EQ(s.kind, canopen::sdo::SdoFrameKind::kAbort) << c.name << ": " << hex(out.frames[0]);
    EXPECT_EQ(s.abort_code, c.abort) << c.name << ": got " << canopen::sdo_abort_text(s.abort_code);
  }
}

TEST(FieldbusSdo, PollTagLeavesOtherResultsInOrder) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  for (std::uint32_t tag : {1u, 2u, 3u, 2u}) {
    ASSERT_TRUE(c.upload(0x1000, 0, tag));
    c.step(0, out);
    c.on_frame(frame("582#4300100092010200"), 0);
  }
  canopen::SdoResult r;
  ASSERT_TRUE(c.poll_tag(2, r));
  EXPECT_EQ(r.tag, 2u);
  EXPECT_FALSE(c.poll_tag(9, r));
  std::vector<std::uint32_t> rest;
  while (c.poll(r)) rest.push_back(r.tag);
  EXPECT_EQ(rest, (std::vector<std::uint32_t>{1, 3, 2}));
}

// Issue 30 part 3: a reply shorter than 8 bytes is taken as lely's client
// takes it (the bytes it lacks read as 0) when it holds what its command
// announces; else the transfer aborts, naming why.
TEST(FieldbusSdo, ShortRepliesAreTakenAsLelyTakesThem) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  canopen::SdoResult r;
  std::int64_t t = 0;
  auto answer = [&](const char* reply) {
    c.step(t += kMs, out);
    c.on_frame(frame(reply), t += kMs);
    c.step(t += kMs, out);
    return c.poll(r);
  };
  ASSERT_TRUE(c.download_value<std::uint16_t>(0x1017, 0, 100, 1));
  ASSERT_TRUE(answer("582#60"));  // download confirmed in 1 byte
  EXPECT_TRUE(r.ok());
  ASSERT_TRUE(c.upload(0x1001, 0, 2));
  ASSERT_TRUE(answer("582#4F0110002A"));  // 1 byte, size indicated: 5 bytes carry it
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.size, 1u);
  EXPECT_EQ(r.u32(), 0x2Au);
  ASSERT_TRUE(c.upload(0x1000, 0, 3));
  ASSERT_TRUE(answer("582#420010000102"));  // expedited without a size: the 2 bytes it has
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.size, 2u);
  EXPECT_EQ(r.u32(), 0x0201u);
  ASSERT_TRUE(c.upload(0x1000, 0, 4));
  ASSERT_TRUE(answer("582#4B001000"));  // 2 bytes announced, none sent
  EXPECT_EQ(r.abort, SdoAbort::kLengthTooLow);
  EXPECT_FALSE(r.aborted_by_server);
  EXPECT_EQ(hex(out.frames.back()), "602#8000100013000706");  // our abort, 0x06070013
  ASSERT_TRUE(c.upload(0x1000, 0, 5));
  ASSERT_TRUE(answer("582#80001000"));  // an abort without its code
  EXPECT_EQ(r.abort, SdoAbort::kGeneral);
  EXPECT_TRUE(r.aborted_by_server);
  ASSERT_TRUE(c.upload(0x1000, 0, 6));
  can::Frame empty = frame("582#00");
  empty.len = 0;
  c.step(t += kMs, out);
  c.on_frame(empty, t += kMs);
  c.step(t += kMs, out);
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.abort, SdoAbort::kCommandSpecifier);  // nothing to read
}

// Issue 30 part 3: a transfer may have its own timeout (a store to 0x1010
// takes seconds); the others keep the client's.
TEST(FieldbusSdo, PerTransferTimeout) {
  canopen::SdoClient c(2, 100 * kMs);
  VecSink out;
  canopen::SdoResult r;
  const std::uint8_t save[4] = {'s', 'a', 'v', 'e'};
  ASSERT_TRUE(c.download(0x1010, 1, save, 1, 3000 * kMs));
  ASSERT_TRUE(c.upload(0x1000, 0, 2));
  c.step(0, out);
  EXPECT_EQ(hex(out.frames.back()), "602#2310100173617665");
  c.step(101 * kMs, out);
  EXPECT_FALSE(c.poll(r));  // the client's 100 ms do not apply
  c.step(3000 * kMs, out);
  EXPECT_FALSE(c.poll(r));
  c.step(3000 * kMs + 1, out);  // first try aborted
  c.step(3000 * kMs + 2, out);  // retried
  EXPECT_EQ(hex(out.frames.back()), "602#2310100173617665");
  c.step(6000 * kMs + 2, out);
  EXPECT_FALSE(c.poll(r));
  c.step(6000 * kMs + 3, out);
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 1u);
  EXPECT_EQ(r.abort, SdoAbort::kTimeout);
  EXPECT_EQ(r.finished_ns - r.started_ns, 6000 * kMs + 3);
  c.step(6000 * kMs + 4, out);  // the upload starts, with the client's timeout
  c.step(6100 * kMs + 5, out);  // first try aborted
  EXPECT_FALSE(c.poll(r));
  c.step(6100 * kMs + 6, out);  // retried
  c.step(6200 * kMs + 7, out);
  ASSERT_TRUE(c.poll(r));
  EXPECT_EQ(r.tag, 2u);
  EXPECT_EQ(r.abort, SdoAbort::kTimeout);
  EXPECT_EQ(r.finished_ns - r.started_ns, 200 * kMs + 3);
}
