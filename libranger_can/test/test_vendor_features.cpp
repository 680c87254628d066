// The vendor's features as the driver keeps them (control/vendor_features.hpp), on their own: a
// controller on a loopback bus fed hand-made messages; whether the chassis has the vendor's
// frames, the remote and lights reports, the version asked once and answered, and lights and
// version requests held until the frames are known. (test_driver_vendor.cpp drives the same
// through the whole driver and the virtual chassis.)
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/request_book.hpp"
#include "ranger_can/control/vendor_features.hpp"
#include "ranger_can/transport/loopback_bus.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

// The vendor's revision: what 0x121 and 0x4A1 are encoded under.
ControllerConfig agx_v2() {
  ControllerConfig c;
  c.profile = *protocol_preset("agx_v2");
  return c;
}

struct Rig {
  LoopbackNetwork network;
  std::unique_ptr<LoopbackBus> bus = network.connect();
  std::unique_ptr<LoopbackBus> chassis = network.connect();  // sees what the controller sends
  ChassisController controller{*bus, agx_v2()};
  VendorFeatures vendor{200ms, 500ms};
  RequestBook book;
  Timestamp now{1s};

  void hear(const Message& m) {
    controller.on_message(m, now, now);
    vendor.on_message(m, now);
  }
  void update(bool may_send = true) { vendor.update(now, controller, may_send, "manual", book); }
  // The IDs the controller sent since the last call.
  std::vector<std::uint32_t> sent() {
    std::vector<std::uint32_t> ids;
    for (auto f = chassis->receive(0ms); f; f = chassis->receive(0ms))
      ids.push_back(f->id);
    return ids;
  }
  RequestOutcome outcome(std::uint64_t id) {
    std::vector<RequestOutcome> all;
    book.copy_to(all);
    for (const RequestOutcome& r : all)
      if (r.id == id) return r;
    return {};
  }
};

VersionResponse version_frame(const std::string& text) {
  VersionResponse v;
  for (std::size_t i = 0; i < text.size() && i < v.text.size(); ++i)
    v.text[i] = text[i];
  v.length = static_cast<std::uint8_t>(text.size());
  return v;
}

TEST(VendorFeatures, AbsentAfterTheWaitWithoutTheirFramesAndRequestsThenFail) {
  Rig rig;
  const auto lights = rig.book.add(RequestOutcome::Kind::kLights, "lights");
  rig.vendor.post({VendorAction::Kind::kLights, lights, {}});
  rig.hear(SystemStatus{});
  rig.update();
  EXPECT_EQ(rig.vendor.frames(), VendorFrames::kUnknown);
  EXPECT_EQ(rig.outcome(lights).state, RequestOutcome::State::kPending) << "held until known";
  rig.now += 200ms;
  rig.update();
  EXPECT_EQ(rig.vendor.frames(), VendorFrames::kAbsent);
  EXPECT_EQ(rig.vendor.firmware().state, FirmwareVersion::State::kUnsupported);
  EXPECT_EQ(rig.outcome(lights).state, RequestOutcome::State::kFailed);
  EXPECT_EQ(rig.outcome(lights).message,
            "lights: unsupported by protocol manual: the chassis sends none of the vendor's frames "
            "(0x231 light state, 0x241 remote state)");
  EXPECT_TRUE(rig.sent().empty());
}

TEST(VendorFeatures, PresentWithTheirFramesTheReportsAreKeptAndTheVersionAskedOnce) {
  Rig rig;
  rig.hear(SystemStatus{});
  RemoteControlState rc;
  rc.stick_left_v = 127;
  rig.hear(rc);
  rig.hear(LightState{true, protocol::LightMode::kOn, 0, protocol::LightMode::kOff, 0, 0});
  rig.update(/*may_send=*/false);
  EXPECT_EQ(rig.vendor.frames(), VendorFrames::kPresent);
  ASSERT_TRUE(rig.vendor.remote());
  EXPECT_DOUBLE_EQ(rig.vendor.remote()->left_vertical, 1.0);
  ASSERT_TRUE(rig.vendor.lights());
  EXPECT_EQ(describe(*rig.vendor.lights()), "front on, rear off");
  EXPECT_EQ(rig.vendor.firmware().state, FirmwareVersion::State::kNotAsked) << "may not send";

  rig.update(/*may_send=*/true);
  EXPECT_EQ(rig.vendor.firmware().state, FirmwareVersion::State::kAsked);
  EXPECT_EQ(rig.sent(), std::vector<std::uint32_t>{protocol::kVersionId});
  rig.update(true);
  EXPECT_TRUE(rig.sent().empty()) << "asked once";
  rig.hear(version_frame("FW 1.2"));
  rig.update(true);
  EXPECT_EQ(rig.vendor.firmware().state, FirmwareVersion::State::kAsked) << "more may follow";
  rig.now += 20ms;
  rig.update(true);
  EXPECT_EQ(rig.vendor.firmware().state, FirmwareVersion::State::kAnswered);
  EXPECT_EQ(rig.vendor.firmware().text, "FW 1.2");
}

TEST(VendorFeatures, AnUnansweredVersionAndLightsSentOnceKnown) {
  Rig rig;
  rig.hear(SystemStatus{});
  rig.hear(RemoteControlState{});
  const auto lights = rig.book.add(RequestOutcome::Kind::kLights, "lights");
  rig.vendor.post({VendorAction::Kind::kLights, lights, {}});
  rig.update(true);
  EXPECT_EQ(rig.outcome(lights).state, RequestOutcome::State::kSent);
  const auto sent = rig.sent();
  EXPECT_NE(std::find(sent.begin(), sent.end(), protocol::kLightCommandId), sent.end());
  rig.now += 501ms;
  rig.update(true);
  EXPECT_EQ(rig.vendor.firmware().state, FirmwareVersion::State::kUnanswered);
}

}  // namespace
}  // namespace ranger
