// The bus behaviour suite (bus_behaviour.hpp) on real SocketCAN sockets over vcan0, plus the
// faults only a kernel interface has (removal). Needs vcan0 and root (CAP_NET_ADMIN, to take the
// link down and up and to stall it with a `plug` qdisc). Without vcan0 these tests FAIL; they
// never skip. scripts/run_vcan_tests.sh runs them natively or inside the VM (tests/vm/).
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <system_error>

#include "bus_behaviour.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"

namespace ranger::bus_test {
namespace {

std::string errno_text() {
  return std::system_category().message(errno);
}

// Runs a shell command (ip, tc); records a failure naming it when it does not succeed.
bool run(const std::string& command) {
  const int status = std::system(command.c_str());
  if (status != 0) {
    ADD_FAILURE() << "`" << command << "` failed (status " << status
                  << "): these tests need root and iproute2 (ip, tc) with sch_plug";
    return false;
  }
  return true;
}

bool set_interface_up(const std::string& name, bool up) {
  const int s = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  struct ifreq ifr;
  std::memset(&ifr, 0, sizeof ifr);
  std::strncpy(ifr.ifr_name, name.c_str(), IFNAMSIZ - 1);
  bool ok = s >= 0 && ::ioctl(s, SIOCGIFFLAGS, &ifr) == 0;
  if (ok) {
    ifr.ifr_flags = static_cast<short>(up ? (ifr.ifr_flags | IFF_UP) : (ifr.ifr_flags & ~IFF_UP));
    ok = ::ioctl(s, SIOCSIFFLAGS, &ifr) == 0;
  }
  if (!ok) {
    ADD_FAILURE() << "cannot set " << name << (up ? " up" : " down") << ": " << errno_text()
                  << " (needs root / CAP_NET_ADMIN)";
  }
  if (s >= 0) ::close(s);
  return ok;
}

}  // namespace

class VcanEnv {
 public:
  static constexpr bool kStampsFromManualClock = false;

  VcanEnv() {
    // Undo what an earlier crashed run may have left behind.
    std::system(("tc qdisc show dev " + interface() +
                 " 2>/dev/null | grep -q plug && tc qdisc del dev " + interface() + " root")
                    .c_str());
    if (::if_nametoindex(interface().c_str()) == 0) {
      ADD_FAILURE() << interface()
                    << " does not exist: the vcan tests need it (scripts/run_vcan_tests.sh "
                       "creates it natively or runs the tests in a VM)";
    } else {
      set_interface_up(interface(), true);
    }
  }
  ~VcanEnv() {
    if (stalled_) stall_transmission(false);
    if (!link_up_) set_link_up(true);
  }

  Result<std::unique_ptr<Bus>> open() { return open_interface(interface()); }
  Result<std::unique_ptr<Bus>> open_interface(const std::string& name) {
    SocketCanOptions o;
    o.clock = &clock_;
    o.reopen_interval = reopen_interval();
    auto r = SocketCanBus::open(name, o);
    if (!r) return r.error();
    return std::unique_ptr<Bus>(std::move(r).value());
  }
  std::string interface() const {
    const char* env = std::getenv("RANGER_TEST_VCAN");
    return env && *env ? env : "vcan0";
  }
  std::string missing_interface() const { return "rcan_missing0"; }

  // Writes the error frame from user space through a raw socket, as a controller would report it.
  void inject_error_frame(const CanFrame& f) {
    const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    ASSERT_GE(s, 0) << "socket(AF_CAN): " << errno_text();
    struct sockaddr_can addr;
    std::memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = static_cast<int>(::if_nametoindex(interface().c_str()));
    const struct can_frame kf = socketcan::to_kernel(f);
    const bool ok = ::bind(s, reinterpret_cast<struct sockaddr*>(&addr), sizeof addr) == 0 &&
                    ::write(s, &kf, sizeof kf) == static_cast<ssize_t>(sizeof kf);
    const std::string why = errno_text();
    ::close(s);
    ASSERT_TRUE(ok) << "cannot write an error frame to " << interface() << ": " << why;
  }

  void set_link_up(bool up) {
    if (set_interface_up(interface(), up)) link_up_ = up;
  }

  // A `plug` qdisc holds every transmitted frame: the socket's queue fills as on a bus where
  // nothing acknowledges. 512 bytes = 32 CAN frames.
  void stall_transmission(bool stalled) {
    const std::string dev = interface();
    if (stalled) {
      stalled_ = run("tc qdisc add dev " + dev + " root plug limit 512");
    } else {
      run("tc qdisc change dev " + dev + " root plug release_indefinite");
      stalled_ = !run("tc qdisc del dev " + dev + " root");
    }
  }

  ManualClock& reopen_clock() { return clock_; }
  std::chrono::nanoseconds reopen_interval() const { return std::chrono::seconds(1); }
  Timestamp stamp_clock_now() const { return SystemClock().now(); }  // SO_TIMESTAMPNS's clock
  // Generous: inside the TCG VM everything is 5-10x slower; waits end when the frame arrives.
  std::chrono::nanoseconds delivery_timeout() const { return std::chrono::seconds(20); }

 private:
  ManualClock clock_;
  bool link_up_ = true;
  bool stalled_ = false;
};

INSTANTIATE_TYPED_TEST_SUITE_P(SocketCan, BusBehaviour, VcanEnv);

// ---- faults only a kernel interface has ---------------------------------------------------------

TEST(SocketCanVcan, InterfaceRemovedWhileOpenIsReportedAndReopenedWhenItReturns) {
  const std::string dev = "rcan_tmp0";
  std::system(("ip link del dev " + dev + " 2>/dev/null").c_str());
  ASSERT_TRUE(run("ip link add dev " + dev + " type vcan && ip link set " + dev + " up"));
  ManualClock clock;
  SocketCanOptions o;
  o.clock = &clock;
  auto a = SocketCanBus::open(dev, o);
  auto b = SocketCanBus::open(dev, o);
  ASSERT_TRUE(a.ok() && b.ok());

  ASSERT_TRUE(run("ip link del dev " + dev));  // the adapter is unplugged
  auto sent = (*a)->send(numbered(kDataId, 1));
  ASSERT_FALSE(sent.ok());
  EXPECT_EQ(sent.error().code, Errc::kInterfaceDown);
  EXPECT_NE(sent.error().message.find(dev), std::string::npos) << sent.error().message;
  auto got = (*b)->receive(std::chrono::seconds(20));
  ASSERT_FALSE(got.ok());
  EXPECT_EQ(got.error().code, Errc::kInterfaceDown) << got.error().message;
  EXPECT_NE(got.error().message.find("disappeared"), std::string::npos) << got.error().message;
  EXPECT_NE(got.error().message.find("does not exist"), std::string::npos)
      << "the failed reopen says why: " << got.error().message;

  ASSERT_TRUE(run("ip link add dev " + dev + " type vcan && ip link set " + dev + " up"));
  clock.advance(o.reopen_interval);
  auto idle = (*b)->receive(kQuietWindow);  // reopens on the new interface index
  ASSERT_FALSE(idle.ok());
  EXPECT_EQ(idle.error().code, Errc::kTimeout) << idle.error().message;
  ASSERT_TRUE((*a)->send(numbered(kDataId, 2)).ok()) << (*a)->status().detail;
  auto again = (*b)->receive(std::chrono::seconds(20));
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(sequence_of(*again), 2u);
  EXPECT_EQ((*a)->status().stats.reopens, 1u);
  EXPECT_EQ((*b)->status().stats.reopens, 1u);
  run("ip link del dev " + dev);
}

TEST(SocketCanVcan, ReceiveTimestampsComeFromTheKernelNotFromTheReader) {
  auto a = SocketCanBus::open("vcan0");
  auto b = SocketCanBus::open("vcan0");
  ASSERT_TRUE(a.ok() && b.ok()) << (a ? b.error().message : a.error().message);
  ASSERT_TRUE((*a)->send(numbered(kDataId, 1)).ok());
  // The frame waits in the socket while the reader is busy; its stamp is when it arrived.
  struct pollfd p = {(*b)->fd(), POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 20000), 1);
  const Timestamp arrived_by = SystemClock().now();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  auto r = (*b)->receive(std::chrono::seconds(0));
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_LE(r->stamp, arrived_by);
}

// More frames than one recvmmsg() takes: every one arrives, in order, whatever the batches.
TEST(SocketCanVcan, ABurstLongerThanOneBatchArrivesWholeAndInOrder) {
  const StayOnOneCpu ordered_stream;  // see StayOnOneCpu (bus_behaviour.hpp)
  auto a = SocketCanBus::open("vcan0");
  auto b = SocketCanBus::open("vcan0");
  ASSERT_TRUE(a.ok() && b.ok()) << (a ? b.error().message : a.error().message);
  const std::uint32_t n = 2 * SocketCanBus::kReceiveBatch + 3;
  for (std::uint32_t i = 0; i < n; ++i)
    ASSERT_TRUE((*a)->send(numbered(kDataId, i)).ok()) << i;
  for (std::uint32_t i = 0; i < n; ++i) {
    auto r = (*b)->receive(std::chrono::seconds(20));
    ASSERT_TRUE(r.ok()) << i << ": " << r.error().message;
    EXPECT_EQ(sequence_of(*r), i);
  }
  auto none = (*b)->receive(std::chrono::seconds(0));
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().code, Errc::kTimeout);
  EXPECT_EQ((*b)->status().stats.rx_frames, n);
}

// Frames read in one batch before a filter change are handed out only if the new filter
// passes them: a filter change takes effect at once, not after the buffered batch.
TEST(SocketCanVcan, AFilterChangeAppliesToFramesAlreadyReadInABatch) {
  auto a = SocketCanBus::open("vcan0");
  auto b = SocketCanBus::open("vcan0");
  auto witness = SocketCanBus::open("vcan0");
  ASSERT_TRUE(a.ok() && b.ok() && witness.ok());
  constexpr std::uint32_t kOtherId = protocol::kSystemStatusId;
  for (std::uint32_t i = 0; i < 4; ++i)
    ASSERT_TRUE((*a)->send(numbered(i % 2 ? kOtherId : kDataId, i)).ok());
  // Delivered to every socket at once: when the witness has all four, so has b.
  for (std::uint32_t i = 0; i < 4; ++i)
    ASSERT_TRUE((*witness)->receive(std::chrono::seconds(20)).ok()) << i;
  auto first = (*b)->receive(std::chrono::seconds(0));  // reads all four in one batch
  ASSERT_TRUE(first.ok()) << first.error().message;
  EXPECT_EQ(sequence_of(*first), 0u);
  (*b)->set_filter({kDataId});
  auto second = (*b)->receive(std::chrono::seconds(0));
  ASSERT_TRUE(second.ok()) << second.error().message;
  EXPECT_EQ(second->id, kDataId);
  EXPECT_EQ(sequence_of(*second), 2u);
  auto none = (*b)->receive(std::chrono::seconds(0));
  EXPECT_FALSE(none.ok());
}

}  // namespace ranger::bus_test
