#include "ranger_can/control/driver.hpp"

#include <poll.h>
#include <pthread.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <utility>

#include <cstdio>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

constexpr std::size_t kMaxFramesPerIteration = 512;

// ThreadSanitizer does not model the acquire fence publish() relies on to reuse a snapshot: under
// it every snapshot is a new one.
#if defined(__has_feature)  // clang
#if __has_feature(thread_sanitizer)
#define RANGER_UNDER_TSAN 1
#endif
#endif
#if defined(__SANITIZE_THREAD__) || defined(RANGER_UNDER_TSAN)  // gcc, clang
constexpr bool kReuseSnapshots = false;
#else
constexpr bool kReuseSnapshots = true;
#endif
constexpr std::size_t kMaxRequests = 16;
// A 0x211 that arrives this soon after a request was sent may have left the chassis before the
// request reached it: the answer is the first one after this.
constexpr std::chrono::nanoseconds kAnswerDelay =
    std::chrono::milliseconds(protocol::frame_period_ms(protocol::kSystemStatusId));

bool is_zero(const BodyTwist& t) {
  return t.vx == 0.0 && t.vy == 0.0 && t.wz == 0.0;
}

// The odometry shares the controller's geometry, limits and protocol profile: one vehicle, one
// reading.
OdometryConfig odometry_config(const DriverConfig& config) {
  OdometryConfig c = config.odometry;
  c.geometry = config.controller.geometry;
  c.limits = config.controller.limits;
  c.profile = config.controller.profile;
  return c;
}

double axis(std::int8_t raw) {
  return std::clamp(raw / protocol::kRemoteAxisFullScale, -1.0, 1.0);
}

std::string light_text(protocol::LightMode mode, std::uint8_t brightness) {
  std::string out(protocol::to_string(mode));
  if (mode == protocol::LightMode::kCustom) out += " " + std::to_string(brightness);
  return out;
}

bool lights_match(const LightsState& s, const LightsRequest& r) {
  auto same = [](protocol::LightMode m1, std::uint8_t b1, protocol::LightMode m2, std::uint8_t b2) {
    return m1 == m2 && (m1 != protocol::LightMode::kCustom || b1 == b2);
  };
  return same(s.front, s.front_brightness, r.front, r.front_brightness) &&
         same(s.rear, s.rear_brightness, r.rear, r.rear_brightness);
}

}  // namespace

std::string_view to_string(VendorFrames v) {
  switch (v) {
    case VendorFrames::kUnknown:
      return "unknown";
    case VendorFrames::kPresent:
      return "present";
    case VendorFrames::kAbsent:
      return "absent";
  }
  return "unknown";
}

std::string_view to_string(FirmwareVersion::State s) {
  switch (s) {
    case FirmwareVersion::State::kNotAsked:
      return "not_asked";
    case FirmwareVersion::State::kAsked:
      return "asked";
    case FirmwareVersion::State::kAnswered:
      return "answered";
    case FirmwareVersion::State::kUnanswered:
      return "unanswered";
    case FirmwareVersion::State::kUnsupported:
      return "unsupported";
  }
  return "unknown";
}

RemoteState remote_state_from(const RemoteControlState& rc, Timestamp received) {
  RemoteState r;
  r.swa = rc.swa;
  r.swb = rc.swb;
  r.swc = rc.swc;
  r.swd = rc.swd;
  r.left_vertical = axis(rc.stick_left_v);
  r.left_horizontal = axis(rc.stick_left_h);
  r.right_vertical = axis(rc.stick_right_v);
  r.right_horizontal = axis(rc.stick_right_h);
  r.knob = axis(rc.var_a);
  r.received = received;
  return r;
}

std::string describe(protocol::LightMode front, std::uint8_t front_brightness,
                     protocol::LightMode rear, std::uint8_t rear_brightness) {
  return "front " + light_text(front, front_brightness) + ", rear " +
         light_text(rear, rear_brightness);
}

std::string_view to_string(RequestOutcome::Kind k) {
  switch (k) {
    case RequestOutcome::Kind::kClearErrors:
      return "clear_errors";
    case RequestOutcome::Kind::kUltrasonic:
      return "ultrasonic";
    case RequestOutcome::Kind::kResume:
      return "resume";
    case RequestOutcome::Kind::kLights:
      return "lights";
    case RequestOutcome::Kind::kPark:
      return "park";
    case RequestOutcome::Kind::kFirmwareVersion:
      return "firmware_version";
  }
  return "unknown";
}

std::string_view to_string(RequestOutcome::State s) {
  switch (s) {
    case RequestOutcome::State::kPending:
      return "pending";
    case RequestOutcome::State::kSent:
      return "sent";
    case RequestOutcome::State::kAnswered:
      return "answered";
    case RequestOutcome::State::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string_view to_string(ProtocolChoice c) {
  return c == ProtocolChoice::kAuto ? "auto" : "forced";
}

Status DriverConfig::validate() const {
  if (Status st = controller.validate(); !st) return st;
  if (Status st = odometry.validate(); !st) return st;
  if (Status st = plausibility.validate(); !st) return st;
  if (protocol == ProtocolChoice::kAuto) {
    if (Status st = identification.validate(); !st) return st;
    if (identify_revision) {
      if (auto p = protocol_preset(*identify_revision); !p) return p.error();
    }
  }
  if (reconnect_interval.count() <= 0 || request_answer_timeout.count() <= 0 ||
      vendor_frames_wait.count() <= 0) {
    return Error{Errc::kOutOfRange,
                 "driver: reconnect_interval, request_answer_timeout and vendor_frames_wait must "
                 "be > 0"};
  }
  return ok_status();
}

const RequestOutcome* DriverSnapshot::request(std::uint64_t id) const {
  for (const RequestOutcome& r : requests) {
    if (r.id == id) return &r;
  }
  return nullptr;
}

// What callers posted since the driver last looked. Guarded by mail_mutex_.
struct Driver::Mail {
  std::optional<MotionRequest> command;  // the latest twist
  bool zero_seen = false;                // a zero twist came before the latest (it re-arms)
  std::optional<std::optional<protocol::MotionMode>> mode;
  std::optional<std::optional<StandstillProbe>> probe;
  struct Action {
    RequestOutcome::Kind kind;  // kClearErrors, kUltrasonic, kPark or kResume
    std::uint64_t id;
    std::uint8_t code;
    bool enable;
  };
  std::vector<Action> actions;
  std::vector<DriverVendorAction> vendor;  // lights, version
};

Driver::Driver(DriverConfig config, std::shared_ptr<BusSource> source, const Clock& clock)
    : config_(std::move(config)),
      source_(std::move(source)),
      bus_name_(source_ ? source_->name() : ""),
      clock_(clock),
      profile_(config_.controller.profile),
      monitor_(config_.plausibility, config_.controller.geometry, config_.controller.profile),
      odometry_(odometry_config(config_)),
      joints_(config_.controller.geometry.wheel_radius),
      mail_(std::make_unique<Mail>()),
      snapshot_(std::make_shared<DriverSnapshot>()) {
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (clock_.monotonic()) timer_fd_ = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  auto first = std::make_shared<DriverSnapshot>();
  first->bus_name = bus_name_;
  first->profile = config_.controller.profile;
  first->protocol = config_.protocol;
  snapshot_ = std::move(first);
}

Driver::~Driver() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
  if (timer_fd_ >= 0) ::close(timer_fd_);
}

void Driver::start() {
  if (thread_.joinable() || stopped_) return;
  thread_ = std::thread([this] { loop(); });
}

void Driver::stop() {
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    stop_requested_ = true;
  }
  wake();
  if (thread_.joinable()) {
    thread_.join();  // the thread sends the stop on its way out
  } else if (!stopped_) {
    // Lock-step owner (or a thread that never started): stop here.
    if (controller_) controller_->shutdown(clock_.now());
    deliver_events();
    publish(clock_.now());
  }
  stopped_ = true;
}

// ---- mailbox --------------------------------------------------------------------------------

Status Driver::command(const MotionRequest& request) {
  Status st = ok_status();
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    if (!opened_once_) {
      return Error{Errc::kInterfaceDown, "not connected to " +
                                             (source_ ? source_->name() : std::string("a bus")) +
                                             (open_error_.empty() ? "" : ": " + open_error_)};
    }
    if (Status finite = check_finite(request); !finite) {
      st = Error{Errc::kNotFinite, "command refused (" + finite.error().message +
                                       "): the chassis is commanded to stop"};
    }
    if (mail_->command && is_zero(mail_->command->twist)) mail_->zero_seen = true;
    mail_->command = request;
  }
  wake();
  return st;
}

Status Driver::set_motion_mode(std::optional<protocol::MotionMode> mode) {
  if (mode) {
    if (Status st = check_drivable(*mode, snapshot()->profile); !st) return st;
  }
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    mail_->mode = mode;
  }
  wake();
  return ok_status();
}

RequestOutcome& Driver::add_request(RequestOutcome::Kind kind, std::string what, bool on) {
  RequestOutcome r;
  r.id = next_request_id_++;
  r.kind = kind;
  r.on = on;
  r.what = std::move(what);
  requests_.push_back(std::move(r));
  while (requests_.size() > kMaxRequests)
    requests_.pop_front();
  return requests_.back();
}

Result<std::uint64_t> Driver::clear_errors(std::uint8_t code) {
  if (code > protocol::kMaxErrorClearCode) {
    return Error{Errc::kInvalidArgument, "code " + std::to_string(code) +
                                             " is not an error-clearing code (valid 0.." +
                                             std::to_string(protocol::kMaxErrorClearCode) + ")"};
  }
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    id = add_request(RequestOutcome::Kind::kClearErrors, "clear_errors " + text::hex(code, 2)).id;
    mail_->actions.push_back({RequestOutcome::Kind::kClearErrors, id, code, false});
  }
  wake();
  return id;
}

std::uint64_t Driver::set_ultrasonic(bool enable) {
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    id = add_request(RequestOutcome::Kind::kUltrasonic,
                     std::string("ultrasonic ") + (enable ? "on" : "off"), enable)
             .id;
    mail_->actions.push_back({RequestOutcome::Kind::kUltrasonic, id, 0, enable});
  }
  wake();
  return id;
}

void Driver::standstill_probe(std::optional<StandstillProbe> probe) {
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    mail_->probe = probe;
  }
  wake();
}

std::uint64_t Driver::resume() {
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    id = add_request(RequestOutcome::Kind::kResume, "resume").id;
    mail_->actions.push_back({RequestOutcome::Kind::kResume, id, 0, false});
  }
  wake();
  return id;
}

Result<std::uint64_t> Driver::set_lights(const LightsRequest& lights) {
  if (lights.front_brightness > 100 || lights.rear_brightness > 100) {
    return Error{Errc::kInvalidArgument, "lights: brightness is 0..100"};
  }
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    id = add_request(RequestOutcome::Kind::kLights,
                     "lights " + describe(lights.front, lights.front_brightness, lights.rear,
                                          lights.rear_brightness))
             .id;
    mail_->vendor.push_back({DriverVendorAction::Kind::kLights, id, lights});
  }
  wake();
  return id;
}

std::uint64_t Driver::set_park(bool on) {
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    id =
        add_request(RequestOutcome::Kind::kPark, std::string("park ") + (on ? "on" : "off"), on).id;
    mail_->actions.push_back({RequestOutcome::Kind::kPark, id, 0, on});
  }
  wake();
  return id;
}

std::uint64_t Driver::request_firmware_version() {
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    id = add_request(RequestOutcome::Kind::kFirmwareVersion, "firmware_version").id;
    mail_->vendor.push_back({DriverVendorAction::Kind::kVersion, id, {}});
  }
  wake();
  return id;
}

RequestOutcome Driver::wait_for(std::uint64_t id, std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock<std::mutex> lock(snapshot_mutex_);
  for (;;) {
    const RequestOutcome* r = snapshot_->request(id);
    const bool done = r && (r->state == RequestOutcome::State::kAnswered ||
                            r->state == RequestOutcome::State::kFailed);
    if (done) return *r;
    if (snapshot_changed_.wait_until(lock, deadline) == std::cv_status::timeout) {
      r = snapshot_->request(id);
      if (r) return *r;
      RequestOutcome lost;
      lost.id = id;
      lost.state = RequestOutcome::State::kFailed;
      lost.message = "unknown request";
      return lost;
    }
  }
}

std::shared_ptr<const DriverSnapshot> Driver::snapshot() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return snapshot_;
}

// ---- the iteration ---------------------------------------------------------------------------

Timestamp Driver::next_due() const {
  if (!bus_) return next_open_attempt_;
  return controller_->next_tick_due();
}

void Driver::try_open(Timestamp now) {
  if (now < next_open_attempt_ || !source_) return;
  next_open_attempt_ = now + config_.reconnect_interval;
  auto bus = source_->open();
  if (!bus) {
    bus_error_ = bus.error().message;
    std::lock_guard<std::mutex> lock(mail_mutex_);
    open_error_ = bus_error_;
    return;
  }
  bus_error_.clear();
  bus_ = std::move(*bus);
  bus_->set_filter(protocol::all_ids());
  ControllerConfig controller_config = config_.controller;
  if (source_->read_only()) controller_config.listen_only = true;
  controller_ = std::make_unique<ChassisController>(*bus_, controller_config);
  controller_->set_send_observer([this](const SentFrame& sent) {
    events_.push_back(SentEvent{sent, sent_wall_time_ ? std::chrono::system_clock::now()
                                                      : std::chrono::system_clock::time_point{}});
  });
  if (config_.protocol == ProtocolChoice::kAuto) {
    // Listen before speaking: the controller hears nothing and says nothing until the
    // identification has proposed the settings.
    identification_changed_ = true;
    identifier_.emplace(config_.identification, config_.controller.geometry,
                        config_.identify_revision, source_->read_only());
    controller_->set_quiet(true);
    controller_->set_identifying(IdentificationPhase::kListening);
  }
  std::lock_guard<std::mutex> lock(mail_mutex_);
  opened_once_ = true;
  open_error_.clear();
}

void Driver::handle_frame(const CanFrame& frame, Timestamp now) {
  if (frame_tap_) frame_tap_(frame);
  const bool identifying = identifier_ && !identifier_->status().done();
  if (identifying) identifier_->on_frame(frame, now);
  if (frame.is_error) {
    controller_->on_frame(frame, now);  // counts it
    return;
  }
  Result<Message> message = decode(frame, profile_);
  frames_.record(frame.id, now, message.ok(), protocol::extra_bytes(frame));
  // While listening, nothing reaches the controller: read under settings not decided yet, a
  // counter would be phantom faults, and those would latch.
  if (identifying && identifier_->status().phase == IdentificationPhase::kListening) return;
  if (!identifying) monitor_.on_frame(frame, now);
  if (!message) {
    if (!identifying) monitor_.on_rejected(frame, message.error().code, now);
    controller_->on_frame(frame, now);  // counts and records the decode error
    return;
  }
  if (std::holds_alternative<SystemStatus>(*message)) {
    ++status_frames_;
    if (!first_status_) first_status_ = now;
  }
  if (std::holds_alternative<VersionResponse>(*message)) last_version_frame_ = now;
  controller_->on_message(*message, frame.stamp, now);
  if (odometry_readable()) {
    odometry_.on_message(*message, frame.stamp);
    odometry_fed_ = true;
  }
  if (joints_readable()) joints_.on_message(*message, frame.stamp);
}

bool Driver::joints_readable() const {
  return !identifier_ || identifier_->wheel_angles_known();
}

bool Driver::odometry_readable() const {
  if (!identifier_ || identifier_->status().decided_ok()) return true;
  // The wheels' odometry reads 0x271 and 0x281 (whose unit no revision changes); 0x221's needs
  // the whole decision.
  return config_.odometry.source == OdometrySource::kWheels && identifier_->wheel_angles_known();
}

void Driver::apply_mail(Timestamp now) {
  Mail mail;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    std::swap(mail, *mail_);
  }
  if (mail.mode) controller_->request_motion_mode(*mail.mode, now);
  if (mail.probe) probe_ = *mail.probe;
  if (mail.command) {
    if (mail.zero_seen && !is_zero(mail.command->twist)) {
      controller_->set_command(MotionRequest{}, now);  // its re-arm must not be lost
    }
    controller_->set_command(*mail.command, now);
  }
  for (const Mail::Action& a : mail.actions) {
    Status st = ok_status();
    switch (a.kind) {
      case RequestOutcome::Kind::kClearErrors:
        st = controller_->clear_errors(a.code, now);
        break;
      case RequestOutcome::Kind::kUltrasonic:
        st = controller_->set_ultrasonic(a.enable, now);
        break;
      case RequestOutcome::Kind::kPark:
        st = controller_->request_park(a.enable, now);
        break;
      case RequestOutcome::Kind::kResume:
        // The operator takes a plausibility stop on: the monitors start over (and trip again
        // if the mismatch persists).
        if (!applied_stop_.empty()) {
          monitor_.reset();
          applied_stop_.clear();
          controller_->set_implausible("");
        }
        st = controller_->resume(now);
        break;
      case RequestOutcome::Kind::kLights:
      case RequestOutcome::Kind::kFirmwareVersion:
        break;  // vendor actions (Mail::vendor, apply_vendor_action)
    }
    std::lock_guard<std::mutex> lock(mail_mutex_);
    for (RequestOutcome& r : requests_) {
      if (r.id != a.id) continue;
      r.sent = now;
      if (!st) {
        r.state = RequestOutcome::State::kFailed;
        r.message = st.error().message;
      } else if (a.kind == RequestOutcome::Kind::kResume) {
        r.state = RequestOutcome::State::kAnswered;
        r.message = "re-armed";
      } else {
        r.state = RequestOutcome::State::kSent;
      }
    }
  }
  for (const DriverVendorAction& a : mail.vendor)
    deferred_.push_back(a);
}

bool Driver::apply_vendor_action(const DriverVendorAction& a, Timestamp now) {
  if (vendor_frames_ == VendorFrames::kUnknown) return false;
  Status st = ok_status();
  if (vendor_frames_ == VendorFrames::kAbsent) {
    st = Error{
        Errc::kInvalidArgument,
        std::string(a.kind == DriverVendorAction::Kind::kLights ? "lights" : "firmware version") +
            ": unsupported by protocol " + profile_.revision +
            ": the chassis sends none of the vendor's frames (0x231 light state, 0x241 "
            "remote state)"};
  } else if (a.kind == DriverVendorAction::Kind::kLights) {
    LightCommand c;
    c.enable = true;
    c.front_mode = a.lights.front;
    c.front_custom = a.lights.front_brightness;
    c.rear_mode = a.lights.rear;
    c.rear_custom = a.lights.rear_brightness;
    st = controller_->set_lights(c, now);
    if (st) sent_lights_.emplace_back(a.id, a.lights);
  } else {
    st = controller_->request_version(now);
    if (st) {
      firmware_ = FirmwareVersion{FirmwareVersion::State::kAsked, ""};
      version_asked_ = now;
    }
  }
  std::lock_guard<std::mutex> lock(mail_mutex_);
  for (RequestOutcome& r : requests_) {
    if (r.id != a.id) continue;
    r.sent = now;
    if (!st) {
      r.state = RequestOutcome::State::kFailed;
      r.message = st.error().message;
    } else {
      r.state = RequestOutcome::State::kSent;
    }
  }
  return true;
}

void Driver::update_vendor(Timestamp now) {
  const ChassisFeedback& fb = controller_->feedback();
  if (fb.remote_control_state) {
    remote_ = remote_state_from(fb.remote_control_state->value, fb.remote_control_state->received);
  }
  if (fb.light_state) {
    const LightState& l = fb.light_state->value;
    lights_ = LightsState{l.enable,    l.front_mode,  l.front_custom,
                          l.rear_mode, l.rear_custom, fb.light_state->received};
  }
  if (fb.light_state || fb.remote_control_state) {
    vendor_frames_ = VendorFrames::kPresent;
  } else if (first_status_ && now - *first_status_ >= config_.vendor_frames_wait) {
    vendor_frames_ = VendorFrames::kAbsent;
  }
  // The version: asked once the chassis is heard speaking the vendor's revision, and we speak.
  const ControllerState& c = controller_->state();
  using VS = FirmwareVersion::State;
  if (firmware_.state == VS::kNotAsked) {
    if (vendor_frames_ == VendorFrames::kAbsent) {
      firmware_.state = VS::kUnsupported;
    } else if (vendor_frames_ == VendorFrames::kPresent && c.link == LinkState::kConnected &&
               !c.quiet && !config_.controller.listen_only && !(source_ && source_->read_only())) {
      if (controller_->request_version(now)) {
        firmware_.state = VS::kAsked;
        version_asked_ = now;
      }
    }
  }
  if (firmware_.state == VS::kAsked) {
    firmware_.text = fb.version;
    if (!fb.version.empty() && now - last_version_frame_ >= kAnswerDelay) {
      firmware_.state = VS::kAnswered;
    } else if (fb.version.empty() && now - version_asked_ > config_.request_answer_timeout) {
      firmware_.state = VS::kUnanswered;
    }
  }
  // A replayed log answers nothing, but may hold the answers of the session it recorded.
  if (firmware_.state != VS::kAsked && !fb.version.empty()) {
    firmware_.text = fb.version;
    if (firmware_.state != VS::kAnswered && now - last_version_frame_ >= kAnswerDelay) {
      firmware_.state = VS::kAnswered;
    }
  }
  std::vector<DriverVendorAction> waiting;
  for (const DriverVendorAction& a : deferred_) {
    if (!apply_vendor_action(a, now)) waiting.push_back(a);
  }
  deferred_.swap(waiting);
}

void Driver::update_requests(Timestamp now) {
  const ControllerState& c = controller_->state();
  const auto& status = controller_->feedback().system_status;
  std::lock_guard<std::mutex> lock(mail_mutex_);
  for (RequestOutcome& r : requests_) {
    if (r.state != RequestOutcome::State::kSent) continue;
    if (r.kind == RequestOutcome::Kind::kClearErrors) {
      if (status && status->received >= r.sent + kAnswerDelay) {
        r.state = RequestOutcome::State::kAnswered;
        r.error_word = c.error_bits;
        const auto names = protocol::error_bit_names(c.error_bits, profile_.error_word);
        r.message = names.empty() ? std::string("the chassis reports no error")
                                  : "the chassis still reports: " + text::join(names);
      } else if (now - r.sent > config_.request_answer_timeout) {
        r.state = RequestOutcome::State::kFailed;
        r.message = "the chassis did not answer (no 0x211) within " +
                    std::to_string(seconds(config_.request_answer_timeout)) + " s";
      }
    } else if (r.kind == RequestOutcome::Kind::kLights) {
      auto it = std::find_if(sent_lights_.begin(), sent_lights_.end(),
                             [&](const auto& p) { return p.first == r.id; });
      if (it == sent_lights_.end()) continue;
      const bool fresh = lights_ && lights_->received >= r.sent + kAnswerDelay;
      if (fresh && lights_match(*lights_, it->second)) {
        r.state = RequestOutcome::State::kAnswered;
        r.message = "the chassis reports " + describe(lights_->front, lights_->front_brightness,
                                                      lights_->rear, lights_->rear_brightness);
      } else if (now - r.sent > config_.request_answer_timeout) {
        r.state = RequestOutcome::State::kFailed;
        r.message = fresh ? "the chassis reports " +
                                describe(lights_->front, lights_->front_brightness, lights_->rear,
                                         lights_->rear_brightness) +
                                (c.control_mode == protocol::ControlMode::kRemote
                                     ? " (the remote control has the chassis)"
                                     : "")
                          : "the chassis did not report its lights (no 0x231) within " +
                                std::to_string(seconds(config_.request_answer_timeout)) + " s";
      }
      if (r.state != RequestOutcome::State::kSent) sent_lights_.erase(it);
    } else if (r.kind == RequestOutcome::Kind::kPark && r.on) {
      const auto limit =
          config_.controller.mode_switch_timeout * config_.controller.mode_switch_max_attempts +
          config_.request_answer_timeout;
      if (c.parked()) {
        r.state = RequestOutcome::State::kAnswered;
        r.message = "parked (0x291 reports park): motion is refused until park is released";
      } else if (!c.park_requested) {
        r.state = RequestOutcome::State::kFailed;
        r.message = "park was released before the chassis reported it";
      } else if (now - r.sent > limit) {
        r.state = RequestOutcome::State::kFailed;
        r.message = "the chassis did not report park (0x291) within " +
                    std::to_string(seconds(limit)) + " s" +
                    (c.refusal != MotionRefusal::kParked
                         ? std::string(" (") + std::string(to_string(c.refusal)) + ")"
                         : std::string());
      }
    } else if (r.kind == RequestOutcome::Kind::kPark) {
      if (c.park_requested) {
        r.state = RequestOutcome::State::kFailed;
        r.message = "park was requested again";
      } else if (c.chassis_mode != protocol::MotionMode::kPark) {
        r.state = RequestOutcome::State::kAnswered;
        r.message = "park released: motion allowed";
      } else if (now - r.sent > config_.controller.mode_switch_timeout *
                                        config_.controller.mode_switch_max_attempts +
                                    config_.request_answer_timeout) {
        r.state = RequestOutcome::State::kAnswered;
        r.message =
            "park released: motion allowed (the chassis still reports park; the next "
            "motion switches it out)";
      }
    } else if (r.kind == RequestOutcome::Kind::kFirmwareVersion) {
      if (firmware_.state == FirmwareVersion::State::kAnswered) {
        r.state = RequestOutcome::State::kAnswered;
        r.message = firmware_.text;
      } else if (firmware_.state == FirmwareVersion::State::kUnanswered) {
        r.state = RequestOutcome::State::kFailed;
        r.message = "the chassis did not answer the version request (0x4A1) within " +
                    std::to_string(seconds(config_.request_answer_timeout)) + " s";
      }
    } else if (r.kind == RequestOutcome::Kind::kUltrasonic) {
      const bool want = r.on;
      if (c.ultrasonic_failed) {
        r.state = RequestOutcome::State::kFailed;
        r.message = "the chassis did not confirm the ultrasonic setting (0x45A)";
      } else if (!c.ultrasonic_requested && c.ultrasonic_enabled == want) {
        r.state = RequestOutcome::State::kAnswered;
        r.message = std::string("ultrasonic avoidance ") + (want ? "enabled" : "disabled") +
                    " (confirmed by the chassis)";
      }
    }
  }
}

void Driver::publish(Timestamp now) {
  std::shared_ptr<DriverSnapshot> s;
  if (kReuseSnapshots && spare_ && spare_.use_count() == 1) {
    // No reader holds it: the last one's reads happened before its release of the count.
    std::atomic_thread_fence(std::memory_order_acquire);
    s = std::move(spare_);
  } else {
    s = std::make_shared<DriverSnapshot>();
  }
  // Every field is assigned (a reused snapshot keeps nothing of its last publication).
  s->now = now;
  s->bus_name = bus_name_;
  s->bus_open = bus_ != nullptr;
  s->read_only = source_ && source_->read_only();
  s->bus_error = bus_error_;
  s->bus = bus_ ? bus_->status() : BusStatus{};
  s->controller = controller_ ? controller_->state() : ControllerState{};
  s->feedback = controller_ ? controller_->feedback() : ChassisFeedback{};
  s->motion_known = controller_ && s->controller.link == LinkState::kConnected;
  s->odometry = odometry_.state();
  s->joints = joints_.joints();
  s->frames = frames_;
  s->profile = profile_;
  s->protocol = config_.protocol;
  if (!identifier_) {
    identification_.reset();
  } else if (!identification_ || !identification_->done() || identification_changed_) {
    identification_ = std::make_shared<const IdentificationStatus>(identifier_->status());
    identification_changed_ = false;
  }
  s->identification = identification_;
  s->plausibility = monitor_.status();
  s->loop_iterations = loop_iterations_;
  s->vendor_frames = vendor_frames_;
  s->remote = remote_;
  s->lights = lights_;
  s->firmware = firmware_;
  {
    std::lock_guard<std::mutex> lock(mail_mutex_);
    s->requests.assign(requests_.begin(), requests_.end());
  }
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    s->sequence = snapshot_->sequence + 1;
    snapshot_ = s;
  }
  spare_ = std::move(published_);
  published_ = std::move(s);
  snapshot_changed_.notify_all();
}

void Driver::deliver_events() {
  if (events_.empty()) return;
  std::vector<SentEvent> events;
  events.swap(events_);
  if (!sent_observer_) return;
  for (const SentEvent& e : events)
    sent_observer_(e);
}

void Driver::step(Timestamp now) {
  ++loop_iterations_;
  if (!bus_) try_open(now);
  if (bus_) {
    // What has arrived (one system call per batch, no clock read); an error ends the list: the
    // bus reports it and reopens.
    received_.clear();
    bus_->receive_queued(received_, kMaxFramesPerIteration);
    for (const Result<CanFrame>& frame : received_) {
      if (frame) handle_frame(*frame, now);
    }
    apply_mail(now);
    run_identification(now);
    run_standstill_probe();
    update_vendor(now);
    controller_->tick(now);
    run_plausibility(now);
    update_requests(now);
  }
  publish(now);
  deliver_events();
  if (step_observer_) {
    try {
      step_observer_(snapshot());
    } catch (...) {  // the observer's own business; the driver goes on
    }
  }
}

void Driver::use_profile(const ProtocolProfile& profile, bool reset_odometry) {
  if (profile == profile_) return;
  profile_ = profile;
  if (Status st = controller_->set_profile(profile); !st) return;
  if (reset_odometry) {
    OdometryConfig c = odometry_config(config_);
    c.profile = profile;
    odometry_ = Odometry(c);  // nothing has moved yet: the pose starts here
  } else {
    odometry_.set_profile(profile);
  }
  monitor_.set_profile(profile);
}

ProtocolProfile Driver::with_configured_settings(const IdentificationStatus& st) const {
  // What the identification kept from its revision's preset, the configured profile (a model's
  // own readings: the MINI V1's mode numbering, spin field and sign) has a better value for,
  // when it is of the same revision.
  ProtocolProfile p = st.profile;
  const ProtocolProfile& configured = config_.controller.profile;
  if (configured.revision != p.revision) return p;
  for (const ProfileSetting& setting : profile_settings()) {
    const bool decided =
        std::any_of(st.decided.begin(), st.decided.end(),
                    [&](const IdentifiedSetting& d) { return d.name == setting.name; });
    if (decided) continue;
    if (auto v = get_setting(configured, setting.name)) set_setting(p, setting.name, *v);
  }
  return p;
}

void Driver::run_identification(Timestamp now) {
  if (!identifier_ || identifier_->status().done()) return;
  // The probe is motion the controller would refuse for a cause of the commander's (a re-arm
  // after the remote control or a stop, an e-stop): it waits for that, not for the chassis.
  const MotionRefusal refusal = controller_->state().refusal;
  switch (refusal) {
    case MotionRefusal::kRearmRequired:
      identifier_->hold_probe(config_.controller.rearm_on_zero_twist
                                  ? "motion needs the re-arm (call resume, or send a zero twist)"
                                  : "motion needs the re-arm (call resume)");
      break;
    case MotionRefusal::kRemote:  // (as of the last tick: the hand-back is being heard now)
    case MotionRefusal::kEstop:
    case MotionRefusal::kCriticalError:
    case MotionRefusal::kLowBattery:
    case MotionRefusal::kImplausible:
      identifier_->hold_probe("motion is refused (" + std::string(to_string(refusal)) + ")");
      break;
    default:
      identifier_->hold_probe("");
      break;
  }
  identifier_->tick(now);
  const IdentificationStatus& st = identifier_->status();
  if (st.decided_ok()) {
    // A chassis driven (by its remote) before the decision keeps the pose it reached.
    use_profile(with_configured_settings(st), /*reset_odometry=*/!odometry_fed_);
    controller_->set_probe(std::nullopt, std::nullopt);
    controller_->set_quiet(false);
    controller_->set_identifying(std::nullopt);
    return;
  }
  if (st.phase == IdentificationPhase::kFailed) {
    // At rest, and saying why: the refusal stays, with the message naming what to set.
    controller_->set_probe(std::nullopt, std::nullopt);
    controller_->set_identifying(IdentificationPhase::kFailed);
    return;
  }
  const IdentificationRequest r = identifier_->request();
  if (r.profile) use_profile(*r.profile, /*reset_odometry=*/!odometry_fed_);
  controller_->set_quiet(r.quiet);
  controller_->set_probe(r.mode, r.probe);
  controller_->set_identifying(st.phase);
}

void Driver::run_standstill_probe() {
  if (identifier_ && !identifier_->status().decided_ok()) return;  // the identification's
  if (probe_) {
    MotionCommand c;
    c.steering_angle = interpretation::manual_from_rep103_command_steering(probe_->steering);
    controller_->set_standstill_probe(true);
    controller_->set_probe(probe_->mode, c);
    probe_active_ = true;
  } else if (probe_active_) {
    controller_->set_probe(std::nullopt, std::nullopt);
    controller_->set_standstill_probe(false);
    probe_active_ = false;
  }
}

void Driver::run_plausibility(Timestamp now) {
  if (identifier_ && !identifier_->status().decided_ok()) return;
  monitor_.update(now, controller_->state(), controller_->feedback(), odometry_.state());
  const auto stop = monitor_.status().stop;
  if (!stop || !applied_stop_.empty()) return;
  applied_stop_ = stop->text();
  controller_->set_implausible(applied_stop_);  // the stop, latched
  // Auto: a setting the identification could not decide at rest is learned here. The stop stays
  // latched (resume re-arms); the cause itself is gone with the setting.
  if (identifier_) identification_changed_ = true;  // adopt() records the stop either way
  if (identifier_ && identifier_->adopt(stop->setting, stop->try_value, stop->detail)) {
    use_profile(with_configured_settings(identifier_->status()), /*reset_odometry=*/false);
    controller_->set_implausible("");
    applied_stop_.clear();
  }
}

// ---- the thread ------------------------------------------------------------------------------

void Driver::wake() {
  if (wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  // A full counter (EAGAIN) means a wake-up is pending anyway.
  [[maybe_unused]] const auto n = ::write(wake_fd_, &one, sizeof one);
}

void Driver::wait(std::chrono::nanoseconds timeout) {
  timeout = std::clamp<std::chrono::nanoseconds>(timeout, 0ns, 1s);
  const timespec ts{static_cast<time_t>(timeout.count() / 1'000'000'000),
                    static_cast<long>(timeout.count() % 1'000'000'000)};
  if (wake_fd_ < 0) {
    ::nanosleep(&ts, nullptr);
    return;
  }
  pollfd fd{wake_fd_, POLLIN, 0};
  if (::ppoll(&fd, 1, &ts, nullptr) > 0 && (fd.revents & POLLIN)) {
    std::uint64_t value;
    [[maybe_unused]] const auto n = ::read(wake_fd_, &value, sizeof value);
  }
}

void Driver::wait_until(Timestamp due) {
  if (due != timer_armed_) {
    itimerspec spec{};
    const auto ns = std::max<Timestamp::rep>(due.count(), 1);  // 0 would disarm it
    spec.it_value = {static_cast<time_t>(ns / 1'000'000'000),
                     static_cast<long>(ns % 1'000'000'000)};
    if (::timerfd_settime(timer_fd_, TFD_TIMER_ABSTIME, &spec, nullptr) != 0) {
      wait(due - clock_.now());
      return;
    }
    timer_armed_ = due;
  }
  // No timeout: the kernel reads no clock for this wait (under emulation a clock read can cost
  // more than the rest of an iteration).
  pollfd fds[2] = {{wake_fd_, POLLIN, 0}, {timer_fd_, POLLIN, 0}};
  if (::ppoll(fds, 2, nullptr, nullptr) <= 0) return;
  if (fds[0].revents & POLLIN) {
    std::uint64_t value;
    [[maybe_unused]] const auto n = ::read(wake_fd_, &value, sizeof value);
  }
  // An expired timer is not read: arming it again (the next instant is a later one) clears it.
  if (fds[1].revents & POLLIN) timer_armed_ = Timestamp{-1};
}

void Driver::loop() {
  ::pthread_setname_np(::pthread_self(), config_.thread_name.substr(0, 15).c_str());
  try {
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mail_mutex_);
        if (stop_requested_) break;
      }
      const Timestamp now = clock_.now();
      step(now);
      // Woken by the next due instant (at least once a second), or by wake().
      if (timer_fd_ >= 0 && wake_fd_ >= 0) {
        wait_until(std::min(next_due(), now + std::chrono::seconds(1)));
      } else {
        wait(next_due() - clock_.now());
      }
    }
  } catch (const std::exception& e) {  // never let an exception escape the thread
    bus_error_ = std::string("driver thread failed: ") + e.what();
  } catch (...) {
    bus_error_ = "driver thread failed";
  }
  const Timestamp now = clock_.now();
  if (controller_) controller_->shutdown(now);
  publish(now);
  deliver_events();
}

}  // namespace ranger
