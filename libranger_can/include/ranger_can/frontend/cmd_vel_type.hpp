// Which message `cmd_vel` is taken as, decided once for both nodes: the parameter cmd_vel_stamped
// (CmdVelStamped, node_parameters.hpp) and, with `auto`, the types of the topic's publishers. The
// rule (CmdVelTypeRule) says which type to take and when that is a change, and words every line
// the nodes log about it; each node only maps it onto its middleware: the ROS 1 node subscribes
// with the type set, or with any type in `auto` (a topic_tools::ShapeShifter, each message read
// as the type its publisher declares), and looks at the master's type of the topic; the ROS 2
// node (through the Python binding, ranger_can.CmdVelTypeRule) subscribes with the type taken
// (Twist while none is) and looks at the graph's publishers.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/frontend/node_parameters.hpp"
#include "ranger_can/text.hpp"

namespace ranger {

// cmd_vel's two message types.
enum class CmdVelType { kTwist, kTwistStamped };
// Their names: the message types as ROS 1 spells them (package/Type).
inline constexpr auto kCmdVelTypeNames = text::enum_names<CmdVelType>({
    {CmdVelType::kTwist, "geometry_msgs/Twist"},
    {CmdVelType::kTwistStamped, "geometry_msgs/TwistStamped"},
});

// How a ROS graph spells a message type: ROS 1 package/Type ("geometry_msgs/Twist"), ROS 2
// package/msg/Type ("geometry_msgs/msg/Twist").
enum class TypeSpelling { kRos1, kRos2 };
inline constexpr auto kTypeSpellingNames = text::enum_names<TypeSpelling>({
    {TypeSpelling::kRos1, "ros1"},
    {TypeSpelling::kRos2, "ros2"},
});

// The type's name as `spelling` has it: kCmdVelTypeNames' for ROS 1, with "msg/" after the
// package for ROS 2.
std::string type_name(CmdVelType type, TypeSpelling spelling);
// A type name in either spelling; nullopt for any other type.
std::optional<CmdVelType> parse_cmd_vel_type(std::string_view name);

// What a decision changed.
enum class CmdVelTypeChange {
  kNone,      // cmd_vel is taken as before
  kTaken,     // a type is taken where none was (start-up, or `auto`'s first publisher)
  kSwitched,  // `auto`: the other type is taken (every publisher uses it now)
};
inline constexpr auto kCmdVelTypeChangeNames = text::enum_names<CmdVelTypeChange>({
    {CmdVelTypeChange::kNone, "none"},
    {CmdVelTypeChange::kTaken, "taken"},
    {CmdVelTypeChange::kSwitched, "switched"},
});

struct CmdVelTypeDecision {
  CmdVelTypeChange change = CmdVelTypeChange::kNone;
  // What cmd_vel is taken as from now on; nullopt: `auto` with none taken yet (the first
  // publisher's type will be).
  std::optional<CmdVelType> taken;
  // The one line to log at info (the start-up's, or the change's); empty: nothing to say.
  std::string line;
};

// `auto` on a graph that gives one type per topic (ROS 1's master: its latest publisher's): the
// type taken is not left while a message of it came within this (its publisher may still be
// there, beside one of the other type).
inline constexpr std::chrono::milliseconds kCmdVelTypeSettle{500};

// The rule. Not thread-safe: a front end that calls it from several threads serialises the calls.
//   fixed (true, false): the type set, from start-up on; nothing else changes it.
//   auto: the type of the topic's publishers once they all use one of the two (none taken until
//     then), and the other whenever they all use the other (unless the type taken still comes:
//     kCmdVelTypeSettle); a front end that reads each message as the type its publisher declares
//     takes a message's type as well (on_message). Publishers of both types, or of another type:
//     no change.
// Each change is said once, in the line of its decision; the lines (ROS 1's spelling):
//   cmd_vel: taken as geometry_msgs/TwistStamped (cmd_vel_stamped true)        a fixed setting
//   cmd_vel: taken as the type of its publishers, geometry_msgs/Twist or geometry_msgs/TwistStamped
//     (cmd_vel_stamped auto: no publisher yet; said again when one appears)   none taken yet
//     (... auto: its publishers do not all use one of them; said again when they do)
//   cmd_vel: taken as geometry_msgs/Twist (cmd_vel_stamped auto: the type of its publishers)
//                                                     taken, at start-up or later, or switched
class CmdVelTypeRule {
 public:
  CmdVelTypeRule(CmdVelStamped setting, TypeSpelling spelling)
      : setting_(setting), spelling_(spelling) {}

  // Start-up: the setting's type, or (auto) the type of the publishers now (`publisher_types`:
  // the graph's, one per publisher or one for the topic; empty: none). Always a line.
  CmdVelTypeDecision start(const std::vector<std::string>& publisher_types);
  // auto: the topic's publishers again (a front end looks every so often). `since_last_message`:
  // how long ago a message of the type taken came, from a front end whose graph gives one type
  // per topic (nullopt: the graph gives every publisher's type). Nothing with a fixed setting.
  CmdVelTypeDecision on_publishers(
      const std::vector<std::string>& publisher_types,
      std::optional<std::chrono::steady_clock::duration> since_last_message = std::nullopt);
  // auto, a front end that reads each message as the type its publisher declares: a message of
  // `type` came, taken when it is not the type taken. Nothing with a fixed setting.
  CmdVelTypeDecision on_message(CmdVelType type);

  // Whether the publishers ever matter (auto): a front end looks at the graph only then.
  bool follows_publishers() const { return setting_ == CmdVelStamped::kAuto; }
  // Whether looking at the publishers now can change anything (auto, and the type taken not
  // still coming: `since_last_message` as on_publishers): a front end that asks a master for
  // them asks only then.
  bool publishers_matter(
      std::optional<std::chrono::steady_clock::duration> since_last_message = std::nullopt) const;
  CmdVelStamped setting() const { return setting_; }
  TypeSpelling spelling() const { return spelling_; }
  std::optional<CmdVelType> taken() const { return taken_; }

 private:
  CmdVelTypeDecision take(CmdVelType type);

  CmdVelStamped setting_;
  TypeSpelling spelling_;
  std::optional<CmdVelType> taken_;
};

// The warning for a message of neither type (a front end that reads each message as the type its
// publisher declares): "cmd_vel: a std_msgs/String is neither geometry_msgs/Twist nor
// geometry_msgs/TwistStamped: not obeyed".
std::string cmd_vel_type_refused_line(std::string_view type, TypeSpelling spelling);

}  // namespace ranger
