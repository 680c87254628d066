#include "ranger_can/transport/socketcan_bus.hpp"

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>
#ifdef SO_MEMINFO
#include <linux/sock_diag.h>
#endif

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <deque>
#include <optional>
#include <system_error>
#include <thread>

#include "bus_internal.hpp"
#include "ranger_can/transport/error_frame.hpp"

namespace ranger {

// Our error-class constants must be the kernel's.
static_assert(can_error::kTxTimeout == CAN_ERR_TX_TIMEOUT);
static_assert(can_error::kLostArbitration == CAN_ERR_LOSTARB);
static_assert(can_error::kController == CAN_ERR_CRTL);
static_assert(can_error::kProtocol == CAN_ERR_PROT);
static_assert(can_error::kTransceiver == CAN_ERR_TRX);
static_assert(can_error::kNoAck == CAN_ERR_ACK);
static_assert(can_error::kBusOff == CAN_ERR_BUSOFF);
static_assert(can_error::kBusError == CAN_ERR_BUSERROR);
static_assert(can_error::kRestarted == CAN_ERR_RESTARTED);
static_assert(can_error::kClassMask == CAN_ERR_MASK);
static_assert(can_error::kCtrlRxOverflow == CAN_ERR_CRTL_RX_OVERFLOW);
static_assert(can_error::kCtrlTxOverflow == CAN_ERR_CRTL_TX_OVERFLOW);
static_assert(can_error::kCtrlRxWarning == CAN_ERR_CRTL_RX_WARNING);
static_assert(can_error::kCtrlTxWarning == CAN_ERR_CRTL_TX_WARNING);
static_assert(can_error::kCtrlRxPassive == CAN_ERR_CRTL_RX_PASSIVE);
static_assert(can_error::kCtrlTxPassive == CAN_ERR_CRTL_TX_PASSIVE);
static_assert(can_error::kCtrlActive == CAN_ERR_CRTL_ACTIVE);
static_assert(can_error::kErrorFrameDlc == CAN_ERR_DLC);

using bus_internal::hex_id;
using bus_internal::IdFilter;
using bus_internal::ReopenSchedule;
using bus_internal::StatusTracker;
using bus_internal::UniqueFd;

namespace {

std::string errno_text(int err) {
  return std::system_category().message(err);
}

bool is_interface_loss(int err) {
  return err == ENETDOWN || err == ENODEV || err == ENXIO;
}

std::string loss_reason(int err) {
  if (err == ENETDOWN) return "interface went down (ENETDOWN)";
  return "interface disappeared (" + errno_text(err) + "; adapter unplugged?)";
}

const char* link_type_name(int type) {
  switch (type) {
    case ARPHRD_ETHER:
      return "Ethernet";
    case ARPHRD_LOOPBACK:
      return "loopback";
    case ARPHRD_NONE:
      return "none (tun)";
    default:
      return "not CAN";
  }
}

bool kernel_has_can() {
  UniqueFd s(::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW));
  return s.valid() || (errno != EAFNOSUPPORT && errno != EPROTONOSUPPORT);
}

// What a user can do on a kernel without CAN support, for interface `name`.
std::string no_can_support_hint(const std::string& name) {
  return "this kernel has no CAN support loaded: load it with `sudo modprobe can-raw` (a "
         "USB-to-CAN adapter also needs `sudo modprobe gs_usb`), then bring the interface up with "
         "`sudo ip link set " +
         name +
         " up type can bitrate 500000`; without any CAN support only the virtual chassis (`sim`) "
         "or a recorded log (`replay:FILE`) can be used";
}

void fill_ifreq(struct ifreq& ifr, const std::string& name) {
  std::memset(&ifr, 0, sizeof ifr);
  std::memcpy(ifr.ifr_name, name.data(), std::min(name.size(), sizeof ifr.ifr_name - 1));
}

std::vector<struct can_filter> kernel_filters(const std::vector<std::uint32_t>& ids) {
  std::vector<struct can_filter> filters;
  // Standard-ID data frames only: the EFF and RTR flags are part of every mask.
  const canid_t flags = CAN_EFF_FLAG | CAN_RTR_FLAG;
  if (ids.empty()) {
    filters.push_back({0, flags});
  } else {
    for (std::uint32_t id : ids)
      filters.push_back({static_cast<canid_t>(id), CAN_SFF_MASK | flags});
  }
  return filters;
}

Status apply_filter(int fd, const std::vector<std::uint32_t>& ids, const std::string& name) {
  const auto filters = kernel_filters(ids);
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                   static_cast<socklen_t>(filters.size() * sizeof(struct can_filter))) != 0) {
    return Error{Errc::kIoError, name + ": cannot install the receive filter (" +
                                     std::to_string(filters.size()) +
                                     " IDs): " + errno_text(errno)};
  }
  return ok_status();
}

Errc errc_for(int err) {
  if (err == EPERM || err == EACCES) return Errc::kPermissionDenied;
  if (err == ENODEV || err == ENXIO) return Errc::kNoSuchInterface;
  if (err == ENETDOWN) return Errc::kInterfaceDown;
  return Errc::kIoError;
}

// The rx drop counter the kernel keeps for a socket, right now (SO_MEMINFO), or -1.
long long current_socket_drops(int fd) {
#ifdef SO_MEMINFO
  std::uint32_t meminfo[SK_MEMINFO_VARS] = {};
  socklen_t len = sizeof meminfo;
  if (::getsockopt(fd, SOL_SOCKET, SO_MEMINFO, meminfo, &len) == 0 &&
      len >= (SK_MEMINFO_DROPS + 1) * sizeof(std::uint32_t)) {
    return meminfo[SK_MEMINFO_DROPS];
  }
#else
  (void)fd;
#endif
  return -1;
}

}  // namespace

// ---- the socket and the per-bus state -----------------------------------------------------------

struct SocketCanBus::Socket {
  UniqueFd fd;
  // Last value of the kernel's per-socket rx drop counter we accounted for (guarded by mutex_).
  std::uint32_t drops_seen = 0;
};

struct SocketCanBus::State {
  State(const std::string& name, const Clock& clock, std::chrono::nanoseconds reopen_interval)
      : tracker(name), schedule(clock, reopen_interval) {}
  StatusTracker tracker;
  ReopenSchedule schedule;
  IdFilter filter;
  std::shared_ptr<Socket> socket;  // null while the interface is down
  // Since the last status(): frames were read, one recvmmsg filled its whole batch.
  bool read_since_status = false;
  bool full_batch_since_status = false;

  // Accounts for the kernel's cumulative drop counter of `s` having reached `count`.
  void account_drops(Socket& s, std::uint32_t count) {
    const std::uint32_t delta = count - s.drops_seen;  // the counter wraps like the kernel's
    if (delta > 0 && delta < 0x80000000u) {
      tracker.stats().rx_dropped += delta;
      s.drops_seen = count;
    }
  }
};

namespace {

Result<UniqueFd> open_can_socket(const std::string& name, const std::vector<std::uint32_t>& filter,
                                 int receive_buffer_bytes) {
  if (name.empty()) return Error{Errc::kInvalidArgument, "CAN interface name is empty"};
  if (name.size() >= IFNAMSIZ) {
    return Error{Errc::kNoSuchInterface, "CAN interface '" + name +
                                             "' does not exist (names are at most " +
                                             std::to_string(IFNAMSIZ - 1) + " characters)"};
  }
  const unsigned ifindex = ::if_nametoindex(name.c_str());
  if (ifindex == 0) {
    const int err = errno;
    std::string msg = "CAN interface '" + name + "' does not exist";
    if (err != ENODEV && err != ENXIO) msg += " (" + errno_text(err) + ")";
    msg += kernel_has_can() ? "; `ip link show` lists the interfaces"
                            : "; also, " + no_can_support_hint(name);
    return Error{Errc::kNoSuchInterface, msg};
  }

  // Link type and flags through a control socket, so that a non-CAN interface is named as such
  // even on a kernel without CAN support.
  UniqueFd ctl(::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0));
  if (!ctl.valid())
    return Error{Errc::kIoError, "cannot create a control socket: " + errno_text(errno)};
  struct ifreq ifr;
  fill_ifreq(ifr, name);
  if (::ioctl(ctl.get(), SIOCGIFHWADDR, &ifr) != 0) {
    const int err = errno;
    return Error{errc_for(err), "cannot read the link type of '" + name + "': " + errno_text(err)};
  }
  const int link_type = ifr.ifr_hwaddr.sa_family;
  if (link_type != ARPHRD_CAN) {
    return Error{Errc::kNotCanInterface,
                 "interface '" + name + "' is not a CAN interface (link type " +
                     std::to_string(link_type) + " = " + link_type_name(link_type) + ", expected " +
                     std::to_string(ARPHRD_CAN) + " = CAN)"};
  }

  UniqueFd fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  if (!fd.valid()) {
    const int err = errno;
    if (err == EAFNOSUPPORT || err == EPROTONOSUPPORT) {
      return Error{Errc::kIoError, "cannot open '" + name + "': " + no_can_support_hint(name)};
    }
    return Error{errc_for(err), "cannot open a CAN socket for '" + name + "': " + errno_text(err)};
  }

  fill_ifreq(ifr, name);
  if (::ioctl(ctl.get(), SIOCGIFFLAGS, &ifr) != 0) {
    const int err = errno;
    return Error{errc_for(err), "cannot read the flags of '" + name + "': " + errno_text(err)};
  }
  if (!(ifr.ifr_flags & IFF_UP)) {
    return Error{Errc::kInterfaceDown,
                 "CAN interface '" + name + "' is down: bring it up with `sudo ip link set " +
                     name + " up type can bitrate 500000` (a vcan interface: `sudo ip link set " +
                     name + " up`)"};
  }

  if (auto st = apply_filter(fd.get(), filter, name); !st) return st.error();
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  const int one = 1;
  struct Option {
    int level, name;
    const void* value;
    socklen_t size;
    const char* what;
  };
  const Option options[] = {
      {SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask, "CAN_RAW_ERR_FILTER"},
      {SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one, "SO_TIMESTAMPNS"},
      {SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one, "SO_RXQ_OVFL"},
  };
  for (const Option& o : options) {
    if (::setsockopt(fd.get(), o.level, o.name, o.value, o.size) != 0) {
      return Error{Errc::kIoError, "cannot set " + std::string(o.what) + " on '" + name +
                                       "': " + errno_text(errno)};
    }
  }
  if (receive_buffer_bytes > 0 &&
      ::setsockopt(fd.get(), SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes,
                   sizeof receive_buffer_bytes) != 0) {
    return Error{Errc::kIoError, "cannot set SO_RCVBUF on '" + name + "': " + errno_text(errno)};
  }

  struct sockaddr_can addr;
  std::memset(&addr, 0, sizeof addr);
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(ifindex);
  if (::bind(fd.get(), reinterpret_cast<struct sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    return Error{errc_for(err), "cannot bind a CAN socket to '" + name + "': " + errno_text(err)};
  }
  return fd;
}

}  // namespace

// ---- SocketCanBus -------------------------------------------------------------------------------

namespace {
const Clock& default_reopen_clock() {
  static const SteadyClock clock;
  return clock;
}
}  // namespace

Result<std::unique_ptr<SocketCanBus>> SocketCanBus::open(const std::string& interface,
                                                         SocketCanOptions options) {
  IdFilter filter;
  filter.set(options.filter);
  auto fd = open_can_socket(interface, filter.ids(), options.receive_buffer_bytes);
  if (!fd) return fd.error();
  auto socket = std::make_shared<Socket>();
  socket->fd = std::move(fd).value();
  return std::make_unique<SocketCanBus>(Key{}, interface, std::move(options), std::move(socket));
}

// The buffers of one recvmmsg(), and the frames it read that receive() has not returned yet.
struct SocketCanBus::ReceiveBatch {
  static constexpr std::size_t kControlBytes =
      CMSG_SPACE(sizeof(struct timespec)) + CMSG_SPACE(sizeof(std::uint32_t));
  struct alignas(struct cmsghdr) Control {
    char bytes[kControlBytes];
  };
  std::array<struct can_frame, kReceiveBatch> frames;
  std::array<struct iovec, kReceiveBatch> iov;
  std::array<Control, kReceiveBatch> control;
  std::array<struct mmsghdr, kReceiveBatch> msgs;
  std::deque<Result<CanFrame>> ready;
  std::uint64_t filter_generation = 0;  // the filter `ready` passed

  // Points the headers at the buffers again (the kernel rewrites the lengths).
  void reset() {
    for (std::size_t i = 0; i < kReceiveBatch; ++i) {
      iov[i] = {&frames[i], sizeof frames[i]};
      std::memset(&msgs[i], 0, sizeof msgs[i]);
      msgs[i].msg_hdr.msg_iov = &iov[i];
      msgs[i].msg_hdr.msg_iovlen = 1;
      msgs[i].msg_hdr.msg_control = control[i].bytes;
      msgs[i].msg_hdr.msg_controllen = kControlBytes;
    }
  }
};

SocketCanBus::SocketCanBus(Key, std::string interface, SocketCanOptions options,
                           std::shared_ptr<Socket> socket)
    : interface_(std::move(interface)),
      options_(std::move(options)),
      rx_(std::make_unique<ReceiveBatch>()) {
  const Clock& clock = options_.clock ? *options_.clock : default_reopen_clock();
  state_ = std::make_unique<State>(interface_, clock, options_.reopen_interval);
  state_->filter.set(options_.filter);
  state_->socket = std::move(socket);
}

SocketCanBus::~SocketCanBus() = default;

std::shared_ptr<SocketCanBus::Socket> SocketCanBus::acquire_socket() {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_->socket ? state_->socket : reopen_if_due_locked();
}

std::shared_ptr<SocketCanBus::Socket> SocketCanBus::reopen_if_due_locked() {
  State& s = *state_;
  if (!s.schedule.due()) return nullptr;
  auto fd = open_can_socket(interface_, s.filter.ids(), options_.receive_buffer_bytes);
  if (!fd) {
    s.schedule.on_failed();
    s.tracker.on_reopen_failed(fd.error().message);
    return nullptr;
  }
  s.socket = std::make_shared<Socket>();
  s.socket->fd = std::move(fd).value();
  s.tracker.on_reopened();
  return s.socket;
}

std::shared_ptr<SocketCanBus::Socket> SocketCanBus::on_interface_lost(
    const std::shared_ptr<Socket>& failed, int err) {
  std::lock_guard<std::mutex> lock(mutex_);
  State& s = *state_;
  if (s.socket != failed) {  // another call got there first
    return s.socket ? s.socket : reopen_if_due_locked();
  }
  if (const long long drops = current_socket_drops(failed->fd.get()); drops >= 0) {
    s.account_drops(*failed, static_cast<std::uint32_t>(drops));
  }
  s.socket.reset();  // closed once no other call still uses it
  s.tracker.on_lost(loss_reason(err));
  s.schedule.on_lost();
  return reopen_if_due_locked();  // the first attempt is immediate: a short blip heals at once
}

Error SocketCanBus::down_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return Error{Errc::kInterfaceDown, state_->tracker.status().detail};
}

Status SocketCanBus::send(const CanFrame& frame) {
  if (auto st = bus_internal::validate_outgoing(frame, interface_); !st) return st;
  auto socket = acquire_socket();
  if (!socket) return down_error();
  const struct can_frame kf = socketcan::to_kernel(frame);
  ssize_t n;
  int err;
  for (int attempt = 0;; ++attempt) {
    do {
      n = ::send(socket->fd.get(), &kf, sizeof kf, MSG_DONTWAIT | MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    err = errno;
    if (n >= 0 || !is_interface_loss(err)) break;
    socket = on_interface_lost(socket, err);
    if (!socket || attempt > 0) return down_error();
  }
  if (n == static_cast<ssize_t>(sizeof kf)) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++state_->tracker.stats().tx_frames;
    return ok_status();
  }
  if (n >= 0) {
    return Error{Errc::kIoError, interface_ + ": short write of frame " + hex_id(frame.id) + " (" +
                                     std::to_string(n) + " bytes)"};
  }
  if (err == EAGAIN || err == EWOULDBLOCK || err == ENOBUFS) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++state_->tracker.stats().tx_dropped;
    return Error{Errc::kWouldBlock,
                 interface_ + ": transmit queue full, frame " + hex_id(frame.id) +
                     " dropped (is anything acknowledging frames? chassis on, bitrate 500k?)"};
  }
  return Error{errc_for(err),
               interface_ + ": cannot send frame " + hex_id(frame.id) + ": " + errno_text(err)};
}

int SocketCanBus::read_batch(const std::shared_ptr<Socket>& socket, int& err) {
  ReceiveBatch& b = *rx_;
  b.reset();
  const int n = ::recvmmsg(socket->fd.get(), b.msgs.data(), static_cast<unsigned>(kReceiveBatch),
                           MSG_DONTWAIT, nullptr);
  err = errno;
  if (n < 0) return (err == EAGAIN || err == EWOULDBLOCK) ? 0 : -1;

  struct timespec now_ts {};
  bool have_now = false;
  std::lock_guard<std::mutex> lock(mutex_);  // once for the whole batch
  State& s = *state_;
  if (b.ready.empty()) b.filter_generation = filter_generation_.load();
  if (n > 0) s.read_since_status = true;
  if (n == static_cast<int>(kReceiveBatch)) s.full_batch_since_status = true;
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
    struct msghdr& msg = b.msgs[i].msg_hdr;
    Timestamp stamp{0};
    bool have_drops = false;
    std::uint32_t drops = 0;
    for (struct cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SCM_TIMESTAMPNS) {
        struct timespec ts;
        std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
        stamp = std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec);
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
        have_drops = true;
      }
    }
    if (stamp.count() == 0) {  // never seen, but a frame must not claim time zero
      if (!have_now) {
        ::clock_gettime(CLOCK_REALTIME, &now_ts);
        have_now = true;
      }
      stamp = std::chrono::seconds(now_ts.tv_sec) + std::chrono::nanoseconds(now_ts.tv_nsec);
    }
    if (have_drops) s.account_drops(*socket, drops);
    auto frame = socketcan::from_kernel(b.frames[i], b.msgs[i].msg_len, interface_);
    if (!frame) {
      b.ready.push_back(frame.error());
      continue;
    }
    frame->stamp = stamp;
    if (frame->is_error) {
      s.tracker.on_error_frame(*frame);
    } else if (!s.filter.accepts(frame->id)) {
      continue;  // sent before a filter change took effect
    } else {
      ++s.tracker.stats().rx_frames;
    }
    b.ready.push_back(std::move(frame));
  }
  return n;
}

Result<int> SocketCanBus::read_queued(std::shared_ptr<Socket>& socket) {
  for (;;) {
    if (!socket) return down_error();
    int err = 0;
    const int n = read_batch(socket, err);
    if (n >= 0) return n;
    if (err == EINTR) continue;
    if (!is_interface_loss(err)) {
      return Error{errc_for(err), interface_ + ": cannot receive: " + errno_text(err)};
    }
    socket = on_interface_lost(socket, err);  // reopened at once if only briefly away
  }
}

void SocketCanBus::refilter_ready() {
  std::deque<Result<CanFrame>>& ready = rx_->ready;
  if (ready.empty() || rx_->filter_generation == filter_generation_.load()) return;
  // The filter changed since these were read: they must pass the new one.
  std::lock_guard<std::mutex> lock(mutex_);
  rx_->filter_generation = filter_generation_.load();
  const IdFilter& filter = state_->filter;
  ready.erase(std::remove_if(ready.begin(), ready.end(),
                             [&filter](const Result<CanFrame>& f) {
                               return f && !f->is_error && !filter.accepts(f->id);
                             }),
              ready.end());
}

Result<CanFrame> SocketCanBus::receive(std::chrono::nanoseconds timeout) {
  using std::chrono::steady_clock;
  std::lock_guard<std::mutex> receive_lock(receive_mutex_);
  std::deque<Result<CanFrame>>& ready = rx_->ready;
  auto next_ready = [&ready] {
    Result<CanFrame> r = std::move(ready.front());
    ready.pop_front();
    return r;
  };
  refilter_ready();
  if (!ready.empty()) return next_ready();  // read by an earlier recvmmsg: no system call
  // The clock is read only by a call that has to wait (a poll with timeout 0 reads none).
  std::optional<steady_clock::time_point> deadline;
  if (timeout > std::chrono::nanoseconds::zero()) deadline = steady_clock::now() + timeout;
  bool poll_reported_error = false;
  for (;;) {
    auto socket = acquire_socket();
    if (!socket) {
      // Nothing to wait on: wait out the timeout like an idle bus, so callers do not spin.
      if (deadline) std::this_thread::sleep_until(*deadline);
      return down_error();
    }
    const auto n = read_queued(socket);
    if (!n) return n.error();
    if (*n > 0) {
      if (!ready.empty()) return next_ready();
      continue;  // every frame was filtered out: read again
    }
    // Nothing queued.
    const int fd = socket->fd.get();
    if (poll_reported_error) {
      int so_error = 0;
      socklen_t len = sizeof so_error;
      ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &len);
      if (so_error != 0 && is_interface_loss(so_error)) {
        if (!on_interface_lost(socket, so_error)) return down_error();
        poll_reported_error = false;
        continue;
      }
      return Error{Errc::kIoError, interface_ + ": poll reported an error on the CAN socket (" +
                                       (so_error ? errno_text(so_error) : "no detail") + ")"};
    }
    const auto remaining =
        deadline ? *deadline - steady_clock::now() : steady_clock::duration::zero();
    if (remaining <= steady_clock::duration::zero()) {
      return Error{Errc::kTimeout, interface_ + ": no frame within the timeout"};
    }
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(remaining).count();
    struct timespec wait = {static_cast<time_t>(ns / 1000000000),
                            static_cast<long>(ns % 1000000000)};
    struct pollfd pfd = {fd, POLLIN, 0};
    const int r = ::ppoll(&pfd, 1, &wait, nullptr);
    if (r < 0 && errno != EINTR) {
      return Error{Errc::kIoError, interface_ + ": poll failed: " + errno_text(errno)};
    }
    if (r > 0 && !(pfd.revents & POLLIN) && (pfd.revents & (POLLERR | POLLHUP | POLLNVAL))) {
      poll_reported_error = true;
    }
    // Read again: a pending socket error is reported by recvmmsg itself.
  }
}

std::size_t SocketCanBus::receive_queued(std::vector<Result<CanFrame>>& out, std::size_t max) {
  std::lock_guard<std::mutex> receive_lock(receive_mutex_);
  std::deque<Result<CanFrame>>& ready = rx_->ready;
  refilter_ready();
  std::size_t count = 0;
  bool queue_read = false;  // a recvmmsg of this call found the kernel's queue drained
  for (;;) {
    while (!ready.empty() && count < max) {
      out.push_back(std::move(ready.front()));
      ready.pop_front();
      ++count;
      if (!out.back()) return count;  // stop after an error: the rest is for the next call
    }
    if (count >= max || queue_read) return count;
    auto socket = acquire_socket();
    const auto n = read_queued(socket);
    if (!n) {
      out.push_back(n.error());
      return count + 1;
    }
    // A short batch emptied the queue; a full one may have left frames behind.
    queue_read = *n < static_cast<int>(kReceiveBatch);
  }
}

int SocketCanBus::fd() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_->socket ? state_->socket->fd.get() : -1;
}

BusStatus SocketCanBus::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  State& s = *state_;
  // Every frame queued after a drop carries the kernel's drop count (SO_RXQ_OVFL), so while
  // frames flow the count is current as they are read. Drops after the last frame read are told
  // by the next one; SO_MEMINFO has them now, and is asked (a system call) only when they can
  // matter: nothing was read since the last status(), or a full batch (a backlog) was.
  if (s.socket && (!s.read_since_status || s.full_batch_since_status)) {
    if (const long long drops = current_socket_drops(s.socket->fd.get()); drops >= 0) {
      s.account_drops(*s.socket, static_cast<std::uint32_t>(drops));
    }
  }
  s.read_since_status = false;
  s.full_batch_since_status = false;
  return s.tracker.status();
}

void SocketCanBus::set_filter(const std::vector<std::uint32_t>& ids) {
  std::lock_guard<std::mutex> lock(mutex_);
  State& s = *state_;
  s.filter.set(ids);
  ++filter_generation_;
  if (s.socket) {
    if (auto st = apply_filter(s.socket->fd.get(), s.filter.ids(), interface_); !st) {
      // The software filter in receive() still applies; report why the kernel one is missing.
      s.tracker.status().detail = st.error().message;
    }
  }
}

// ---- kernel frame conversion --------------------------------------------------------------------

namespace socketcan {

Result<CanFrame> from_kernel(const struct can_frame& kf, std::size_t nbytes,
                             std::string_view interface) {
  const std::string where(interface);
  if (nbytes != sizeof(struct can_frame)) {
    return Error{Errc::kBadDlc, where + ": received " + std::to_string(nbytes) +
                                    " bytes, not a classic CAN frame (" +
                                    std::to_string(sizeof(struct can_frame)) + " bytes); dropped"};
  }
  CanFrame f;
  if (kf.can_id & CAN_ERR_FLAG) {
    f.is_error = true;
    f.id = kf.can_id & CAN_ERR_MASK;
  } else if (kf.can_id & CAN_EFF_FLAG) {
    return Error{Errc::kUnknownId, where + ": extended (29-bit) frame " +
                                       hex_id(kf.can_id & CAN_EFF_MASK) +
                                       " dropped: RANGER uses 11-bit IDs"};
  } else if (kf.can_id & CAN_RTR_FLAG) {
    return Error{Errc::kInvalidArgument,
                 where + ": remote frame " + hex_id(kf.can_id & CAN_SFF_MASK) + " dropped"};
  } else {
    f.id = kf.can_id & CAN_SFF_MASK;
  }
  if (kf.can_dlc > CanFrame::kMaxDlc) {
    return Error{Errc::kBadDlc, where + ": frame " + hex_id(f.id) + " has DLC " +
                                    std::to_string(kf.can_dlc) +
                                    ", more than the 8 bytes of a classic CAN frame; dropped"};
  }
  f.dlc = kf.can_dlc;
  std::copy(kf.data, kf.data + f.dlc, f.data.begin());
  return f;
}

struct can_frame to_kernel(const CanFrame& frame) {
  struct can_frame kf;
  std::memset(&kf, 0, sizeof kf);
  kf.can_id =
      frame.is_error ? (CAN_ERR_FLAG | (frame.id & CAN_ERR_MASK)) : (frame.id & CAN_SFF_MASK);
  kf.can_dlc = std::min<std::uint8_t>(frame.dlc, CAN_MAX_DLEN);
  std::copy(frame.data.begin(), frame.data.begin() + kf.can_dlc, kf.data);
  return kf;
}

}  // namespace socketcan

}  // namespace ranger
