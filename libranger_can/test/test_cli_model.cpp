// --model, --protocol, --set and --chassis-variant on the sub-commands that talk to a chassis
// (sim, monitor, send, scenario) and --model on odom: what each makes of a vehicle, and that a bad
// value is a usage error (exit 2) listing the valid ones.
#include <gtest/gtest.h>

#include <string>

#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "support/cli_run.hpp"

namespace ranger::cli {
namespace {

bool contains(const std::string& hay, const std::string& needle) {
  return hay.find(needle) != std::string::npos;
}

TEST(CliModel, EveryChassisCommandTakesTheVehicleOptions) {
  for (auto command : {run_sim, run_monitor, run_send, run_scenario, run_odom}) {
    const auto r = test::run_cli(command, {"--help"});
    EXPECT_EQ(r.rc, 0);
    EXPECT_TRUE(contains(r.out, "--model MODEL")) << r.out;
    for (const std::string& model : model_names())
      EXPECT_TRUE(contains(r.out, model)) << r.out;
    EXPECT_TRUE(contains(r.out, "--protocol ")) << r.out;
    EXPECT_TRUE(contains(r.out, "manual|agx_v2")) << r.out;  // (auto| first where it identifies)
    EXPECT_TRUE(contains(r.out, "--set NAME=VALUE")) << r.out;
  }
}

TEST(CliModel, SimHelpListsEveryVariant) {
  const auto r = test::run_cli(run_sim, {"--help"});
  for (const sim::VariantInfo& v : sim::variants()) {
    EXPECT_TRUE(contains(r.out, "  " + v.name + " ")) << v.name;
    EXPECT_TRUE(contains(r.out, v.description)) << v.name;
  }
  EXPECT_TRUE(contains(r.out, "--chassis-variant VARIANT"));
}

TEST(CliModel, BadValuesAreUsageErrorsListingTheValidOnes) {
  const struct {
    test::CliCommand command;
    cli::Args args;
    std::string mentions;
  } cases[] = {
      {run_sim, {"vcan0", "--model", "ranger_maxi"}, "ranger_mini_v1"},
      {run_sim, {"vcan0", "--chassis-variant", "wobbly"}, "steer_left_positive"},
      {run_sim, {"vcan0", "--protocol", "v3"}, "agx_v2"},
      {run_sim, {"vcan0", "--set", "tx_dlc=5"}, "0|8"},
      {run_monitor, {"can0", "--model", "x"}, "ranger_mini_v3"},
      {run_monitor, {"can0", "--set", "bogus=1"}, "steering_unit_111"},
      {run_send, {"can0", "control", "can", "--model", "x"}, "ranger_mini_v2"},
      {run_send, {"can0", "control", "can", "--protocol", "x"}, "manual"},
      {run_scenario, {"--model", "x"}, "ranger_mini_v1"},
      {run_scenario, {"--chassis-variant", "x"}, "undecidable"},
      {run_odom, {"--model", "x"}, "ranger_mini_v1"},
  };
  for (const auto& c : cases) {
    const auto r = test::run_cli(c.command, c.args);
    EXPECT_EQ(r.rc, 2) << c.args[1];
    EXPECT_TRUE(contains(r.err, c.mentions)) << r.err;
  }
}

TEST(CliModel, SendEncodesInTheVehiclesProtocol) {
  const struct {
    cli::Args args;
    std::string frame;
  } cases[] = {
      // The manual: spin 0.3 m/s wheel speed in bytes 4-5, counter-clockwise positive.
      {{"can0", "motion", "0", "0", "0.3", "-n"}, "can0 111#00000000012C0000"},
      // MINI V1: the spin negated, every frame 8 bytes.
      {{"can0", "motion", "0", "0", "0.3", "-n", "--model", "ranger_mini_v1"},
       "can0 111#00000000FED40000"},
      // MINI V1 steering: 10 deg right = +1000 in 0.01 deg, right positive.
      {{"can0", "motion", "0", "-10", "0", "-n", "--model", "ranger_mini_v1"},
       "can0 111#00000000000003E8"},
      // agx_v2: the spin as a yaw rate in bytes 2-3 (0.5 m/s / 0.5258 m = 951 mrad/s).
      {{"can0", "motion", "0", "0", "0.5", "-n", "--protocol", "agx_v2"},
       "can0 111#000003B700000000"},
      // agx_v2: 10 deg left = +175 mrad, left positive.
      {{"can0", "motion", "0", "10", "0", "-n", "--protocol", "agx_v2"},
       "can0 111#00000000000000AF"},
      {{"can0", "mode", "spin", "-n", "--protocol", "agx_v2"}, "can0 141#0200000000000000"},
  };
  for (const auto& c : cases) {
    const auto r = test::run_cli(run_send, c.args);
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(contains(r.out, c.frame)) << r.out << " expected " << c.frame;
  }
  // --set after the model: the MINI V1 without its negated spin.
  const auto ccw = test::run_cli(run_send, {"can0", "motion", "0", "0", "0.3", "-n", "--model",
                                            "ranger_mini_v1", "--set", "spin_sign=ccw"});
  EXPECT_TRUE(contains(ccw.out, "111#00000000012C0000")) << ccw.out;
}

TEST(CliModel, SimRunsTheVariantOnAnInterface) {
  LoopbackOptions options;
  options.interface = "vsim_model0";
  auto network = std::make_shared<LoopbackNetwork>(options);
  register_loopback_interface(network);
  auto listener = network->connect();
  const auto r = test::run_cli(
      run_sim, {"vsim_model0", "--chassis-variant", "agx_v2", "--duration", "0.2", "--no-stdin"});
  unregister_loopback_interface("vsim_model0");
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "variant agx_v2, protocol agx_v2")) << r.out;
  int remote_state = 0;
  for (auto f = listener->receive(std::chrono::nanoseconds(0)); f;
       f = listener->receive(std::chrono::nanoseconds(0))) {
    EXPECT_EQ(f->dlc, 8) << std::hex << f->id;
    if (f->id == protocol::kRemoteControlStateId) ++remote_state;
  }
  EXPECT_GT(remote_state, 0);
}

TEST(CliModel, ScenarioDrivesAModelsChassisWithTheModelsDriver) {
  const std::string script =
      "cmd 0.3 0 0.2\nwait 3\nexpect moving\nexpect odom.yaw > 0.2\n"
      "mode spin\ncmd 0 0 0.25\nwait 5\nexpect truth.wz > 0.2\nexpect odom.wz > 0.2\n";
  const auto r = test::run_cli(run_scenario,
                               {"--model", "ranger_mini_v1", "--protocol", "agx_v2",
                                "--chassis-variant", "mini_v1", "--every", "10"},
                               script);
  EXPECT_EQ(r.rc, 0) << r.err;
  // The same chassis driven by a RANGER driver (manual protocol): it turns the wrong way.
  const auto wrong = test::run_cli(
      run_scenario, {"--protocol", "manual", "--chassis-variant", "spin_cw", "--every", "10"},
      "mode spin\ncmd 0 0 0.25\nwait 5\nexpect truth.wz > 0.2\n");
  EXPECT_EQ(wrong.rc, 1);
  const auto right = test::run_cli(run_scenario,
                                   {"--protocol", "manual", "--chassis-variant", "spin_cw", "--set",
                                    "spin_sign=cw", "--every", "10"},
                                   "mode spin\ncmd 0 0 0.25\nwait 5\nexpect truth.wz > 0.2\n");
  EXPECT_EQ(right.rc, 0) << right.err;
}

}  // namespace
}  // namespace ranger::cli
