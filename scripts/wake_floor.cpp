// What a thread that wakes 60 times a second costs before it does any work of its own: the floor
// under the driver thread's CPU in the vendor-bench VM (docs/PERFORMANCE.md, "Against the vendor's
// driver"). Each wake-up waits in ppoll (an eventfd and a 16.7 ms timeout), then per MODE:
//   idle      nothing
//   clock     two clock_gettime(CLOCK_MONOTONIC)
//   send      the clocks and one frame sent on vcan0 (0x7F0, no RANGER ID)
//   sendrecv  the above and every frame queued on an unfiltered vcan0 socket read (recv)
//   work      about 100 000 instructions of floating-point arithmetic, nothing else
// Prints the process's CPU time (getrusage), user and system, per second and per wake-up.
// Usage: wake_floor MODE SECONDS   (scripts/wake_floor.sh builds and runs it in the VM)
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {
double seconds(const timeval& t) {
  return static_cast<double>(t.tv_sec) + t.tv_usec / 1e6;
}
}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  const int secs = argc > 2 ? std::atoi(argv[2]) : 0;
  if ((mode != "idle" && mode != "clock" && mode != "send" && mode != "sendrecv" &&
       mode != "work") ||
      secs <= 0) {
    std::fprintf(stderr, "usage: wake_floor idle|clock|send|sendrecv|work SECONDS\n");
    return 2;
  }
  const int ev = ::eventfd(0, EFD_NONBLOCK);
  const int s = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (ev < 0 || s < 0) {
    std::perror("wake_floor: eventfd/socket");
    return 1;
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, "vcan0", IFNAMSIZ - 1);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  if (::ioctl(s, SIOCGIFINDEX, &ifr) != 0) {
    std::perror("wake_floor: vcan0");
    return 1;
  }
  addr.can_ifindex = ifr.ifr_ifindex;
  const int one = 1;
  ::setsockopt(s, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one);  // as the driver's socket
  if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    std::perror("wake_floor: bind");
    return 1;
  }
  can_frame frame{};
  frame.can_id = 0x7F0;
  frame.can_dlc = 8;
  const int wakes = secs * 60;
  for (int i = 0; i < wakes; ++i) {
    const timespec period{0, 16'666'667};
    pollfd p{ev, POLLIN, 0};
    ::ppoll(&p, 1, &period, nullptr);
    if (mode == "work") {
      volatile double x = 1.0;
      for (int k = 0; k < 25000; ++k)
        x = x * 1.0000001 + 1e-9;
      continue;
    }
    if (mode == "idle") continue;
    timespec t;
    ::clock_gettime(CLOCK_MONOTONIC, &t);
    ::clock_gettime(CLOCK_MONOTONIC, &t);
    if (mode == "clock") continue;
    ::send(s, &frame, sizeof frame, MSG_DONTWAIT);
    if (mode == "sendrecv") {
      char buf[sizeof(can_frame)];
      while (::recv(s, buf, sizeof buf, MSG_DONTWAIT) > 0) {
      }
    }
  }
  rusage ru{};
  ::getrusage(RUSAGE_SELF, &ru);
  const double user = seconds(ru.ru_utime);
  const double sys = seconds(ru.ru_stime);
  std::printf(
      "%-8s %d wake-ups in %d s: %.2f %% of a core (user %.3f s, system %.3f s), %.0f us each\n",
      mode.c_str(), wakes, secs, 100.0 * (user + sys) / secs, user, sys,
      1e6 * (user + sys) / wakes);
  return 0;
}
