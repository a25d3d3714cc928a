// ST call parser tests: every signature of the table, wrong counts, unknown
// keywords, out-of-range values, literals, tags and binding.
#include <gtest/gtest.h>

#include <cctype>
#include <string>

#include "motion/instructions.hpp"
#include "motion/st_parser.hpp"

using namespace canmotion::motion;

namespace {

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

/// A valid call for any instruction, built from the table. `variant` picks
/// which enumeration entry (keyword or number) each Enum operand uses.
std::string valid_call(Instr i, int variant, bool numeric_enums, bool upper_case) {
  const InstrSig& s = signature(i);
  std::string t = std::string(s.name) + "(";
  for (std::size_t k = 0; k < s.operands.size(); ++k) {
    const OperandSig& o = s.operands[k];
    if (k) t += ", ";
    switch (o.kind) {
      case OperandKind::Axis: t += k == 0 ? "Ax1" : "Ax2"; break;
      case OperandKind::Control: t += "ctl"; break;
      case OperandKind::Group: t += "grp"; break;
      case OperandKind::CoordSystem: t += "cs1"; break;
      case OperandKind::CamArray: t += "cam1[2]"; break;
      case OperandKind::CamProfile: t += "prof[0]"; break;
      case OperandKind::Real: t += variant % 2 ? "1.5e1" : "10"; break;
      case OperandKind::Int: t += "3"; break;
      case OperandKind::RealArray: t += variant % 2 ? "arr" : "0"; break;
      case OperandKind::Enum: {
        const auto& e = o.enums[static_cast<std::size_t>(variant) % o.enums.size()];
        std::string kw(e.keyword);
        t += numeric_enums ? std::to_string(e.value) : (upper_case ? upper(kw) : kw);
        break;
      }
    }
  }
  return t + ");";
}

Symbols syms() {
  Symbols s;
  s.axes["ax1"] = 0;
  s.axes["Ax2"] = 1;
  s.controls["ctl"] = 5;
  s.groups["grp"] = 0;
  s.coordinate_systems["cs1"] = 0;
  s.cams["cam1"] = 3;
  s.cam_profiles["prof"] = 4;
  s.real_arrays["arr"] = 1;
  s.numeric_tags["speedTag"] = 42.5;
  s.numeric_tags["table[3]"] = 7;
  return s;
}

}  // namespace

TEST(Parser, EverySignatureParsesWithKeywordsNumbersAndAnyCase) {
  const Symbols sym = syms();
  for (std::size_t i = 0; i < kInstrCount; ++i) {
    const Instr in = static_cast<Instr>(i);
    const InstrSig& s = signature(in);
    std::size_t max_enum = 1;
    for (const auto& o : s.operands)
      if (o.kind == OperandKind::Enum) max_enum = std::max(max_enum, o.enums.size());
    for (int v = 0; v < static_cast<int>(max_enum); ++v) {
      for (int mode = 0; mode < 3; ++mode) {
        const std::string text = valid_call(in, v, mode == 1, mode == 2);
        SCOPED_TRACE(text);
        const ParseResult r = parse_st_call(text);
        ASSERT_TRUE(r.ok()) << r.error.message;
        EXPECT_EQ(r.call->instr, in);
        ASSERT_EQ(r.call->operands.size(), s.operands.size());
        Request q;
        const auto e = bind_call(*r.call, sym, q);
        ASSERT_FALSE(e.has_value()) << *e;
        EXPECT_EQ(q.count, s.operands.size());
        // enumerations arrive as their numbers, whatever the spelling
        for (std::size_t k = 0; k < s.operands.size(); ++k) {
          if (s.operands[k].kind == OperandKind::Enum) {
            EXPECT_EQ(q.op[k].value, s.operands[k].enums[static_cast<std::size_t>(v) % s.operands[k].enums.size()].value);
          }
        }
      }
    }
  }
}

TEST(Parser, TheIssueExample) {
  const ParseResult r = parse_st_call(
      "MAM(X, mam1, 0, 100, 50, unitspersec, 500, unitspersec2, 500, unitspersec2, trapezoidal, 100, 100, %oftime, "
      "disabled, 0, 0, 0, 0, 0);");
  ASSERT_TRUE(r.ok()) << r.error.message;
  EXPECT_EQ(r.call->operands[13].number, 2);  // %oftime
  EXPECT_EQ(r.call->operands[17].kind, StOperand::Kind::Number);  // LockDirection given as 0
}

TEST(Parser, OperandCountErrorsNameTheSignature) {
  const ParseResult r = parse_st_call("MAS(X, mas1, all, no, 0, unitspersec2, no, 0);");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error.message.find("MAS expects 9 operands, found 8"), std::string::npos) << r.error.message;
  EXPECT_NE(r.error.message.find("JerkUnits"), std::string::npos);
  const ParseResult r2 = parse_st_call("MSO(X, a, b);");
  ASSERT_FALSE(r2.ok());
  EXPECT_NE(r2.error.message.find("MSO expects 2 operands, found 3"), std::string::npos);
  EXPECT_FALSE(parse_st_call("MSO();").ok());
}

TEST(Parser, UnknownKeywordNamesInstructionOperandFoundAndAllowed) {
  const ParseResult r = parse_st_call("MAS(X, mas1, sideways, no, 0, unitspersec2, no, 0, unitspersec3);");
  ASSERT_FALSE(r.ok());
  const std::string& m = r.error.message;
  EXPECT_NE(m.find("MAS operand 2 (StopType)"), std::string::npos) << m;
  EXPECT_NE(m.find("unknown keyword 'sideways'"), std::string::npos) << m;
  EXPECT_NE(m.find("all (0)"), std::string::npos) << m;
  EXPECT_NE(m.find("directcontrol (10)"), std::string::npos) << m;
  EXPECT_EQ(r.error.column, 14u);
}

TEST(Parser, OutOfRangeEnumNumbersAndWrongLiteralKinds) {
  {
    const ParseResult r = parse_st_call("MAS(X, m, 11, no, 0, unitspersec2, no, 0, unitspersec3);");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error.message.find("value 11 is out of range"), std::string::npos) << r.error.message;
  }
  {
    const ParseResult r = parse_st_call("MAS(X, m, 1.5, no, 0, unitspersec2, no, 0, unitspersec3);");
    ASSERT_FALSE(r.ok());
  }
  {  // MAJ has no seconds speed units
    const ParseResult r = parse_st_call("MAJ(X,j,0,5,seconds,1,unitspersec2,1,unitspersec2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none);");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error.message.find("MAJ operand 4 (SpeedUnits)"), std::string::npos) << r.error.message;
  }
  {  // Int operand given a real literal
    const ParseResult r = parse_st_call("MAG(S, M, g, same, 1, 1.5, 3, actual, real, disabled, 0, unitspersec2);");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error.message.find("MAG operand 5 (SlaveCounts): expected an integer"), std::string::npos) << r.error.message;
  }
  {  // axis operand given a number
    const ParseResult r = parse_st_call("MSO(3, m);");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error.message.find("MSO operand 0 (Axis): expected an axis tag name, found number 3"), std::string::npos)
        << r.error.message;
  }
  {  // cam profile must be [0]
    const ParseResult r = parse_st_call("MATC(X, t, same, prof[1], 1, 1, once, immediate, 0, none, timedrivenmode);");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error.message.find("only element [0]"), std::string::npos) << r.error.message;
  }
  {  // Immediate-only enumeration does not accept a tag
    const ParseResult r = parse_st_call("MDS(X, m, 10, myunits);");
    ASSERT_FALSE(r.ok());
  }
}

TEST(Parser, SyntaxErrors) {
  EXPECT_FALSE(parse_st_call("").ok());
  EXPECT_FALSE(parse_st_call("MSO X, m;").ok());
  EXPECT_FALSE(parse_st_call("MSO(X, m").ok());
  EXPECT_FALSE(parse_st_call("MSO(X m);").ok());
  EXPECT_FALSE(parse_st_call("MSO(X, m); extra").ok());
  EXPECT_FALSE(parse_st_call("MSO(X, #);").ok());
  const ParseResult u = parse_st_call("MOVE(X, m);");
  ASSERT_FALSE(u.ok());
  EXPECT_NE(u.error.message.find("unknown instruction 'MOVE'"), std::string::npos);
  EXPECT_NE(u.error.message.find("MAM"), std::string::npos);
}

TEST(Parser, LiteralsCommentsAndTags) {
  const Symbols sym = syms();
  Request q;
  const auto e = parse_and_bind(
      "(* jog *) maj(AX1, CTL, reverse, speedTag, UnitsPerSec, 1_000, unitspersec2, 2.5e2, unitspersec2, SCurve, "
      "table[3], 100, %OfTime, Disabled, Programmed, -0.5, None) // comment",
      sym, q);
  ASSERT_FALSE(e.has_value()) << *e;
  EXPECT_EQ(q.instr, Instr::MAJ);
  EXPECT_EQ(q.control, 5);
  EXPECT_EQ(q.op[0].ref, 0);
  EXPECT_EQ(q.op[2].value, 1);
  EXPECT_EQ(q.op[3].value, 42.5);
  EXPECT_EQ(q.op[5].value, 1000);
  EXPECT_EQ(q.op[7].value, 250);
  EXPECT_EQ(q.op[9].value, 1);
  EXPECT_EQ(q.op[10].value, 7);
  EXPECT_EQ(q.op[15].value, -0.5);
}

TEST(Parser, BindErrorsNameTheOperand) {
  const Symbols sym = syms();
  Request q;
  auto e = parse_and_bind("MSO(Nope, ctl);", sym, q);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(*e, "MSO operand 0 (Axis): unknown axis 'Nope'");
  e = parse_and_bind("MSO(ax1, nope);", sym, q);
  ASSERT_TRUE(e.has_value());
  EXPECT_NE(e->find("unknown MOTION_INSTRUCTION tag 'nope'"), std::string::npos);
  e = parse_and_bind("MAJ(ax1,ctl,0,missing,unitspersec,1,unitspersec2,1,unitspersec2,trapezoidal,0,0,unitspersec3,disabled,programmed,0,none);", sym, q);
  ASSERT_TRUE(e.has_value());
  EXPECT_NE(e->find("MAJ operand 3 (Speed): unknown numeric tag 'missing'"), std::string::npos) << *e;
}

TEST(Signatures, OperandCountsMatchTheReference) {
  const std::pair<Instr, std::size_t> counts[] = {
      {Instr::MSO, 2},  {Instr::MSF, 2},   {Instr::MASD, 2}, {Instr::MASR, 2},  {Instr::MAFR, 2}, {Instr::MAS, 9},
      {Instr::MAH, 2},  {Instr::MAJ, 17},  {Instr::MAM, 20}, {Instr::MAG, 12},  {Instr::MCD, 17}, {Instr::MRP, 5},
      {Instr::MCCP, 6}, {Instr::MAPC, 13}, {Instr::MATC, 11}, {Instr::MDAC, 5}, {Instr::MDS, 4},  {Instr::MGS, 3},
      {Instr::MGSD, 2}, {Instr::MGSR, 2},  {Instr::MCLM, 22}, {Instr::MCCM, 25}, {Instr::MCS, 9}, {Instr::MCSD, 2},
      {Instr::MCCD, 18}, {Instr::MDCC, 5}};
  for (const auto& [i, n] : counts) EXPECT_EQ(signature(i).operands.size(), n) << signature(i).name;
  EXPECT_EQ(operand_index(Instr::MATC, "TimeScaling"), 5);  // the seed's EXERR example
  EXPECT_EQ(operand_index(Instr::MAS, "DecelRate"), 4);
}

TEST(Signatures, CheckOperandsGivesTheOperandIndex) {
  std::array<double, 9> v{0, 0, 0, 0, 1, 0, 0, 1, 0};
  EXPECT_TRUE(check_operands(Instr::MAS, v).ok);
  v[2] = 12;  // StopType out of range
  const auto c = check_operands(Instr::MAS, v);
  EXPECT_FALSE(c.ok);
  EXPECT_EQ(c.index, 2);
}

TEST(Decode, TypedParamsFromTheBoundRequest) {
  const Symbols sym = syms();
  Request q;
  ASSERT_FALSE(parse_and_bind("MAM(ax1, ctl, rotarynegative, 12.5, 30, %ofmaximum, 400, unitspersec2, 300, "
                              "unitspersec2, scurve, 60, 40, %oftime, enabled, current, 0, none, arr, 0);",
                              sym, q));
  const Params p = decode(q);
  ASSERT_TRUE(std::holds_alternative<MamParams>(p));
  const auto& m = std::get<MamParams>(p);
  EXPECT_EQ(m.axis, 0);
  EXPECT_EQ(m.move_type, MoveType::RotaryNegative);
  EXPECT_EQ(m.position, 12.5);
  EXPECT_EQ(m.dyn.speed, 30);
  EXPECT_EQ(m.dyn.speed_units, 1);
  EXPECT_EQ(m.dyn.accel, 400);
  EXPECT_EQ(m.dyn.decel, 300);
  EXPECT_EQ(m.dyn.profile, ProfileType::SCurve);
  EXPECT_EQ(m.dyn.accel_jerk, 60);
  EXPECT_EQ(m.dyn.decel_jerk, 40);
  EXPECT_EQ(m.dyn.jerk_units, 2);
  EXPECT_EQ(m.dyn.merge, Merge::Enabled);
  EXPECT_EQ(m.dyn.merge_speed, MergeSpeed::Current);
  EXPECT_EQ(m.dyn.at.speed, 4);  // the rate operands' positions (EXERR) come with them
  EXPECT_EQ(m.dyn.at.accel, 6);
  EXPECT_EQ(m.dyn.at.jerk_units, 13);
  EXPECT_EQ(m.event_distance, 1);
  EXPECT_EQ(m.calculated_data, 0xFFFF);
  ASSERT_FALSE(parse_and_bind("MAG(ax1, Ax2, ctl, reverse, 0.5, 1, 3, command, fraction_slave_master_counts, enabled, 20, %ofmaximum);", sym, q));
  const auto g = std::get<MagParams>(decode(q));
  EXPECT_EQ(g.slave, 0);
  EXPECT_EQ(g.master, 1);
  EXPECT_EQ(g.direction, CamDirection::Reverse);
  EXPECT_TRUE(g.fractional);
  EXPECT_TRUE(g.clutch);
  EXPECT_EQ(g.master_counts, 3);
  EXPECT_EQ(g.accel_units, 1);
  ASSERT_FALSE(parse_and_bind("MDS(ax1, ctl, 10, unitspersec);", sym, q));
  EXPECT_FALSE(std::get<MdsParams>(decode(q)).percent_of_maximum);  // seed numbering: unitspersec = 1
  ASSERT_FALSE(parse_and_bind("MATC(ax1, ctl, same, prof[0], 2, 3, continuous, pending, 0, immediateforwardonly, masterdrivenmode);", sym, q));
  const auto t = std::get<MatcParams>(decode(q));
  EXPECT_EQ(t.cam_profile, 4);
  EXPECT_EQ(t.time_scaling, 3);
  EXPECT_EQ(t.execution_mode, 1);
  EXPECT_EQ(t.execution_schedule, 1);
  EXPECT_EQ(t.lock_direction, LockDirection::ImmediateForwardOnly);
  EXPECT_TRUE(t.master_driven);
}

TEST(Decode, CoordinatedOperandsAreTyped) {
  const Symbols sym = syms();
  Request q;
  ASSERT_FALSE(parse_and_bind("MCCM(cs1, ctl, incremental, arr[1], radius, arr[0], counterclockwisefull, 20, "
                              "%ofmaximum, 30, %ofmaximum, 40, unitspersec2, scurve, 50, 60, %oftime, "
                              "commandtoleranceprogrammed, allmotion, current, 0.5, 0, none, 0, 0);",
                              sym, q));
  const auto c = std::get<MccmParams>(decode(q));
  EXPECT_TRUE(c.circle);
  EXPECT_EQ(c.move_type, MoveType::Incremental);
  EXPECT_EQ(c.circle_type, coord::CircleType::Radius);
  EXPECT_EQ(c.direction, coord::CircleDirection::CounterClockwiseFull);
  EXPECT_EQ(c.termination, coord::Termination::CommandToleranceProgrammed);
  EXPECT_EQ(c.merge, coord::CoordMerge::AllMotion);
  EXPECT_EQ(c.merge_speed, MergeSpeed::Current);
  EXPECT_EQ(c.position_start, 1);
  EXPECT_EQ(c.dyn.speed_units, SpeedUnits::PercentOfMaximum);
  EXPECT_EQ(c.dyn.decel_units, AccelUnits::UnitsPerSec2);
  EXPECT_EQ(c.dyn.profile, ProfileType::SCurve);
  EXPECT_EQ(c.dyn.jerk_units, JerkUnits::PercentOfTime);
  EXPECT_EQ(c.dyn.at.speed, 7);
  EXPECT_EQ(c.dyn.at.jerk_units, 16);
  ASSERT_FALSE(parse_and_bind("MCLM(cs1, ctl, 0, arr, 10, unitspersec, 5, unitspersec2, 5, unitspersec2, trapezoidal, "
                              "0, 0, unitspersec3, 4, 1, programmed, 0, 0, none, 0, 0);",
                              sym, q));
  const auto l = std::get<MclmParams>(decode(q));
  EXPECT_FALSE(l.circle);
  EXPECT_EQ(l.move_type, MoveType::Absolute);
  EXPECT_EQ(l.termination, coord::Termination::FollowContourVelocityConstrained);  // by number
  EXPECT_EQ(l.merge, coord::CoordMerge::CoordinatedMotion);
  EXPECT_EQ(l.dyn.at.speed, 4);
  ASSERT_FALSE(parse_and_bind("MCS(cs1, ctl, coordinatedtransform, yes, 10, %ofmaximum, no, 0, %oftime);", sym, q));
  EXPECT_EQ(std::get<McsParams>(decode(q)).stop_type, CoordStopType::CoordinatedTransform);
  ASSERT_FALSE(parse_and_bind("MCCD(cs1, ctl, coordinatedmove, yes, 5, unitspermasterunit, no, 0, unitspersec2, yes, 8, "
                              "unitspermasterunit2, no, 0, no, 0, unitspersec3, activeandpendingmotion);",
                              sym, q));
  const auto d = std::get<MccdParams>(decode(q));
  EXPECT_TRUE(d.change_speed);
  EXPECT_FALSE(d.change_accel);
  EXPECT_TRUE(d.change_decel);
  EXPECT_EQ(d.scope, coord::ChangeScope::ActiveAndPendingMotion);
  EXPECT_EQ(d.dyn.speed_units, SpeedUnits::UnitsPerMasterUnit);
  EXPECT_EQ(d.dyn.decel, 8);
  EXPECT_EQ(d.dyn.at.accel, 7);  // MCCD's own positions (Change operands between)
  EXPECT_EQ(d.dyn.at.decel_jerk, 15);
}
