// Identification tells the three readings apart on first contact (manual, agx_v2, mini_v3): the
// RANGER MINI 3.0 by the frames and lengths only its manual has (0x312, 0x291 of 3 bytes) and a
// 0x211 byte 7 that does not count; a chassis with the MINI 3.0's frames and agx_v2's counter fits
// none and stays at rest, naming what to set. The driver in auto on sim:mini_v3 decides mini_v3
// with that evidence; the vendor SDK's reading (agx_v2) stays selectable on it.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "ranger_can/wire/codec.hpp"
#include "support/identify_rig.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using test::IdentifyRig;

std::vector<CanFrame> read_log(const std::string& path) {
  std::ifstream in(path);
  std::vector<CanFrame> frames;
  std::string line;
  while (std::getline(in, line)) {
    auto e = parse_candump_line(line);
    if (e) frames.push_back(e->frame);
  }
  return frames;
}

bool has_line(const std::vector<std::string>& lines, const std::string& needle) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(needle) != std::string::npos; });
}

std::string all_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines)
    out += l + "\n";
  return out;
}

// A chassis at rest for `duration`: 0x211, 0x291 and (with `rear`) 0x312 every 20 ms, encoded
// under `profile`, with a counter in 0x211 byte 7 when `counting`.
std::vector<CanFrame> at_rest(const ProtocolProfile& profile, bool rear, bool counting,
                              std::chrono::milliseconds duration) {
  std::vector<CanFrame> out;
  std::uint8_t counter = 0;
  for (Timestamp t{0}; t < duration; t += 20ms) {
    SystemStatus s;
    s.control_mode = protocol::ControlMode::kCan;
    s.control_mode_raw = 1;
    s.battery_voltage = 48.0;
    CanFrame status = *encode(s, profile);
    if (counting) status.data[7] = counter++;
    std::vector<CanFrame> frames = {status, *encode(MotionModeFeedback{}, profile)};
    if (rear) {
      OdometerFeedback o;
      o.rear = true;
      frames.push_back(*encode(o, profile));
    }
    for (CanFrame f : frames) {
      f.stamp = t;
      out.push_back(f);
    }
  }
  return out;
}

TEST(IdentifyMiniV3, TheBundledLogIsTheMini30WithItsEvidence) {
  const auto s = identify_log(read_log(std::string(RANGER_DATA_DIR) + "/sample_mini_v3.log"));
  ASSERT_TRUE(s.decided_ok()) << s.message;
  EXPECT_EQ(s.revision, "mini_v3");
  EXPECT_EQ(s.profile, *protocol_preset("mini_v3")) << describe(s.profile);
  EXPECT_TRUE(has_line(s.evidence, "0x312 (rear_odometer)")) << all_lines(s.evidence);
  EXPECT_TRUE(has_line(s.evidence, "0x291 (motion_mode) of 3 bytes")) << all_lines(s.evidence);
  EXPECT_TRUE(has_line(s.evidence, "preset mini_v3")) << all_lines(s.evidence);
  EXPECT_TRUE(has_line(s.evidence, "no counter; the preset's layout (mini32) stands"))
      << all_lines(s.evidence);
}

TEST(IdentifyMiniV3, EachSignatureAloneDecidesIt) {
  const ProtocolProfile mini = *protocol_preset("mini_v3");
  // 0x291 of 3 bytes alone (no 0x312).
  auto a = identify_log(at_rest(mini, false, false, 1500ms));
  ASSERT_TRUE(a.decided_ok()) << a.message;
  EXPECT_EQ(a.revision, "mini_v3");
  // 0x312 alone, 0x291 padded to 8 (a padding MINI: its length no longer tells).
  ProtocolProfile padded = mini;
  padded.tx_dlc = 8;
  auto b = identify_log(at_rest(padded, true, false, 1500ms));
  ASSERT_TRUE(b.decided_ok()) << b.message;
  EXPECT_EQ(b.revision, "mini_v3");
  EXPECT_EQ(*get_setting(b.profile, "tx_dlc"), "8") << "padding: commands padded as well";
  EXPECT_FALSE(has_line(b.evidence, "of 3 bytes"));
  // The vendor's revision at rest is not taken for a MINI 3.0.
  auto c = identify_log(at_rest(*protocol_preset("agx_v2"), false, true, 1500ms));
  ASSERT_TRUE(c.decided_ok()) << c.message;
  EXPECT_EQ(c.revision, "manual") << "no vendor-only frame among these: the manual's preset";
  EXPECT_EQ(*get_setting(c.profile, "error_word"), "agx16");
}

TEST(IdentifyMiniV3, The30sFramesWithACountingByte7FitNoRevision) {
  // 0x312 and 0x291 of 3 bytes (only the MINI 3.0 has them) but byte 7 counting (agx_v2's
  // counter, where the MINI 3.0 has faults): neither reading fits; nothing is guessed.
  const auto s = identify_log(at_rest(*protocol_preset("mini_v3"), true, true, 1500ms));
  EXPECT_EQ(s.phase, IdentificationPhase::kFailed);
  EXPECT_NE(s.message.find("no revision fits"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("protocol: mini_v3"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("ranger_can commission IFACE --wheels-lifted"), std::string::npos);
}

TEST(IdentifyMiniV3, TheDriverInAutoDecidesMiniV3OnTheVirtualMini30AndDrives) {
  DriverConfig c = test::auto_config();
  const ModelPreset model = *model_preset("ranger_mini_v3");
  c.controller.geometry = model.geometry;
  c.controller.limits = model.limits;
  IdentifyRig rig("sim:mini_v3", c);
  rig.command({0.5, 0.0, 0.0});
  ASSERT_TRUE(rig.run_until(
      [&] {
        const auto s = rig.snapshot();
        return s->identification && s->identification->done();
      },
      15s));
  const auto s = rig.snapshot();
  const IdentificationStatus& id = *s->identification;
  ASSERT_TRUE(id.decided_ok()) << id.message;
  EXPECT_EQ(id.revision, "mini_v3");
  EXPECT_EQ(s->profile, *protocol_preset("mini_v3")) << describe(s->profile);
  EXPECT_TRUE(has_line(id.evidence, "0x312 (rear_odometer)")) << all_lines(id.evidence);
  EXPECT_EQ(rig.truth().distance_travelled, 0.0) << "nothing rolled while identifying";
  rig.expect_route("sim:mini_v3 auto");
}

TEST(IdentifyMiniV3, TheVendorSdksReadingStaysSelectable) {
  // protocol agx_v2 forced on a MINI 3.0: the vendor SDK's way (0x291's third byte ignored as an
  // extra byte, commands padded to 8, its byte 7 read as a counter) still drives it.
  DriverConfig c = test::forced_config(*protocol_preset("agx_v2"));
  const ModelPreset model = *model_preset("ranger_mini_v3");
  c.controller.geometry = model.geometry;
  c.controller.limits = model.limits;
  IdentifyRig rig("sim:mini_v3", c);
  ASSERT_TRUE(rig.wait_ready());
  rig.expect_route("sim:mini_v3 forced agx_v2");
}

}  // namespace
}  // namespace ranger
