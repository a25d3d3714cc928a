#pragma once
/// \file motion/instr/mdac.hpp
/// MDAC family: Motion Drive Axis Coordination links a slave's motion types
/// to a master (master-driven motion, MDSC), with queued masters
/// (motion/instr/mdac.cpp).

#include <cstddef>

#include "motion/instr/common.hpp"

namespace canmotion::motion {

struct MdacParams {
  static constexpr Instr kInstr = Instr::MDAC;
  AxisId slave = kNoAxis, master = kNoAxis;
  std::uint8_t motion_type = 0;  ///< 0 all, 1 move, 2 jog, 3 time cam, 4 master offset move
  MasterReference master_reference = MasterReference::Actual;
  static MdacParams decode(const Operands& q) noexcept;
};
using MdacInstructions = TypeList<MdacParams>;

Err start(Ctx& x, const MdacParams& p) noexcept;

namespace mdac {
/// Break every link of a slave (MAS All, MGS, MASD/MGSD, Stop Drive and
/// Shutdown faults): the MDACs' IP and AC cleared.
void break_links(Core& c, AxisRt& slave) noexcept;
/// Break the links of every slave of `master` (MASD/MGSD/shutdown of the master).
void break_links_of_master(Core& c, AxisId master) noexcept;
/// A motion of type `link` goes IP: a queued master takes over the link.
void promote_pending(Core& c, AxisRt& a, std::size_t link) noexcept;
/// Make `g` follow the master of the slave's link `link` (the queued one if
/// any): ERR 93 without a link, 97 when the slave moves but the master does
/// not; `start` becomes per master unit.
Err master_driven_setup(Core& c, AxisRt& a, std::size_t link, ProfileGen& g, Kin& start) noexcept;
}  // namespace mdac

}  // namespace canmotion::motion
