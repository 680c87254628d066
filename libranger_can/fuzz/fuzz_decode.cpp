// Fuzzes the frame decoder with arbitrary identifiers, DLCs (0..15: a corrupt DLC nibble must
// not be trusted), bytes, error flags and protocol profiles (every setting's value drawn from the
// input, so every revision and every mix of them are reached).
//
// Properties (each a FUZZ_CHECK):
//  * decode() never crashes and refuses what it cannot read with the documented error codes:
//    kInvalidArgument for error frames, kUnknownId exactly for IDs outside every revision,
//    kBadDlc exactly for a DLC shorter than the ID's layout (the profile's frame layout's) or
//    above 8, kOutOfRange only for a
//    0x221/0x271 steering angle beyond interpretation::kMaxPlausibleSteeringRad; every error has a
//    message;
//  * a longer frame decodes from its leading bytes: no byte past the layout is read,
//    so the same frame with other bytes past its layout, or cut to its layout, decodes to the
//    same message (compared through its encoding) or the same error; no byte past `dlc` either;
//  * encode(decode(x)) under the same profile (with tx_dlc 0) reproduces x's layout bytes, up to
//    exactly what the protocol cannot carry back: reserved bytes are sent as zero, a boolean byte
//    as 0x01, 0x111 fields saturate to their valid range, BMS SOC/SOH to 100 %; only command
//    frames with values a host may not send (a 0x141 mode the numbering lacks, a 0x421 mode other
//    than standby/CAN, a 0x441 code > 0x10, a 0x121 light mode > 3 or one light_modes on_off
//    lacks, a 0x423 where the frame layout has none) fail to re-encode; with tx_dlc 8 the same
//    bytes come back zero-padded to 8;
//  * the protocol tables (names, bit names of every layout, faults) answer for any value.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/profile.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace {

namespace protocol = ranger::protocol;
using ranger::CanFrame;
using ranger::Errc;
using ranger::ProtocolProfile;

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

// A profile with every setting drawn from the input.
ProtocolProfile consume_profile(FuzzedDataProvider& in) {
  ProtocolProfile p;
  for (const auto& s : ranger::profile_settings()) {
    const auto i = in.ConsumeIntegralInRange<std::size_t>(0, s.values.size() - 1);
    FUZZ_CHECK(ranger::set_setting(p, s.name, s.values[i]).ok());
  }
  FUZZ_CHECK(p.validate().ok());
  return p;
}

// `f` cut to its layout under `p` (the bytes a decoder reads): a 0x4A1 answer is all text.
CanFrame cut_to_layout(CanFrame f, const ProtocolProfile& p) {
  if (f.id == protocol::kVersionId && !protocol::is_version_request(f)) return f;
  const int layout = protocol::layout_dlc(f.id, p.frame_layout);
  f.dlc = static_cast<std::uint8_t>(layout);
  for (std::size_t i = static_cast<std::size_t>(layout); i < CanFrame::kMaxDlc; ++i)
    f.data[i] = 0;
  return f;
}

// What encode(decode(f)) must produce under `p` with tx_dlc 0, for a valid frame `f` cut to its
// layout (see the header comment).
CanFrame canonical(CanFrame f, const ProtocolProfile& p) {
  switch (f.id) {
    case protocol::kMotionCommandId:
      saturate_i16_field(f, 0, 2600);  // interpretation::kMaxLinearSpeedMps
      if (p.spin_field == ranger::SpinField::kWheelSpeed) saturate_i16_field(f, 4, 1000);
      saturate_i16_field(f, 6,
                         p.steering_unit_111 == ranger::AngleUnit::kMilliradian ? 1571 : 9000);
      break;
    case protocol::kUltrasonicSettingId:
    case protocol::kUltrasonicSettingFeedbackId:
      f.data[0] = f.data[0] != 0;
      break;
    case protocol::kMotionModeFeedbackId:
      f.data[1] = f.data[1] != 0;
      break;
    case protocol::kLightCommandId:
    case protocol::kLightStateId:
      f.data[0] = f.data[0] != 0;
      f.data[5] = f.data[6] = 0;
      if (p.light_modes == ranger::LightModes::kOnOff) {  // bytes 2-6 reserved (0x121: 2-7)
        f.data[2] = f.data[3] = f.data[4] = 0;
        if (f.id == protocol::kLightCommandId) f.data[7] = 0;
      }
      break;
    case protocol::kRemoteControlStateId:
      f.data[6] = 0;
      break;
    case protocol::kSystemStatusId:
      if (p.error_word == ranger::ErrorWordLayout::kAgxV2_16) f.data[6] = 0;
      break;
    case protocol::kVersionId:
      if (protocol::is_version_request(f)) f.dlc = 1;
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
bool unsendable_command(const CanFrame& f, const ProtocolProfile& p) {
  switch (f.id) {
    case protocol::kMotionModeCommandId:
      return !protocol::motion_mode_from_wire(f.data[0], p.mode_numbering).has_value();
    case protocol::kControlModeCommandId:
      return f.data[0] != 0 && f.data[0] != 1;
    case protocol::kErrorClearCommandId:
      return f.data[0] > protocol::kMaxErrorClearCode;
    case protocol::kLightCommandId:
      if (p.light_modes == ranger::LightModes::kOnOff) return f.data[1] > 1;  // no breathing
      return f.data[1] > 3 || f.data[3] > 3;
    case protocol::kDriveModeCommandId:
      return !protocol::find_frame(f.id)->in(p.frame_layout) ||
             !protocol::drive_mode_from_wire(f.data[0]).has_value();
    default:
      return false;
  }
}

void check_tables(FuzzedDataProvider& in, std::uint32_t id) {
  FUZZ_CHECK(!protocol::frame_name(id).empty());
  const auto word = in.ConsumeIntegral<std::uint32_t>();
  for (const auto layout : ranger::kErrorWordLayoutNames.values()) {
    for (const auto& name : protocol::error_bit_names(word, layout))
      FUZZ_CHECK(!name.empty());
    (void)protocol::is_critical_error(word, layout);
    const int motor = in.ConsumeIntegralInRange<int>(-1, 10);
    const auto fault =
        static_cast<protocol::Fault>(in.ConsumeIntegralInRange<int>(0, protocol::kFaultCount - 1));
    const std::uint32_t bit = protocol::fault_bit(fault, layout, motor);
    FUZZ_CHECK((bit & (bit - 1)) == 0);
  }
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
  const ProtocolProfile profile = consume_profile(in);
  ProtocolProfile unpadded = profile;
  unpadded.tx_dlc = 0;

  CanFrame frame;
  // Mostly RANGER IDs so that every decoder is reached; otherwise any 32-bit value.
  frame.id = in.ConsumeIntegralInRange<int>(0, 3) != 0
                 ? kIds[in.ConsumeIntegralInRange<std::size_t>(0, kIds.size() - 1)]
                 : in.ConsumeIntegral<std::uint32_t>();
  // The layout's length or 8 (padded) three times in four; otherwise any nibble.
  const int layout = protocol::layout_dlc(frame.id, profile.frame_layout);
  const int pick = in.ConsumeIntegralInRange<int>(0, 3);
  frame.dlc = layout >= 0 && pick != 0 ? static_cast<std::uint8_t>(pick == 1 ? 8 : layout)
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

  const auto message = ranger::decode(frame, profile);
  const auto dirty_message = ranger::decode(dirty, profile);
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
    } else if (code == Errc::kOutOfRange) {
      FUZZ_CHECK(frame.id == protocol::kMotionFeedbackId ||
                 frame.id == protocol::kSteeringAnglesId);
      FUZZ_CHECK(frame.dlc >= layout && frame.dlc <= 8);
      // The same content cut to its layout is just as impossible.
      const auto cut = ranger::decode(cut_to_layout(frame, profile), profile);
      FUZZ_CHECK(!cut.ok() && cut.error().message == message.error().message);
    } else {
      FUZZ_CHECK(code == Errc::kBadDlc);
      FUZZ_CHECK(frame.dlc < layout || frame.dlc > 8);
    }
    return 0;
  }

  FUZZ_CHECK(!frame.is_error);
  FUZZ_CHECK(protocol::is_known_id(frame.id));
  FUZZ_CHECK(frame.dlc >= layout && frame.dlc <= 8);
  FUZZ_CHECK(ranger::id_of(*message) == frame.id);

  // Extra bytes are ignored: the frame cut to its layout decodes to the same message.
  const CanFrame cut = cut_to_layout(frame, profile);
  FUZZ_CHECK(protocol::extra_bytes(frame, profile.frame_layout) == frame.dlc - cut.dlc);
  const auto cut_message = ranger::decode(cut, profile);
  FUZZ_CHECK(cut_message.ok());
  FUZZ_CHECK(cut_message->index() == message->index());

  const auto encoded = ranger::encode(*message, unpadded);
  const auto dirty_encoded = ranger::encode(*dirty_message, unpadded);
  const auto cut_encoded = ranger::encode(*cut_message, unpadded);
  FUZZ_CHECK(encoded.ok() == dirty_encoded.ok());
  FUZZ_CHECK(encoded.ok() == cut_encoded.ok());
  if (!encoded.ok()) {
    FUZZ_CHECK(unsendable_command(frame, profile));
    FUZZ_CHECK(encoded.error().code == Errc::kInvalidArgument);
    FUZZ_CHECK(!encoded.error().message.empty());
    return 0;
  }
  FUZZ_CHECK(!unsendable_command(frame, profile));
  FUZZ_CHECK(*encoded == *dirty_encoded);  // bytes past the DLC made no difference
  FUZZ_CHECK(*encoded == *cut_encoded);    // nor did bytes past the layout
  FUZZ_CHECK(encoded->stamp.count() == 0);
  FUZZ_CHECK(*encoded == canonical(cut, profile));

  // The canonical frame is a fixed point.
  const auto again = ranger::decode(*encoded, profile);
  FUZZ_CHECK(again.ok());
  const auto reencoded = ranger::encode(*again, unpadded);
  FUZZ_CHECK(reencoded.ok() && *reencoded == *encoded);

  // Padded (tx_dlc 8): the same bytes, zero-padded to 8, and they decode back.
  ProtocolProfile padded = profile;
  padded.tx_dlc = 8;
  const auto eight = ranger::encode(*message, padded);
  FUZZ_CHECK(eight.ok() && eight->dlc == 8);
  for (std::size_t i = 0; i < CanFrame::kMaxDlc; ++i)
    FUZZ_CHECK(eight->data[i] == (i < encoded->dlc ? encoded->data[i] : 0));
  const auto back = ranger::decode(*eight, profile);
  FUZZ_CHECK(back.ok() && back->index() == message->index());
  return 0;
}
