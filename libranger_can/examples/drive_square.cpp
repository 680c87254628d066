// drive_square: drives a square with ranger::Driver and prints the odometry, without ROS.
//
//   drive_square [BUS] [SIDE_M]     BUS: sim (default), sim:VARIANT, can0, ...; SIDE_M: 0.5
//
// Crab-drives the four sides (oblique mode: forwards, left, backwards, right, never turning),
// then stops. On a real chassis: wheels off the ground first, or a clear floor of SIDE_M.
// Exit status 0 when the square was driven and the odometry closes it (back within 10 % of a
// side), 1 otherwise (the reason on stderr), 2 for bad arguments.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include <ranger_can/clock.hpp>
#include <ranger_can/control/driver.hpp>
#include <ranger_can/sim/sim_bus_source.hpp>

namespace {

using namespace std::chrono_literals;

void print_pose(const ranger::DriverSnapshot& s, const char* label) {
  std::printf("%-10s x=%+.3f m  y=%+.3f m  yaw=%+.2f deg  refusal=%s\n", label, s.odometry.pose.x,
              s.odometry.pose.y, ranger::rad_to_deg(s.odometry.pose.yaw),
              std::string(ranger::to_string(s.controller.refusal)).c_str());
}

// Publishes `twist` every 50 ms (as a teleop or planner would) for `seconds`.
void drive(ranger::Driver& driver, const ranger::BodyTwist& twist, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    driver.command(ranger::MotionRequest{twist, ranger::protocol::MotionMode::kOblique});
    std::this_thread::sleep_for(50ms);
  }
}

// Publishes `twist` until the odometry has moved `metres` from where it was (each side as long
// as the chassis itself says, however busy the machine), or until `limit_s` has passed.
bool drive_distance(ranger::Driver& driver, const ranger::BodyTwist& twist, double metres,
                    double limit_s) {
  const auto start = driver.snapshot()->odometry.pose;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (std::chrono::steady_clock::now() < end) {
    const auto pose = driver.snapshot()->odometry.pose;
    if (std::hypot(pose.x - start.x, pose.y - start.y) >= metres) return true;
    driver.command(ranger::MotionRequest{twist, ranger::protocol::MotionMode::kOblique});
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string bus = argc > 1 ? argv[1] : "sim";
  const double side = argc > 2 ? std::atof(argv[2]) : 0.5;
  if (argc > 3 || !(side > 0.0 && side <= 5.0)) {
    std::fprintf(stderr, "usage: drive_square [BUS] [SIDE_M (0..5]]\n");
    return 2;
  }
  ranger::SteadyClock clock;
  auto source = ranger::sim::open_bus_source(bus, clock);
  if (!source) {
    std::fprintf(stderr, "drive_square: %s\n", source.error().message.c_str());
    return 2;
  }
  ranger::DriverConfig config;  // the library's defaults: RANGER geometry, manual protocol
  ranger::Driver driver(config, *source, clock);
  driver.start();

  // Wait until the chassis is in CAN command mode (the driver asks for it by itself; a generous
  // limit, so that a busy machine is not mistaken for a silent chassis).
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (driver.snapshot()->controller.control_mode != ranger::protocol::ControlMode::kCan) {
    if (std::chrono::steady_clock::now() > deadline) {
      const auto s = driver.snapshot();
      std::fprintf(stderr, "drive_square: no CAN command mode on %s within 30 s (%s)\n",
                   bus.c_str(), s->bus_open ? std::string(ranger::to_string(s->controller.link)).c_str()
                                            : s->bus_error.c_str());
      return 1;
    }
    std::this_thread::sleep_for(20ms);
  }
  print_pose(*driver.snapshot(), "start");

  const double speed = 0.25;  // m/s
  const ranger::BodyTwist sides[] = {{speed, 0, 0}, {0, speed, 0}, {-speed, 0, 0}, {0, -speed, 0}};
  const char* names[] = {"forwards", "left", "backwards", "right"};
  for (int i = 0; i < 4; ++i) {
    // The first side waits for the switch to oblique mode, every side for the wheels to turn
    // (the driver holds the speed back meanwhile: steer first), before the side is timed.
    drive(driver, sides[i], 0.1);
    while (driver.snapshot()->controller.refusal == ranger::MotionRefusal::kSwitching ||
           driver.snapshot()->controller.steer_first_factor < 1.0) {
      drive(driver, sides[i], 0.05);
    }
    if (!drive_distance(driver, sides[i], side, 3.0 * side / speed + 10.0)) {
      std::fprintf(stderr, "drive_square: the %s side did not reach %.3f m\n", names[i], side);
      driver.stop();
      return 1;
    }
    print_pose(*driver.snapshot(), names[i]);
  }
  drive(driver, {}, 1.0);  // stop and let the chassis settle
  const auto s = driver.snapshot();
  print_pose(*s, "end");
  driver.stop();

  const double closure = std::hypot(s->odometry.pose.x, s->odometry.pose.y);
  std::printf("distance %.3f m, closure error %.3f m\n", s->odometry.distance, closure);
  if (s->odometry.distance < 3.5 * side) {
    std::fprintf(stderr, "drive_square: drove only %.3f m of %.3f m\n", s->odometry.distance,
                 4 * side);
    return 1;
  }
  if (closure > 0.1 * side) {
    std::fprintf(stderr, "drive_square: the square does not close (%.3f m)\n", closure);
    return 1;
  }
  return 0;
}
