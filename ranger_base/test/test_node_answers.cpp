// Word-for-word parity of the ROS 1 node's answers with the library (node_answers.test): every
// service's response message is the library's (frontend/answers.hpp: the checks, the requests'
// answers, the motion-mode words), and each answer has exactly one log line, the library's
// answer_line of it, at its severity; the driver's request events are not logged besides. A front
// end that re-words an answer, or logs one twice, fails here (the ROS 2 node's counterpart:
// ros2/ranger_base/test/test_answer_words.py).
#include <gtest/gtest.h>
#include <ranger_msgs/ClearErrors.h>
#include <ranger_msgs/SetDriveMode.h>
#include <ranger_msgs/SetLights.h>
#include <ranger_msgs/SetMotionMode.h>
#include <ranger_msgs/SetUltrasonic.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <ranger_can/control/vocabulary.hpp>
#include <ranger_can/frontend/answers.hpp>
#include <ranger_can/wire/profile.hpp>

namespace {

std::mutex logs_mutex;
std::vector<rosgraph_msgs::Log> logs;  // the node's lines, by logs_mutex

void on_log(const rosgraph_msgs::Log::ConstPtr& m) {
  if (m->name.find("ranger_base_node") == std::string::npos) return;
  std::lock_guard<std::mutex> lock(logs_mutex);
  logs.push_back(*m);
}

std::vector<rosgraph_msgs::Log> lines_with(const std::string& text) {
  std::lock_guard<std::mutex> lock(logs_mutex);
  std::vector<rosgraph_msgs::Log> out;
  std::copy_if(logs.begin(), logs.end(), std::back_inserter(out),
               [&](const rosgraph_msgs::Log& l) { return l.msg == text; });
  return out;
}

// Polls `condition` (the timeout only bounds how long a failing test waits).
bool wait_for(const std::function<bool()>& condition, double timeout_s = 30.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end && ros::ok()) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return condition();
}

std::uint8_t level_of(ranger::Severity s) {
  return s == ranger::Severity::kWarn ? rosgraph_msgs::Log::WARN : rosgraph_msgs::Log::INFO;
}

template <class Srv>
Srv call(const std::string& name, Srv srv) {
  ros::NodeHandle nh;
  auto client = nh.serviceClient<Srv>(name);
  EXPECT_TRUE(client.waitForExistence(ros::Duration(30.0))) << name;
  EXPECT_TRUE(client.call(srv)) << name;
  return srv;
}

template <class Response>
ranger::ServiceAnswer said(const Response& r) {
  return {static_cast<bool>(r.success), r.message};
}

class Answers : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    spinner_ = std::make_unique<ros::AsyncSpinner>(1);
    spinner_->start();
    ros::NodeHandle nh;
    rosout_ = nh.subscribe("/rosout", 1000, on_log);
    // The node's log reaches us once a line of its own does: a request whose answer is logged.
    ASSERT_TRUE(wait_for([] {
      ranger_msgs::SetMotionMode m;
      m.request.mode = ranger_msgs::SetMotionMode::Request::AUTOMATIC;
      call("set_motion_mode", m);
      return !lines_with("set_motion_mode: " + ranger::motion_mode_pinned(std::nullopt)).empty();
    }));
  }
  static void TearDownTestSuite() {
    rosout_.shutdown();
    spinner_->stop();
    // Destroyed here, not at exit: a static spinner outliving roscpp's own statics is a
    // heap-use-after-free in ~AsyncSpinner (the ASan build of the ROS tests, as test_node_sim).
    spinner_.reset();
  }

  // `answer` is the library's answer to the request: the response says it, and its one log line
  // is the library's line of it, at its severity.
  void expect_answered(const std::string& service, const ranger::ServiceAnswer& response,
                       const ranger::ServiceAnswer& library) {
    EXPECT_EQ(response.success, library.success) << service << ": " << response.message;
    EXPECT_EQ(response.message, library.message) << service;
    expect_logged_once(service, response);
  }
  void expect_logged_once(const std::string& service, const ranger::ServiceAnswer& response) {
    const ranger::LogLine line = ranger::answer_line(service, response);
    expected_.push_back(line);
    ASSERT_TRUE(wait_for([&] { return !lines_with(line.text).empty(); })) << line.text;
  }
  // After a last answer (logged after every earlier one): each expected line exactly once.
  void TearDown() override {
    ranger_msgs::SetMotionMode m;
    m.request.mode = ranger_msgs::SetMotionMode::Request::OBLIQUE;
    m = call("set_motion_mode", m);
    const auto last =
        ranger::answer_line("set_motion_mode", {m.response.success, m.response.message});
    ASSERT_TRUE(wait_for([&] { return !lines_with(last.text).empty(); })) << last.text;
    for (const auto& line : expected_) {
      const auto found = lines_with(line.text);
      ASSERT_EQ(found.size(), 1u) << "logged " << found.size() << " times: " << line.text;
      EXPECT_EQ(found.front().level, level_of(line.severity)) << line.text;
    }
    std::lock_guard<std::mutex> lock(logs_mutex);
    logs.clear();
  }

  std::vector<ranger::LogLine> expected_;
  static std::unique_ptr<ros::AsyncSpinner> spinner_;
  static ros::Subscriber rosout_;
};
std::unique_ptr<ros::AsyncSpinner> Answers::spinner_;
ros::Subscriber Answers::rosout_;

TEST_F(Answers, TheChecksAreTheLibrarysWords) {
  ranger_msgs::SetLights lights;
  lights.request.front_mode = 7;
  lights.request.rear_mode = ranger_msgs::SetLights::Request::ON;
  lights = call("set_lights", lights);
  expect_answered("set_lights", said(lights.response),
                  {false, ranger::lights_request(7, 0, 1, 0).error().message});

  lights.request.front_mode = ranger_msgs::SetLights::Request::ON;
  lights.request.rear_mode = ranger_msgs::SetLights::Request::CUSTOM;
  lights.request.rear_brightness = 101;
  lights = call("set_lights", lights);
  expect_answered("set_lights", said(lights.response),
                  {false, ranger::lights_request(1, 0, 3, 101).error().message});

  ranger_msgs::SetUltrasonic both;
  both.request.enable = both.request.disable = true;
  both = call("set_ultrasonic", both);
  expect_answered("set_ultrasonic", said(both.response),
                  *ranger::ultrasonic_request_refused(true, true));

  ranger_msgs::SetDriveMode drive;
  drive.request.mode = 5;
  drive = call("set_drive_mode", drive);
  expect_answered("set_drive_mode", said(drive.response),
                  {false, ranger::drive_mode_request(5).error().message});
}

TEST_F(Answers, TheMotionModeAnswersAreTheLibrarysWords) {
  ranger_msgs::SetMotionMode m;
  m.request.mode = 7;
  m = call("set_motion_mode", m);
  expect_answered("set_motion_mode", said(m.response),
                  {false, ranger::unknown_motion_mode_number(7, ranger::manual_profile())});
  m.request.mode = ranger_msgs::SetMotionMode::Request::SPIN;
  m = call("set_motion_mode", m);
  expect_answered("set_motion_mode", said(m.response),
                  {true, ranger::motion_mode_pinned(ranger::MotionMode::kSpin)});
}

TEST_F(Answers, TheRequestsAnswersAreLoggedOnceEachSuccessOrFailure) {
  // resume: re-armed (the library's words), or why not.
  auto resume = call("resume", std_srvs::Trigger{});
  if (resume.response.success) {
    ranger::RequestOutcome answered;
    answered.state = ranger::RequestOutcome::State::kAnswered;
    EXPECT_EQ(resume.response.message, ranger::resume_answer(answered).message);
  }
  expect_logged_once("resume", said(resume.response));
  // park on the manual's chassis: refused by the driver, in its words, logged once as a warning.
  std_srvs::SetBool park;
  park.request.data = true;
  park = call("park", park);
  EXPECT_FALSE(park.response.success);
  expect_logged_once("park", said(park.response));
  // clear_errors: the chassis's answer, in the library's words.
  ranger_msgs::ClearErrors clear;
  clear.request.code = ranger_msgs::ClearErrors::Request::ALL_NON_CRITICAL;
  clear = call("clear_errors", clear);
  EXPECT_EQ(clear.response.message.rfind("clear_errors code 0 (", 0), 0u) << clear.response.message;
  expect_logged_once("clear_errors", said(clear.response));
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_node_answers");
  return RUN_ALL_TESTS();
}
