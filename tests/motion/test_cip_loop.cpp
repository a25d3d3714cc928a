// The runtime contract of AXIS_CIP_DRIVE axes, closed through a tiny drive
// model written here (not the project's emulator): enable handshake, CSP
// tracking with lag, fault and fault reset, drive homing in mode 6, and MSF.
// Virtual clock: one update() per cycle.
#include <gtest/gtest.h>

#include <cmath>

#include "rig.hpp"

using namespace canmotion::motion;
using canmotion::motion::test::mam;
using canmotion::motion::test::Rig;

namespace {

/// Minimal drive: follows the target with a one-cycle transport delay and a
/// first-order lag; enables after `enable_delay` cycles; homing takes
/// `homing_cycles` and ends with the actual position set to `home_offset`
/// (0x607C); a fault stays until a fault reset.
struct SimDrive {
  double pos = 0, vel = 0, target = 0;
  DriveState state = DriveState::NotReady;
  int enable_count = 0, enable_delay = 3;
  bool fault = false;
  int homing_count = 0, homing_cycles = 50;
  double home_offset = 0;
  bool attained = false;

  void cycle(const AxisOutput& o, double T) {
    if (o.fault_reset && fault) { fault = false; state = DriveState::NotReady; }
    if (fault) { state = DriveState::Fault; return; }
    if (o.enable) {
      if (state != DriveState::Enabled && ++enable_count >= enable_delay) state = DriveState::Enabled;
    } else {
      state = DriveState::NotReady;
      enable_count = 0;
    }
    if (state != DriveState::Enabled) { vel = 0; target = o.position; return; }
    if (o.mode == DriveMode::Homing && o.homing_start) {
      attained = false;
      if (++homing_count >= homing_cycles) { pos = home_offset; attained = true; }
      else pos += o.homing.speed_search * T;
      vel = 0;
      target = o.position;  // the runtime keeps writing 0x607A (= actual while homing)
      return;
    }
    if (homing_count > 0) target = o.position;  // mode switch: the drive takes the fresh 0x607A
    homing_count = 0;
    const double old = pos;
    pos += 0.5 * (target - pos);  // lag
    vel = (pos - old) / T;
    target = o.position;          // applied at the next SYNC
  }
  AxisFeedback feedback() const {
    AxisFeedback f;
    f.position = pos;
    f.velocity = vel;
    f.drive = state;
    f.drive_fault = fault;
    f.homing_attained = attained;
    return f;
  }
};

struct Loop {
  Rig r;
  SimDrive d;
  explicit Loop(AxisConfig c) {
    r.add_axis("D", c);
    r.fb[0] = d.feedback();
  }
  void run(int n = 1) {
    for (int i = 0; i < n; ++i) {
      r.step();
      d.cycle(r.out[0], r.p->period());
      r.fb[0] = d.feedback();
    }
  }
};

AxisConfig cip() {
  AxisConfig c;
  c.type = AxisType::CipDrive;
  c.max_speed = 100;
  c.max_accel = c.max_decel = 1000;
  c.position_error_tolerance = 0.5;
  c.homing.sequence = HomingConfig::Sequence::Marker;
  c.homing.home_position = 25;
  return c;
}

}  // namespace

TEST(CipLoop, EnableMoveFaultResetHomeDisable) {
  Loop L(cip());
  L.d.pos = L.d.target = 3.0;
  L.r.fb[0] = L.d.feedback();
  // MSO: DN once the drive reports Operation Enabled
  ASSERT_EQ(L.r.exec("MSO(D, mso);"), Err::None);
  int n = 0;
  while (!L.r.tag("mso").dn() && n < 100) { L.run(); ++n; }
  EXPECT_GE(n, 3);
  EXPECT_LT(n, 10);
  EXPECT_EQ(L.r.axis("D").state, AxisState::ServoControl);
  EXPECT_DOUBLE_EQ(L.r.out[0].position, 3.0);  // loop closed where the drive stands
  // MAM: the drive follows within the lag, no position error fault
  ASSERT_EQ(L.r.exec(mam("D", "m", 0, 20, 10)), Err::None);
  double worst = 0;
  while (!L.r.tag("m").pc()) {
    L.run();
    worst = std::max(worst, std::fabs(L.r.axis("D").position_error));
  }
  L.run(20);
  EXPECT_LT(worst, 0.5);
  EXPECT_EQ(L.r.axis("D").exception_faults, 0u);
  EXPECT_NEAR(L.r.axis("D").actual_position, 20.0, 1e-6);
  // drive fault: Stop Drive (default) -> Faulted, enable dropped
  L.d.fault = true;
  L.run(2);
  EXPECT_EQ(L.r.axis("D").state, AxisState::Faulted);
  EXPECT_TRUE(L.r.axis("D").fault(axis_fault::PhysicalAxisFault));
  EXPECT_FALSE(L.r.out[0].enable);
  EXPECT_EQ(L.r.exec("MSO(D, mso2);"), Err::AxisInFaultedState);
  // MAFR pulses a fault reset; then MSO again
  ASSERT_EQ(L.r.exec("MAFR(D, fr);"), Err::None);
  L.run(1);
  EXPECT_FALSE(L.d.fault);
  L.run(1);
  EXPECT_EQ(L.r.axis("D").state, AxisState::Ready);
  ASSERT_EQ(L.r.exec("MSO(D, mso3);"), Err::None);
  L.run(10);
  EXPECT_TRUE(L.r.tag("mso3").dn());
  // MAH: drive homing mode 6, home offset 0 on the drive -> user position 25
  ASSERT_EQ(L.r.exec("MAH(D, mah);"), Err::None);
  while (!L.r.tag("mah").pc() && !L.r.tag("mah").er() && n < 100000) { L.run(); ++n; }
  EXPECT_TRUE(L.r.tag("mah").pc());
  EXPECT_TRUE(L.r.axis("D").motion(motion_status::AxisHomedStatus));
  L.run(5);
  EXPECT_NEAR(L.r.axis("D").actual_position, 25.0, 1e-9);
  EXPECT_EQ(L.r.out[0].mode, DriveMode::CyclicPosition);
  // move in the homed frame
  ASSERT_EQ(L.r.exec(mam("D", "m2", 0, 30, 10)), Err::None);
  while (!L.r.tag("m2").pc()) L.run();
  L.run(20);
  EXPECT_NEAR(L.r.axis("D").actual_position, 30.0, 1e-6);
  // MSF: DN once the drive left Operation Enabled
  ASSERT_EQ(L.r.exec("MSF(D, msf);"), Err::None);
  EXPECT_FALSE(L.r.tag("msf").dn());
  L.run(2);
  EXPECT_TRUE(L.r.tag("msf").dn());
  EXPECT_EQ(L.r.axis("D").state, AxisState::Ready);
}

TEST(CipLoop, EnableTimeoutIsServoMessageFailure) {
  Loop L(cip());
  L.d.enable_delay = 1000000;  // never enables
  ASSERT_EQ(L.r.exec("MSO(D, mso);"), Err::None);
  L.run(5100);
  EXPECT_TRUE(L.r.tag("mso").er());
  EXPECT_EQ(L.r.tag("mso").err, 12);
  EXPECT_EQ(L.r.tag("mso").exerr, 16);
}

// Issue 16 item 8. MAS StopType 4 home, 5 tune, 6 test [reference §2.6]: "stops
// only the named kind of motion; other kinds keep running". Home: the drive
// homing (mode 6) is cancelled: the MAH loses IP (no PC), HomingStatus
// clears, the drive returns to CSP at its actual position, not homed; MAS
// gets DN and PC (the drive stops at once in CSP). Tune and test: canmotion
// runs no tune or test process, so MAS refuses them clearly (ERR 13, EXERR 2 =
// StopType) and a running move is not touched.
TEST(CipLoop, MasHomeCancelsDriveHomingTuneAndTestAreRefused) {
  Loop L(cip());
  ASSERT_EQ(L.r.exec("MSO(D, on);"), Err::None);
  L.run(10);
  ASSERT_TRUE(L.r.tag("on").dn());
  ASSERT_EQ(L.r.exec("MAH(D, mah);"), Err::None);
  L.run(10);
  ASSERT_EQ(L.r.out[0].mode, DriveMode::Homing);
  ASSERT_TRUE(L.r.axis("D").motion(motion_status::HomingStatus));
  const std::string mas = "MAS(D, s, home, no, 0, unitspersec2, no, 0, unitspersec3);";
  ASSERT_EQ(L.r.exec(mas), Err::None);
  EXPECT_TRUE(L.r.tag("s").dn() && L.r.tag("s").pc());
  EXPECT_FALSE(L.r.tag("mah").ip());
  EXPECT_FALSE(L.r.tag("mah").pc());
  L.run(1);
  EXPECT_EQ(L.r.out[0].mode, DriveMode::CyclicPosition);
  EXPECT_DOUBLE_EQ(L.r.out[0].position, L.d.pos);  // from the actual position: no jump
  EXPECT_FALSE(L.r.axis("D").motion(motion_status::HomingStatus));
  EXPECT_FALSE(L.r.axis("D").motion(motion_status::AxisHomedStatus));
  L.run(100);
  EXPECT_FALSE(L.r.tag("mah").pc());  // the homing never completes
  // tune / test: refused, the move goes on
  ASSERT_EQ(L.r.exec(mam("D", "m", 1, 5, 10)), Err::None);
  L.run(10);
  for (const char* type : {"tune", "test", "5", "6"}) {
    SCOPED_TRACE(type);
    EXPECT_EQ(L.r.exec(std::string("MAS(D, t, ") + type + ", no, 0, unitspersec2, no, 0, unitspersec3);"),
              Err::ParameterOutOfRange);
    EXPECT_EQ(L.r.tag("t").exerr, 2);
    EXPECT_FALSE(L.r.tag("t").dn());
  }
  L.run(1);
  EXPECT_TRUE(L.r.tag("m").ip());
  EXPECT_FALSE(L.r.axis("D").motion(motion_status::StoppingStatus));
  EXPECT_NEAR(L.r.axis("D").command_velocity, 10.0, 1e-9);
}
