// The chassis-facing sub-commands of the ranger_can tool: `sim`, `monitor` and `send`.
// Argument handling and the pieces behind them (control language, monitor view) are tested
// deterministically; one in-process session runs all three together on a loopback interface and
// asserts on outcomes only (what was received and printed), never on how long anything took.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "cli_monitor_view.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "support/cli_run.hpp"
#include "support/fake_bus.hpp"

namespace ranger::cli {
namespace {

using namespace std::chrono_literals;

using CliRun = test::CliOutcome;

CliRun run(test::CliCommand command, const Args& args, const std::string& input = "") {
  return test::run_cli(command, args, input);
}

bool contains(const std::string& hay, const std::string& needle) {
  return hay.find(needle) != std::string::npos;
}

// ---- usage errors: exit 2, naming the argument ------------------------------------------------

TEST(CliSim, BadArgumentsAreUsageErrorsNamingTheArgument) {
  struct Case {
    Args args;
    std::string mentions;
  };
  const Case cases[] = {
      {{}, "missing IFACE"},
      {{"vcan0", "--soc", "150"}, "--soc"},
      {{"vcan0", "--soc"}, "--soc needs a value"},
      {{"vcan0", "--batteries", "5"}, "--batteries"},
      {{"vcan0", "--ultrasonic", "1,2,3"}, "1 or 8"},
      {{"vcan0", "--ultrasonic", "abc"}, "'abc'"},
      {{"vcan0", "--error", "bogus"}, "bogus"},
      {{"vcan0", "--mode-switch-time", "nan"}, "--mode-switch-time"},
      {{"vcan0", "--frobnicate"}, "--frobnicate"},
      {{"vcan0", "vcan1"}, "vcan1"},
      {{"vcan0", "--remote=yes"}, "--remote takes no value"},
  };
  for (const auto& c : cases) {
    const CliRun r = run(run_sim, c.args);
    EXPECT_EQ(r.rc, 2) << c.mentions;
    EXPECT_TRUE(contains(r.err, c.mentions)) << r.err;
  }
  EXPECT_EQ(run(run_sim, {"--help"}).rc, 0);
  EXPECT_TRUE(contains(run(run_sim, {"--help"}).out, "estop on|off"));
}

TEST(CliMonitor, BadArgumentsAreUsageErrors) {
  EXPECT_EQ(run(run_monitor, {}).rc, 2);
  const CliRun r = run(run_monitor, {"vcan0", "--rate", "0"});
  EXPECT_EQ(r.rc, 2);
  EXPECT_TRUE(contains(r.err, "--rate")) << r.err;
  EXPECT_EQ(run(run_monitor, {"vcan0", "--count", "x"}).rc, 2);
  EXPECT_EQ(run(run_monitor, {"vcan0", "--bogus"}).rc, 2);
  EXPECT_EQ(run(run_monitor, {"--help"}).rc, 0);
}

TEST(CliSend, BadArgumentsAreUsageErrorsNamingTheArgument) {
  struct Case {
    Args args;
    std::string mentions;
  };
  const Case cases[] = {
      {{}, "missing IFACE"},
      {{"vcan0"}, "missing COMMAND"},
      {{"vcan0", "mode", "fly"}, "'fly'"},
      {{"vcan0", "mode"}, "usage"},
      {{"vcan0", "control", "remote"}, "'remote'"},
      {{"vcan0", "clear-errors", "17"}, "CODE"},
      {{"vcan0", "ultrasonic", "maybe"}, "'maybe'"},
      {{"vcan0", "motion", "3", "0", "0"}, "motion V"},
      {{"vcan0", "motion", "nan", "0", "0"}, "not a finite number"},
      {{"vcan0", "motion", "0", "91", "0"}, "STEER_DEG"},
      {{"vcan0", "motion", "0", "0", "1.5"}, "SPIN"},
      {{"vcan0", "motion", "0", "0"}, "usage"},
      {{"vcan0", "fly"}, "unknown command 'fly'"},
      {{"vcan0", "mode", "spin", "--bogus"}, "--bogus"},
  };
  for (const auto& c : cases) {
    const CliRun r = run(run_send, c.args);
    EXPECT_EQ(r.rc, 2) << c.mentions;
    EXPECT_TRUE(contains(r.err, c.mentions)) << r.err;
  }
}

TEST(CliSend, DryRunPrintsTheExactFrame) {
  struct Case {
    Args args;
    std::string frame;
  };
  const Case cases[] = {
      {{"can0", "mode", "ackermann", "-n"}, "can0 141#00"},
      {{"can0", "mode", "oblique", "-n"}, "can0 141#01"},
      {{"can0", "mode", "spin", "-n"}, "can0 141#02"},
      {{"can0", "control", "can", "-n"}, "can0 421#01"},
      {{"can0", "control", "standby", "-n"}, "can0 421#00"},
      {{"can0", "clear-errors", "-n"}, "can0 441#00"},
      {{"can0", "clear-errors", "0x10", "-n"}, "can0 441#10"},
      {{"can0", "clear-errors", "9", "-n"}, "can0 441#09"},
      {{"can0", "ultrasonic", "on", "-n"}, "can0 451#01"},
      {{"can0", "ultrasonic", "off", "-n"}, "can0 451#00"},
      // The manual's samples: forward 150 mm/s; steering 10 deg to the right (REP-103: -10).
      {{"can0", "motion", "0.15", "0", "0", "-n"}, "can0 111#0096000000000000"},
      {{"can0", "motion", "0", "-10", "0", "-n"}, "can0 111#00000000000003E8"},
      {{"can0", "motion", "-0.5", "20", "-1", "-n"}, "can0 111#FE0C0000FC18F830"},
  };
  for (const auto& c : cases) {
    const CliRun r = run(run_send, c.args);
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(contains(r.out, c.frame)) << r.out << " expected " << c.frame;
  }
}

TEST(CliSend, UnreachableInterfaceIsARuntimeFailure) {
  const CliRun r = run(run_send, {"ranger_no_such_if0", "control", "can"});
  EXPECT_EQ(r.rc, 1);
  EXPECT_TRUE(contains(r.err, "ranger_no_such_if0")) << r.err;
}

// ---- the sim control language -----------------------------------------------------------------

TEST(CliSimControl, EveryCommandReachesTheChassis) {
  test::FakeBus bus;
  sim::VirtualChassis chassis(bus, {}, Timestamp{0});
  auto apply = [&](const std::string& line) {
    auto r = sim::apply_chassis_command(line, chassis);
    EXPECT_TRUE(r.ok()) << line << ": " << (r ? "" : r.error().message);
    return r.ok() ? *r : std::string();
  };
  apply("remote on");
  EXPECT_EQ(chassis.snapshot().control_mode, protocol::ControlMode::kRemote);
  apply("remote can");
  EXPECT_EQ(chassis.snapshot().control_mode, protocol::ControlMode::kCan);
  apply("remote on");
  apply("remote off");
  EXPECT_EQ(chassis.snapshot().control_mode, protocol::ControlMode::kStandby);
  apply("remote lost");
  EXPECT_TRUE(chassis.snapshot().error_bits & (1u << protocol::error_bit_index(7, 2)));
  apply("clear 0x0A");
  EXPECT_EQ(chassis.snapshot().error_bits, 0u);
  apply("estop on");
  EXPECT_TRUE(chassis.snapshot().emergency_stop);
  apply("estop off");
  EXPECT_FALSE(chassis.snapshot().emergency_stop);
  apply("error 15");
  EXPECT_EQ(chassis.snapshot().error_bits, 1u << 15);
  apply("error 15 off");
  apply("error steering_servo_warning_front_right");
  EXPECT_NE(chassis.snapshot().error_bits, 0u);
  apply("clear");
  EXPECT_EQ(chassis.snapshot().error_bits, 0u);
  apply("battery 8");
  EXPECT_NEAR(chassis.snapshot().battery.soc, 8.0, 1e-9);
  EXPECT_FALSE(chassis.snapshot().motion_allowed);
  apply("silent on");
  EXPECT_TRUE(chassis.snapshot().silent);
  apply("silent off");
  apply("silent 0.5");
  EXPECT_TRUE(chassis.snapshot().silent);
  apply("silent off");
  apply("stuck on");
  apply("stuck off");
  apply("ultrasonic on");
  EXPECT_TRUE(chassis.snapshot().ultrasonic_enabled);
  apply("ultrasonic 3 250");
  EXPECT_TRUE(chassis.snapshot().error_bits & (1u << protocol::error_bit_index(7, 1)));
  apply("ultrasonic all 4000");
  apply("ultrasonic off");
  apply("pose 1 2 0.5");
  EXPECT_DOUBLE_EQ(chassis.snapshot().pose.x, 1.0);
  EXPECT_DOUBLE_EQ(chassis.snapshot().pose.yaw, 0.5);
  chassis.step(Timestamp{0});  // the boot frames
  const auto before = bus.sent.size();
  apply("garbage 5");
  chassis.step(Timestamp{0});
  EXPECT_EQ(bus.sent.size() - before, 5u);
  EXPECT_TRUE(contains(apply("status"), "control standby"));
  EXPECT_EQ(apply("# a comment"), "");
  EXPECT_EQ(apply("   "), "");
}

TEST(CliSimControl, BadCommandsAreReportedNotApplied) {
  test::FakeBus bus;
  sim::VirtualChassis chassis(bus, {}, Timestamp{0});
  for (const char* line : {"fly", "estop maybe", "error 32", "error bogus", "battery 101",
                           "battery x", "silent -1", "garbage 0", "ultrasonic 9 100",
                           "ultrasonic 1 -5", "pose 1 2", "clear 17", "remote sideways"}) {
    auto r = sim::apply_chassis_command(line, chassis);
    EXPECT_FALSE(r.ok()) << line;
  }
  EXPECT_EQ(chassis.snapshot().error_bits, 0u);
  EXPECT_FALSE(chassis.snapshot().emergency_stop);
}

// ---- the monitor view -------------------------------------------------------------------------

TEST(CliMonitorView, ShowsWhatTheChassisReports) {
  test::FakeBus bus;
  sim::VirtualChassis chassis(bus, {}, Timestamp{0});
  ChassisMonitor monitor;
  auto feed_until = [&](Timestamp end) {
    for (Timestamp t = chassis.now(); t <= end; t += 1ms) {
      chassis.step(t);
      for (const auto& f : bus.sent)
        monitor.on_frame(f, t);
      bus.sent.clear();
    }
  };
  auto command = [&](const Message& m) {
    const CanFrame f = *encode(m);
    monitor.on_frame(f, chassis.now());  // the monitor sees the host's frames too
    chassis.on_frame(f, chassis.now());
  };
  command(ControlModeCommand{protocol::ControlMode::kCan});
  MotionCommand turn_left;
  turn_left.linear_speed = 0.5;
  turn_left.steering_angle = interpretation::manual_from_rep103_command_steering(15 * M_PI / 180);
  for (int i = 0; i < 100; ++i) {
    command(turn_left);
    feed_until(chassis.now() + 20ms);
  }
  chassis.set_error_bit(protocol::error_bit_index(6, 7), true);
  feed_until(chassis.now() + 1500ms);

  const Timestamp now = chassis.now();
  const std::string text = monitor.render_text("vsim0", BusStatus{}, now, false);
  EXPECT_TRUE(contains(text, "control can")) << text;
  EXPECT_TRUE(contains(text, "mode ackermann")) << text;
  EXPECT_TRUE(contains(text, "15.00 deg left")) << text;
  EXPECT_TRUE(contains(text, "over_current")) << text;
  EXPECT_TRUE(contains(text, "front_right")) << text;
  EXPECT_TRUE(contains(text, "0x211  50.0 (50)")) << text;
  EXPECT_TRUE(contains(text, "0x261  10.0 (10)")) << text;
  EXPECT_TRUE(contains(text, "0x111")) << text;
  EXPECT_FALSE(contains(text, "\x1b[")) << "no colour codes when colour is off";
  EXPECT_NEAR(monitor.rate(protocol::kSystemStatusId, now), 50.0, 1.0);
  EXPECT_NEAR(monitor.rate(protocol::kBmsBaseId, now), 2.0, 1.0);

  const std::string json = monitor.render_json("vsim0", BusStatus{}, now);
  EXPECT_TRUE(contains(json, "\"control_mode\":\"can\"")) << json;
  EXPECT_TRUE(contains(json, "\"errors\":[\"over_current_protection\"]") ||
              contains(json, "over_current"))
      << json;

  // The chassis falls silent: the view says so.
  chassis.set_silent(true);
  feed_until(chassis.now() + 1s);
  EXPECT_TRUE(contains(monitor.render_text("vsim0", BusStatus{}, chassis.now(), false), "SILENT"));
}

TEST(CliMonitorView, SaysSoWhenNothingArrives) {
  ChassisMonitor monitor;
  const std::string text = monitor.render_text("can0", BusStatus{}, Timestamp{0}, false);
  EXPECT_TRUE(contains(text, "no frames received yet")) << text;
  EXPECT_FALSE(monitor.heard_chassis());
}

TEST(CliSim, BadControlLinesFromAPipeAreBoundedThenCounted) {
  LoopbackOptions options;
  options.interface = "vsim_cli1";
  auto network = std::make_shared<LoopbackNetwork>(options);
  register_loopback_interface(network);
  std::string input;
  for (int i = 0; i < 1000; ++i)
    input += "frobnicate " + std::to_string(i) + "\n";
  input += "quit\n";
  const CliRun r = run(run_sim, {"vsim_cli1", "--quiet"}, input);
  unregister_loopback_interface("vsim_cli1");
  EXPECT_EQ(r.rc, 0) << r.err;
  const auto err = test::lines_of(r.err);
  ASSERT_EQ(err.size(), 22u) << r.err;
  EXPECT_TRUE(contains(err[0], "frobnicate")) << err[0];
  EXPECT_EQ(err[20], "ranger_can sim: more bad control lines: counted, not shown");
  EXPECT_EQ(err[21], "ranger_can sim: 1000 bad control line(s) (the first 20 shown)");
}

// ---- sim + send + monitor together, in-process ------------------------------------------------

TEST(CliSession, SimSendAndMonitorWorkTogetherOnALoopbackInterface) {
  LoopbackOptions options;
  options.interface = "vsim_cli0";
  options.filter = {};  // every ID, like candump
  auto network = std::make_shared<LoopbackNetwork>(options);
  register_loopback_interface(network);

  char dir_template[] = "/tmp/ranger_cli_sim_XXXXXX";
  ASSERT_NE(::mkdtemp(dir_template), nullptr);
  const std::string dir = dir_template;
  const std::string fifo = dir + "/control";
  const std::string pose = dir + "/pose.jsonl";

  CliRun sim_run{};
  std::thread sim([&] {
    sim_run = run(
        run_sim,
        {"vsim_cli0", "--control", fifo, "--pose-out", pose, "--soc", "42", "--duration", "120"},
        "error 2\n");
  });
  // Wait (bounded) for the simulator to be on the network.
  for (int i = 0; i < 1000 && network->endpoint_count() == 0; ++i)
    std::this_thread::sleep_for(10ms);
  ASSERT_GT(network->endpoint_count(), 0u);

  const CliRun sent = run(run_send, {"vsim_cli0", "control", "can"});
  EXPECT_EQ(sent.rc, 0) << sent.err;
  EXPECT_TRUE(contains(sent.out, "vsim_cli0 421#01")) << sent.out;

  // The monitor sees the chassis in CAN mode (retrying while the change propagates); a 1 s
  // window holds at least one 500 ms BMS frame.
  std::string json;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const CliRun mon = run(run_monitor, {"vsim_cli0", "--once", "--window", "1.0", "--json"});
    ASSERT_EQ(mon.rc, 0) << mon.err;
    json = mon.out;
    if (contains(json, "\"control_mode\":\"can\"")) break;
  }
  EXPECT_TRUE(contains(json, "\"control_mode\":\"can\"")) << json;
  EXPECT_TRUE(contains(json, "\"soc\":4")) << json;            // 42 % minus a little drain
  EXPECT_TRUE(contains(json, "remote_control_lost")) << json;  // from the stdin command

  {
    std::ofstream control(fifo);
    control << "quit\n";
  }
  sim.join();
  EXPECT_EQ(sim_run.rc, 0) << sim_run.err;
  EXPECT_TRUE(contains(sim_run.out, "control mode standby -> can (0x421)")) << sim_run.out;
  EXPECT_TRUE(contains(sim_run.out, "stopped;")) << sim_run.out;

  std::ifstream lines(pose);
  std::string first;
  ASSERT_TRUE(std::getline(lines, first));
  EXPECT_TRUE(contains(first, "\"x\":")) << first;
  EXPECT_TRUE(contains(first, "\"yaw\":")) << first;
  struct stat st {};
  EXPECT_NE(::stat(fifo.c_str(), &st), 0) << "the FIFO the simulator created is removed";

  unregister_loopback_interface("vsim_cli0");
  std::remove(pose.c_str());
  ::rmdir(dir.c_str());
}

}  // namespace
}  // namespace ranger::cli
