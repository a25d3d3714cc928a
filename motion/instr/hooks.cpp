// The families' answers to the core's hooks (motion/hooks.hpp): which
// family acts at each event of an axis, in which order. The only file that
// joins the core's events to the families; the core includes none of them.
// Realtime-safe, allocation-free.
#include "motion/hooks.hpp"

#include "motion/core.hpp"
#include "motion/instr/coord.hpp"
#include "motion/instr/direct.hpp"
#include "motion/instr/home.hpp"
#include "motion/instr/mdac.hpp"
#include "motion/instr/position_cam.hpp"
#include "motion/instr/servo.hpp"
#include "motion/instr/time_cam.hpp"

namespace canmotion::motion::hooks {

void drive_feedback(Core& c, AxisRt& a) noexcept {
  if (a.servo.reset.valid() && !a.servo.fault_reset_pulse) servo::reset_feedback(c, a);  // MAFR, MASR, MGSR
  if (a.hs.mso.valid() || a.hs.msf.valid()) servo::feedback(c, a);
  if (a.direct.waiting || a.direct.stop.valid()) direct::feedback(c, a);  // MDS, its MAS
  if (a.hs.homing) home::feedback(c, a);                                    // MAH on the drive
}

void drive_output(AxisRt& a, AxisOutput& out) noexcept {
  if (a.direct.status) direct::output(a, out);  // MDS: CSV or CST
  if (a.hs.homing) home::output(a, out);        // MAH: mode 6 and the homing objects
}

void servo_off(Core& c, AxisRt& a) noexcept {
  time_cam::drop_pending(c, a);
  position_cam::drop_pending(c, a);
  direct::end(c, a, false);
  if (a.hs.homing) home::cancel(c, a);
}

void break_links(Core& c, AxisRt& a, bool as_master) noexcept {
  mdac::break_links(c, a);                                    // an axis fault breaks the MDAC link [seed 000] ...
  if (as_master) mdac::break_links_of_master(c, c.id_of(a));  // ... of the master too when it is faulted
}

void shutdown(Core& c, AxisRt& a) noexcept {
  mdac::break_links(c, a);                        // MASD/MGSD on a slave ...
  mdac::break_links_of_master(c, c.id_of(a));     // ... and on a master
  coordsys::on_shutdown(c, c.id_of(a));           // MDCC links: as a member and as a master
}

bool stop_path(Core& c, AxisRt& a, OwnerRef owner) noexcept { return coordsys::stop_member_path(c, a, owner); }

void cycle_end(Core& c) noexcept { coordsys::update_tags(c); }

}  // namespace canmotion::motion::hooks
