#include "ranger_can/frontend/cmd_vel_type.hpp"

namespace ranger {

namespace {

constexpr std::string_view kRos2Kind = "msg/";

// The publishers' one type: every publisher's type (at least one) is the same of the two.
std::optional<CmdVelType> publishers_type(const std::vector<std::string>& types) {
  std::optional<CmdVelType> out;
  for (const std::string& t : types) {
    const auto type = parse_cmd_vel_type(t);
    if (!type || (out && *out != *type)) return std::nullopt;
    out = type;
  }
  return out;
}

std::string auto_words(std::string_view why) {
  return std::string(" (cmd_vel_stamped ") + std::string(to_string(CmdVelStamped::kAuto)) + ": " +
         std::string(why) + ")";
}

}  // namespace

std::string type_name(CmdVelType type, TypeSpelling spelling) {
  const std::string_view name = kCmdVelTypeNames.name(type);
  if (spelling == TypeSpelling::kRos1) return std::string(name);
  const std::size_t slash = name.find('/') + 1;
  return std::string(name.substr(0, slash)) + std::string(kRos2Kind) +
         std::string(name.substr(slash));
}

std::optional<CmdVelType> parse_cmd_vel_type(std::string_view name) {
  // Without building a name: the ROS 1 node asks for every message.
  for (const auto& [type, ros1] : kCmdVelTypeNames) {
    if (name == ros1) return type;
    const std::size_t slash = ros1.find('/') + 1;
    if (name.size() == ros1.size() + kRos2Kind.size() &&
        name.substr(0, slash) == ros1.substr(0, slash) &&
        name.substr(slash, kRos2Kind.size()) == kRos2Kind &&
        name.substr(slash + kRos2Kind.size()) == ros1.substr(slash)) {
      return type;
    }
  }
  return std::nullopt;
}

CmdVelTypeDecision CmdVelTypeRule::start(const std::vector<std::string>& publisher_types) {
  const std::string taken_as = "cmd_vel: taken as ";
  if (setting_ != CmdVelStamped::kAuto) {
    const CmdVelType type =
        setting_ == CmdVelStamped::kStamped ? CmdVelType::kTwistStamped : CmdVelType::kTwist;
    taken_ = type;
    return {CmdVelTypeChange::kTaken, type,
            taken_as + type_name(type, spelling_) + " (cmd_vel_stamped " +
                std::string(to_string(setting_)) + ")"};
  }
  if (const auto type = publishers_type(publisher_types)) return take(*type);
  taken_.reset();
  return {CmdVelTypeChange::kNone, std::nullopt,
          taken_as + "the type of its publishers, " + type_name(CmdVelType::kTwist, spelling_) +
              " or " + type_name(CmdVelType::kTwistStamped, spelling_) +
              auto_words(publisher_types.empty()
                             ? "no publisher yet; said again when one appears"
                             : "its publishers do not all use one of them; said again when "
                               "they do")};
}

bool CmdVelTypeRule::publishers_matter(
    std::optional<std::chrono::steady_clock::duration> since_last_message) const {
  if (!follows_publishers()) return false;
  // The type taken still comes: its publisher may still be there (the graph gave one type).
  return !(taken_ && since_last_message && *since_last_message < kCmdVelTypeSettle);
}

CmdVelTypeDecision CmdVelTypeRule::on_publishers(
    const std::vector<std::string>& publisher_types,
    std::optional<std::chrono::steady_clock::duration> since_last_message) {
  if (!publishers_matter(since_last_message)) return {CmdVelTypeChange::kNone, taken_, {}};
  const auto type = publishers_type(publisher_types);
  if (!type || type == taken_) return {CmdVelTypeChange::kNone, taken_, {}};
  return take(*type);
}

CmdVelTypeDecision CmdVelTypeRule::on_message(CmdVelType type) {
  if (!follows_publishers() || type == taken_) return {CmdVelTypeChange::kNone, taken_, {}};
  return take(type);
}

CmdVelTypeDecision CmdVelTypeRule::take(CmdVelType type) {
  const CmdVelTypeChange change = taken_ ? CmdVelTypeChange::kSwitched : CmdVelTypeChange::kTaken;
  taken_ = type;
  return {
      change, type,
      "cmd_vel: taken as " + type_name(type, spelling_) + auto_words("the type of its publishers")};
}

std::string cmd_vel_type_refused_line(std::string_view type, TypeSpelling spelling) {
  return "cmd_vel: a " + std::string(type) + " is neither " +
         type_name(CmdVelType::kTwist, spelling) + " nor " +
         type_name(CmdVelType::kTwistStamped, spelling) + ": not obeyed";
}

}  // namespace ranger
