// Which message cmd_vel is taken as (frontend/cmd_vel_type.hpp), as both nodes map it: the type
// names in each graph's spelling, the rule (a fixed setting; `auto` following the publishers, and
// a message's own type where a front end reads it) and every line it words. The graph and the
// time since the last message are given, never read.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ranger_can/frontend/cmd_vel_type.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

const std::vector<std::string> kNone;
const std::vector<std::string> kTwist1{"geometry_msgs/Twist"};
const std::vector<std::string> kStamped1{"geometry_msgs/TwistStamped"};
const std::vector<std::string> kTwist2{"geometry_msgs/msg/Twist", "geometry_msgs/msg/Twist"};
const std::vector<std::string> kStamped2{"geometry_msgs/msg/TwistStamped"};
const std::vector<std::string> kBoth2{"geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"};

const std::string kTaken1 = "cmd_vel: taken as geometry_msgs/";
const std::string kTaken2 = "cmd_vel: taken as geometry_msgs/msg/";
const std::string kFromPublishers = " (cmd_vel_stamped auto: the type of its publishers)";

TEST(CmdVelType, TheTypeNamesInEachSpelling) {
  EXPECT_EQ(type_name(CmdVelType::kTwist, TypeSpelling::kRos1), "geometry_msgs/Twist");
  EXPECT_EQ(type_name(CmdVelType::kTwistStamped, TypeSpelling::kRos1),
            "geometry_msgs/TwistStamped");
  EXPECT_EQ(type_name(CmdVelType::kTwist, TypeSpelling::kRos2), "geometry_msgs/msg/Twist");
  EXPECT_EQ(type_name(CmdVelType::kTwistStamped, TypeSpelling::kRos2),
            "geometry_msgs/msg/TwistStamped");
  for (const CmdVelType t : kCmdVelTypeNames.values()) {
    for (const TypeSpelling s : kTypeSpellingNames.values())
      EXPECT_EQ(parse_cmd_vel_type(type_name(t, s)), t) << type_name(t, s);
  }
  for (const char* other : {"std_msgs/String", "geometry_msgs/msg/Twist2", "geometry_msgs/msg/",
                            "geometry_msgs/srv/Twist", "Twist", "", "*"}) {
    EXPECT_FALSE(parse_cmd_vel_type(other).has_value()) << other;
  }
}

TEST(CmdVelType, AFixedSettingTakesItsTypeFromStartUpOnAndNothingChangesIt) {
  CmdVelTypeRule stamped(CmdVelStamped::kStamped, TypeSpelling::kRos1);
  const auto s = stamped.start(kTwist1);  // the publishers do not matter
  EXPECT_EQ(s.change, CmdVelTypeChange::kTaken);
  EXPECT_EQ(s.taken, CmdVelType::kTwistStamped);
  EXPECT_EQ(s.line, kTaken1 + "TwistStamped (cmd_vel_stamped true)");
  EXPECT_FALSE(stamped.follows_publishers());
  EXPECT_FALSE(stamped.publishers_matter());

  CmdVelTypeRule plain(CmdVelStamped::kPlain, TypeSpelling::kRos2);
  const auto p = plain.start(kStamped2);
  EXPECT_EQ(p.taken, CmdVelType::kTwist);
  EXPECT_EQ(p.line, kTaken2 + "Twist (cmd_vel_stamped false)");
  for (const auto& types : {kNone, kTwist2, kStamped2, kBoth2}) {
    const auto d = plain.on_publishers(types);
    EXPECT_EQ(d.change, CmdVelTypeChange::kNone);
    EXPECT_EQ(d.taken, CmdVelType::kTwist);
    EXPECT_TRUE(d.line.empty()) << d.line;
  }
  const auto m = plain.on_message(CmdVelType::kTwistStamped);
  EXPECT_EQ(m.change, CmdVelTypeChange::kNone);
  EXPECT_TRUE(m.line.empty());
  EXPECT_EQ(plain.taken(), CmdVelType::kTwist);
}

TEST(CmdVelType, AutoWithoutAPublisherTakesNoneYetAndSaysSo) {
  CmdVelTypeRule ros1(CmdVelStamped::kAuto, TypeSpelling::kRos1);
  const auto d = ros1.start(kNone);
  EXPECT_EQ(d.change, CmdVelTypeChange::kNone);
  EXPECT_FALSE(d.taken.has_value());
  EXPECT_EQ(d.line,
            "cmd_vel: taken as the type of its publishers, geometry_msgs/Twist or "
            "geometry_msgs/TwistStamped (cmd_vel_stamped auto: no publisher yet; said again when "
            "one appears)");
  EXPECT_TRUE(ros1.follows_publishers());

  CmdVelTypeRule ros2(CmdVelStamped::kAuto, TypeSpelling::kRos2);
  EXPECT_EQ(ros2.start(kNone).line,
            "cmd_vel: taken as the type of its publishers, geometry_msgs/msg/Twist or "
            "geometry_msgs/msg/TwistStamped (cmd_vel_stamped auto: no publisher yet; said again "
            "when one appears)");
  // Publishers of both types, or of another type: none taken either, said as it is.
  for (const auto& types :
       {kBoth2, std::vector<std::string>{"std_msgs/String"},
        std::vector<std::string>{"geometry_msgs/msg/Twist", "std_msgs/msg/String"}}) {
    CmdVelTypeRule r(CmdVelStamped::kAuto, TypeSpelling::kRos2);
    const auto m = r.start(types);
    EXPECT_FALSE(m.taken.has_value());
    EXPECT_EQ(m.line,
              "cmd_vel: taken as the type of its publishers, geometry_msgs/msg/Twist or "
              "geometry_msgs/msg/TwistStamped (cmd_vel_stamped auto: its publishers do not all "
              "use one of them; said again when they do)");
  }
}

TEST(CmdVelType, AutoTakesThePublishersTypeAtStartUp) {
  CmdVelTypeRule r(CmdVelStamped::kAuto, TypeSpelling::kRos2);
  const auto d = r.start(kStamped2);
  EXPECT_EQ(d.change, CmdVelTypeChange::kTaken);
  EXPECT_EQ(d.taken, CmdVelType::kTwistStamped);
  EXPECT_EQ(d.line, kTaken2 + "TwistStamped" + kFromPublishers);
  // Looked at again, the same: nothing more to say.
  const auto again = r.on_publishers(kStamped2);
  EXPECT_EQ(again.change, CmdVelTypeChange::kNone);
  EXPECT_TRUE(again.line.empty());
}

// The ROS 2 node's way: the graph gives every publisher's type.
TEST(CmdVelType, AutoFollowsThePublishersAndSaysEachChangeOnce) {
  CmdVelTypeRule r(CmdVelStamped::kAuto, TypeSpelling::kRos2);
  r.start(kNone);
  EXPECT_EQ(r.on_publishers(kNone).change, CmdVelTypeChange::kNone);
  const auto first = r.on_publishers(kStamped2);
  EXPECT_EQ(first.change, CmdVelTypeChange::kTaken);
  EXPECT_EQ(first.line, kTaken2 + "TwistStamped" + kFromPublishers);
  EXPECT_TRUE(r.on_publishers(kStamped2).line.empty());
  EXPECT_TRUE(r.on_publishers(kNone).line.empty());  // gone: the type taken stays
  // A publisher of the other type beside one of the type taken: no change.
  const auto both = r.on_publishers(kBoth2);
  EXPECT_EQ(both.change, CmdVelTypeChange::kNone);
  EXPECT_EQ(both.taken, CmdVelType::kTwistStamped);
  const auto other = r.on_publishers(kTwist2);
  EXPECT_EQ(other.change, CmdVelTypeChange::kSwitched);
  EXPECT_EQ(other.taken, CmdVelType::kTwist);
  EXPECT_EQ(other.line, kTaken2 + "Twist" + kFromPublishers);
  EXPECT_TRUE(r.on_publishers(kTwist2).line.empty());
  EXPECT_EQ(r.on_publishers(kStamped2).change, CmdVelTypeChange::kSwitched);
  EXPECT_EQ(r.taken(), CmdVelType::kTwistStamped);
}

// The ROS 1 node's way: the master gives one type for the topic (its latest publisher's), and
// each message comes as the type its publisher declares.
TEST(CmdVelType, OneTypePerTopicLeavesTheTypeTakenOnlyOnceItNoLongerComes) {
  CmdVelTypeRule r(CmdVelStamped::kAuto, TypeSpelling::kRos1);
  r.start(kNone);
  EXPECT_TRUE(r.publishers_matter(0ms));
  // None taken yet: the master's type is taken whenever a message came (it was of no type taken).
  EXPECT_EQ(r.on_publishers(kStamped1, 0ms).change, CmdVelTypeChange::kTaken);
  EXPECT_TRUE(r.on_message(CmdVelType::kTwistStamped).line.empty());  // the same: said once
  // The master has the other type, but the type taken came 100 ms ago: it stays.
  EXPECT_FALSE(r.publishers_matter(100ms));  // the master need not be asked
  EXPECT_TRUE(r.publishers_matter(kCmdVelTypeSettle));
  EXPECT_TRUE(r.publishers_matter());
  const auto recent = r.on_publishers(kTwist1, 100ms);
  EXPECT_EQ(recent.change, CmdVelTypeChange::kNone);
  EXPECT_EQ(recent.taken, CmdVelType::kTwistStamped);
  EXPECT_EQ(r.on_publishers(kTwist1, kCmdVelTypeSettle - 1ms).change, CmdVelTypeChange::kNone);
  const auto settled = r.on_publishers(kTwist1, kCmdVelTypeSettle);
  EXPECT_EQ(settled.change, CmdVelTypeChange::kSwitched);
  EXPECT_EQ(settled.line, kTaken1 + "Twist" + kFromPublishers);
  EXPECT_TRUE(r.on_message(CmdVelType::kTwist).line.empty());
}

TEST(CmdVelType, AMessagesOwnTypeIsTakenWhenItIsNotTheTypeTaken) {
  CmdVelTypeRule r(CmdVelStamped::kAuto, TypeSpelling::kRos1);
  r.start(kNone);
  const auto first = r.on_message(CmdVelType::kTwist);
  EXPECT_EQ(first.change, CmdVelTypeChange::kTaken);
  EXPECT_EQ(first.line, kTaken1 + "Twist" + kFromPublishers);
  const auto same = r.on_message(CmdVelType::kTwist);
  EXPECT_EQ(same.change, CmdVelTypeChange::kNone);
  EXPECT_TRUE(same.line.empty());
  const auto other = r.on_message(CmdVelType::kTwistStamped);
  EXPECT_EQ(other.change, CmdVelTypeChange::kSwitched);
  EXPECT_EQ(other.line, kTaken1 + "TwistStamped" + kFromPublishers);
}

// node_cmd_vel_stamped.test's sequence on the ROS 1 node: a publisher of each type in turn, the
// master looked at between messages; the log has each change once, as it came.
TEST(CmdVelType, APublisherOfEachTypeInTurnIsSaidOnceEach) {
  CmdVelTypeRule r(CmdVelStamped::kAuto, TypeSpelling::kRos1);
  std::vector<std::string> said;
  auto say = [&](const CmdVelTypeDecision& d) {
    if (!d.line.empty()) said.push_back(d.line);
  };
  const std::string at_start = r.start(kNone).line;
  said.push_back(at_start);
  for (const auto& [publishers, type] :
       {std::pair{kStamped1, CmdVelType::kTwistStamped}, std::pair{kTwist1, CmdVelType::kTwist},
        std::pair{kStamped1, CmdVelType::kTwistStamped}}) {
    // The master has the new type; the type taken came 10 ms ago (none taken the first time).
    say(r.on_publishers(publishers, 10ms));
    say(r.on_message(type));
    say(r.on_publishers(publishers, 10ms));
    say(r.on_message(type));
    say(r.on_publishers(publishers, 1s));
  }
  EXPECT_EQ(said, (std::vector<std::string>{at_start, kTaken1 + "TwistStamped" + kFromPublishers,
                                            kTaken1 + "Twist" + kFromPublishers,
                                            kTaken1 + "TwistStamped" + kFromPublishers}));
}

TEST(CmdVelType, AMessageOfNeitherTypeIsRefusedInTheFrontEndsSpelling) {
  EXPECT_EQ(cmd_vel_type_refused_line("std_msgs/String", TypeSpelling::kRos1),
            "cmd_vel: a std_msgs/String is neither geometry_msgs/Twist nor "
            "geometry_msgs/TwistStamped: not obeyed");
  EXPECT_EQ(cmd_vel_type_refused_line("std_msgs/msg/String", TypeSpelling::kRos2),
            "cmd_vel: a std_msgs/msg/String is neither geometry_msgs/msg/Twist nor "
            "geometry_msgs/msg/TwistStamped: not obeyed");
}

}  // namespace
}  // namespace ranger
