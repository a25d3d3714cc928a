// The cycle's burst against the interface's transmit queue (issue 15 item 2):
// check_tx_queue() sizes it at start-up (sans-IO), and DriveNetwork::cycle()
// never loses the SYNC to a queue shorter than the burst.
#include <gtest/gtest.h>

#include <vector>

#include "fieldbus/canopen/tx_queue.hpp"
#include "fieldbus/cia402/drive_proxy.hpp"
#include "fieldbus/emulator/sim_rig.hpp"

using namespace canmotion;
using canopen::TxBurst;
using canopen::TxQueueCheck;

TEST(TxQueue, BurstCountsRpdosSyncSdoHeartbeatAndNmt) {
  TxBurst b;
  b.rpdos = 10;  // 10 CSP axes, one RPDO each
  b.sdo_nodes = 10;
  b.master_heartbeat = true;
  EXPECT_EQ(b.cyclic_frames(), 11u);
  EXPECT_EQ(b.frames(), 10u + 1 + 10 + 1 + 1);
}

TEST(TxQueue, KernelDefaultOf10IsTooShortForTenAxes) {
  TxBurst b{10, 10, true};
  const TxQueueCheck refuse = canopen::check_tx_queue(10, b, false);
  EXPECT_EQ(refuse.action, TxQueueCheck::Action::kRefuse);
  EXPECT_EQ(refuse.needed, 23u);
  const std::string m = refuse.message("can0");
  EXPECT_NE(m.find("interface can0 has txqueuelen 10"), std::string::npos) << m;
  EXPECT_NE(m.find("up to 23 frames (10 RPDOs, 1 SYNC, 10 SDOs, 1 heartbeat, 1 NMT)"), std::string::npos) << m;
  EXPECT_NE(m.find("ip link set can0 txqueuelen 23"), std::string::npos) << m;
  EXPECT_EQ(canopen::check_tx_queue(10, b, true).action, TxQueueCheck::Action::kRaise);
  EXPECT_EQ(canopen::check_tx_queue(23, b, false).action, TxQueueCheck::Action::kOk);
  EXPECT_EQ(canopen::check_tx_queue(1000, b, true).action, TxQueueCheck::Action::kOk);  // never lowered
  EXPECT_EQ(canopen::check_tx_queue(0, b, false).action, TxQueueCheck::Action::kOk);    // no queue (vcan)
  // Two axes with csp_csv_cst (2 RPDOs each), no master heartbeat: 4 + 1 + 2 + 0 + 1.
  EXPECT_EQ(canopen::check_tx_queue(10, TxBurst{4, 2, false}, false).action, TxQueueCheck::Action::kOk);
}

namespace {
/// Nine CSP drives (one RPDO each) on a master whose interface queues 10
/// frames a cycle and a master heartbeat every cycle: 9 RPDOs + SYNC +
/// heartbeat (+ SDO while configuring) do not fit in the queue. The drives
/// do not watch the master's heartbeat (0x1016 left out), so the refused
/// heartbeats only cost the heartbeat. Returns the SYNCs the queue refused
/// from power-on to 250 cycles after all drives were enabled.
std::uint64_t syncs_refused_with_nine_axes(std::uint32_t tx_queue_frames, std::uint64_t* skipped,
                                           bool sync_first = false) {
  emulator::SimRigConfig cfg;
  cfg.sync_first = sync_first;
  cfg.cycle_ns = 4'000'000;
  cfg.nodes = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  cfg.master.heartbeat_period_ms = 4;  // one master heartbeat every cycle
  cfg.drive.consumer_heartbeat_ms = 0;
  cfg.tx_queue_depth = 10;
  cfg.tx_queue_frames = tx_queue_frames;
  emulator::SimRig rig(cfg);
  rig.power_on();
  EXPECT_TRUE(rig.run_until([&] { return rig.network().all_operational() || rig.network().any_failed(); }, 2000));
  rig.network().enable_all();
  EXPECT_TRUE(rig.run_until([&] { return rig.network().all_enabled() || rig.network().any_failed(); }, 2000));
  for (std::size_t i = 0; i < rig.network().size(); ++i)
    EXPECT_FALSE(rig.network().at(i).failed()) << rig.network().at(i).failure().to_string();
  for (int i = 0; i < 250; ++i) rig.step();
  EXPECT_GT(rig.tx_refused() + rig.network().tx_budget_skipped(), 0u) << "the burst never exceeded the queue";
  if (tx_queue_frames != 0) {
    EXPECT_EQ(rig.tx_refused(), 0u) << "the network wrote past the queue length it was given";
  }
  if (skipped != nullptr) *skipped = rig.network().tx_budget_skipped();
  return rig.syncs_refused();
}
}  // namespace

// The SYNC goes right after the RPDOs, before SDO requests and the
// heartbeat: a queue too short for the burst drops those, never the SYNC
// (on main the order was heartbeat, RPDOs, SDO, SYNC: the SYNC was the 11th
// frame and refused in every cycle once the nine drives ran). With the
// queue's length given (NetworkConfig::tx_queue_frames, the runtime passes
// the interface's txqueuelen) the network itself stops at the queue's length.
TEST(TxQueue, SyncIsNeverTheFrameDroppedWhenTheBurstExceedsTheQueue) {
  EXPECT_EQ(syncs_refused_with_nine_axes(0, nullptr), 0u);
  std::uint64_t skipped = 0;
  EXPECT_EQ(syncs_refused_with_nine_axes(10, &skipped), 0u);
  EXPECT_GT(skipped, 0u) << "the budget never left a frame out";
}

// controller.sync_first (issue 28): the SYNC is the first frame of the burst
// and takes the place kept for it; the RPDOs, SDO requests and the heartbeat
// after it share the rest of the queue, so the SYNC is still never the frame
// a short queue drops, and the network still writes no more than the queue's length.
TEST(TxQueue, SyncFirstKeepsTheSyncAndTheQueueLength) {
  EXPECT_EQ(syncs_refused_with_nine_axes(0, nullptr, true), 0u);
  std::uint64_t skipped = 0;
  EXPECT_EQ(syncs_refused_with_nine_axes(10, &skipped, true), 0u);
  EXPECT_GT(skipped, 0u) << "the budget never left a frame out";
}

namespace {
/// The frames the master sent in each cycle of a SimRig (bus tap), from
/// power-on until `cycles` cycles after every drive was enabled.
struct Bursts {
  std::vector<std::vector<can::Frame>> cycles;  // [cycle] -> the master's frames, in order
};
Bursts master_bursts(bool sync_first, std::uint8_t sync_counter_overflow, int cycles_enabled) {
  emulator::SimRigConfig cfg;
  cfg.nodes = {2, 3};
  cfg.sync_first = sync_first;
  cfg.master.sync_counter_overflow = sync_counter_overflow;
  emulator::SimRig rig(cfg);
  Bursts b;
  rig.bus().set_tap([&](const can::TimedFrame& f, std::string_view) {
    // The master's frames: SYNC, NMT, RPDOs (0x200/0x300 + node), SDO requests, its heartbeat.
    const std::uint32_t id = f.frame.id;
    const bool from_master = id == 0x080 || id == 0x000 || (id >= 0x201 && id <= 0x27F) ||
                             (id >= 0x301 && id <= 0x37F) || (id >= 0x601 && id <= 0x67F) ||
                             id == 0x700u + cfg.master.node_id;
    if (!from_master) return;
    const auto k = static_cast<std::size_t>(f.t_ns / cfg.cycle_ns);
    if (b.cycles.size() <= k) b.cycles.resize(k + 1);
    b.cycles[k].push_back(f.frame);
  });
  rig.power_on();
  EXPECT_TRUE(rig.run_until([&] { return rig.network().all_operational() || rig.network().any_failed(); }, 2000));
  rig.network().enable_all();
  EXPECT_TRUE(rig.run_until([&] { return rig.network().all_enabled() || rig.network().any_failed(); }, 2000));
  for (int i = 0; i < cycles_enabled; ++i) rig.step();
  EXPECT_EQ(rig.drive(2).feedback().tpdo_missed, 0u);
  EXPECT_EQ(rig.drive(3).feedback().tpdo_missed, 0u);
  b.cycles.resize(rig.cycles());
  return b;
}
}  // namespace

// Every cycle has exactly one SYNC; with sync_first it is the first frame
// the master sends in the cycle, else it follows the last RPDO. The SYNC
// counter (0x1019 = 5) counts 1..5 without a gap in both orders.
TEST(TxQueue, SyncIsFirstInTheBurstWithSyncFirstAndAfterTheRpdosOtherwise) {
  for (const bool sync_first : {false, true}) {
    SCOPED_TRACE(sync_first ? "sync_first" : "RPDOs, then SYNC");
    const Bursts b = master_bursts(sync_first, 5, 100);
    ASSERT_GT(b.cycles.size(), 100u);
    std::uint8_t expect_counter = 1;
    int with_rpdos = 0;
    for (std::size_t k = 0; k < b.cycles.size(); ++k) {
      const auto& c = b.cycles[k];
      int syncs = 0;
      std::size_t sync_at = 0, last_rpdo = 0;
      bool rpdo = false;
      for (std::size_t i = 0; i < c.size(); ++i) {
        if (c[i].id == 0x080) {
          ++syncs;
          sync_at = i;
          ASSERT_EQ(c[i].len, 1) << "cycle " << k;
          EXPECT_EQ(c[i].data[0], expect_counter) << "cycle " << k;
          expect_counter = static_cast<std::uint8_t>(expect_counter == 5 ? 1 : expect_counter + 1);
        }
        if (c[i].id >= 0x201 && c[i].id <= 0x37F) {
          rpdo = true;
          last_rpdo = i;
        }
      }
      ASSERT_EQ(syncs, 1) << "cycle " << k;
      if (sync_first) {
        EXPECT_EQ(sync_at, 0u) << "cycle " << k;
      } else if (rpdo) {
        EXPECT_GT(sync_at, last_rpdo) << "cycle " << k;
      }
      with_rpdos += rpdo ? 1 : 0;
    }
    EXPECT_GE(with_rpdos, 100);
  }
}
