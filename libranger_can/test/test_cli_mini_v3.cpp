// The RANGER MINI 3.0 (`mini_v3`) through the command line: `decode --protocol mini_v3 --json`
// gives every frame of its table the transcription's values and units (test/data/
// mini_v3_table.log: one frame per row of PROTOCOL_MINI_V3.md's tables), `send` writes its drive
// mode, lights, park and clear codes and refuses by name what it lacks, `identify` tells the
// three readings apart on the virtual chassis.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <string>
#include <vector>

#include "cli_monitor_view.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "ranger_can/wire/codec.hpp"
#include "support/cli_run.hpp"

namespace ranger {
namespace {

using test::lines_of;
using test::run_cli;

const std::string kTable = std::string(RANGER_SOURCE_DIR) + "/test/data/mini_v3_table.log";

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(CliMiniV3, DecodeJsonGivesEveryFrameOfTheTableItsValuesAndUnits) {
  const auto r = run_cli(cli::run_decode, {kTable, "--protocol", "mini_v3", "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto l = lines_of(r.out);
  ASSERT_EQ(l.size(), 17u) << r.out;
  for (const auto& line : l)
    EXPECT_FALSE(contains(line, "\"error\"")) << line;
  // 0x111: linear m/s, spin angular velocity rad/s, inner angle rad (the codec's sign: right +).
  EXPECT_TRUE(contains(l[0],
                       "\"linear_speed\":1.5,\"yaw_rate\":0.5,\"spin_speed\":0.0,"
                       "\"steering_angle\":-0.3}"))
      << l[0];
  EXPECT_TRUE(contains(l[1], "\"mode\":3,\"mode_name\":\"park\"")) << l[1];
  EXPECT_TRUE(contains(l[2], "\"mode_name\":\"can\"")) << l[2];
  EXPECT_TRUE(contains(l[3],
                       "\"name\":\"drive_mode_command\",\"dlc\":1,\"data\":\"01\","
                       "\"mode\":1,\"mode_name\":\"voltage\""))
      << l[3];
  EXPECT_TRUE(contains(l[4], "\"code\":15,\"description\":\"over-current fault\"")) << l[4];
  EXPECT_TRUE(contains(l[5], "\"enable\":true,\"front_mode\":1,\"front_mode_name\":\"on\""))
      << l[5];
  // 0x211: the 32-bit fault word by meaning, no counter.
  EXPECT_TRUE(contains(l[6],
                       "\"battery_voltage\":48.0,\"error_bits\":1147011,\"errors\":["
                       "\"battery_under_voltage\",\"battery_over_voltage\","
                       "\"emergency_stop\",\"over_current\","
                       "\"steering_calibration_fault_front_right\","
                       "\"steering_calibration_timeout\"],\"critical\":true}"))
      << l[6];
  EXPECT_FALSE(contains(l[6], "counter")) << l[6];
  EXPECT_TRUE(contains(l[7],
                       "\"speed\":-0.2,\"yaw_rate\":0.7,\"lateral_speed\":0.0,"
                       "\"steering_angle\":-0.1}"))
      << l[7];
  EXPECT_TRUE(contains(l[8], "\"rear_mode_name\":\"off\"") && contains(l[8], "\"counter\":5"))
      << l[8];
  EXPECT_TRUE(contains(l[9], "\"angles\":[-1.009,1.009,-1.009,1.009]")) << l[9];
  EXPECT_TRUE(contains(l[10], "\"speeds\":[0.5,-0.5,0.0,0.001]")) << l[10];
  // 0x291 of 3 bytes: mode, switching, drive mode.
  EXPECT_TRUE(contains(l[11],
                       "\"dlc\":3,\"data\":\"030001\",\"mode\":3,\"mode_name\":\"park\","
                       "\"switching\":false,\"drive_mode\":1,\"drive_mode_name\":"
                       "\"voltage\"}"))
      << l[11];
  // Front and rear odometry in metres (the wire's mm).
  EXPECT_TRUE(contains(l[12],
                       "\"axle\":\"front\",\"left_wheel\":12345,\"right_wheel\":-250,"
                       "\"left_distance\":12.345,\"right_distance\":-0.25}"))
      << l[12];
  EXPECT_TRUE(contains(l[13], "\"name\":\"rear_odometer\"") &&
              contains(l[13], "\"left_distance\":12.34,\"right_distance\":12.395}"))
      << l[13];
  EXPECT_TRUE(contains(l[14],
                       "\"soc\":80.0,\"soh\":99.0,\"voltage\":48.5,\"current\":-3.0,"
                       "\"temperature\":26.5}"))
      << l[14];
  // 0x362 of length 4: accepted, nothing extra.
  EXPECT_TRUE(contains(l[15], "\"dlc\":4,") &&
              contains(l[15],
                       "\"alarms\":[\"under_voltage\",\"charge_over_current\"],"
                       "\"warnings\":[\"high_temperature\"]}"))
      << l[15];
  EXPECT_FALSE(contains(l[15], "extra_bytes")) << l[15];
  // A padded 0x291: its 3 bytes, the other 5 ignored and counted.
  EXPECT_TRUE(contains(l[16], "\"extra_bytes\":5,") && contains(l[16], "\"switching\":true"))
      << l[16];
}

TEST(CliMiniV3, TheVendorsReadingOfTheSameFramesDiffers) {
  // agx_v2 reads bytes 4-5 of 0x211 as its word and byte 7 as a counter; 0x291's third byte is
  // an extra byte; the odometers' unit is not stated.
  const auto r = run_cli(cli::run_decode, {kTable, "--protocol", "agx_v2", "--json"});
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto l = lines_of(r.out);
  ASSERT_EQ(l.size(), 17u);
  EXPECT_TRUE(contains(l[6], "\"counter\":131")) << l[6];
  EXPECT_TRUE(contains(l[11], "\"extra_bytes\":1")) << l[11];
  EXPECT_FALSE(contains(l[12], "left_distance")) << l[12];
}

TEST(CliMiniV3, SendWritesItsCommandsAndRefusesWhatItLacksByName) {
  auto send = [](std::vector<std::string> args) {
    args.insert(args.begin(), "can0");
    args.insert(args.end(), {"--protocol", "mini_v3", "--dry-run"});
    return run_cli(cli::run_send, args);
  };
  const auto voltage = send({"drive_mode", "voltage"});
  ASSERT_EQ(voltage.rc, 0) << voltage.err;
  EXPECT_TRUE(contains(voltage.out, "can0 423#01   mode=1 (voltage)")) << voltage.out;
  EXPECT_TRUE(contains(send({"drive_mode", "current"}).out, "can0 423#00"));
  EXPECT_TRUE(contains(send({"park", "on"}).out, "can0 141#03"));
  EXPECT_TRUE(contains(send({"clear-errors", "0x0B"}).out, "can0 441#0B"));
  EXPECT_TRUE(contains(send({"lights", "on"}).out, "can0 121#0101000000000000"));
  EXPECT_TRUE(contains(send({"lights", "off"}).out, "can0 121#0100000000000000"));
  struct Refused {
    std::vector<std::string> args;
    const char* message;
  } refused[] = {
      {{"lights", "breathing"}, "breathing lights: unsupported by protocol mini_v3"},
      {{"lights", "on", "on"}, "a rear light: unsupported by protocol mini_v3"},
      {{"lights", "custom:40"}, "brightness: unsupported by protocol mini_v3"},
      {{"mode", "side_slip"},
       "side_slip: unsupported by protocol mini_v3 (its motion-mode "
       "numbering mini_v3 has no side_slip mode)"},
  };
  for (const auto& c : refused) {
    const auto r = send(c.args);
    EXPECT_EQ(r.rc, 1) << c.args[0];
    EXPECT_TRUE(contains(r.err, c.message)) << r.err;
    EXPECT_EQ(r.out, "");
  }
  // No drive mode on the vendor's reading: refused by name.
  const auto agx =
      run_cli(cli::run_send, {"can0", "drive_mode", "voltage", "--protocol", "agx_v2", "-n"});
  EXPECT_EQ(agx.rc, 1);
  EXPECT_TRUE(contains(agx.err,
                       "drive modes: unsupported by protocol agx_v2 (its frame layout "
                       "agx_v2 has no 0x423 drive mode command)"))
      << agx.err;
  const auto bad = send({"drive_mode", "torque"});
  EXPECT_EQ(bad.rc, 2);
  EXPECT_TRUE(contains(bad.err, "drive_mode: unknown drive mode 'torque' (current, voltage)"))
      << bad.err;
  // The model's protocol is mini_v3.
  const auto model =
      run_cli(cli::run_send, {"can0", "drive_mode", "voltage", "--model", "ranger_mini_v3", "-n"});
  EXPECT_EQ(model.rc, 0) << model.err;
}

TEST(CliMiniV3, MonitorShowsTheDriveModeAndBothOdometers) {
  cli::ChassisMonitor monitor(std::chrono::seconds(1), *protocol_preset("mini_v3"));
  const Timestamp now(std::chrono::seconds(5));
  std::ifstream in(kTable);
  for (std::string line; std::getline(in, line);) {
    auto e = parse_candump_line(line);
    ASSERT_TRUE(e.ok()) << line;
    monitor.on_frame(e->frame, now);
  }
  const std::string view = monitor.render_text("can0", BusStatus{}, now, false);
  EXPECT_TRUE(contains(view, "Motion    mode spin   SWITCHING   drive current")) << view;
  EXPECT_TRUE(contains(view, "Odometer front  left 12.345 m  right -0.250 m")) << view;
  EXPECT_TRUE(contains(view, "Odometer rear   left 12.340 m  right 12.395 m")) << view;
  EXPECT_TRUE(contains(view, "emergency_stop")) << view;
  EXPECT_TRUE(contains(view, "alarms under_voltage,charge_over_current")) << view;
  const std::string json = monitor.render_json("can0", BusStatus{}, now);
  EXPECT_TRUE(contains(json, "\"drive_mode\":\"current\"")) << json;
  EXPECT_TRUE(contains(json, "\"rear_odometer\":{\"left\":12.34,\"right\":12.395}")) << json;
}

TEST(CliMiniV3, IdentifyTellsTheThreeReadingsApart) {
  const auto mini = run_cli(cli::run_identify, {"sim:mini_v3", "--model", "ranger_mini_v3"});
  ASSERT_EQ(mini.rc, 0) << mini.err;
  EXPECT_TRUE(contains(mini.out, "(simulated time): mini_v3\n")) << mini.out;
  EXPECT_TRUE(contains(mini.out, "0x312 (rear_odometer)")) << mini.out;
  EXPECT_TRUE(contains(mini.out, "0x291 (motion_mode) of 3 bytes")) << mini.out;
  EXPECT_TRUE(contains(mini.out, "error_word                 mini32          decided")) << mini.out;
  EXPECT_TRUE(contains(mini.out, "expected +-53.62 deg")) << "its own geometry: " << mini.out;
  EXPECT_TRUE(
      contains(run_cli(cli::run_identify, {"sim:agx_v2"}).out, "(simulated time): agx_v2\n"));
  EXPECT_TRUE(contains(run_cli(cli::run_identify, {"sim"}).out, "(simulated time): manual\n"));
}

}  // namespace
}  // namespace ranger
