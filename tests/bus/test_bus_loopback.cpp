// The bus behaviour suite (bus_behaviour.hpp) on the in-process loopback bus. Runs anywhere.
#include <memory>
#include <string>

#include "bus_behaviour.hpp"
#include "ranger_can/transport/loopback_bus.hpp"

namespace ranger::bus_test {

class LoopbackEnv {
 public:
  static constexpr bool kStampsFromManualClock = true;

  LoopbackEnv() : network_(options(clock_)) {}

  Result<std::unique_ptr<Bus>> open() { return open_interface(interface()); }
  Result<std::unique_ptr<Bus>> open_interface(const std::string& name) {
    auto r = network_.open(name);
    if (!r) return r.error();
    return std::unique_ptr<Bus>(std::move(r).value());
  }
  std::string interface() const { return network_.interface(); }
  std::string missing_interface() const { return "rcan_missing0"; }

  void inject_error_frame(const CanFrame& f) { network_.inject_error_frame(f); }
  void set_link_up(bool up) { network_.set_link_up(up); }
  void stall_transmission(bool stalled) { network_.stall_transmission(stalled); }

  ManualClock& reopen_clock() { return clock_; }
  std::chrono::nanoseconds reopen_interval() const { return std::chrono::seconds(1); }
  Timestamp stamp_clock_now() const { return clock_.now(); }
  std::chrono::nanoseconds delivery_timeout() const { return std::chrono::seconds(5); }

 private:
  static LoopbackOptions options(const Clock& clock) {
    LoopbackOptions o;
    o.interface = "loopback0";
    o.clock = &clock;
    o.reopen_interval = std::chrono::seconds(1);
    return o;
  }
  ManualClock clock_{Timestamp{std::chrono::seconds(1000)}};
  LoopbackNetwork network_;
};

INSTANTIATE_TYPED_TEST_SUITE_P(Loopback, BusBehaviour, LoopbackEnv);

// ---- loopback-only behaviour --------------------------------------------------------------------

TEST(LoopbackNetwork, EndpointsAndNetworkMayBeDestroyedInAnyOrder) {
  std::unique_ptr<Bus> survivor;
  {
    LoopbackNetwork network;
    survivor = network.connect();
    auto other = network.connect();
    EXPECT_EQ(network.endpoint_count(), 2u);
    other.reset();
    EXPECT_EQ(network.endpoint_count(), 1u);
  }
  auto r = survivor->receive(std::chrono::milliseconds(1));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kTimeout);
}

TEST(LoopbackNetwork, ReceiveQueueOverflowDropsNewestFramesAndCountsThem) {
  LoopbackOptions o;
  o.rx_queue_capacity = 4;
  LoopbackNetwork network(o);
  auto a = network.connect();
  auto b = network.connect();
  for (std::uint32_t i = 0; i < 10; ++i)
    ASSERT_TRUE(a->send(numbered(kDataId, i)).ok());
  EXPECT_EQ(b->status().stats.rx_dropped, 6u);
  for (std::uint32_t i = 0; i < 4; ++i) {
    auto r = b->receive(std::chrono::seconds(1));
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(sequence_of(*r), i) << "the oldest frames are kept, in order";
  }
}

TEST(LoopbackNetwork, BlockedReceiveWakesWhenTheLinkGoesDown) {
  LoopbackNetwork network;
  auto b = network.connect();
  std::thread taker([&] { network.set_link_up(false); });
  // Returns once the link is down; the generous timeout only bounds a failure.
  auto r = b->receive(std::chrono::seconds(30));
  taker.join();
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, Errc::kInterfaceDown) << r.error().message;
}

TEST(LoopbackNetwork, EndpointOpenedWhileDownReopensWhenTheLinkComesBack) {
  ManualClock clock;
  LoopbackOptions o;
  o.clock = &clock;
  LoopbackNetwork network(o);
  network.set_link_up(false);
  auto a = network.connect();
  EXPECT_EQ(a->status().state, BusState::kDown);
  network.set_link_up(true);
  auto b = network.connect();
  ASSERT_TRUE(a->send(numbered(kDataId, 1)).ok()) << "first reopen attempt is immediate";
  EXPECT_EQ(a->status().stats.reopens, 1u);
  auto r = b->receive(std::chrono::seconds(1));
  ASSERT_TRUE(r.ok()) << r.error().message;
}

}  // namespace ranger::bus_test
