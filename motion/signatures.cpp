#include "motion/signatures.hpp"

#include <array>
#include <cmath>

namespace canmotion::motion {
namespace {

using K = OperandKind;
using E = EnumEntry;

// ------------------------------------------------------------ enumerations
// Sources: reference 1.3 (shared), 2.x (per instruction); seeds 000-004.
constexpr E kNoYes[] = {{"no", 0}, {"yes", 1}};
constexpr E kSpeedUnitsMam[] = {{"unitspersec", 0}, {"%ofmaximum", 1}, {"seconds", 3}, {"unitspermasterunit", 4}, {"masterunits", 7}};
constexpr E kSpeedUnitsMaj[] = {{"unitspersec", 0}, {"%ofmaximum", 1}, {"unitspermasterunit", 4}};
constexpr E kAccelUnitsMam[] = {{"unitspersec2", 0}, {"%ofmaximum", 1}, {"seconds", 3}, {"unitspermasterunit2", 4}, {"masterunits", 7}};
constexpr E kAccelUnitsMaj[] = {{"unitspersec2", 0}, {"%ofmaximum", 1}, {"unitspermasterunit2", 4}};
constexpr E kAccelUnits01[] = {{"unitspersec2", 0}, {"%ofmaximum", 1}};
constexpr E kJerkUnitsMam[] = {{"unitspersec3", 0}, {"%ofmaximum", 1}, {"%oftime", 2}, {"seconds", 3}, {"unitspermasterunit3", 4}, {"%oftimemasterdriven", 6}, {"masterunits", 7}};
constexpr E kJerkUnitsMaj[] = {{"unitspersec3", 0}, {"%ofmaximum", 1}, {"%oftime", 2}, {"unitspermasterunit3", 4}, {"%oftimemasterdriven", 6}};
constexpr E kJerkUnitsMas[] = {{"unitspersec3", 0}, {"%ofmaximum", 1}, {"%oftime", 2}};
constexpr E kProfile[] = {{"trapezoidal", 0}, {"scurve", 1}, {"s_curve", 1}};
constexpr E kMerge[] = {{"disabled", 0}, {"enabled", 1}};
constexpr E kMergeCoord[] = {{"disabled", 0}, {"coordinatedmotion", 1}, {"allmotion", 2}};
constexpr E kMergeSpeed[] = {{"programmed", 0}, {"current", 1}};
// MATC seed spells "positionforward"/"positionreverse"; the reference "...only".
constexpr E kLockDir[] = {{"none", 0}, {"immediateforwardonly", 1}, {"immediatereverseonly", 2}, {"positionforwardonly", 3},
                          {"positionreverseonly", 4}, {"positionforward", 3}, {"positionreverse", 4}};
constexpr E kMoveType[] = {{"absolute", 0}, {"incremental", 1}, {"rotaryshortestpath", 2}, {"rotarypositive", 3},
                           {"rotarynegative", 4}, {"absolutemasteroffset", 5}, {"incrementalmasteroffset", 6}};
constexpr E kCoordMoveType[] = {{"absolute", 0}, {"incremental", 1}};
constexpr E kJogDir[] = {{"forward", 0}, {"reverse", 1}};
constexpr E kCamDir[] = {{"same", 0}, {"opposite", 1}, {"reverse", 2}, {"unchanged", 3}};
constexpr E kStopType[] = {{"all", 0}, {"jog", 1}, {"move", 2}, {"gear", 3}, {"home", 4}, {"tune", 5}, {"test", 6},
                           {"timecam", 7}, {"positioncam", 8}, {"masteroffsetmove", 9}, {"directcontrol", 10}};
constexpr E kMasterRef[] = {{"actual", 0}, {"command", 1}};
constexpr E kRatioFormat[] = {{"real", 0}, {"fraction_slave_master_counts", 1}, {"fractionslavemastercounts", 1}};
constexpr E kClutch[] = {{"enabled", 0}, {"disabled", 1}};
constexpr E kMcdType[] = {{"jog", 0}, {"move", 1}};
constexpr E kMrpType[] = {{"absolute", 0}, {"relative", 1}};
constexpr E kMrpSelect[] = {{"actual", 0}, {"command", 1}};
constexpr E kExecModeMapc[] = {{"once", 0}, {"continuous", 1}, {"persistent", 2}};
constexpr E kExecModeMatc[] = {{"once", 0}, {"continuous", 1}};
constexpr E kExecSchedMapc[] = {{"immediate", 0}, {"pending", 1}, {"forwardonly", 2}, {"reverseonly", 3}, {"bidirectional", 4}};
constexpr E kExecSchedMatc[] = {{"immediate", 0}, {"pending", 1}};
constexpr E kMasterDir[] = {{"bidirectional", 0}, {"forwardonly", 1}, {"reverseonly", 2}};
constexpr E kInstrMode[] = {{"timedrivenmode", 0}, {"masterdrivenmode", 1}};
constexpr E kMdacType[] = {{"all", 0}, {"move", 1}, {"jog", 2}, {"timecam", 3}, {"masteroffsetmove", 4}};
// MDS Speed Units: the seed (002, the specification) numbers them
// 0 = % of Maximum, 1 = Units per Sec (ICS has the reverse); the seed wins.
constexpr E kMdsUnits[] = {{"%ofmaximum", 0}, {"unitspersec", 1}};
constexpr E kMgsMode[] = {{"programmed", 0}, {"faststop", 1}, {"fastdisable", 2}};
constexpr E kTermType[] = {{"actualtolerance", 0}, {"nosettle", 1}, {"commandtolerance", 2}, {"nodecel", 3},
                           {"followcontourvelocityconstrained", 4}, {"followcontourvelocityunconstrained", 5},
                           {"commandtoleranceprogrammed", 6}};
constexpr E kCircleType[] = {{"via", 0}, {"center", 1}, {"radius", 2}, {"centerincremental", 3}};
constexpr E kCircleDir[] = {{"clockwise", 0}, {"counterclockwise", 1}, {"clockwisefull", 2}, {"counterclockwisefull", 3}};
constexpr E kMcsStop[] = {{"all", 0}, {"coordinatedmove", 2}, {"coordinatedtransform", 3}};
constexpr E kMccdType[] = {{"coordinatedmove", 1}};
constexpr E kMccdScope[] = {{"activemotion", 0}, {"activeandpendingmotion", 1}};
constexpr E kCoordSpeedUnits[] = {{"unitspersec", 0}, {"%ofmaximum", 1}, {"unitspermasterunit", 4}};

constexpr OperandSig ax(std::string_view n) { return {n, K::Axis}; }
constexpr OperandSig ctl() { return {"MotionControl", K::Control}; }
/// "Immediate" enumeration: keyword or number only.
constexpr OperandSig en(std::string_view n, std::span<const E> e) { return {n, K::Enum, e, Range::Any, false}; }
/// "Immediate or Tag" enumeration: keyword, number or numeric tag.
constexpr OperandSig ent(std::string_view n, std::span<const E> e) { return {n, K::Enum, e, Range::Any, true}; }
constexpr OperandSig real(std::string_view n, Range r = Range::Any) { return {n, K::Real, {}, r}; }
constexpr OperandSig integer(std::string_view n, Range r = Range::Any) { return {n, K::Int, {}, r}; }

constexpr OperandSig kAxisCtl[] = {ax("Axis"), ctl()};
constexpr OperandSig kGroupCtl[] = {{"Group", K::Group}, ctl()};
constexpr OperandSig kCsCtl[] = {{"CoordinateSystem", K::CoordSystem}, ctl()};

constexpr OperandSig kMas[] = {ax("Axis"), ctl(), en("StopType", kStopType), en("ChangeDecel", kNoYes),
                               real("DecelRate"), en("DecelUnits", kAccelUnits01), en("ChangeDecelJerk", kNoYes),
                               real("DecelJerk"), en("JerkUnits", kJerkUnitsMas)};

constexpr OperandSig kMaj[] = {ax("Axis"), ctl(), ent("Direction", kJogDir), real("Speed", Range::NonNegative),
                               en("SpeedUnits", kSpeedUnitsMaj), real("AccelRate", Range::Positive),
                               en("AccelUnits", kAccelUnitsMaj), real("DecelRate", Range::Positive),
                               en("DecelUnits", kAccelUnitsMaj), en("Profile", kProfile), real("AccelJerk"),
                               real("DecelJerk"), en("JerkUnits", kJerkUnitsMaj), en("Merge", kMerge),
                               en("MergeSpeed", kMergeSpeed), real("LockPosition"), ent("LockDirection", kLockDir)};

constexpr OperandSig kMam[] = {ax("Axis"), ctl(), ent("MoveType", kMoveType), real("Position"),
                               real("Speed", Range::NonNegative), en("SpeedUnits", kSpeedUnitsMam),
                               real("AccelRate", Range::Positive), en("AccelUnits", kAccelUnitsMam),
                               real("DecelRate", Range::Positive), en("DecelUnits", kAccelUnitsMam),
                               en("Profile", kProfile), real("AccelJerk"), real("DecelJerk"),
                               en("JerkUnits", kJerkUnitsMam), en("Merge", kMerge), en("MergeSpeed", kMergeSpeed),
                               real("LockPosition"), ent("LockDirection", kLockDir),
                               {"EventDistance", K::RealArray}, {"CalculatedData", K::RealArray}};

constexpr OperandSig kMag[] = {ax("SlaveAxis"), ax("MasterAxis"), ctl(), ent("Direction", kCamDir), real("Ratio"),
                               integer("SlaveCounts"), integer("MasterCounts"), en("MasterReference", kMasterRef),
                               en("RatioFormat", kRatioFormat), en("Clutch", kClutch), real("AccelRate"),
                               en("AccelUnits", kAccelUnits01)};

constexpr OperandSig kMcd[] = {ax("Axis"), ctl(), en("MotionType", kMcdType), en("ChangeSpeed", kNoYes),
                               real("Speed", Range::NonNegative), en("ChangeAccel", kNoYes), real("AccelRate"),
                               en("ChangeDecel", kNoYes), real("DecelRate"), en("ChangeAccelJerk", kNoYes),
                               real("AccelJerk"), en("ChangeDecelJerk", kNoYes), real("DecelJerk"),
                               en("SpeedUnits", kSpeedUnitsMaj), en("AccelUnits", kAccelUnitsMaj),
                               en("DecelUnits", kAccelUnitsMaj), en("JerkUnits", kJerkUnitsMaj)};

constexpr OperandSig kMrp[] = {ax("Axis"), ctl(), en("Type", kMrpType), en("PositionSelect", kMrpSelect), real("Position")};

constexpr OperandSig kMccp[] = {ctl(), {"Cam", K::CamArray}, integer("Length"), real("StartSlope"), real("EndSlope"),
                                {"CamProfile", K::CamProfile}};

constexpr OperandSig kMapc[] = {ax("SlaveAxis"), ax("MasterAxis"), ctl(), ent("Direction", kCamDir),
                                {"CamProfile", K::CamProfile}, real("SlaveScaling"), real("MasterScaling"),
                                en("ExecutionMode", kExecModeMapc), en("ExecutionSchedule", kExecSchedMapc),
                                real("MasterLockPosition"), real("CamLockPosition"), en("MasterReference", kMasterRef),
                                en("MasterDirection", kMasterDir)};

constexpr OperandSig kMatc[] = {ax("Axis"), ctl(), ent("Direction", kCamDir), {"CamProfile", K::CamProfile},
                                real("DistanceScaling"), real("TimeScaling"), en("ExecutionMode", kExecModeMatc),
                                en("ExecutionSchedule", kExecSchedMatc), real("LockPosition"),
                                ent("LockDirection", kLockDir), en("InstructionMode", kInstrMode)};

constexpr OperandSig kMdac[] = {ax("SlaveAxis"), ax("MasterAxis"), ctl(), ent("MotionType", kMdacType),
                                en("MasterReference", kMasterRef)};

constexpr OperandSig kMds[] = {ax("Axis"), ctl(), real("Speed"), en("SpeedUnits", kMdsUnits)};

constexpr OperandSig kMgs[] = {{"Group", K::Group}, ctl(), en("StopMode", kMgsMode)};

constexpr OperandSig kMclm[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), ent("MoveType", kCoordMoveType),
                                {"Position", K::RealArray}, real("Speed", Range::NonNegative),
                                en("SpeedUnits", kCoordSpeedUnits), real("AccelRate", Range::Positive),
                                en("AccelUnits", kAccelUnitsMaj), real("DecelRate", Range::Positive),
                                en("DecelUnits", kAccelUnitsMaj), en("Profile", kProfile), real("AccelJerk"),
                                real("DecelJerk"), en("JerkUnits", kJerkUnitsMaj), ent("TerminationType", kTermType),
                                en("Merge", kMergeCoord), en("MergeSpeed", kMergeSpeed), real("CommandTolerance"),
                                real("LockPosition"), ent("LockDirection", kLockDir), {"EventDistance", K::RealArray},
                                {"CalculatedData", K::RealArray}};

constexpr OperandSig kMccm[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), ent("MoveType", kCoordMoveType),
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

constexpr OperandSig kMcs[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), en("StopType", kMcsStop),
                               en("ChangeDecel", kNoYes), real("DecelRate"), en("DecelUnits", kAccelUnits01),
                               en("ChangeDecelJerk", kNoYes), real("DecelJerk"), en("JerkUnits", kJerkUnitsMas)};

constexpr OperandSig kMccd[] = {{"CoordinateSystem", K::CoordSystem}, ctl(), en("MotionType", kMccdType),
                                en("ChangeSpeed", kNoYes), real("Speed", Range::NonNegative),
                                en("SpeedUnits", kCoordSpeedUnits), en("ChangeAccel", kNoYes), real("AccelRate"),
                                en("AccelUnits", kAccelUnitsMaj), en("ChangeDecel", kNoYes), real("DecelRate"),
                                en("DecelUnits", kAccelUnitsMaj), en("ChangeAccelJerk", kNoYes), real("AccelJerk"),
                                en("ChangeDecelJerk", kNoYes), real("DecelJerk"), en("JerkUnits", kJerkUnitsMaj),
                                en("Scope", kMccdScope)};

constexpr OperandSig kMdcc[] = {{"SlaveSystem", K::CoordSystem}, ax("MasterAxis"), ctl(),
                                en("MasterReference", kMasterRef), real("NominalMasterVelocity")};

constexpr std::array<InstrSig, kInstrCount> kTable{{
    {Instr::MSO, "MSO", kAxisCtl, true},
    {Instr::MSF, "MSF", kAxisCtl, true},
    {Instr::MASD, "MASD", kAxisCtl, true},
    {Instr::MASR, "MASR", kAxisCtl, true},
    {Instr::MAFR, "MAFR", kAxisCtl, true},
    {Instr::MAS, "MAS", kMas, true},
    {Instr::MAH, "MAH", kAxisCtl, true},
    {Instr::MAJ, "MAJ", kMaj, true},
    {Instr::MAM, "MAM", kMam, true},
    {Instr::MAG, "MAG", kMag, true},
    {Instr::MCD, "MCD", kMcd, true},
    {Instr::MRP, "MRP", kMrp, true},
    {Instr::MCCP, "MCCP", kMccp, true},
    {Instr::MAPC, "MAPC", kMapc, true},
    {Instr::MATC, "MATC", kMatc, true},
    {Instr::MDAC, "MDAC", kMdac, true},
    {Instr::MDS, "MDS", kMds, true},
    {Instr::MGS, "MGS", kMgs, true},
    {Instr::MGSD, "MGSD", kGroupCtl, true},
    {Instr::MGSR, "MGSR", kGroupCtl, true},
    {Instr::MCLM, "MCLM", kMclm, false},
    {Instr::MCCM, "MCCM", kMccm, false},
    {Instr::MCS, "MCS", kMcs, false},
    {Instr::MCSD, "MCSD", kCsCtl, false},
    {Instr::MCCD, "MCCD", kMccd, false},
    {Instr::MDCC, "MDCC", kMdcc, false},
}};

constexpr char lower(char c) noexcept { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool iequal(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

}  // namespace

const InstrSig& signature(Instr i) noexcept { return kTable[static_cast<std::size_t>(i)]; }

std::optional<Instr> find_instruction(std::string_view name) noexcept {
  for (const auto& s : kTable)
    if (iequal(s.name, name)) return s.id;
  return std::nullopt;
}

std::optional<std::int32_t> find_keyword(std::span<const EnumEntry> e, std::string_view kw) noexcept {
  for (const auto& x : e)
    if (iequal(x.keyword, kw)) return x.value;
  return std::nullopt;
}

bool enum_contains(std::span<const EnumEntry> e, std::int32_t v) noexcept {
  for (const auto& x : e)
    if (x.value == v) return true;
  return false;
}

int operand_index(Instr i, std::string_view name) noexcept {
  const auto ops = signature(i).operands;
  for (std::size_t k = 0; k < ops.size(); ++k)
    if (ops[k].name == name) return static_cast<int>(k);
  return -1;
}

OperandCheck check_operands(Instr i, std::span<const double> values) noexcept {
  const auto ops = signature(i).operands;
  for (std::size_t k = 0; k < ops.size() && k < values.size(); ++k) {
    const OperandSig& o = ops[k];
    const double v = values[k];
    bool ok = true;
    switch (o.kind) {
      case K::Real:
        ok = std::isfinite(v) && (o.range != Range::Positive || v > 0) && (o.range != Range::NonNegative || v >= 0);
        break;
      case K::Int:
        ok = std::isfinite(v) && v == std::floor(v) && std::fabs(v) <= 2147483647.0 &&
             (o.range != Range::Positive || v > 0) && (o.range != Range::NonNegative || v >= 0);
        break;
      case K::Enum:
        ok = std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e9 &&
             enum_contains(o.enums, static_cast<std::int32_t>(v));
        break;
      default:
        break;
    }
    if (!ok) return OperandCheck{false, static_cast<int>(k)};
  }
  return OperandCheck{};
}

}  // namespace canmotion::motion
