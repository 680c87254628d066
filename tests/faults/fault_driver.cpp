// A minimal driver process for the fault suite: a ChassisController on a SocketCAN interface,
// commanding one constant twist (as a teleop would, every 20 ms) until SIGINT/SIGTERM, when it
// shuts down cleanly (a zero 0x111). test_faults_vcan.cpp SIGKILLs it instead, so that nothing
// but the chassis's own watchdog can stop the vehicle.
//
//   fault_driver IFACE VX [VY [WZ]]
//
// Prints one line per change of the controller's refusal reason ("refusal: none" once driving).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) {
  g_stop = true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace std::chrono_literals;
  if (argc < 3) {
    std::fprintf(stderr, "usage: fault_driver IFACE VX [VY [WZ]]\n");
    return 2;
  }
  const ranger::BodyTwist twist{std::atof(argv[2]), argc > 3 ? std::atof(argv[3]) : 0.0,
                                argc > 4 ? std::atof(argv[4]) : 0.0};
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  auto bus = ranger::SocketCanBus::open(argv[1]);
  if (!bus) {
    std::fprintf(stderr, "fault_driver: %s\n", bus.error().message.c_str());
    return 1;
  }
  const ranger::SteadyClock clock;
  ranger::ChassisController controller(**bus);
  auto next_command = clock.now();
  auto refusal = ranger::MotionRefusal::kNone;
  bool printed = false;
  while (!g_stop) {
    const auto now = clock.now();
    if (now >= next_command) {
      (void)controller.set_command(twist, now);
      next_command = now + 20ms;
    }
    controller.tick(now);
    if (!printed || controller.state().refusal != refusal) {
      refusal = controller.state().refusal;
      printed = true;
      std::printf("refusal: %s\n", std::string(ranger::to_string(refusal)).c_str());
      std::fflush(stdout);
    }
    const auto wait = std::clamp<std::chrono::nanoseconds>(
        std::min(controller.next_tick_due(), next_command) - clock.now(), 0ns, 20ms);
    for (auto f = (*bus)->receive(wait); f; f = (*bus)->receive(0ns)) {
      controller.on_frame(*f, clock.now());
    }
  }
  controller.shutdown(clock.now());
  std::printf("shut down\n");
  return 0;
}
