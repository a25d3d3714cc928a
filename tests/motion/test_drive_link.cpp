// AXIS_CIP_DRIVE axes and the drive behind them (issue 12): MAFR, MASR and
// MGSR wait until the drive has left Fault (ER on a transition timeout or
// after the drive timeout); an axis whose drive refused its configuration or
// never answered (AxisFeedback::link) is not configured: ERR 11 at once for
// MSO, MAH and MDS, ERR 12 for one that was waiting, ConfigFault/ModuleFault
// in AxisFault.
#include <gtest/gtest.h>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::cip_direct;
using canmotion::motion::test::Rig;

namespace {

AxisConfig cip() {
  AxisConfig c;
  c.type = AxisType::CipDrive;
  c.max_speed = 100;
  c.max_accel = c.max_decel = 1000;
  return c;
}

/// A CIP axis "D" servo on, then its drive faults (Stop Drive: faulted).
Rig faulted_rig() {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::Enabled;
  EXPECT_EQ(r.exec("MSO(D, mso);"), Err::None);
  r.step();
  EXPECT_TRUE(r.tag("mso").dn());
  r.fb[0].drive = DriveState::Fault;
  r.fb[0].drive_fault = true;
  r.step();
  EXPECT_EQ(r.axis("D").state, AxisState::Faulted);
  return r;
}

bool fault_bit(const AxisTag& t, unsigned b) { return (t.axis_fault >> b) & 1u; }

/// Drive `i` leaves Fault (Switch on disabled).
void leave_fault(Rig& r, std::size_t i = 0) {
  r.fb[i].drive = DriveState::NotReady;
  r.fb[i].drive_fault = false;
}

TEST(FaultReset, MafrIsDoneWhenTheDriveHasLeftFaultNotBefore) {
  Rig r = faulted_rig();
  ASSERT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  EXPECT_FALSE(r.tag("fr").dn()) << "DN while the drive is still in Fault";
  r.step();
  EXPECT_EQ(r.axis("D").axis_fault, 0u);  // the axis faults are cleared
  EXPECT_TRUE(r.out[0].fault_reset) << "the fault reset goes out in this cycle";
  r.step(3);  // the drive is slow to leave Fault: no DN, and the fault is not latched again
  EXPECT_FALSE(r.out[0].fault_reset) << "one pulse";
  EXPECT_FALSE(r.tag("fr").dn());
  EXPECT_FALSE(r.tag("fr").er());
  EXPECT_EQ(r.axis("D").state, AxisState::Ready);
  leave_fault(r);
  r.step();
  EXPECT_TRUE(r.tag("fr").dn());
  EXPECT_EQ(r.axis("D").axis_fault, 0u);
  EXPECT_EQ(r.exec("MSO(D, mso2);"), Err::None);
  r.step();
  r.fb[0].drive = DriveState::Enabled;
  r.step();
  EXPECT_TRUE(r.tag("mso2").dn());
}

TEST(FaultReset, MafrOnAHealthyDriveIsDoneAtOnce) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::NotReady;
  r.step();
  ASSERT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  EXPECT_TRUE(r.tag("fr").dn());
}

TEST(FaultReset, TransitionTimeoutEndsMafrWithErr12AndFaultsAgain) {
  Rig r = faulted_rig();
  ASSERT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  r.step(5);
  r.fb[0].transition_timeout = true;  // the runtime gave up on the fault reset
  r.step();
  EXPECT_TRUE(r.tag("fr").er());
  EXPECT_FALSE(r.tag("fr").dn());
  EXPECT_EQ(r.tag("fr").err, 12);
  EXPECT_EQ(r.tag("fr").exerr, 16);
  r.step();
  EXPECT_EQ(r.axis("D").state, AxisState::Faulted) << "the drive fault is latched again";
  EXPECT_TRUE(fault_bit(r.axis("D"), axis_fault::PhysicalAxisFault));
}

TEST(FaultReset, MafrGivesUpAfterTheDriveTimeout) {
  Rig r = faulted_rig();
  ASSERT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  const int n = r.step_until([&] { return r.tag("fr").dn() || r.tag("fr").er(); }, 10000);
  EXPECT_TRUE(r.tag("fr").er());
  EXPECT_EQ(r.tag("fr").err, 12);
  EXPECT_NEAR(n, 5000, 2);  // 5 s at 1 ms
}

TEST(FaultReset, MasrLeavesShutdownAndWaitsForTheDrive) {
  Rig r = faulted_rig();
  ASSERT_EQ(r.exec("MASD(D, sd);"), Err::None);
  ASSERT_EQ(r.exec("MASR(D, sr);"), Err::None);
  EXPECT_FALSE(r.tag("sr").dn());
  EXPECT_EQ(r.axis("D").state, AxisState::Ready);
  r.step(2);
  EXPECT_FALSE(r.tag("sr").dn());
  leave_fault(r);
  r.step();
  EXPECT_TRUE(r.tag("sr").dn());
}

TEST(FaultReset, MgsrIsDoneWhenEveryDriveOfTheGroupLeftFault) {
  Rig r;
  AxisConfig c = cip();
  c.group = 0;
  r.add_axis("A", c);
  r.add_axis("B", c);
  r.add_axis("V", AxisConfig{});  // a virtual axis of the group: nothing to wait for
  for (int i = 0; i < 2; ++i) {
    r.fb[i].drive = DriveState::Fault;
    r.fb[i].drive_fault = true;
  }
  r.step();
  ASSERT_EQ(r.exec("MGSR(g, sr);"), Err::None);
  EXPECT_FALSE(r.tag("sr").dn());
  r.step();
  EXPECT_TRUE(r.out[0].fault_reset);
  EXPECT_TRUE(r.out[1].fault_reset);
  leave_fault(r);
  r.step(2);
  EXPECT_FALSE(r.tag("sr").dn()) << "B is still in Fault";
  leave_fault(r, 1);
  r.step();
  EXPECT_TRUE(r.tag("sr").dn());
  EXPECT_FALSE(r.tag("sr").er());
}

TEST(FaultReset, MgsrEndsWithErrorWhenOneDriveStaysInFault) {
  Rig r;
  AxisConfig c = cip();
  r.add_axis("A", c);
  r.add_axis("B", c);
  for (int i = 0; i < 2; ++i) {
    r.fb[i].drive = DriveState::Fault;
    r.fb[i].drive_fault = true;
  }
  r.step();
  ASSERT_EQ(r.exec("MGSR(g, sr);"), Err::None);
  r.step();  // the pulses go out
  leave_fault(r);
  r.fb[1].transition_timeout = true;
  r.step();
  EXPECT_TRUE(r.tag("sr").er());
  EXPECT_EQ(r.tag("sr").err, 12);
  r.step(10);
  EXPECT_FALSE(r.tag("sr").dn()) << "DN after ER";
}

TEST(FaultReset, MsoIssuedWhileTheResetWaitsWaitsToo) {
  Rig r = faulted_rig();
  ASSERT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  ASSERT_EQ(r.exec("MSO(D, mso2);"), Err::None);
  r.step(3);  // still in Fault: the MSO does not fail (ERR 12) meanwhile
  EXPECT_FALSE(r.tag("mso2").er());
  leave_fault(r);
  r.step();
  EXPECT_TRUE(r.tag("fr").dn());
  r.fb[0].drive = DriveState::Enabled;
  r.step();
  EXPECT_TRUE(r.tag("mso2").dn());
}

TEST(FaultReset, LostNodeWaitsUntilItIsBack) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::NotReady;
  r.fb[0].node_lost = true;
  r.step();
  EXPECT_TRUE(fault_bit(r.axis("D"), axis_fault::ModuleFault));
  ASSERT_EQ(r.exec("MASR(D, sr);"), Err::None);
  r.step(10);
  EXPECT_FALSE(r.tag("sr").dn());
  EXPECT_EQ(r.axis("D").axis_fault, 0u) << "not latched again while the reset waits";
  r.fb[0].node_lost = false;
  r.fb[0].link = DriveLink::Configuring;  // it came back with a boot-up: configured again
  r.step(5);
  EXPECT_FALSE(r.tag("sr").dn());
  r.fb[0].link = DriveLink::Up;
  r.step();
  EXPECT_TRUE(r.tag("sr").dn());
}

TEST(DriveLinkFailed, MsoMahMdsGetErr11AtOnce) {
  Rig r;
  r.add_axis("D", cip_direct(AxisConfig::DirectMode::Velocity));
  r.fb[0].link = DriveLink::ConfigFailed;
  r.step();
  EXPECT_TRUE(fault_bit(r.axis("D"), axis_fault::ConfigFault));
  EXPECT_EQ(r.exec("MSO(D, mso);"), Err::AxisNotConfigured);
  EXPECT_EQ(r.tag("mso").err, 11);
  EXPECT_EQ(r.exec("MAH(D, mah);"), Err::AxisNotConfigured);
  EXPECT_EQ(r.exec("MDS(D, mds, 10, unitspersec);"), Err::AxisNotConfigured);
  r.fb[0].link = DriveLink::NoModule;
  r.step();
  EXPECT_TRUE(fault_bit(r.axis("D"), axis_fault::ModuleFault));
  EXPECT_FALSE(fault_bit(r.axis("D"), axis_fault::ConfigFault));
  EXPECT_EQ(r.exec("MSO(D, mso2);"), Err::AxisNotConfigured);
  // MAFR still runs: the runtime retries the boot (fault_reset pulse).
  ASSERT_EQ(r.exec("MAFR(D, fr);"), Err::None);
  r.step();
  EXPECT_TRUE(r.out[0].fault_reset);
  r.fb[0].link = DriveLink::Configuring;
  r.step(3);
  EXPECT_FALSE(r.tag("fr").dn());
  EXPECT_EQ(r.axis("D").axis_fault, 0u) << std::hex << r.axis("D").axis_fault;
  r.fb[0].link = DriveLink::Up;
  r.step();
  EXPECT_TRUE(r.tag("fr").dn());
  EXPECT_EQ(r.exec("MSO(D, mso3);"), Err::None);
}

TEST(DriveLinkFailed, PendingMsoAndMdsEndWithErr12WhenTheBootFails) {
  Rig r;
  r.add_axis("D", cip_direct(AxisConfig::DirectMode::Velocity));
  r.add_axis("E", cip());
  r.fb[0].link = r.fb[1].link = DriveLink::Configuring;  // still booting
  r.step();
  ASSERT_EQ(r.exec("MDS(D, mds, 10, unitspersec);"), Err::None);
  ASSERT_EQ(r.exec("MSO(E, mso);"), Err::None);
  r.step(10);
  EXPECT_FALSE(r.tag("mso").er());
  r.fb[0].link = DriveLink::ConfigFailed;
  r.fb[1].link = DriveLink::NoModule;
  r.step();
  EXPECT_TRUE(r.tag("mso").er());
  EXPECT_EQ(r.tag("mso").err, 12);
  EXPECT_EQ(r.tag("mso").exerr, 16);
  EXPECT_TRUE(r.tag("mds").er());
  EXPECT_EQ(r.tag("mds").err, 12);
  EXPECT_FALSE(r.out[1].enable);
}

TEST(DriveLinkFailed, PendingMsoEndsOnATransitionTimeout) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::NotReady;
  ASSERT_EQ(r.exec("MSO(D, mso);"), Err::None);
  r.step(10);
  r.fb[0].transition_timeout = true;  // the drive did not enable within the runtime's timeout
  r.step();
  EXPECT_TRUE(r.tag("mso").er());
  EXPECT_EQ(r.tag("mso").err, 12);
  EXPECT_FALSE(r.out[0].enable);
}

// The wait on the drive is bounded by the axis's own drive_wait_limit (the
// runtime's drive.timeouts.wait_ms), and each wait that ends with an error
// is recorded for the log with its instruction, tag and cause (issue 26).
TEST(DriveWait, MsoWaitsItsAxisLimitAndTheEndIsRecorded) {
  Rig r;
  AxisConfig c = cip();
  c.drive_wait_limit = 0.25;  // 250 cycles at 1 ms
  r.add_axis("D", c);
  r.fb[0].drive = DriveState::NotReady;
  r.fb[0].link = DriveLink::Configuring;  // the drive is booting
  ASSERT_EQ(r.exec("MSO(D, mso);"), Err::None);
  r.step(250);  // the feedback of update N is judged at the planner's cycle N - 1
  EXPECT_FALSE(r.tag("mso").er());
  EXPECT_EQ(r.axis("D").drive_wait_errors, 0u);
  r.step();
  EXPECT_TRUE(r.tag("mso").er());
  EXPECT_EQ(r.tag("mso").err, 12);
  EXPECT_EQ(r.tag("mso").exerr, 16);
  ASSERT_EQ(r.axis("D").drive_wait_errors, 1u);
  const DriveWaitEnd& w = r.axis("D").last_drive_wait;
  EXPECT_EQ(w.instr, Instr::MSO);
  EXPECT_EQ(w.cause, DriveWaitCause::Limit);
  EXPECT_EQ(w.waited_cycles, 250u);
  EXPECT_EQ(w.err, 12);
  EXPECT_EQ(w.exerr, 16);
}

// An MSO still waiting when the axis latches a fault (here the drive
// rebooted: a drive fault with Stop Drive) ends then, not at its limit: the
// drive is not enabled again before MAFR.
TEST(DriveWait, PendingMsoEndsWhenTheAxisFaults) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::NotReady;
  ASSERT_EQ(r.exec("MSO(D, mso);"), Err::None);
  r.step(5);
  r.fb[0].drive_fault = true;  // e.g. an unexpected boot-up
  r.fb[0].link = DriveLink::Configuring;
  r.step(2);
  EXPECT_TRUE(r.tag("mso").er());
  EXPECT_EQ(r.tag("mso").err, 12);
  EXPECT_EQ(r.axis("D").last_drive_wait.cause, DriveWaitCause::AxisFaulted);
  EXPECT_FALSE(r.out[0].enable);
}

// MASD waits on nothing (issue 26 lists it among the drive instructions): on
// a drive that is still booting it ends with DN in the scan that issues it,
// ends a pending MSO with ER, and the drive is not enabled.
TEST(DriveWait, MasdEndsAtOnceWhateverTheDriveDoes) {
  Rig r;
  r.add_axis("D", cip());
  r.fb[0].drive = DriveState::NotReady;
  r.fb[0].link = DriveLink::Configuring;  // the drive is booting
  ASSERT_EQ(r.exec("MSO(D, mso);"), Err::None);
  r.step(3);
  ASSERT_FALSE(r.tag("mso").dn());
  ASSERT_EQ(r.exec("MASD(D, sd);"), Err::None);
  EXPECT_TRUE(r.tag("sd").dn()) << "DN in the scan that issues it";
  EXPECT_FALSE(r.tag("sd").er());
  r.step(2);
  EXPECT_TRUE(r.tag("mso").er()) << "the pending MSO ends with the shutdown";
  EXPECT_EQ(r.tag("mso").err, 12);
  EXPECT_EQ(r.axis("D").state, AxisState::Shutdown);
  EXPECT_FALSE(r.out[0].enable);
}

}  // namespace
