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
std::uint64_t syncs_refused_with_nine_axes(std::uint32_t tx_queue_frames, std::uint64_t* skipped) {
  emulator::SimRigConfig cfg;
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
