#pragma once
/// \file motion/signatures.hpp
/// THE table of motion instruction signatures: operand order, names, kinds,
/// enumerations (ST keyword and number) and basic ranges. Both the ST call
/// parser (motion/st_parser.hpp) and the planner's operand validation
/// (ERR 13 with the operand index in EXERR) read it; nothing else spells out
/// an operand list. Constant data; realtime-safe.

#include <cstdint>
#include <array>
#include <optional>
#include <span>
#include <string_view>

namespace canmotion::motion {

/// Every instruction the ST parser accepts (reference scope, 26 instructions).
enum class Instr : std::uint8_t {
  MSO, MSF, MASD, MASR, MAFR, MAS, MAH, MAJ, MAM, MAG, MCD, MRP, MCCP, MAPC,
  MATC, MDAC, MDS, MGS, MGSD, MGSR, MCLM, MCCM, MCS, MCSD, MCCD, MDCC,
  Count
};
inline constexpr std::size_t kInstrCount = static_cast<std::size_t>(Instr::Count);

/// Largest operand count of any instruction (MCCM: 25).
inline constexpr std::size_t kMaxOperands = 25;

/// What an operand is in ST.
enum class OperandKind : std::uint8_t {
  Axis,         ///< axis tag name
  Control,      ///< MOTION_INSTRUCTION tag name
  Group,        ///< MOTION_GROUP tag name
  CoordSystem,  ///< COORDINATE_SYSTEM tag name
  CamArray,     ///< CAM[] element, e.g. cam1[0] (index = first point)
  CamProfile,   ///< CAM_PROFILE[] element; must be [0]
  Real,         ///< REAL immediate or numeric tag
  Int,          ///< DINT immediate or numeric tag (integral value)
  Enum,         ///< enumeration: keyword (case-insensitive) or its number
  RealArray,    ///< REAL[] tag, or the literal 0 for "none"
};

/// Basic value rule checked for every execution (ERR 13 when violated).
/// Instruction-specific conditional rules (e.g. "jerk > 0 only for S-curve")
/// are checked by the instruction's start().
enum class Range : std::uint8_t {
  Any,          ///< any finite value
  Positive,     ///< > 0
  NonNegative,  ///< >= 0
  Uint32,       ///< Int operands of type UINT32: 0 .. 4294967295 (else DINT: |v| <= 2147483647)
};

/// One enumeration entry: ST keyword (lower case, spaces removed) and number.
struct EnumEntry {
  std::string_view keyword;
  std::int32_t value;
};

/// One operand of an instruction.
struct OperandSig {
  std::string_view name;
  OperandKind kind;
  std::span<const EnumEntry> enums{};  ///< for Enum operands
  Range range = Range::Any;
  bool tag_allowed = true;  ///< Real/Int/Enum: may be given as a numeric tag
};

/// One instruction.
struct InstrSig {
  Instr id;
  std::string_view name;
  std::span<const OperandSig> operands;
  bool executable;  ///< the planner runs it (else it is parsed and rejected with ERR 75)
  /// It would start motion: refused in Program mode (ERR 24 Illegal
  /// Controller Mode). The others make an axis safe or ready, or compute.
  bool starts_motion;
};

/// THE table: constant data, in the header so that operand positions are
/// compile-time constants (operand_index, op<I>()).
namespace signature_table {
using K = OperandKind;
using E = EnumEntry;

// ------------------------------------------------------------ enumerations
// Sources: reference 1.3 (shared), 2.x (per instruction); seeds 000-004.
inline constexpr E kNoYes[] = {{"no", 0}, {"yes", 1}};
inline constexpr E kSpeedUnitsMam[] = {{"unitspersec", 0}, {"%ofmaximum", 1}, {"seconds", 3}, {"unitspermasterunit", 4}, {"masterunits", 7}};
inline constexpr E kSpeedUnitsMaj[] = {{"unitspersec", 0}, {"%ofmaximum", 1}, {"unitspermasterunit", 4}};
inline constexpr E kAccelUnitsMam[] = {{"unitspersec2", 0}, {"%ofmaximum", 1}, {"seconds", 3}, {"unitspermasterunit2", 4}, {"masterunits", 7}};
inline constexpr E kAccelUnitsMaj[] = {{"unitspersec2", 0}, {"%ofmaximum", 1}, {"unitspermasterunit2", 4}};
inline constexpr E kAccelUnits01[] = {{"unitspersec2", 0}, {"%ofmaximum", 1}};
inline constexpr E kJerkUnitsMam[] = {{"unitspersec3", 0}, {"%ofmaximum", 1}, {"%oftime", 2}, {"seconds", 3}, {"unitspermasterunit3", 4}, {"%oftimemasterdriven", 6}, {"masterunits", 7}};
inline constexpr E kJerkUnitsMaj[] = {{"unitspersec3", 0}, {"%ofmaximum", 1}, {"%oftime", 2}, {"unitspermasterunit3", 4}, {"%oftimemasterdriven", 6}};
inline constexpr E kJerkUnitsMas[] = {{"unitspersec3", 0}, {"%ofmaximum", 1}, {"%oftime", 2}};
inline constexpr E kProfile[] = {{"trapezoidal", 0}, {"scurve", 1}, {"s_curve", 1}};
inline constexpr E kMerge[] = {{"disabled", 0}, {"enabled", 1}};
inline constexpr E kMergeCoord[] = {{"disabled", 0}, {"coordinatedmotion", 1}, {"allmotion", 2}};
inline constexpr E kMergeSpeed[] = {{"programmed", 0}, {"current", 1}};
// MATC seed spells "positionforward"/"positionreverse"; the reference "...only".
inline constexpr E kLockDir[] = {{"none", 0}, {"immediateforwardonly", 1}, {"immediatereverseonly", 2}, {"positionforwardonly", 3},
                                 {"positionreverseonly", 4}, {"positionforward", 3}, {"positionreverse", 4}};
inline constexpr E kMoveType[] = {{"absolute", 0}, {"incremental", 1}, {"rotaryshortestpath", 2}, {"rotarypositive", 3},
                                  {"rotarynegative", 4}, {"absolutemasteroffset", 5}, {"incrementalmasteroffset", 6}};
inline constexpr E kCoordMoveType[] = {{"absolute", 0}, {"incremental", 1}};
inline constexpr E kJogDir[] = {{"forward", 0}, {"reverse", 1}};
inline constexpr E kCamDir[] = {{"same", 0}, {"opposite", 1}, {"reverse", 2}, {"unchanged", 3}};
inline constexpr E kStopType[] = {{"all", 0}, {"jog", 1}, {"move", 2}, {"gear", 3}, {"home", 4}, {"tune", 5}, {"test", 6},
                                  {"timecam", 7}, {"positioncam", 8}, {"masteroffsetmove", 9}, {"directcontrol", 10}};
inline constexpr E kMasterRef[] = {{"actual", 0}, {"command", 1}};
inline constexpr E kRatioFormat[] = {{"real", 0}, {"fraction_slave_master_counts", 1}, {"fractionslavemastercounts", 1}};
inline constexpr E kClutch[] = {{"enabled", 0}, {"disabled", 1}};
inline constexpr E kMcdType[] = {{"jog", 0}, {"move", 1}};
inline constexpr E kMrpType[] = {{"absolute", 0}, {"relative", 1}};
inline constexpr E kMrpSelect[] = {{"actual", 0}, {"command", 1}};
inline constexpr E kExecModeMapc[] = {{"once", 0}, {"continuous", 1}, {"persistent", 2}};
inline constexpr E kExecModeMatc[] = {{"once", 0}, {"continuous", 1}};
inline constexpr E kExecSchedMapc[] = {{"immediate", 0}, {"pending", 1}, {"forwardonly", 2}, {"reverseonly", 3}, {"bidirectional", 4}};
inline constexpr E kExecSchedMatc[] = {{"immediate", 0}, {"pending", 1}};
inline constexpr E kMasterDir[] = {{"bidirectional", 0}, {"forwardonly", 1}, {"reverseonly", 2}};
inline constexpr E kInstrMode[] = {{"timedrivenmode", 0}, {"masterdrivenmode", 1}};
inline constexpr E kMdacType[] = {{"all", 0}, {"move", 1}, {"jog", 2}, {"timecam", 3}, {"masteroffsetmove", 4}};
// MDS Speed Units: the seed (002, the specification) numbers them
// 0 = % of Maximum, 1 = Units per Sec (ICS has the reverse); the seed wins.
inline constexpr E kMdsUnits[] = {{"%ofmaximum", 0}, {"unitspersec", 1}};
inline constexpr E kMgsMode[] = {{"programmed", 0}, {"faststop", 1}, {"fastdisable", 2}};
inline constexpr E kTermType[] = {{"actualtolerance", 0}, {"nosettle", 1}, {"commandtolerance", 2}, {"nodecel", 3},
                                  {"followcontourvelocityconstrained", 4}, {"followcontourvelocityunconstrained", 5},
                                  {"commandtoleranceprogrammed", 6}};
inline constexpr E kCircleType[] = {{"via", 0}, {"center", 1}, {"radius", 2}, {"centerincremental", 3}};
inline constexpr E kCircleDir[] = {{"clockwise", 0}, {"counterclockwise", 1}, {"clockwisefull", 2}, {"counterclockwisefull", 3}};
inline constexpr E kMcsStop[] = {{"all", 0}, {"coordinatedmove", 2}, {"coordinatedtransform", 3}};
inline constexpr E kMccdType[] = {{"coordinatedmove", 1}};
inline constexpr E kMccdScope[] = {{"activemotion", 0}, {"activeandpendingmotion", 1}};
inline constexpr E kCoordSpeedUnits[] = {{"unitspersec", 0}, {"%ofmaximum", 1}, {"unitspermasterunit", 4}};

constexpr OperandSig ax(std::string_view n) { return {n, K::Axis}; }
constexpr OperandSig ctl() { return {"MotionControl", K::Control}; }
/// "Immediate" enumeration: keyword or number only.
constexpr OperandSig en(std::string_view n, std::span<const E> e) { return {n, K::Enum, e, Range::Any, false}; }
/// "Immediate or Tag" enumeration: keyword, number or numeric tag.
constexpr OperandSig ent(std::string_view n, std::span<const E> e) { return {n, K::Enum, e, Range::Any, true}; }
constexpr OperandSig real(std::string_view n, Range r = Range::Any) { return {n, K::Real, {}, r}; }
constexpr OperandSig integer(std::string_view n, Range r = Range::Any) { return {n, K::Int, {}, r}; }

inline constexpr OperandSig kAxisCtl[] = {ax("Axis"), ctl()};
inline constexpr OperandSig kGroupCtl[] = {{"Group", K::Group}, ctl()};
inline constexpr OperandSig kCsCtl[] = {{"CoordinateSystem", K::CoordSystem}, ctl()};

inline constexpr OperandSig kMas[] = {ax("Axis"), ctl(), en("StopType", kStopType), en("ChangeDecel", kNoYes),
                                      real("DecelRate"), en("DecelUnits", kAccelUnits01), en("ChangeDecelJerk", kNoYes),
                                      real("DecelJerk"), en("JerkUnits", kJerkUnitsMas)};

inline constexpr OperandSig kMaj[] = {ax("Axis"), ctl(), ent("Direction", kJogDir), real("Speed", Range::NonNegative),
                                      en("SpeedUnits", kSpeedUnitsMaj), real("AccelRate", Range::Positive),
                                      en("AccelUnits", kAccelUnitsMaj), real("DecelRate", Range::Positive),
                                      en("DecelUnits", kAccelUnitsMaj), en("Profile", kProfile), real("AccelJerk"),
                                      real("DecelJerk"), en("JerkUnits", kJerkUnitsMaj), en("Merge", kMerge),
                                      en("MergeSpeed", kMergeSpeed), real("LockPosition"), ent("LockDirection", kLockDir)};

inline constexpr OperandSig kMam[] = {ax("Axis"), ctl(), ent("MoveType", kMoveType), real("Position"),
                                      real("Speed", Range::NonNegative), en("SpeedUnits", kSpeedUnitsMam),
                                      real("AccelRate", Range::Positive), en("AccelUnits", kAccelUnitsMam),
                                      real("DecelRate", Range::Positive), en("DecelUnits", kAccelUnitsMam),
                                      en("Profile", kProfile), real("AccelJerk"), real("DecelJerk"),
                                      en("JerkUnits", kJerkUnitsMam), en("Merge", kMerge), en("MergeSpeed", kMergeSpeed),
                                      real("LockPosition"), ent("LockDirection", kLockDir),
                                      {"EventDistance", K::RealArray}, {"CalculatedData", K::RealArray}};

inline constexpr OperandSig kMag[] = {ax("SlaveAxis"), ax("MasterAxis"), ctl(), ent("Direction", kCamDir), real("Ratio"),
                                      integer("SlaveCounts", Range::Uint32), integer("MasterCounts", Range::Uint32), en("MasterReference", kMasterRef),
                                      en("RatioFormat", kRatioFormat), en("Clutch", kClutch), real("AccelRate"),
                                      en("AccelUnits", kAccelUnits01)};

inline constexpr OperandSig kMcd[] = {ax("Axis"), ctl(), en("MotionType", kMcdType), en("ChangeSpeed", kNoYes),
                                      real("Speed", Range::NonNegative), en("ChangeAccel", kNoYes), real("AccelRate"),
                                      en("ChangeDecel", kNoYes), real("DecelRate"), en("ChangeAccelJerk", kNoYes),
                                      real("AccelJerk"), en("ChangeDecelJerk", kNoYes), real("DecelJerk"),
                                      en("SpeedUnits", kSpeedUnitsMaj), en("AccelUnits", kAccelUnitsMaj),
                                      en("DecelUnits", kAccelUnitsMaj), en("JerkUnits", kJerkUnitsMaj)};

inline constexpr OperandSig kMrp[] = {ax("Axis"), ctl(), en("Type", kMrpType), en("PositionSelect", kMrpSelect), real("Position")};

inline constexpr OperandSig kMccp[] = {ctl(), {"Cam", K::CamArray}, integer("Length"), real("StartSlope"), real("EndSlope"),
                                       {"CamProfile", K::CamProfile}};

inline constexpr OperandSig kMapc[] = {ax("SlaveAxis"), ax("MasterAxis"), ctl(), ent("Direction", kCamDir),
                                       {"CamProfile", K::CamProfile}, real("SlaveScaling"), real("MasterScaling"),
                                       en("ExecutionMode", kExecModeMapc), en("ExecutionSchedule", kExecSchedMapc),
                                       real("MasterLockPosition"), real("CamLockPosition"), en("MasterReference", kMasterRef),
                                       en("MasterDirection", kMasterDir)};

inline constexpr OperandSig kMatc[] = {ax("Axis"), ctl(), ent("Direction", kCamDir), {"CamProfile", K::CamProfile},
                                       real("DistanceScaling"), real("TimeScaling"), en("ExecutionMode", kExecModeMatc),
                                       en("ExecutionSchedule", kExecSchedMatc), real("LockPosition"),
                                       ent("LockDirection", kLockDir), en("InstructionMode", kInstrMode)};

inline constexpr OperandSig kMdac[] = {ax("SlaveAxis"), ax("MasterAxis"), ctl(), ent("MotionType", kMdacType),
                                       en("MasterReference", kMasterRef)};

inline constexpr OperandSig kMds[] = {ax("Axis"), ctl(), real("Speed"), en("SpeedUnits", kMdsUnits)};

inline constexpr OperandSig kMgs[] = {{"Group", K::Group}, ctl(), en("StopMode", kMgsMode)};

inline constexpr OperandSig kMclm[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), ent("MoveType", kCoordMoveType),
                                       {"Position", K::RealArray}, real("Speed", Range::NonNegative),
                                       en("SpeedUnits", kCoordSpeedUnits), real("AccelRate", Range::Positive),
                                       en("AccelUnits", kAccelUnitsMaj), real("DecelRate", Range::Positive),
                                       en("DecelUnits", kAccelUnitsMaj), en("Profile", kProfile), real("AccelJerk"),
                                       real("DecelJerk"), en("JerkUnits", kJerkUnitsMaj), ent("TerminationType", kTermType),
                                       en("Merge", kMergeCoord), en("MergeSpeed", kMergeSpeed), real("CommandTolerance"),
                                       real("LockPosition"), ent("LockDirection", kLockDir), {"EventDistance", K::RealArray},
                                       {"CalculatedData", K::RealArray}};

inline constexpr OperandSig kMccm[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), ent("MoveType", kCoordMoveType),
                                       {"Position", K::RealArray}, ent("CircleType", kCircleType),
                                       {"Via/Center/Radius", K::RealArray}, ent("Direction", kCircleDir),
                                       real("Speed", Range::NonNegative), en("SpeedUnits", kCoordSpeedUnits),
                                       real("AccelRate", Range::Positive), en("AccelUnits", kAccelUnitsMaj),
                                       real("DecelRate", Range::Positive), en("DecelUnits", kAccelUnitsMaj),
                                       en("Profile", kProfile), real("AccelJerk"), real("DecelJerk"),
                                       en("JerkUnits", kJerkUnitsMaj), ent("TerminationType", kTermType),
                                       en("Merge", kMergeCoord), en("MergeSpeed", kMergeSpeed), real("CommandTolerance"),
                                       real("LockPosition"), ent("LockDirection", kLockDir), {"EventDistance", K::RealArray},
                                       {"CalculatedData", K::RealArray}};

inline constexpr OperandSig kMcs[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), en("StopType", kMcsStop),
                                      en("ChangeDecel", kNoYes), real("DecelRate"), en("DecelUnits", kAccelUnits01),
                                      en("ChangeDecelJerk", kNoYes), real("DecelJerk"), en("JerkUnits", kJerkUnitsMas)};

inline constexpr OperandSig kMccd[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), en("MotionType", kMccdType),
                                       en("ChangeSpeed", kNoYes), real("Speed", Range::NonNegative),
                                       en("SpeedUnits", kCoordSpeedUnits), en("ChangeAccel", kNoYes), real("AccelRate"),
                                       en("AccelUnits", kAccelUnitsMaj), en("ChangeDecel", kNoYes), real("DecelRate"),
                                       en("DecelUnits", kAccelUnitsMaj), en("ChangeAccelJerk", kNoYes), real("AccelJerk"),
                                       en("ChangeDecelJerk", kNoYes), real("DecelJerk"), en("JerkUnits", kJerkUnitsMaj),
                                       en("Scope", kMccdScope)};

inline constexpr OperandSig kMdcc[] = {{"SlaveSystem", K::CoordSystem}, ax("MasterAxis"), ctl(),
                                       en("MasterReference", kMasterRef), real("NominalMasterVelocity")};

inline constexpr std::array<InstrSig, kInstrCount> kTable{{
    {Instr::MSO, "MSO", kAxisCtl, true, false},
    {Instr::MSF, "MSF", kAxisCtl, true, false},
    {Instr::MASD, "MASD", kAxisCtl, true, false},
    {Instr::MASR, "MASR", kAxisCtl, true, false},
    {Instr::MAFR, "MAFR", kAxisCtl, true, false},
    {Instr::MAS, "MAS", kMas, true, false},
    {Instr::MAH, "MAH", kAxisCtl, true, true},
    {Instr::MAJ, "MAJ", kMaj, true, true},
    {Instr::MAM, "MAM", kMam, true, true},
    {Instr::MAG, "MAG", kMag, true, true},
    {Instr::MCD, "MCD", kMcd, true, true},
    {Instr::MRP, "MRP", kMrp, true, false},
    {Instr::MCCP, "MCCP", kMccp, true, false},
    {Instr::MAPC, "MAPC", kMapc, true, true},
    {Instr::MATC, "MATC", kMatc, true, true},
    {Instr::MDAC, "MDAC", kMdac, true, true},
    {Instr::MDS, "MDS", kMds, true, true},
    {Instr::MGS, "MGS", kMgs, true, false},
    {Instr::MGSD, "MGSD", kGroupCtl, true, false},
    {Instr::MGSR, "MGSR", kGroupCtl, true, false},
    {Instr::MCLM, "MCLM", kMclm, true, true},
    {Instr::MCCM, "MCCM", kMccm, true, true},
    {Instr::MCS, "MCS", kMcs, true, false},
    {Instr::MCSD, "MCSD", kCsCtl, true, false},
    {Instr::MCCD, "MCCD", kMccd, true, true},
    {Instr::MDCC, "MDCC", kMdcc, true, true},
}};

static_assert([] {
  for (std::size_t i = 0; i < kInstrCount; ++i)
    if (kTable[i].id != static_cast<Instr>(i)) return false;
  return true;
}(), "the signature table is indexed by Instr");
}  // namespace signature_table

/// Signature of an instruction. Realtime-safe; usable in constant expressions.
constexpr const InstrSig& signature(Instr i) noexcept { return signature_table::kTable[static_cast<std::size_t>(i)]; }
/// Find an instruction by name, case-insensitive. Realtime-safe.
std::optional<Instr> find_instruction(std::string_view name) noexcept;
/// Keyword lookup in an enumeration, case-insensitive. Realtime-safe.
std::optional<std::int32_t> find_keyword(std::span<const EnumEntry> e, std::string_view kw) noexcept;
/// True if `v` is one of the enumeration's numbers. Realtime-safe.
bool enum_contains(std::span<const EnumEntry> e, std::int32_t v) noexcept;
/// Index of the operand called `name` in instruction `i` (ST position; -1 if
/// absent). Realtime-safe; usable in constant expressions.
constexpr int operand_index(Instr i, std::string_view name) noexcept {
  const auto ops = signature(i).operands;
  for (std::size_t k = 0; k < ops.size(); ++k)
    if (ops[k].name == name) return static_cast<int>(k);
  return -1;
}

/// Index of operand `name` of instruction `I`, at compile time: a name that
/// is not in the table is a compile error. The planner's EXERR values and
/// typed params come from here, e.g. `op<Instr::MAM>("Speed")` (4).
template <Instr I>
consteval int op(std::string_view name) {
  const int k = operand_index(I, name);
  if (k < 0) throw "op<I>(name): no operand of that name in the signature table";
  return k;
}

/// Result of checking one operand value against the table.
struct OperandCheck {
  bool ok = true;
  int index = -1;  ///< first offending operand (ST index, = EXERR for ERR 13)
};
/// Check numeric operand values (indexed by ST operand position; non-numeric
/// operands are skipped) against enumerations and ranges. Realtime-safe.
OperandCheck check_operands(Instr i, std::span<const double> values) noexcept;

}  // namespace canmotion::motion
