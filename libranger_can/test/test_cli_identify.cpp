// `ranger_can identify` and `ranger_can commission` on the virtual chassis (simulated time), the
// commissioning file and its loader, and --protocol auto on logs (decode, odom).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "ranger_can/control/commissioning.hpp"
#include "support/cli_run.hpp"

namespace ranger {
namespace {

using test::run_cli;

std::string temp_path(const std::string& name) {
  return std::string(::testing::TempDir()) + "/" + name;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CliIdentify, IdentifiesTheVirtualChassisWithItsEvidence) {
  const auto r = run_cli(cli::run_identify, {"sim"});
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("identified in "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(simulated time): manual\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("steering_unit_271          centideg        decided"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("evidence:\n  - no frame only the vendor's revision sends"),
            std::string::npos);
  EXPECT_NE(r.out.find("spin position at standstill"), std::string::npos);
}

TEST(CliIdentify, AMiniIsJudgedByItsOwnGeometryWithModel) {
  // The spin position is +-atan(wheelbase/track): 45 deg on a MINI, 57.8 deg on a RANGER.
  const auto mini = run_cli(cli::run_identify, {"sim:mini_v1", "--model", "ranger_mini_v1"});
  ASSERT_EQ(mini.rc, 0) << mini.err;
  EXPECT_NE(mini.out.find("expected +-45.00 deg"), std::string::npos) << mini.out;
  EXPECT_NE(mini.out.find("steering_unit_271          centideg        decided"), std::string::npos)
      << mini.out;
  const auto ranger = run_cli(cli::run_identify, {"sim:mini_v1"});
  EXPECT_NE(ranger.out.find("spin check inconclusive"), std::string::npos) << ranger.out;
  const auto bad = run_cli(cli::run_identify, {"sim", "--model", "nope"});
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("--model: 'nope' is not one of ranger, ranger_mini_v1"), std::string::npos)
      << bad.err;
}

TEST(CliIdentify, AReplayedLogIsIdentifiedFromItsFramesAlone) {
  const auto r =
      run_cli(cli::run_identify, {std::string("replay:") + RANGER_DATA_DIR + "/sample_agx_v2.log"});
  // A short log, replayed at its own pace: what it holds decides (or it says what is missing).
  EXPECT_TRUE(r.rc == 0 || r.rc == 1) << r.err;
  if (r.rc == 0) EXPECT_NE(r.out.find("agx_v2"), std::string::npos) << r.out;
}

TEST(CliIdentify, UsageAndHelp) {
  EXPECT_EQ(run_cli(cli::run_identify, {}).rc, 2);
  const auto help = run_cli(cli::run_identify, {"--help"});
  EXPECT_EQ(help.rc, 0);
  EXPECT_NE(help.out.find("usage: ranger_can identify IFACE"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--protocol auto|manual|agx_v2"), std::string::npos);
  EXPECT_EQ(run_cli(cli::run_identify, {"sim", "--timeout", "1"}).rc, 2);
}

TEST(CliCommission, WithoutWheelsLiftedItExplainsAndSendsNothing) {
  const auto r = run_cli(cli::run_commission, {"sim", "--output", temp_path("never.yaml")});
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.out.find("chassis on blocks"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("not without --wheels-lifted (nothing was sent)"), std::string::npos);
  EXPECT_FALSE(std::ifstream(temp_path("never.yaml")).good());
}

TEST(CliCommission, WritesAFileTheLoaderReadsBack) {
  const std::string path = temp_path("commission_sim.yaml");
  std::remove(path.c_str());
  const auto r = run_cli(cli::run_commission, {"sim", "--wheels-lifted", "--output", path});
  ASSERT_EQ(r.rc, 0) << r.err << r.out;
  for (const char* needle : {"spin_field                 wheel_speed         decided",
                             "feedback_speed             mean_wheel          decided",
                             "vehicle_status_1_is_estop  true                kept", "wrote "}) {
    EXPECT_NE(r.out.find(needle), std::string::npos) << needle << " in\n" << r.out;
  }
  const auto loaded = load_commissioning_file(path);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_EQ(*loaded, *protocol_preset("manual")) << describe(*loaded);
  const std::string text = slurp(path);
  EXPECT_NE(text.find("\nprotocol: manual\n"), std::string::npos);
  EXPECT_NE(text.find("# decided: "), std::string::npos);
  EXPECT_NE(text.find("# not decided (kept): needs the e-stop pressed"), std::string::npos);
}

TEST(CommissioningFile, ErrorsNameTheLine) {
  auto bad = parse_commissioning_text("protocol: agx_v2\n\nsteering_unit_111: mrad\n", "c.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("c.yaml: line 3: protocol setting steering_unit_111 = "
                                     "'mrad' is invalid (valid: centideg|millirad)"),
            std::string::npos)
      << bad.error().message;
  EXPECT_NE(parse_commissioning_text("spin_sign: cw\nspin_sign: ccw\n", "f")
                .error()
                .message.find("f: line 2: 'spin_sign' is given twice"),
            std::string::npos);
  EXPECT_NE(parse_commissioning_text("tx_dlc: 8\nprotocol: agx_v2\n", "f")
                .error()
                .message.find("line 2: 'protocol' must come before"),
            std::string::npos);
  EXPECT_NE(parse_commissioning_text("just words\n", "f").error().message.find("line 1:"),
            std::string::npos);
  EXPECT_NE(parse_commissioning_text("counter: 1\n", "f")
                .error()
                .message.find("unknown protocol setting 'counter'"),
            std::string::npos);
  EXPECT_EQ(load_commissioning_file("/nonexistent/x.yaml").error().code, Errc::kIoError);
  auto ok = parse_commissioning_text("# a comment\nprotocol: agx_v2  # preset\ntx_dlc: 0\n", "f");
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  EXPECT_EQ(describe(*ok), "agx_v2 with tx_dlc=0");
}

TEST(CliAuto, DecodeIdentifiesTheLogByDefault) {
  const std::string agx = std::string(RANGER_DATA_DIR) + "/sample_agx_v2.log";
  const auto automatic = run_cli(cli::run_decode, {agx, "--json"});
  const auto forced = run_cli(cli::run_decode, {agx, "--json", "--protocol", "agx_v2"});
  ASSERT_EQ(automatic.rc, 0) << automatic.err;
  EXPECT_EQ(automatic.out, forced.out);
  const std::string manual = std::string(RANGER_DATA_DIR) + "/sample.log";
  EXPECT_EQ(run_cli(cli::run_decode, {manual}).out,
            run_cli(cli::run_decode, {manual, "--protocol", "manual"}).out);
  // From standard input too.
  const auto piped = run_cli(cli::run_decode, {"--json"}, slurp(agx));
  EXPECT_EQ(piped.out, forced.out);
}

TEST(CliAuto, OdomIdentifiesTheLogByDefault) {
  const std::string agx = std::string(RANGER_DATA_DIR) + "/sample_agx_v2.log";
  const auto automatic = run_cli(cli::run_odom, {agx, "--quiet"});
  const auto forced = run_cli(cli::run_odom, {agx, "--quiet", "--protocol", "agx_v2"});
  ASSERT_EQ(automatic.rc, forced.rc) << automatic.err;
  EXPECT_EQ(automatic.out, forced.out);
}

}  // namespace
}  // namespace ranger
