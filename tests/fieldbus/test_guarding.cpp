// Node guarding (issue 30 part 4): golden bytes of the RTR request and the
// answers, and the master-side toggle / state check.
#include <gtest/gtest.h>

#include "fieldbus/canopen/nmt.hpp"

namespace co = canmotion::canopen;
namespace can = canmotion::can;

TEST(Guarding, RequestIsRemoteFrameOn0x700PlusNodeDlc1) {
  const can::Frame f = co::make_guard_request(5);
  EXPECT_EQ(f.id, 0x705U);
  EXPECT_EQ(f.flags, can::kRemote);
  EXPECT_TRUE(f.remote());
  EXPECT_FALSE(f.extended());
  EXPECT_EQ(f.len, 1U);
  EXPECT_EQ(f.data[0], 0U);
  EXPECT_EQ(co::make_guard_request(127).id, 0x77FU);
}

TEST(Guarding, ResponseGoldenBytes) {
  EXPECT_EQ(co::make_guard_response(5, co::NmtState::kPreOperational, false), (can::Frame{0x705, {0x7F}}));
  EXPECT_EQ(co::make_guard_response(5, co::NmtState::kPreOperational, true), (can::Frame{0x705, {0xFF}}));
  EXPECT_EQ(co::make_guard_response(5, co::NmtState::kOperational, true), (can::Frame{0x705, {0x85}}));
  EXPECT_EQ(co::make_guard_response(5, co::NmtState::kStopped, false), (can::Frame{0x705, {0x04}}));
  EXPECT_FALSE(co::make_guard_response(5, co::NmtState::kOperational, true).remote());
}

TEST(Guarding, ToggleAlternatesFromZero) {
  co::GuardChecker g;
  EXPECT_EQ(g.check(can::Frame{0x705, {0x7F}}, 5), co::GuardAnswer::kOk);
  EXPECT_EQ(g.state(), co::NmtState::kPreOperational);
  EXPECT_EQ(g.check(can::Frame{0x705, {0x85}}, 5), co::GuardAnswer::kOk);
  EXPECT_EQ(g.state(), co::NmtState::kOperational);
  EXPECT_EQ(g.check(can::Frame{0x705, {0x05}}, 5), co::GuardAnswer::kOk);
}

TEST(Guarding, RepeatedToggleIsAnError) {
  co::GuardChecker g;
  EXPECT_EQ(g.check(can::Frame{0x705, {0x05}}, 5), co::GuardAnswer::kOk);
  EXPECT_EQ(g.check(can::Frame{0x705, {0x05}}, 5), co::GuardAnswer::kToggleError);
  EXPECT_EQ(g.expected_toggle(), true);  // unchanged by the error
  g.reset();
  EXPECT_EQ(g.check(can::Frame{0x705, {0x85}}, 5), co::GuardAnswer::kToggleError);
}

TEST(Guarding, BadStateAndNonAnswers) {
  co::GuardChecker g;
  EXPECT_EQ(g.check(can::Frame{0x705, {0x00}}, 5), co::GuardAnswer::kBadState);  // boot-up: the node reset
  EXPECT_EQ(g.check(can::Frame{0x705, {0x13}}, 5), co::GuardAnswer::kBadState);
  EXPECT_EQ(g.check(can::Frame{0x706, {0x05}}, 5), co::GuardAnswer::kNotAnswer);
  EXPECT_EQ(g.check(co::make_guard_request(5), 5), co::GuardAnswer::kNotAnswer);  // our own RTR
  EXPECT_EQ(g.check(can::Frame{0x705, {0x05, 0x00}}, 5), co::GuardAnswer::kNotAnswer);
  EXPECT_EQ(g.check(can::Frame{0x705, {0x05}}, 5), co::GuardAnswer::kOk);  // none of the above moved the toggle
}
