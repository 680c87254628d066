// Fuzzes the chassis identification (control/identification.hpp) with arbitrary frame streams
// of both revisions' IDs (any bytes, any length, padded or short) and hostile time steps, live
// (on_frame + tick, as the driver feeds it) and passively over a log (identify_log), and the
// scenario script parser with arbitrary text.
//
// Properties (each a FUZZ_CHECK): no undefined behaviour (UBSan); the identification ends in at
// most its timeout after its start plus a tick after the last frame; a decided profile validates;
// its confidence is in [0, 1]; the evidence stays bounded; a probe it asks for is a zero-speed,
// finite command; a script either parses or fails with a "line N" message.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/sim/scenario.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace {

namespace protocol = ranger::protocol;
using ranger::CanFrame;
using namespace std::chrono_literals;

CanFrame any_frame(FuzzedDataProvider& in) {
  static const std::vector<std::uint32_t> ids = protocol::all_ids();
  CanFrame f;
  f.id = in.ConsumeBool() ? ids[in.ConsumeIntegralInRange<std::size_t>(0, ids.size() - 1)]
                          : in.ConsumeIntegralInRange<std::uint32_t>(0, 0x7FF);
  f.dlc = in.ConsumeIntegralInRange<std::uint8_t>(0, 8);
  for (std::size_t i = 0; i < f.dlc; ++i)
    f.data[i] = in.ConsumeIntegral<std::uint8_t>();
  f.is_error = in.ConsumeIntegralInRange<int>(0, 31) == 0;
  return f;
}

void check_status(const ranger::IdentificationStatus& s) {
  FUZZ_CHECK(s.confidence >= 0.0 && s.confidence <= 1.0);
  FUZZ_CHECK(s.evidence.size() < 1000);
  if (s.decided_ok()) FUZZ_CHECK(s.profile.validate().ok());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const int which = in.ConsumeIntegralInRange<int>(0, 2);
  if (which == 2) {  // the scenario parser
    const std::string text = in.ConsumeRemainingBytesAsString();
    auto script = ranger::sim::parse_scenario(std::string_view(text));
    if (!script) FUZZ_CHECK(script.error().message.find("line ") != std::string::npos);
    return 0;
  }
  ranger::IdentificationConfig config;
  std::vector<CanFrame> log;
  ranger::ChassisIdentifier live(config, {}, std::nullopt, /*read_only=*/which == 1);
  ranger::Timestamp now{1'000'000'000};
  live.tick(now);  // the identification's clock starts here (the driver's first step)
  while (in.remaining_bytes() > 0 && log.size() < 4000) {
    CanFrame f = any_frame(in);
    now += std::chrono::microseconds(in.ConsumeIntegralInRange<int>(0, 50'000));
    f.stamp = now;
    log.push_back(f);
    live.on_frame(f, now);
    live.tick(now);
    const ranger::IdentificationRequest r = live.request();
    if (r.probe) {
      FUZZ_CHECK(r.probe->linear_speed == 0.0 && r.probe->spin_speed == 0.0);
      FUZZ_CHECK(std::isfinite(r.probe->steering_angle));
    }
    check_status(live.status());
  }
  // Silence after the stream: the identification must end within its timeout (ticked as the
  // driver does, at least every 20 ms).
  const ranger::Timestamp end = now + config.timeout + 1s;
  while (now < end && !live.status().done()) {
    now += 20ms;
    live.tick(now);
  }
  if (which == 1) live.finish(now);
  FUZZ_CHECK(live.status().done());
  check_status(live.status());
  check_status(ranger::identify_log(log));
  return 0;
}
