// Fault injection that needs a real kernel socket, on vcan0: an error frame written to the
// interface (bus-off, then restart) while a `plug` qdisc holds every frame, the interface taken
// down and up, and a driver *process* killed with SIGKILL while `ranger_can sim` runs. The
// chassis runs on its own thread (VirtualChassisRunner) or as the CLI process, on the real clock.
// Assertions are on outcomes, with generous time limits (the throwaway VM runs several times
// slower than real hardware); where timing is asserted, it is on the kernel's frame timestamps.
//
// Needs vcan0 and root (ip, tc with sch_plug); without them these tests FAIL, they never skip.
// scripts/run_vcan_tests.sh runs them natively or inside the VM (tests/vm/run_in_vm.sh).
#include <gtest/gtest.h>
#include <linux/can.h>
#include <net/if.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/sim/virtual_chassis_runner.hpp"
#include "ranger_can/transport/error_frame.hpp"
#include "ranger_can/transport/socketcan_bus.hpp"
#include "wire_audit.hpp"

extern char** environ;

namespace ranger::faults {
namespace {

using namespace std::chrono_literals;

std::string interface_name() {
  const char* env = std::getenv("RANGER_TEST_VCAN");
  return env && *env ? env : "vcan0";
}

std::string errno_text() {
  return std::system_category().message(errno);
}

// Writes an error frame onto the interface through a raw socket, as a CAN controller reports one.
void write_error_frame(const CanFrame& f) {
  const int s = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  ASSERT_GE(s, 0) << "socket(AF_CAN): " << errno_text();
  struct sockaddr_can addr;
  std::memset(&addr, 0, sizeof addr);
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(::if_nametoindex(interface_name().c_str()));
  const struct can_frame kf = socketcan::to_kernel(f);
  const bool ok = ::bind(s, reinterpret_cast<struct sockaddr*>(&addr), sizeof addr) == 0 &&
                  ::write(s, &kf, sizeof kf) == static_cast<ssize_t>(sizeof kf);
  const std::string why = errno_text();
  ::close(s);
  ASSERT_TRUE(ok) << "cannot write an error frame to " << interface_name() << ": " << why;
}

std::unique_ptr<SocketCanBus> open_or_fail(
    std::vector<std::uint32_t> filter = protocol::all_ids()) {
  SocketCanOptions o;
  o.filter = std::move(filter);
  auto bus = SocketCanBus::open(interface_name(), o);
  if (!bus) {
    ADD_FAILURE() << "cannot open " << interface_name() << ": " << bus.error().message
                  << " (scripts/run_vcan_tests.sh creates vcan0 or runs the tests in a VM)";
    return nullptr;
  }
  return std::move(*bus);
}

// Leaves vcan0 as a test found it even when the test fails half-way.
class InterfaceGuard {
 public:
  InterfaceGuard() {
    std::system(("tc qdisc del dev " + interface_name() + " root 2>/dev/null").c_str());
    std::system(("ip link set dev " + interface_name() + " up").c_str());
  }
  ~InterfaceGuard() {
    std::system(("tc qdisc del dev " + interface_name() + " root 2>/dev/null").c_str());
    std::system(("ip link set dev " + interface_name() + " up").c_str());
  }
};

// The driver loop on the test's thread, the chassis on its runner thread, an observer socket.
class VcanFaultRig {
 public:
  // Slack of the wire audit's staleness rule: how late the driver may read a frame the observer
  // already has (scheduling in the VM).
  static constexpr std::chrono::nanoseconds kAuditSlack = 500ms;
  static constexpr double kTimingSlack = 5.0;

  VcanFaultRig()
      : chassis_bus_(open_or_fail()),
        driver_bus_(open_or_fail()),
        observer_bus_(open_or_fail({})),
        audit_(ControllerConfig{}, kAuditSlack) {
    if (!ready()) return;
    runner_ = std::make_unique<sim::VirtualChassisRunner>(*chassis_bus_,
                                                          sim::VirtualChassisConfig{}, clock_);
    controller_ = std::make_unique<ChassisController>(*driver_bus_);
  }
  ~VcanFaultRig() {
    controller_.reset();
    if (runner_) runner_->stop();
  }
  bool ready() const { return chassis_bus_ && driver_bus_ && observer_bus_; }

  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
    if (!runner_) return false;
    const Timestamp end =
        clock_.now() + std::chrono::duration_cast<std::chrono::nanoseconds>(timeout * kTimingSlack);
    while (clock_.now() < end) {
      step();
      EXPECT_TRUE(runner_->running()) << runner_->failure();
      if (done()) return true;
    }
    return done();
  }
  void run_for(std::chrono::nanoseconds d) {
    const Timestamp end = clock_.now() + d;
    while (clock_.now() < end)
      step();
  }
  void command(const BodyTwist& twist) {
    request_ = twist;
    next_request_ = clock_.now();
  }
  // Runs a shell command (ip, tc) on another thread while the driver loop keeps running, as the
  // fault would strike a running driver; records a failure naming it when it does not succeed.
  bool run(const std::string& shell_command) {
    std::atomic<bool> done{false};
    int status = -1;
    std::thread t([&] {
      status = std::system(shell_command.c_str());
      done = true;
    });
    while (!done)
      step();
    t.join();
    if (status != 0) {
      ADD_FAILURE() << "`" << shell_command << "` failed (status " << status
                    << "): these tests need root and iproute2 (ip, tc) with sch_plug";
    }
    return status == 0;
  }

  ChassisController& controller() { return *controller_; }
  const ControllerState& state() const { return controller_->state(); }
  SocketCanBus& driver_bus() { return *driver_bus_; }
  sim::ChassisSnapshot snapshot() {
    sim::ChassisSnapshot s;
    runner_->with_chassis([&](sim::VirtualChassis& c) { s = c.snapshot(); });
    return s;
  }
  const WireAudit& audit() const { return audit_; }

  // After an involuntary stop whose cause has cleared: held at rest (kRearmRequired) while the
  // caller asks for `twist`, and after a zero twist (no re-arm); resume re-arms; then `twist`
  // drives above `min_speed`.
  ::testing::AssertionResult rearm_by_resume_then_drive(const BodyTwist& twist, double min_speed) {
    command(twist);
    if (!run_until([&] { return state().refusal == MotionRefusal::kRearmRequired; }, 2s)) {
      return ::testing::AssertionFailure() << "refusal " << to_string(state().refusal);
    }
    run_for(500ms);
    command(BodyTwist{});
    run_for(200ms);
    command(twist);
    run_for(300ms);
    if (snapshot().speed != 0.0) return ::testing::AssertionFailure() << "moved before the re-arm";
    if (state().refusal != MotionRefusal::kRearmRequired) {
      return ::testing::AssertionFailure() << "re-armed without resume";
    }
    // The re-arm, asked while the chassis is heard. In the VM on a loaded host the chassis's
    // thread can go unscheduled past link_timeout: the driver then refuses the resume, rightly
    // ("not connected (stale)"), and latches the silence; the caller asks again once the chassis
    // is heard (each refusal is reported by the retry that follows it, up to five).
    std::string refusals;
    for (int attempt = 1;; ++attempt) {
      if (!run_until([&] { return state().link == LinkState::kConnected; }, 2s)) {
        return ::testing::AssertionFailure() << "chassis not heard again" << refusals;
      }
      audit_.on_rearm_attempt(clock_.now());
      const Status st = controller_->resume(clock_.now());
      if (st) break;
      refusals += "; resume " + std::to_string(attempt) + " refused: " + st.error().message;
      if (state().link == LinkState::kConnected || attempt == 5) {
        return ::testing::AssertionFailure() << "resume refused" << refusals;
      }
      std::printf("[ retry    ] resume %d refused while the chassis was silent: %s\n", attempt,
                  st.error().message.c_str());
    }
    return drive(twist, min_speed);
  }

  ::testing::AssertionResult drive(const BodyTwist& twist, double min_speed) {
    if (!ready()) return ::testing::AssertionFailure() << "no vcan";
    command(twist);
    if (run_until([&] { return snapshot().speed >= min_speed; }, 10s)) {
      return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure()
           << "chassis at " << snapshot().speed << " m/s; refusal " << to_string(state().refusal);
  }

 private:
  void step() {
    const Timestamp now = clock_.now();
    if (request_ && now >= next_request_) {
      EXPECT_TRUE(controller_->set_command(*request_, now).ok());
      next_request_ = now + 20ms;
    }
    controller_->tick(now);
    const auto wait =
        std::clamp<std::chrono::nanoseconds>(controller_->next_tick_due() - clock_.now(), 0ns, 5ms);
    for (auto f = driver_bus_->receive(wait); f; f = driver_bus_->receive(0ns)) {
      controller_->on_frame(*f, clock_.now());
    }
    for (;;) {
      auto f = observer_bus_->receive(0ns);
      if (!f) {
        if (f.error().code == Errc::kInterfaceDown) audit_.forget();
        break;
      }
      audit_.on_frame(*f);
    }
  }

  SteadyClock clock_;
  std::unique_ptr<SocketCanBus> chassis_bus_;
  std::unique_ptr<SocketCanBus> driver_bus_;
  std::unique_ptr<SocketCanBus> observer_bus_;
  std::unique_ptr<sim::VirtualChassisRunner> runner_;
  std::unique_ptr<ChassisController> controller_;
  WireAudit audit_;
  std::optional<BodyTwist> request_;
  Timestamp next_request_{0};
};

class VcanFaults : public ::testing::Test {
 protected:
  void TearDown() override {
    for (const std::string& v : rig_.audit().violations())
      ADD_FAILURE() << "wire audit: " << v;
  }
  InterfaceGuard guard_;
  VcanFaultRig rig_;
};

TEST_F(VcanFaults, BusOffFromAnErrorFrameStopsTheChassisAndRestartResumes) {
  ASSERT_TRUE(rig_.drive({0.5, 0, 0}, 0.45));
  const BusStatistics before = rig_.driver_bus().status().stats;

  // The controller reports bus-off; then nothing is acknowledged (a plug qdisc holds every frame).
  write_error_frame(can_error::make(can_error::kBusOff));
  ASSERT_TRUE(
      rig_.run_until([&] { return rig_.driver_bus().status().state == BusState::kBusOff; }, 2s));
  ASSERT_TRUE(rig_.run("tc qdisc add dev " + interface_name() + " root plug limit 512"));
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().refusal == MotionRefusal::kLinkLost; }, 2s));
  // The driver treats bus-off as link loss at once, so the zero commands it sent before the plug
  // went in may stop the chassis first; then no 0x111 gets through and the chassis's own
  // watchdog declares the host lost.
  ASSERT_TRUE(rig_.run_until([&] { return rig_.snapshot().speed == 0.0; }, 3s));
  ASSERT_TRUE(rig_.run_until([&] { return rig_.snapshot().host_link_lost; }, 2s))
      << "no 0x111 may get through the plugged queue";

  // Restart: the queue drains, traffic flows again, the controller reports error-active again
  // (the restart report is written once frames flow: right after the qdisc is removed the kernel
  // may still drop a frame); motion resumes after the caller's re-arm (link loss latches).
  ASSERT_TRUE(
      rig_.run("tc qdisc change dev " + interface_name() + " root plug release_indefinite"));
  ASSERT_TRUE(rig_.run("tc qdisc del dev " + interface_name() + " root"));
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().link == LinkState::kConnected; }, 3s));
  write_error_frame(can_error::make(can_error::kRestarted));
  ASSERT_TRUE(
      rig_.run_until([&] { return rig_.driver_bus().status().state == BusState::kActive; }, 2s))
      << "bus " << to_string(rig_.driver_bus().status().state) << " ("
      << rig_.driver_bus().status().detail << ")";
  ASSERT_TRUE(rig_.rearm_by_resume_then_drive({0.5, 0, 0}, 0.45));
  const BusStatistics after = rig_.driver_bus().status().stats;
  EXPECT_EQ(after.restarts - before.restarts, 1u);
  EXPECT_GE(after.error_frames - before.error_frames, 2u);
  EXPECT_FALSE(rig_.snapshot().host_link_lost);
}

TEST_F(VcanFaults, InterfaceDownAndUpStopsTheChassisThenReopensAndResumes) {
  ASSERT_TRUE(rig_.drive({0.5, 0, 0}, 0.45));
  const BusStatistics before = rig_.driver_bus().status().stats;

  ASSERT_TRUE(rig_.run("ip link set dev " + interface_name() + " down"));
  ASSERT_TRUE(rig_.run_until(
      [&] {
        return rig_.driver_bus().status().state == BusState::kDown &&
               rig_.state().refusal == MotionRefusal::kLinkLost;
      },
      2s));
  ASSERT_TRUE(rig_.run_until([&] { return rig_.snapshot().speed == 0.0; }, 3s));
  EXPECT_TRUE(rig_.snapshot().host_link_lost);
  rig_.run_for(1s);
  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kDown);

  ASSERT_TRUE(rig_.run("ip link set dev " + interface_name() + " up"));
  ASSERT_TRUE(rig_.run_until([&] { return rig_.state().link == LinkState::kConnected; }, 5s))
      << "refusal " << to_string(rig_.state().refusal);
  ASSERT_TRUE(rig_.rearm_by_resume_then_drive({0.5, 0, 0}, 0.45));
  EXPECT_EQ(rig_.driver_bus().status().state, BusState::kActive);
  EXPECT_GE(rig_.driver_bus().status().stats.reopens - before.reopens, 1u);
  EXPECT_FALSE(rig_.snapshot().host_link_lost);
}

// ---- a real driver process, killed --------------------------------------------------------------

// A child process with its output in a log file; killed (SIGKILL) if still running at the end.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::string& log) {
    std::vector<char*> args;
    for (const std::string& a : argv)
      args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    const int rc = posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
      ADD_FAILURE() << "cannot start " << argv[0] << ": " << std::system_category().message(rc);
      pid_ = -1;
    }
  }
  ~Process() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  bool started() const { return pid_ > 0; }
  bool alive() const { return pid_ > 0 && ::waitpid(pid_, nullptr, WNOHANG) == 0; }
  // Sends `signal` and reaps the process; returns its wait status.
  int kill_and_wait(int signal) {
    int status = -1;
    if (pid_ > 0) {
      ::kill(pid_, signal);
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
    return status;
  }

 private:
  pid_t pid_ = -1;
};

TEST(VcanFaultsProcess, SigkilledDriverLeavesTheChassisToStopByItsWatchdog) {
  InterfaceGuard guard;
  auto observer = open_or_fail({});
  ASSERT_TRUE(observer);
  const std::string log_dir = RANGER_FAULTS_LOG_DIR;
  Process sim({RANGER_CLI_PATH, "sim", interface_name(), "--no-stdin", "--duration", "120"},
              log_dir + "/sigkill_sim.log");
  Process driver({RANGER_FAULT_DRIVER_PATH, interface_name(), "0.5"},
                 log_dir + "/sigkill_driver.log");
  ASSERT_TRUE(sim.started() && driver.started());
  WireAudit audit(ControllerConfig{}, VcanFaultRig::kAuditSlack);

  // Reads the observer until `done(frame)` or the timeout; every frame goes through the audit
  // and updates what the wire last said.
  const SteadyClock clock;
  Timestamp last_command{0}, first_slower{0}, stopped{0};
  double speed = -1.0;
  bool host_lost_reported = false;
  auto read_until = [&](const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
    const Timestamp end = clock.now() + timeout;
    while (clock.now() < end) {
      auto f = observer->receive(20ms);
      if (!f) continue;
      audit.on_frame(*f);
      const auto m = decode(*f);
      if (!m) continue;
      if (f->id == protocol::kMotionCommandId) last_command = f->stamp;
      if (const auto* s = std::get_if<SystemStatus>(&*m)) {
        host_lost_reported = s->error_bits & (1u << protocol::error_bit_index(6, 1));
      }
      if (const auto* mf = std::get_if<MotionFeedback>(&*m)) {
        speed = mf->speed;
        if (last_command.count() != 0 && first_slower.count() == 0 && speed < 0.45) {
          first_slower = f->stamp;
        }
        if (speed == 0.0 && stopped.count() == 0) stopped = f->stamp;
      }
      if (done()) return true;
    }
    return false;
  };

  ASSERT_TRUE(read_until([&] { return speed >= 0.45; }, 60s))
      << "the driver never got the simulated chassis moving (see " << log_dir << "/sigkill_*.log)";

  // SIGKILL: no shutdown, no stop frame. 0x111 frames the kernel had already taken may still
  // appear on the wire; the last one counts.
  const int status = driver.kill_and_wait(SIGKILL);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  first_slower = stopped = Timestamp{0};
  ASSERT_TRUE(read_until([&] { return stopped.count() != 0 && host_lost_reported; }, 30s))
      << "the chassis did not stop after the driver was killed (speed " << speed << ")";
  ASSERT_NE(last_command.count(), 0) << "no 0x111 seen after the kill was started";
  // On the kernel's timestamps: the chassis kept the last command until its 500 ms watchdog (not
  // before: the driver sent no stop), and it braked right after (generous bound for the VM).
  const auto watchdog = std::chrono::milliseconds(protocol::kChassisCommandTimeoutMs);
  std::printf("[faults] sigkill: last 0x111 -> first slower 0x221 %.1f ms, -> stopped %.1f ms\n",
              std::chrono::duration<double, std::milli>(first_slower - last_command).count(),
              std::chrono::duration<double, std::milli>(stopped - last_command).count());
  EXPECT_GE(first_slower - last_command, watchdog - 50ms);
  EXPECT_LE(first_slower - last_command, watchdog + 1500ms);
  EXPECT_GT(stopped, first_slower);
  EXPECT_TRUE(sim.alive()) << "the simulated chassis must outlive its driver";
  const int sim_status = sim.kill_and_wait(SIGTERM);
  EXPECT_TRUE(WIFEXITED(sim_status) && WEXITSTATUS(sim_status) == 0) << "status " << sim_status;
  for (const std::string& v : audit.violations())
    ADD_FAILURE() << "wire audit: " << v;
}

}  // namespace
}  // namespace ranger::faults
