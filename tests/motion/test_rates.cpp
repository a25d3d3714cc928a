// units::convert_rates, the one decoder of a move's rate operands (MAM, MAJ,
// MCLM, MCCM, MCCD; issue 27 item 6): its order of checks, the rules that
// belong to an axis's maxima, the selection of MCCD's changed values and the
// ramp of a %ofTime jerk.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "motion/units.hpp"

namespace canmotion::motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// MAM's rate operands (positions as in its signature), in units per second.
RateOperands mam(double speed, double accel, double decel, double aj = 0, double dj = 0) {
  RateOperands y;
  y.at = RateIndex{op<Instr::MAM>("Speed"),     op<Instr::MAM>("SpeedUnits"), op<Instr::MAM>("AccelRate"),
                   op<Instr::MAM>("AccelUnits"), op<Instr::MAM>("DecelRate"), op<Instr::MAM>("DecelUnits"),
                   op<Instr::MAM>("AccelJerk"),  op<Instr::MAM>("DecelJerk"), op<Instr::MAM>("JerkUnits")};
  y.speed = speed;
  y.accel = accel;
  y.decel = decel;
  y.accel_jerk = aj;
  y.decel_jerk = dj;
  return y;
}

/// Maxima as an AxisConfig or a CoordSystemConfig name them (units::rule_for).
struct Maxima {
  double max_speed, max_accel, max_decel, max_accel_jerk, max_decel_jerk;
};
units::RateRule maxima(double v, double a, double d, double ja, double jd, bool axis) {
  return units::rule_for(Maxima{v, a, d, ja, jd}, axis);
}

TEST(Rates, RatesAndPercentOfMaximum) {
  RateOperands y = mam(50, 20, 40);
  y.accel_units = AccelUnits::PercentOfMaximum;
  Limits lim;
  bool md = true;
  const auto c = units::convert_rates(y, maxima(100, 1000, 2000, 0, 0, true), lim, md);
  ASSERT_TRUE(c.ok());
  EXPECT_FALSE(md);
  EXPECT_EQ(lim.v, 50);
  EXPECT_EQ(lim.a, 200);  // 20 % of 1000
  EXPECT_EQ(lim.d, 40);
  EXPECT_EQ(lim.ja, kInf);  // trapezoidal: the jerks are not converted
  EXPECT_EQ(lim.jd, kInf);
}

TEST(Rates, UnitsOfOneModeFirst) {
  RateOperands y = mam(-1, 0, 0);  // also out of range: the mode comes first
  y.decel_units = AccelUnits::UnitsPerMasterUnit2;
  Limits lim;
  bool md = false;
  EXPECT_EQ(units::convert_rates(y, maxima(1, 1, 1, 1, 1, true), lim, md).err, Err::MdscUnitsConflict);
  // the jerk's units count only with an S-curve (rule.jerks)
  y = mam(1, 1, 1);
  y.jerk_units = JerkUnits::UnitsPerMasterUnit3;
  units::RateRule r = maxima(1, 1, 1, 1, 1, true);
  EXPECT_TRUE(units::convert_rates(y, r, lim, md).ok());
  r.jerks = true;
  EXPECT_EQ(units::convert_rates(y, r, lim, md).err, Err::MdscUnitsConflict);
  // all master driven
  y.speed_units = SpeedUnits::UnitsPerMasterUnit;
  y.accel_units = y.decel_units = AccelUnits::UnitsPerMasterUnit2;
  y.accel_jerk = y.decel_jerk = 3;
  EXPECT_TRUE(units::convert_rates(y, r, lim, md).ok());
  EXPECT_TRUE(md);
}

TEST(Rates, AnAxisRefusesPercentOfAZeroMaximum) {
  // decel of a zero max decel: ERR 54 before the accel is checked
  RateOperands y = mam(10, -1, 50);
  y.decel_units = AccelUnits::PercentOfMaximum;
  Limits lim;
  bool md = false;
  EXPECT_EQ(units::convert_rates(y, maxima(100, 100, 0, 0, 0, true), lim, md).err, Err::ZeroMaxDecel);
  // accel of a zero max accel: ERR 13 at AccelRate on an axis; a coordinate
  // system (maxima > 0 by its configuration) checks the operand only
  y = mam(10, 50, 5);
  y.accel_units = AccelUnits::PercentOfMaximum;
  const auto c = units::convert_rates(y, maxima(100, 0, 100, 0, 0, true), lim, md);
  EXPECT_EQ(c.err, Err::ParameterOutOfRange);
  EXPECT_EQ(c.operand, op<Instr::MAM>("AccelRate"));
  EXPECT_TRUE(units::convert_rates(y, maxima(100, 0, 100, 0, 0, false), lim, md).ok());
  // %ofMaximum jerk: an axis without max decel jerk ERR 76, without max
  // accel jerk ERR 13 at AccelJerk; a coordinate system gets the zero jerk
  y = mam(10, 50, 50, 20, 20);
  y.jerk_units = JerkUnits::PercentOfMaximum;
  units::RateRule r = maxima(100, 100, 100, 0, 1000, true);
  r.jerks = true;
  const auto j = units::convert_rates(y, r, lim, md);
  EXPECT_EQ(j.err, Err::ParameterOutOfRange);
  EXPECT_EQ(j.operand, op<Instr::MAM>("AccelJerk"));
  r.max_decel_jerk = 0;
  EXPECT_EQ(units::convert_rates(y, r, lim, md).err, Err::ZeroMaxDecelJerk);
  r.axis = false;
  ASSERT_TRUE(units::convert_rates(y, r, lim, md).ok());
  EXPECT_EQ(lim.ja, 0);
  EXPECT_EQ(lim.jd, 0);
}

TEST(Rates, JerkUnitsMustGiveAJerk) {
  RateOperands y = mam(10, 50, 50, 1, 1);
  y.jerk_units = JerkUnits::Seconds;
  units::RateRule r = maxima(100, 100, 100, 100, 100, true);
  r.jerks = true;
  Limits lim;
  bool md = false;
  const auto c = units::convert_rates(y, r, lim, md);
  EXPECT_EQ(c.err, Err::ParameterOutOfRange);
  EXPECT_EQ(c.operand, op<Instr::MAM>("JerkUnits"));
}

TEST(Rates, PercentOfTimeRefersToTheMovesRampOrTheGivenOne) {
  RateOperands y = mam(0, 50, 80, 100, 100);  // zero speed: the idle speed
  y.jerk_units = JerkUnits::PercentOfTime;
  units::RateRule r = maxima(100, 100, 100, 100, 100, true);
  r.jerks = true;
  r.idle_speed = 25;
  Limits lim;
  bool md = false;
  ASSERT_TRUE(units::convert_rates(y, r, lim, md).ok());
  EXPECT_EQ(lim.ja, jerk_from_percent_of_time(50, 25, 100));
  EXPECT_EQ(lim.jd, jerk_from_percent_of_time(80, 25, 100));
  y.speed = 40;  // the move's own speed
  ASSERT_TRUE(units::convert_rates(y, r, lim, md).ok());
  EXPECT_EQ(lim.ja, jerk_from_percent_of_time(50, 40, 100));
  r.ramp = units::JerkRamp{300, 400, 60};  // MCCD: the system's
  ASSERT_TRUE(units::convert_rates(y, r, lim, md).ok());
  EXPECT_EQ(lim.ja, jerk_from_percent_of_time(300, 60, 100));
  EXPECT_EQ(lim.jd, jerk_from_percent_of_time(400, 60, 100));
}

TEST(Rates, OnlyTheSelectedValuesAreConverted) {
  // MCCD: the Change operands select; an unselected value is neither checked nor written
  RateOperands y = mam(5, -3, 70, 0, 30);
  y.speed_units = SpeedUnits::UnitsPerMasterUnit;  // unselected: no conflict
  units::RateRule r = maxima(100, 100, 100, 100, 100, false);
  r.speed = r.accel = false;
  r.jerks = true;
  r.accel_jerk = false;
  Limits lim{1, 2, 3, 4, 5};
  bool md = true;
  ASSERT_TRUE(units::convert_rates(y, r, lim, md).ok());
  EXPECT_FALSE(md);
  EXPECT_EQ(lim.v, 1);
  EXPECT_EQ(lim.a, 2);
  EXPECT_EQ(lim.d, 70);
  EXPECT_EQ(lim.ja, 4);
  EXPECT_EQ(lim.jd, 30);
  r.accel = true;  // selected: Accel <= 0 is ERR 13 at AccelRate
  const auto c = units::convert_rates(y, r, lim, md);
  EXPECT_EQ(c.err, Err::ParameterOutOfRange);
  EXPECT_EQ(c.operand, op<Instr::MAM>("AccelRate"));
}

}  // namespace
}  // namespace canmotion::motion
