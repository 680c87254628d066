// The identification and plausibility wiring (control/settings_supervisor.hpp) on its own: a
// controller on a loopback bus and hand-made frames. Forced settings need no identification;
// under protocol auto the controller is kept quiet while listening, nothing is read as joints or
// odometry until decided, and the decision reaches the driver (UseProfile); a plausibility stop
// goes to the controller latched, and the operator's resume clears it.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/settings_supervisor.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "ranger_can/wire/codec.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

struct Rig {
  explicit Rig(ProtocolChoice choice) {
    SettingsSupervisorConfig c;
    c.protocol = choice;
    c.configured = manual_profile();
    supervisor =
        std::make_unique<SettingsSupervisor>(c, [this](const ProtocolProfile& p, bool reset) {
          used.push_back(p);
          resets.push_back(reset);
          supervisor->on_profile(p);
        });
  }
  LoopbackNetwork network;
  std::unique_ptr<LoopbackBus> bus = network.connect();
  ChassisController controller{*bus, ControllerConfig{}};
  std::unique_ptr<SettingsSupervisor> supervisor;
  std::vector<ProtocolProfile> used;
  std::vector<bool> resets;
  Timestamp now{1s};

  // What a manual chassis at rest sends every 20 ms, encoded under `profile`.
  void hear_rest(const ProtocolProfile& profile, std::chrono::milliseconds d, bool counter) {
    std::uint8_t n = 0;
    for (const Timestamp end = now + d; now < end; now += 20ms) {
      SystemStatus st;
      st.battery_voltage = 49.8;
      if (counter) st.counter = n++;
      for (const Message& m : std::vector<Message>{st, MotionModeFeedback{}}) {
        auto f = encode(m, profile);
        ASSERT_TRUE(f.ok());
        f->stamp = now;
        supervisor->on_frame(*f, now);
        if (!supervisor->identifying()) supervisor->monitor_frame(*f, now);
      }
      supervisor->run_identification(now, controller, false);
      supervisor->run_plausibility(now, controller, OdometryState{});
    }
  }
};

TEST(SettingsSupervisor, ForcedSettingsNeedNoIdentification) {
  Rig rig(ProtocolChoice::kForced);
  rig.supervisor->start(rig.controller, false);
  EXPECT_FALSE(rig.supervisor->identifying());
  EXPECT_TRUE(rig.supervisor->decided());
  EXPECT_TRUE(rig.supervisor->joints_readable());
  EXPECT_TRUE(rig.supervisor->odometry_readable());
  EXPECT_FALSE(rig.supervisor->status());
  EXPECT_FALSE(rig.controller.state().quiet);
  EXPECT_FALSE(rig.controller.state().identifying);
}

TEST(SettingsSupervisor, AutoListensQuietlyThenHandsTheDecisionToTheDriver) {
  Rig rig(ProtocolChoice::kAuto);
  rig.supervisor->start(rig.controller, /*read_only=*/true);  // decided from the frames alone
  EXPECT_TRUE(rig.supervisor->listening());
  EXPECT_TRUE(rig.controller.state().quiet);
  EXPECT_EQ(rig.controller.state().identifying, IdentificationPhase::kListening);
  EXPECT_FALSE(rig.supervisor->joints_readable());
  EXPECT_FALSE(rig.supervisor->odometry_readable());
  const auto listening = rig.supervisor->status();
  ASSERT_TRUE(listening);
  EXPECT_EQ(listening->phase, IdentificationPhase::kListening);

  rig.hear_rest(manual_profile(), 2s, false);
  ASSERT_TRUE(rig.supervisor->decided()) << rig.supervisor->status()->message;
  ASSERT_FALSE(rig.used.empty());
  EXPECT_EQ(rig.used.back(), manual_profile());
  EXPECT_TRUE(rig.resets.back()) << "nothing moved yet: the odometry starts over";
  EXPECT_FALSE(rig.controller.state().quiet);
  EXPECT_FALSE(rig.controller.state().identifying);
  // Shared between snapshots once decided.
  EXPECT_EQ(rig.supervisor->status(), rig.supervisor->status());
}

TEST(SettingsSupervisor, APlausibilityStopIsLatchedInTheControllerUntilResume) {
  Rig rig(ProtocolChoice::kForced);
  rig.supervisor->start(rig.controller, false);
  // 0x211 byte 7 counting up under the manual's 32-bit error word: the error word is agx16's.
  rig.hear_rest(*protocol_preset("agx_v2"), 2s, true);
  const auto& stop = rig.supervisor->plausibility().stop;
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->setting, "error_word");
  EXPECT_NE(rig.controller.state().implausible_reason.find("error_word: try agx16"),
            std::string::npos)
      << rig.controller.state().implausible_reason;
  rig.supervisor->resume(rig.controller);
  EXPECT_TRUE(rig.controller.state().implausible_reason.empty());
  EXPECT_FALSE(rig.supervisor->plausibility().stop) << "the monitors start over";
}

TEST(SettingsSupervisor, TheStandstillProbeGoesToTheControllerAndEnds) {
  Rig rig(ProtocolChoice::kForced);
  rig.supervisor->set_standstill_probe(StandstillProbe{protocol::MotionMode::kAckermann, 0.1});
  rig.supervisor->run_standstill_probe(rig.controller);
  EXPECT_TRUE(rig.controller.state().standstill_probe);
  ASSERT_TRUE(rig.controller.state().probe);
  rig.supervisor->set_standstill_probe(std::nullopt);
  rig.supervisor->run_standstill_probe(rig.controller);
  EXPECT_FALSE(rig.controller.state().standstill_probe);
  EXPECT_FALSE(rig.controller.state().probe);
}

}  // namespace
}  // namespace ranger
