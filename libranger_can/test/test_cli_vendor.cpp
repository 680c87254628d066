// The vendor's additions in the CLI: `send lights|park|version` (dry run, refusals by name),
// the remote state, lights and firmware version in `monitor`, the firmware version in `identify`.
#include <gtest/gtest.h>

#include <string>

#include "cli_monitor_view.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/profile.hpp"
#include "support/cli_run.hpp"

namespace ranger {
namespace {

using test::run_cli;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(CliSendVendor, LightsDryRunPrintsTheFrame) {
  const auto r = run_cli(cli::run_send, {"can0", "lights", "breathing", "custom:40", "--protocol",
                                         "agx_v2", "--dry-run"});
  ASSERT_EQ(r.rc, 0) << r.err;
  // enable 1, front breathing (2) brightness 0, rear custom (3) brightness 40 (0x28); padded to 8.
  EXPECT_TRUE(contains(r.out, "can0 121#0102000328000000")) << r.out;
  EXPECT_TRUE(contains(r.out, "(dry run, not sent)")) << r.out;
  const auto release =
      run_cli(cli::run_send, {"can0", "lights", "release", "--protocol", "agx_v2", "-n"});
  ASSERT_EQ(release.rc, 0) << release.err;
  EXPECT_TRUE(contains(release.out, "can0 121#00")) << release.out;
}

TEST(CliSendVendor, BadLightsAreUsageErrorsNamingTheArgument) {
  const auto bad = run_cli(cli::run_send, {"can0", "lights", "on", "dim", "-n"});
  EXPECT_EQ(bad.rc, 2);
  EXPECT_TRUE(contains(bad.err, "lights REAR: expected off, on, breathing or custom:PCT"))
      << bad.err;
  const auto pct = run_cli(cli::run_send, {"can0", "lights", "custom:101", "on", "-n"});
  EXPECT_EQ(pct.rc, 2);
  EXPECT_TRUE(contains(pct.err, "custom:PCT")) << pct.err;
}

TEST(CliSendVendor, ParkOnAndOffUnderTheVendorsNumbering) {
  const auto on = run_cli(cli::run_send, {"can0", "park", "on", "--protocol", "agx_v2", "-n"});
  ASSERT_EQ(on.rc, 0) << on.err;
  EXPECT_TRUE(contains(on.out, "can0 141#0300000000000000")) << on.out;
  const auto off = run_cli(cli::run_send, {"can0", "park", "off", "--protocol", "agx_v2", "-n"});
  ASSERT_EQ(off.rc, 0) << off.err;
  EXPECT_TRUE(contains(off.out, "can0 141#0000000000000000")) << off.out;
}

TEST(CliSendVendor, ParkIsRefusedByNameWithoutAParkMode) {
  const auto manual = run_cli(cli::run_send, {"can0", "park", "on", "-n"});
  EXPECT_EQ(manual.rc, 1);
  EXPECT_TRUE(contains(manual.err, "park: unsupported by protocol manual")) << manual.err;
  EXPECT_TRUE(manual.out.empty()) << manual.out;
  const auto mini =
      run_cli(cli::run_send, {"can0", "park", "on", "--model", "ranger_mini_v1", "-n"});
  EXPECT_EQ(mini.rc, 1);
  EXPECT_TRUE(contains(mini.err, "park: unsupported by protocol")) << mini.err;
}

TEST(CliSendVendor, SideSlipIsModeThreeOnTheMiniV1) {
  const auto r =
      run_cli(cli::run_send, {"can0", "mode", "side_slip", "--model", "ranger_mini_v1", "-n"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "can0 141#03")) << r.out;
  const auto manual = run_cli(cli::run_send, {"can0", "mode", "side_slip", "-n"});
  EXPECT_EQ(manual.rc, 1);
  EXPECT_TRUE(contains(manual.err, "side_slip: unsupported by protocol manual")) << manual.err;
}

TEST(CliSendVendor, VersionRequestIsOneByte) {
  const auto r = run_cli(cli::run_send, {"can0", "version", "--protocol", "agx_v2", "-n"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "can0 4A1#01")) << r.out;
}

TEST(CliMonitorVendor, ShowsTheRemoteTheLightsAndTheFirmware) {
  const ProtocolProfile agx = *protocol_preset("agx_v2");
  cli::ChassisMonitor monitor(std::chrono::seconds(1), agx);
  RemoteControlState rc;
  rc.swa = protocol::RemoteSwitch::kDown;
  rc.swb = protocol::RemoteSwitch::kMiddle;
  rc.swc = protocol::RemoteSwitch::kUp;
  rc.swd = protocol::RemoteSwitch::kUp;
  rc.stick_left_v = 50;
  rc.stick_right_h = -100;
  LightState lights;
  lights.enable = true;
  lights.front_mode = protocol::LightMode::kBreathing;
  lights.rear_mode = protocol::LightMode::kCustom;
  lights.rear_custom = 40;
  VersionResponse v;
  const std::string text = "fw 5.7.3";
  std::copy(text.begin(), text.end(), v.text.begin());
  v.length = static_cast<std::uint8_t>(text.size());
  const Timestamp now(std::chrono::seconds(5));
  for (const Message& m : {Message{rc}, Message{lights}, Message{v}}) {
    auto frame = encode(m, agx);
    ASSERT_TRUE(frame.ok());
    monitor.on_frame(*frame, now);
  }
  const std::string view = monitor.render_text("can0", BusStatus{}, now, false);
  EXPECT_TRUE(contains(view, "Remote   SWA down  SWB middle  SWC up  SWD up")) << view;
  EXPECT_TRUE(contains(view, "left stick (+0.50 fwd, +0.00 right)")) << view;
  EXPECT_TRUE(contains(view, "right stick (+0.00 fwd, -1.00 right)")) << view;
  EXPECT_TRUE(contains(view, "Lights   front breathing, rear custom 40  (under CAN control)"))
      << view;
  EXPECT_TRUE(contains(view, "Firmware fw 5.7.3")) << view;
  const std::string json = monitor.render_json("can0", BusStatus{}, now);
  EXPECT_TRUE(contains(json, R"("remote":{"swa":"down","swb":"middle")")) << json;
  EXPECT_TRUE(contains(json, R"("rear":"custom","rear_brightness":40)")) << json;
  EXPECT_TRUE(contains(json, R"("firmware_version":"fw 5.7.3")")) << json;
}

TEST(CliIdentifyVendor, PrintsTheFirmwareVersion) {
  const auto agx = run_cli(cli::run_identify, {"sim:agx_v2"});
  ASSERT_EQ(agx.rc, 0) << agx.err;
  EXPECT_TRUE(contains(agx.out, "firmware: ranger_sim 0.1.0\n")) << agx.out;
  const auto manual = run_cli(cli::run_identify, {"sim"});
  ASSERT_EQ(manual.rc, 0) << manual.err;
  EXPECT_TRUE(contains(manual.out, "firmware: unknown (the chassis sends none of the vendor's"))
      << manual.out;
}

}  // namespace
}  // namespace ranger
