#pragma once
/// \file motion/hooks.hpp
/// The events of an axis at which instruction families act on state outside
/// the generators (drive handshakes, pending cams, direct control, drive
/// homing, MDAC links, coordinate systems). The core (core.cpp, cycle.cpp)
/// calls these hooks and knows no family; motion/instr/hooks.cpp answers each
/// by calling the families concerned, in a fixed order. Together with the
/// generator interface (motion/generator.hpp: step, on_fold) they are
/// everything the core calls of the families, so the dependency points one
/// way: families -> core. A family that needs a new event adds a hook here,
/// its call in the core and its answer in instr/hooks.cpp.
/// Every hook is noexcept, allocation-free and realtime-safe.

#include "motion/control_tag.hpp"

namespace canmotion::motion {

struct Core;        // motion/core.hpp
struct AxisRt;      // motion/core.hpp
struct AxisOutput;  // motion/io.hpp

namespace hooks {

/// Each cycle, after a CIP axis's feedback was read: the instructions that
/// wait for its drive, in this order, each only while it waits: a fault
/// reset after its pulse went out (MAFR, MASR, MGSR), MSO or MSF, MDS or the
/// MAS stopping it, drive homing (MAH). Usually none waits: the hook tests
/// each wait first, and the product's link-time optimisation inlines it into
/// the cycle.
void drive_feedback(Core& c, AxisRt& a) noexcept;

/// The output of an axis under direct control (MDS: CSV or CST) or drive
/// homing (the homing objects), over the CSP output the core wrote. Called
/// only when the axis is in one of them.
void drive_output(AxisRt& a, AxisOutput& out) noexcept;

/// The servo goes off and the generators were aborted: the pending cams
/// dropped, direct control ended, a drive homing cancelled.
void servo_off(Core& c, AxisRt& a) noexcept;

/// An exception action breaks the MDAC links of the axis as a slave (Stop
/// Planner), and with `as_master` also those of its slaves (Stop Drive).
void break_links(Core& c, AxisRt& a, bool as_master) noexcept;

/// The axis was shut down (servo off, Shutdown state set): its MDAC links
/// broken as slave and as master, the MDCC links of the coordinate systems it
/// is a member or the master of broken.
void shutdown(Core& c, AxisRt& a) noexcept;

/// A stop of all motion of the axis that reaches its coordinated slot (MAS
/// All, MGS, Stop Planner): the path of its coordinate system stops along
/// itself, for `owner`, and the slot stays. True when a path moves.
bool stop_path(Core& c, AxisRt& a, OwnerRef owner) noexcept;

/// Once per cycle, after every axis stepped: the coordinate systems' tags.
void cycle_end(Core& c) noexcept;

}  // namespace hooks
}  // namespace canmotion::motion
