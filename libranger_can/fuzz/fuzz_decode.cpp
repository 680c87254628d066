// Fuzzes the frame decoder with arbitrary identifiers, DLCs (0..15: a corrupt DLC nibble must
// not be trusted), bytes and error flags.
//
// Properties (each a FUZZ_CHECK):
//  * decode() never crashes and refuses what it cannot read with the documented error codes:
//    kInvalidArgument for error frames, kUnknownId exactly for IDs outside the protocol, kBadDlc
//    for a DLC other than the protocol's; every error has a message;
//  * no byte past `dlc` is read: the same frame with different bytes beyond its DLC decodes to
//    the same message (compared through its encoding) or the same error;
//  * encode(decode(x)) reproduces x byte for byte, up to exactly what the protocol cannot carry
//    back: reserved bytes are sent as zero, a boolean byte as 0x01, 0x111 fields saturate to their
//    valid range, BMS SOC/SOH to 100 %; only command frames with values a host may not send
//    (0x141 mode > 2, 0x421 mode other than standby/CAN, 0x441 code > 0x10) fail to re-encode;
//  * the protocol tables (names, bit names) answer for any value.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace {

namespace protocol = ranger::protocol;
using ranger::CanFrame;
using ranger::Errc;

std::uint16_t get_u16(const CanFrame& f, int at) {
  return static_cast<std::uint16_t>(f.data[at] << 8 | f.data[at + 1]);
}
void put_i16(CanFrame& f, int at, int v) {
  const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
  f.data[at] = static_cast<std::uint8_t>(u >> 8);
  f.data[at + 1] = static_cast<std::uint8_t>(u);
}
void saturate_i16_field(CanFrame& f, int at, int limit) {
  const int v = static_cast<std::int16_t>(get_u16(f, at));
  put_i16(f, at, std::clamp(v, -limit, limit));
}

bool is_low_speed(std::uint32_t id) {
  return id > protocol::kMotorLowSpeedBaseId &&
         id <= protocol::kMotorLowSpeedBaseId + protocol::kMotorCount;
}
bool is_bms_data(std::uint32_t id) {
  return id >= protocol::kBmsBaseId && id < protocol::kBmsBaseId + 2 * 5 &&
         (id - protocol::kBmsBaseId) % 2 == 0;
}

// What encode(decode(f)) must produce for a valid frame `f` (see the header comment).
CanFrame canonical(CanFrame f) {
  switch (f.id) {
    case protocol::kMotionCommandId:
      f.data[2] = f.data[3] = 0;
      saturate_i16_field(f, 0, 2600);  // interpretation::kMaxLinearSpeedMps
      saturate_i16_field(f, 4, 1000);
      saturate_i16_field(f, 6, 9000);
      break;
    case protocol::kMotionFeedbackId:
      f.data[2] = f.data[3] = f.data[4] = f.data[5] = 0;
      break;
    case protocol::kUltrasonicSettingId:
    case protocol::kUltrasonicSettingFeedbackId:
      f.data[0] = f.data[0] != 0;
      break;
    case protocol::kMotionModeFeedbackId:
      f.data[1] = f.data[1] != 0;
      break;
    default:
      if (is_low_speed(f.id)) f.data[6] = f.data[7] = 0;
      if (is_bms_data(f.id)) {
        f.data[0] = std::min<std::uint8_t>(f.data[0], 100);
        f.data[1] = std::min<std::uint8_t>(f.data[1], 100);
      }
      break;
  }
  return f;
}

// Commands whose decoded value a host may not send: the only frames that may fail to re-encode.
bool unsendable_command(const CanFrame& f) {
  switch (f.id) {
    case protocol::kMotionModeCommandId:
      return f.data[0] > 2;
    case protocol::kControlModeCommandId:
      return f.data[0] != 0 && f.data[0] != 1;
    case protocol::kErrorClearCommandId:
      return f.data[0] > protocol::kMaxErrorClearCode;
    default:
      return false;
  }
}

void check_tables(FuzzedDataProvider& in, std::uint32_t id) {
  FUZZ_CHECK(!protocol::frame_name(id).empty());
  const auto word = in.ConsumeIntegral<std::uint32_t>();
  for (const auto& name : protocol::error_bit_names(word))
    FUZZ_CHECK(!name.empty());
  (void)protocol::is_critical_error(word);
  const auto byte = in.ConsumeIntegral<std::uint8_t>();
  for (const auto& name : protocol::driver_status_names(byte))
    FUZZ_CHECK(!name.empty());
  for (const auto& name : protocol::bms_status_names(byte, static_cast<std::uint8_t>(word))) {
    FUZZ_CHECK(!name.empty());
  }
  FUZZ_CHECK(!protocol::ultrasonic_status_name(static_cast<std::int16_t>(word)).empty());
  FUZZ_CHECK(!protocol::error_clear_description(byte).empty());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::vector<std::uint32_t> kIds = protocol::all_ids();
  FuzzedDataProvider in(data, size);

  CanFrame frame;
  // Mostly RANGER IDs so that every decoder is reached; otherwise any 32-bit value.
  frame.id = in.ConsumeIntegralInRange<int>(0, 3) != 0
                 ? kIds[in.ConsumeIntegralInRange<std::size_t>(0, kIds.size() - 1)]
                 : in.ConsumeIntegral<std::uint32_t>();
  // The DLC the protocol wants three times in four; otherwise any nibble.
  const int wanted = protocol::expected_dlc(frame.id);
  frame.dlc = wanted >= 0 && in.ConsumeIntegralInRange<int>(0, 3) != 0
                  ? static_cast<std::uint8_t>(wanted)
                  : in.ConsumeIntegralInRange<std::uint8_t>(0, 15);
  frame.is_error = in.ConsumeIntegralInRange<int>(0, 31) == 0;
  const std::size_t valid = std::min<std::size_t>(frame.dlc, CanFrame::kMaxDlc);
  for (std::size_t i = 0; i < valid; ++i)
    frame.data[i] = in.ConsumeIntegral<std::uint8_t>();
  // The same frame with garbage past its DLC (which the CanFrame contract says is zero).
  CanFrame dirty = frame;
  for (std::size_t i = valid; i < CanFrame::kMaxDlc; ++i) {
    dirty.data[i] = static_cast<std::uint8_t>(0xA5 ^ in.ConsumeIntegral<std::uint8_t>());
  }

  const auto message = ranger::decode(frame);
  const auto dirty_message = ranger::decode(dirty);
  FUZZ_CHECK(message.ok() == dirty_message.ok());
  check_tables(in, frame.id);

  if (!message.ok()) {
    const Errc code = message.error().code;
    FUZZ_CHECK(code == dirty_message.error().code);
    FUZZ_CHECK(message.error().message == dirty_message.error().message);
    FUZZ_CHECK(!message.error().message.empty());
    if (frame.is_error) {
      FUZZ_CHECK(code == Errc::kInvalidArgument);
    } else if (!protocol::is_known_id(frame.id)) {
      FUZZ_CHECK(code == Errc::kUnknownId);
    } else {
      FUZZ_CHECK(code == Errc::kBadDlc);
      FUZZ_CHECK(frame.dlc != wanted);
    }
    return 0;
  }

  FUZZ_CHECK(!frame.is_error);
  FUZZ_CHECK(protocol::is_known_id(frame.id));
  FUZZ_CHECK(frame.dlc == wanted);
  FUZZ_CHECK(ranger::id_of(*message) == frame.id);

  const auto encoded = ranger::encode(*message);
  const auto dirty_encoded = ranger::encode(*dirty_message);
  FUZZ_CHECK(encoded.ok() == dirty_encoded.ok());
  if (!encoded.ok()) {
    FUZZ_CHECK(unsendable_command(frame));
    FUZZ_CHECK(encoded.error().code == Errc::kInvalidArgument);
    FUZZ_CHECK(!encoded.error().message.empty());
    return 0;
  }
  FUZZ_CHECK(!unsendable_command(frame));
  FUZZ_CHECK(*encoded == *dirty_encoded);  // bytes past the DLC made no difference
  FUZZ_CHECK(encoded->stamp.count() == 0);
  FUZZ_CHECK(*encoded == canonical(frame));

  // The canonical frame is a fixed point.
  const auto again = ranger::decode(*encoded);
  FUZZ_CHECK(again.ok());
  const auto reencoded = ranger::encode(*again);
  FUZZ_CHECK(reencoded.ok() && *reencoded == *encoded);
  return 0;
}
