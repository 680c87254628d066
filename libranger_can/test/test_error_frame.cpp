// Error frames -> bus state: the one interpretation every Bus uses (error_frame.hpp).
#include "ranger_can/transport/error_frame.hpp"

#include <gtest/gtest.h>

namespace ranger {
namespace {

using namespace can_error;

TEST(ErrorFrame, BusOffIsBusOff) {
  const auto r = interpret_error_frame(make(kBusOff));
  ASSERT_TRUE(r.new_state.has_value());
  EXPECT_EQ(*r.new_state, BusState::kBusOff);
  EXPECT_EQ(r.description, "bus-off");
  EXPECT_FALSE(r.restarted);
}

TEST(ErrorFrame, ControllerBitsMapToWarningAndPassive) {
  struct Case {
    std::uint8_t ctrl;
    BusState state;
  };
  for (const Case c : {Case{kCtrlRxWarning, BusState::kErrorWarning},
                       Case{kCtrlTxWarning, BusState::kErrorWarning},
                       Case{kCtrlRxPassive, BusState::kErrorPassive},
                       Case{kCtrlTxPassive, BusState::kErrorPassive},
                       Case{kCtrlTxWarning | kCtrlRxPassive, BusState::kErrorPassive},
                       Case{kCtrlActive, BusState::kActive}}) {
    const auto r = interpret_error_frame(make(kController, c.ctrl));
    ASSERT_TRUE(r.new_state.has_value()) << int{c.ctrl};
    EXPECT_EQ(*r.new_state, c.state) << int{c.ctrl};
    EXPECT_TRUE(r.controller_problem);
  }
}

TEST(ErrorFrame, OverflowIsAControllerProblemWithoutStateChange) {
  const auto r = interpret_error_frame(make(kController, kCtrlRxOverflow));
  EXPECT_FALSE(r.new_state.has_value());
  EXPECT_TRUE(r.controller_problem);
  EXPECT_EQ(r.description, "controller: rx buffer overflow");
}

TEST(ErrorFrame, RestartReturnsToActiveButBusOffInTheSameFrameWins) {
  const auto restarted = interpret_error_frame(make(kRestarted));
  ASSERT_TRUE(restarted.new_state.has_value());
  EXPECT_EQ(*restarted.new_state, BusState::kActive);
  EXPECT_TRUE(restarted.restarted);

  const auto both = interpret_error_frame(make(kRestarted | kBusOff));
  EXPECT_EQ(*both.new_state, BusState::kBusOff);
}

TEST(ErrorFrame, NoAckExplainsTheLikelyCauseAndLeavesTheStateAlone) {
  const auto r = interpret_error_frame(make(kNoAck));
  EXPECT_FALSE(r.new_state.has_value());
  EXPECT_NE(r.description.find("no ACK"), std::string::npos);
}

TEST(ErrorFrame, CountersAreReported) {
  CanFrame f = make(kCounters);
  f.data[6] = 130;
  f.data[7] = 5;
  EXPECT_EQ(interpret_error_frame(f).description, "error counters tx=130 rx=5");
}

TEST(ErrorFrame, DataFramesAreNotErrorReports) {
  CanFrame f;
  f.id = kBusOff;  // 0x040 as a data ID means nothing
  const auto r = interpret_error_frame(f);
  EXPECT_FALSE(r.new_state.has_value());
  EXPECT_TRUE(r.description.empty());
}

TEST(BusState, HasReadableNames) {
  EXPECT_EQ(to_string(BusState::kActive), "active");
  EXPECT_EQ(to_string(BusState::kErrorWarning), "error-warning");
  EXPECT_EQ(to_string(BusState::kErrorPassive), "error-passive");
  EXPECT_EQ(to_string(BusState::kBusOff), "bus-off");
  EXPECT_EQ(to_string(BusState::kDown), "down");
}

}  // namespace
}  // namespace ranger
