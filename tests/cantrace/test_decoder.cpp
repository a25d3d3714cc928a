// Unit tests of the trace decoder, its text rendering and the streaming analyzer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>

#include "fieldbus/trace/analyzer.hpp"
#include "fieldbus/trace/decoder.hpp"
#include "fieldbus/trace/format.hpp"
#include "fieldbus/trace/reader.hpp"
#include "fieldbus/trace/trace_config.hpp"

namespace tr = canmotion::trace;
namespace can = canmotion::can;

namespace {

can::TimedFrame tf(std::uint32_t id, std::initializer_list<std::uint8_t> b, std::int64_t t = 0) {
  can::TimedFrame x;
  x.frame = can::Frame(id, b);
  x.t_ns = t;
  return x;
}

std::string desc(const tr::Decoded& d) {
  fmt::memory_buffer b;
  tr::format_description(d, b);
  return std::string(b.data(), b.size());
}

// Expedited SDO write + confirmation on node n.
void sdo_write(tr::Decoder& dec, std::uint8_t n, std::uint16_t idx, std::uint8_t sub, std::uint32_t v) {
  const auto lo = static_cast<std::uint8_t>(idx & 0xFF), hi = static_cast<std::uint8_t>(idx >> 8);
  dec.decode(tf(0x600U + n, {0x23, lo, hi, sub, static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v >> 8),
                             static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 24)}));
  dec.decode(tf(0x580U + n, {0x60, lo, hi, sub, 0, 0, 0, 0}));
}

unsigned env_seed(unsigned dflt) {
  const char* s = std::getenv("CANMOTION_SEED");
  return s != nullptr ? static_cast<unsigned>(std::strtoul(s, nullptr, 10)) : dflt;
}
int env_count(int dflt) {
  const char* s = std::getenv("CANMOTION_COUNT");
  return s != nullptr ? std::atoi(s) : dflt;
}

}  // namespace

TEST(TraceDecoder, DefaultCspMapping) {
  tr::Decoder dec;
  const auto& r = dec.decode(tf(0x201, {0x0F, 0x00, 0x18, 0xFC, 0xFF, 0xFF}));  // target -1000
  EXPECT_EQ(r.kind, tr::EventKind::kPdo);
  EXPECT_FALSE(r.pdo_tx);
  EXPECT_EQ(r.layout, tr::LayoutSource::kDefault);
  EXPECT_TRUE(r.has_controlword);
  EXPECT_EQ(r.controlword, 0x000F);
  EXPECT_TRUE(r.has_target);
  EXPECT_EQ(r.target_position, -1000);
  EXPECT_EQ(desc(r), "RPDO1 node 1: Controlword=0x000F [Enable operation], Target position=-1000");
  const auto& t = dec.decode(tf(0x185, {0x37, 0x06, 0xA0, 0x86, 0x01, 0x00}));
  EXPECT_EQ(t.node, 5);
  EXPECT_EQ(t.statusword, 0x0637);
  EXPECT_EQ(t.actual_position, 100000);
  EXPECT_EQ(desc(t), "TPDO1 node 5: Statusword=0x0637 [Operation enabled], Position actual value=100000");
  // TPDO2 has no default layout: reported raw.
  EXPECT_EQ(desc(dec.decode(tf(0x285, {1, 2}))), "TPDO2 node 5: 2 bytes, mapping unknown");
}

TEST(TraceDecoder, MappingFromSdoWritesOnlyWhenConfirmed) {
  tr::Decoder dec;
  // Remap TPDO1 of node 3 to statusword + mode display (3 bytes).
  sdo_write(dec, 3, 0x1A00, 0, 0);
  sdo_write(dec, 3, 0x1A00, 1, 0x60410010);
  sdo_write(dec, 3, 0x1A00, 2, 0x60610008);
  // sub0 = 2 requested but aborted by the drive: mapping stays incomplete.
  dec.decode(tf(0x603, {0x2F, 0x00, 0x1A, 0x00, 0x02, 0, 0, 0}));
  dec.decode(tf(0x583, {0x80, 0x00, 0x1A, 0x00, 0x42, 0x00, 0x04, 0x06}));
  tr::PdoLayout l;
  EXPECT_EQ(dec.layout_of(3, true, 1, l), tr::LayoutSource::kTrace);
  EXPECT_EQ(l.count, 0);  // sub0 = 0 was confirmed: mapping disabled
  sdo_write(dec, 3, 0x1A00, 0, 2);
  EXPECT_EQ(dec.layout_of(3, true, 1, l), tr::LayoutSource::kTrace);
  ASSERT_EQ(l.count, 2);
  const auto& r = dec.decode(tf(0x183, {0x37, 0x12, 0xF8}));
  EXPECT_EQ(r.layout, tr::LayoutSource::kTrace);
  EXPECT_EQ(r.problem, nullptr);
  EXPECT_EQ(desc(r), "TPDO1 node 3: Statusword=0x1237 [Operation enabled], Modes of operation display=-8 [?]")
      << "mode display is INTEGER8: 0xF8 is -8";
}

TEST(TraceDecoder, ConfigLayoutWinsOverTrace) {
  tr::Decoder dec;
  tr::PdoLayout cfg;
  cfg.entries[0] = tr::MapEntry{0x6041, 0, 16};
  cfg.count = 1;
  ASSERT_TRUE(dec.set_config_layout(2, true, 1, cfg));
  EXPECT_FALSE(dec.set_config_layout(0, true, 1, cfg));
  EXPECT_FALSE(dec.set_config_layout(2, true, 5, cfg));
  sdo_write(dec, 2, 0x1A00, 0, 0);
  sdo_write(dec, 2, 0x1A00, 1, 0x60640020);
  sdo_write(dec, 2, 0x1A00, 0, 1);
  const auto& r = dec.decode(tf(0x182, {0x50, 0x02}));
  EXPECT_EQ(r.layout, tr::LayoutSource::kConfig);
  EXPECT_TRUE(r.has_statusword);
  EXPECT_FALSE(r.has_actual);
}

TEST(TraceDecoder, CobIdRemapMovesThePdo) {
  tr::Decoder dec;
  sdo_write(dec, 1, 0x1800, 1, 0x000001F0);  // TPDO1 of node 1 now on 0x1F0
  const auto& r = dec.decode(tf(0x1F0, {0x37, 0x02, 1, 0, 0, 0}));
  EXPECT_EQ(r.kind, tr::EventKind::kPdo);
  EXPECT_EQ(r.node, 1);
  EXPECT_EQ(r.pdo_number, 1);
  EXPECT_TRUE(r.pdo_tx);
  // The old id falls back to its pre-defined meaning (TPDO1 of node 1 is gone; 0x181 is TPDO1 node 1 by default).
  sdo_write(dec, 1, 0x1800, 1, 0x800001F0);  // disabled
  EXPECT_EQ(dec.decode(tf(0x1F0, {0})).node, 0x70);
  EXPECT_EQ(dec.tpdo_transmission_type(1, 1), 255);
  sdo_write(dec, 1, 0x1800, 2, 1);
  EXPECT_EQ(dec.tpdo_transmission_type(1, 1), 1);
}

TEST(TraceDecoder, SegmentedUploadReassembled) {
  tr::Decoder dec;
  dec.decode(tf(0x601, {0x40, 0x08, 0x10, 0, 0, 0, 0, 0}));
  auto r = desc(dec.decode(tf(0x581, {0x41, 0x08, 0x10, 0, 13, 0, 0, 0})));
  EXPECT_EQ(r, "SDO node 1 read 0x1008:00 Manufacturer device name: segmented, 13 bytes");
  dec.decode(tf(0x601, {0x60, 0, 0, 0, 0, 0, 0, 0}));
  const auto& s1 = dec.decode(tf(0x581, {0x00, 'c', 'a', 'n', 'm', 'o', 't', 'i'}));
  EXPECT_FALSE(s1.sdo_has_value);
  dec.decode(tf(0x601, {0x70, 0, 0, 0, 0, 0, 0, 0}));
  const auto& s2 = dec.decode(tf(0x581, {0x13, 'o', 'n', '-', 'e', 'm', 'u', 0}));
  EXPECT_TRUE(s2.sdo_complete);
  EXPECT_EQ(s2.sdo_total, 13U);
  EXPECT_EQ(desc(s2),
            "SDO node 1 read segment (toggle 1, 6 bytes, last): 0x1008:00 Manufacturer device name = \"canmotion-emu\"");
}

TEST(TraceDecoder, SegmentedDownloadAndLongValueTruncated) {
  tr::Decoder dec;
  // 300-byte write to an unknown object: value kept up to kSdoValueCapacity.
  dec.decode(tf(0x604, {0x21, 0x00, 0x21, 0x00, 0x2C, 0x01, 0, 0}));
  dec.decode(tf(0x584, {0x60, 0x00, 0x21, 0x00, 0, 0, 0, 0}));
  std::uint32_t sent = 0;
  bool toggle = false;
  const tr::Decoded* last = nullptr;
  while (sent < 300) {
    const std::uint32_t n = std::min<std::uint32_t>(7, 300 - sent);
    const bool c = sent + n == 300;
    const auto b0 = static_cast<std::uint8_t>((toggle ? 0x10 : 0) | ((7 - n) << 1) | (c ? 1 : 0));
    last = &dec.decode(tf(0x604, {b0, 1, 2, 3, 4, 5, 6, 7}));
    sent += n;
    if (!c) {
      dec.decode(tf(0x584, {static_cast<std::uint8_t>(0x20 | (toggle ? 0x10 : 0)), 0, 0, 0, 0, 0, 0, 0}));
    }
    toggle = !toggle;
    if (c) break;
  }
  ASSERT_NE(last, nullptr);
  EXPECT_TRUE(last->sdo_has_value);
  EXPECT_EQ(last->sdo_total, 300U);
  EXPECT_EQ(last->value.size(), tr::kSdoValueCapacity);
  const auto& resp = dec.decode(tf(0x584, {static_cast<std::uint8_t>(0x20 | (toggle ? 0 : 0x10)), 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_TRUE(resp.sdo_complete);
  EXPECT_EQ(desc(resp).find("0x2100:00 written, 300 bytes") != std::string::npos, true) << desc(resp);
}

TEST(TraceDecoder, AbortsOrphansAndProblems) {
  tr::Decoder dec;
  EXPECT_EQ(desc(dec.decode(tf(0x582, {0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06}))),
            "SDO node 2 abort by server 0x6060:00 Modes of operation: 0x06090030 invalid value for parameter (download only)");
  EXPECT_TRUE(dec.decode(tf(0x582, {0x00, 1, 2, 3, 4, 5, 6, 7})).sdo_orphan);
  EXPECT_NE(dec.decode(tf(0x602, {0x40, 0x00})).problem, nullptr);
  EXPECT_NE(dec.decode(tf(0x000, {0x01})).problem, nullptr);
  EXPECT_NE(dec.decode(tf(0x080, {1, 2})).problem, nullptr);
  const auto& rtr = dec.decode([] {
    auto x = tf(0x181, {});
    x.frame.flags = can::kRemote;
    return x;
  }());
  EXPECT_NE(rtr.problem, nullptr);
}

TEST(TraceDecoder, NetworkManagementFrames) {
  tr::Decoder dec;
  EXPECT_EQ(desc(dec.decode(tf(0x000, {0x01, 0x00}))), "NMT start -> all nodes");
  EXPECT_EQ(desc(dec.decode(tf(0x000, {0x81, 0x05}))), "NMT reset node -> node 5");
  EXPECT_EQ(desc(dec.decode(tf(0x080, {7}))), "SYNC counter=7");
  EXPECT_EQ(desc(dec.decode(tf(0x705, {0x00}))), "Boot-up node 5");
  EXPECT_EQ(desc(dec.decode(tf(0x705, {0x05}))), "Heartbeat node 5: operational");
  EXPECT_EQ(desc(dec.decode(tf(0x085, {0x11, 0x86, 0x21, 0, 0, 0, 0, 0}))),
            "EMCY node 5: 0x8611 following error; error register 0x21 (generic, device profile)");
  const auto& e = dec.decode_error(0x40, 5);
  EXPECT_EQ(e.kind, tr::EventKind::kErrorFrame);
  EXPECT_EQ(desc(e), "ERROR FRAME: bus-off");
  auto ext = tf(0x12345678, {1});
  ext.frame.flags = can::kExtended;
  EXPECT_EQ(dec.decode(ext).kind, tr::EventKind::kUnknown);
}

// canmotiond writes 0x1006 = 0 (before 0x1019) and, with drive.sync_watch,
// the period to each node in turn: a later node's 0 keeps the period.
TEST(TraceDecoder, CommunicationCyclePeriodZeroIsNoPeriod) {
  tr::Decoder dec;
  sdo_write(dec, 2, 0x1006, 0, 0);
  EXPECT_EQ(dec.sync_period_from_trace_ns(), 0);
  sdo_write(dec, 2, 0x1006, 0, 4000);
  EXPECT_EQ(dec.sync_period_from_trace_ns(), 4'000'000);
  sdo_write(dec, 3, 0x1006, 0, 0);
  EXPECT_EQ(dec.sync_period_from_trace_ns(), 4'000'000);
}

TEST(TraceDecoder, FrameBitsWorstCase) {
  EXPECT_EQ(tr::frame_bits_worst_case(can::Frame(0x181, {1, 2, 3, 4, 5, 6, 7, 8})), 135U);
  EXPECT_EQ(tr::frame_bits_worst_case(can::Frame(0x080, {})), 55U);
  can::Frame ext(0x1234, {1, 2, 3, 4, 5, 6, 7, 8});
  ext.flags = can::kExtended;
  EXPECT_EQ(tr::frame_bits_worst_case(ext), 160U);
}

// A small bus: SYNC every 1 ms, node 1 RPDO + TPDO; some cycles without TPDO.
TEST(TraceAnalyzer, MissingTpdoFollowingErrorAndJitter) {
  tr::Decoder dec;
  tr::AnalyzerOptions ao;
  ao.nominal_period_ns = 1'000'000;
  tr::Analyzer an(ao);
  std::int64_t t = 0;
  std::int32_t target = 0;
  int samples = 0;
  auto feed = [&](const can::TimedFrame& f) {
    tr::Sample s;
    if (an.feed(dec.decode(f), dec, &s)) ++samples;
  };
  for (int k = 0; k < 100; ++k) {
    target += 10;
    const auto b = [](std::int32_t v, int i) { return static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> (8 * i)); };
    feed(tf(0x201, {0x0F, 0x00, b(target, 0), b(target, 1), b(target, 2), b(target, 3)}, t));
    // Periods alternate 990 / 1010 us: jitter +-10 us.
    feed(tf(0x080, {}, t + 100'000));
    const std::int32_t actual = target - 3;
    if (k < 40 || k >= 45) {  // 5 cycles without TPDO
      feed(tf(0x181, {0x37, 0x02, b(actual, 0), b(actual, 1), b(actual, 2), b(actual, 3)}, t + 200'000));
    }
    t += (k % 2) ? 1'010'000 : 990'000;
  }
  an.finish(dec);
  const tr::NodeSummary& n = an.node(1);
  EXPECT_EQ(n.missing_tpdo, 5U);
  EXPECT_EQ(n.ferr_max_abs, 3);
  EXPECT_NEAR(n.ferr_rms(), 3.0, 1e-9);
  EXPECT_EQ(samples, 95);
  const tr::BusSummary& b = an.bus();
  EXPECT_EQ(b.syncs, 100U);
  EXPECT_EQ(b.period_ns.n, 99U);
  EXPECT_NEAR(b.period_ns.mean, 1'000'000.0, 250.0);
  EXPECT_EQ(b.period_ns.min, 990'000.0);
  EXPECT_EQ(b.period_ns.max, 1'010'000.0);
  std::uint64_t total = b.jitter.below + b.jitter.above;
  for (auto c : b.jitter.bins) total += c;
  EXPECT_EQ(total, 99U);
  EXPECT_EQ(b.jitter.below + b.jitter.above, 0U);
  ASSERT_EQ(n.timeline.size(), 1U);
  EXPECT_EQ(n.timeline[0].state, canmotion::cia402::State::kOperationEnabled);
}

// Streaming: memory does not grow with the trace. Lists stay at their caps,
// the bus-load series at its maximum number of windows.
TEST(TraceAnalyzer, BoundedMemoryOnLongTraces) {
  tr::Decoder dec;
  tr::AnalyzerOptions ao;
  ao.timeline_cap = 50;
  ao.list_cap = 20;
  ao.max_load_windows = 64;
  ao.load_window_ns = 1'000'000;
  tr::Analyzer an(ao);
  std::int64_t t = 0;
  for (int k = 0; k < 200'000; ++k) {
    an.feed(dec.decode(tf(0x080, {}, t)), dec, nullptr);
    // Toggle between two states every cycle and send an EMCY every 100 cycles.
    const std::uint8_t sw = (k % 2) ? 0x37 : 0x33;
    an.feed(dec.decode(tf(0x181, {sw, 0x02, 0, 0, 0, 0}, t + 1000)), dec, nullptr);
    if (k % 100 == 0) an.feed(dec.decode(tf(0x081, {0x10, 0x86, 1, 0, 0, 0, 0, 0}, t + 2000)), dec, nullptr);
    if (k % 1000 == 0) an.feed(dec.decode_error(0x04, t + 3000), dec, nullptr);
    t += 1'000'000;
  }
  an.finish(dec);
  const tr::NodeSummary& n = an.node(1);
  EXPECT_EQ(n.timeline.size(), 50U);
  EXPECT_EQ(n.timeline_dropped, 200'000U - 50U);
  EXPECT_EQ(n.emcys.size(), 20U);
  EXPECT_EQ(n.emcy_count, 2000U);
  EXPECT_EQ(an.bus().error_list.size(), 20U);
  EXPECT_LE(an.bus().load.size(), 64U);
  EXPECT_GE(an.bus().load_window_ns, 200'000LL * 1'000'000 / 64);
}

TEST(TraceReader, TimeBases) {
  tr::LineReader r(true);
  can::TimedFrame f;
  std::string_view iface;
  ASSERT_EQ(r.feed(" (000.000000)  vcan0  080   [0] ", f, iface), tr::LineReader::Status::kFrame);
  ASSERT_EQ(r.feed(" (000.001500)  vcan0  080   [0] ", f, iface), tr::LineReader::Status::kFrame);
  ASSERT_EQ(r.feed(" (000.001500)  vcan0  080   [0] ", f, iface), tr::LineReader::Status::kFrame);
  EXPECT_EQ(f.t_ns, 3'000'000);
  EXPECT_TRUE(r.has_time());
  tr::LineReader r9;
  ASSERT_EQ(r9.feed("(1700000000.123456789) can1 080#", f, iface), tr::LineReader::Status::kFrame);
  EXPECT_EQ(r9.time_digits(), 9);
  EXPECT_EQ(iface, "can1");
  EXPECT_EQ(r9.feed("garbage", f, iface), tr::LineReader::Status::kMalformed);
  EXPECT_EQ(r9.malformed(), 1U);
}

TEST(TraceConfig, ReadsAxesUnitsAndProfiles) {
  const auto c = tr::parse_trace_config(R"(
controller: {period_ms: 1}
buses: [{name: b, interface: can0, bitrate: 500000}]
drives: {pdo: csp}
axes:
  - {name: X, bus: b, node: 3, units: mm, conversion_constant: 1000}
  - {name: V, type: AXIS_VIRTUAL}
  - {name: Y, bus: b, node: 4, drive: {pdo: csp_csv_cst}}
)", "t.yaml");
  EXPECT_EQ(c.period_ns, 1'000'000);
  ASSERT_EQ(c.nodes.size(), 2U);
  EXPECT_EQ(c.nodes[0].axis, "X");
  EXPECT_EQ(c.nodes[0].interface, "can0");
  EXPECT_DOUBLE_EQ(c.nodes[0].counts_per_unit, 1000.0);
  EXPECT_TRUE(c.nodes[0].layouts.tpdo_set[0]);
  EXPECT_FALSE(c.nodes[0].layouts.tpdo_set[1]);
  EXPECT_TRUE(c.nodes[1].layouts.tpdo_set[1]);
  try {
    (void)tr::parse_trace_config("axes:\n  - {name: X, node: 300}\n", "bad.yaml");
    FAIL() << "node 300 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:2:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("axes[0].node"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)tr::parse_trace_config("drives: {pdo: foo}\n", "p.yaml"), std::runtime_error);
}

// Property: random frames (any id, flags, length) decode and render without
// crashing; PDO fields never claim bytes beyond the frame.
TEST(TraceDecoder, RandomFramesNeverBreakTheDecoder) {
  const unsigned seed = env_seed(777);
  const int count = env_count(200'000);
  std::mt19937_64 rng(seed);
  tr::Decoder dec;
  tr::Analyzer an{tr::AnalyzerOptions{}};
  fmt::memory_buffer out;
  for (int i = 0; i < count; ++i) {
    can::TimedFrame f;
    f.t_ns = static_cast<std::int64_t>(i) * 1000;
    const auto r = rng();
    f.frame.id = static_cast<std::uint32_t>((r & 1) ? (r >> 8) % 0x800 : 0x580 + (r >> 8) % 0x100);
    f.frame.len = static_cast<std::uint8_t>((r >> 20) % 9);
    f.frame.flags = static_cast<std::uint8_t>(((r >> 30) % 16 == 0) ? can::kRemote : 0);
    if ((r >> 34) % 64 == 0) f.frame.flags = can::kError;
    for (auto& b : f.frame.data) b = static_cast<std::uint8_t>(rng());
    const tr::Decoded& d = dec.decode(f);
    for (std::uint8_t k = 0; k < d.field_count; ++k) {
      if (d.fields[k].present) {
        ASSERT_LE(d.pdo_mapped_bits, 64) << "seed " << seed;
      }
    }
    out.clear();
    tr::format_text(d, "vcan0", {}, out);
    tr::format_json(d, "vcan0", {}, out);
    ASSERT_GT(out.size(), 0U) << "seed " << seed;
    an.feed(d, dec, nullptr);
  }
  an.finish(dec);
  EXPECT_EQ(an.bus().frames, static_cast<std::uint64_t>(count)) << "seed " << seed;
}

// A drive that reports the position of the previous cycle's target: the lag
// fit finds 1, and --lag 1 gives a zero following error.
TEST(TraceAnalyzer, LagFitFindsTheDriveDelay) {
  for (std::uint32_t lag : {0U, 1U}) {
    tr::Decoder dec;
    tr::AnalyzerOptions ao;
    ao.ferr_lag_cycles = lag;
    tr::Analyzer an(ao);
    std::int64_t t = 0;
    std::int32_t target = 0, previous = 0;
    const auto b = [](std::int32_t v, int i) { return static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> (8 * i)); };
    for (int k = 0; k < 50; ++k) {
      previous = target;
      target += 100;
      an.feed(dec.decode(tf(0x201, {0x0F, 0x00, b(target, 0), b(target, 1), b(target, 2), b(target, 3)}, t)), dec, nullptr);
      an.feed(dec.decode(tf(0x080, {}, t + 100'000)), dec, nullptr);
      an.feed(dec.decode(tf(0x181, {0x37, 0x02, b(previous, 0), b(previous, 1), b(previous, 2), b(previous, 3)}, t + 200'000)),
              dec, nullptr);
      t += 1'000'000;
    }
    an.finish(dec);
    const tr::NodeSummary& n = an.node(1);
    EXPECT_EQ(n.best_lag(), 1U);
    EXPECT_EQ(n.lag_max_abs[1], 0);
    EXPECT_EQ(n.lag_max_abs[0], 100);
    EXPECT_EQ(n.ferr_max_abs, lag == 1 ? 0 : 100) << "lag " << lag;
  }
}

// A TPDO that misses its cycle but arrives in the next one (two TPDOs there)
// is counted as late, not missing; a TPDO that never comes stays missing.
TEST(TraceAnalyzer, LateTpdoIsNotMissing) {
  tr::Decoder dec;
  tr::Analyzer an{tr::AnalyzerOptions{}};
  std::int64_t t = 0;
  for (int k = 0; k < 20; ++k) {
    an.feed(dec.decode(tf(0x080, {}, t)), dec, nullptr);
    if (k == 5) {
      // nothing in cycle 5 ...
    } else if (k == 6) {
      // ... and two in cycle 6: the first was late
      an.feed(dec.decode(tf(0x181, {0x37, 0x02, 0, 0, 0, 0}, t + 1000)), dec, nullptr);
      an.feed(dec.decode(tf(0x181, {0x37, 0x02, 0, 0, 0, 0}, t + 2000)), dec, nullptr);
    } else if (k != 12) {  // cycle 12: lost for good
      an.feed(dec.decode(tf(0x181, {0x37, 0x02, 0, 0, 0, 0}, t + 1000)), dec, nullptr);
    }
    t += 1'000'000;
  }
  an.finish(dec);
  EXPECT_EQ(an.node(1).late_tpdo, 1U);
  EXPECT_EQ(an.node(1).missing_tpdo, 1U);
  ASSERT_EQ(an.node(1).missing_times.size(), 1U);
  EXPECT_EQ(an.node(1).missing_times[0], 12'000'000);
}
