#include "ranger_can/control/driver.hpp"

#include <pthread.h>

#include <algorithm>
#include <exception>
#include <tuple>
#include <utility>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

constexpr std::size_t kMaxFramesPerIteration = 512;

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

SettingsSupervisorConfig settings_config(const DriverConfig& c) {
  return SettingsSupervisorConfig{c.protocol,       c.identify_revision,   c.identification,
                                  c.plausibility,   c.controller.geometry, c.controller.profile,
                                  c.odometry.source};
}

RequestTiming request_timing(const DriverConfig& c) {
  // Park: the controller's switch with its attempts, then the answer.
  return RequestTiming{c.request_answer_timeout,
                       c.controller.mode_switch_timeout * c.controller.mode_switch_max_attempts +
                           c.request_answer_timeout};
}

EventTrackerConfig tracker_config(const DriverConfig& c, const BusSource* source) {
  EventTrackerConfig t;
  t.bus = source ? source->name() : std::string();
  const auto kind = bus_kind(t.bus);
  t.socketcan = kind && *kind == BusKind::kSocketCan;
  t.commands = !c.controller.listen_only && !(source && source->read_only());
  t.reconnect_interval = c.reconnect_interval;
  t.link_timeout = c.controller.link_timeout;
  return t;
}

std::shared_ptr<const DriverSnapshot> first_snapshot(const DriverConfig& c, std::string bus) {
  auto first = std::make_shared<DriverSnapshot>();
  first->bus_name = std::move(bus);
  first->profile = c.controller.profile;
  first->protocol = c.protocol;
  return first;
}

}  // namespace

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

Driver::Driver(DriverConfig config, std::shared_ptr<BusSource> source, const Clock& clock)
    : config_(std::move(config)),
      source_(std::move(source)),
      bus_name_(source_ ? source_->name() : ""),
      clock_(clock),
      profile_(config_.controller.profile),
      settings_(settings_config(config_),
                [this](const ProtocolProfile& p, bool reset_odometry) {
                  use_profile(p, reset_odometry);
                }),
      odometry_(odometry_config(config_)),
      joints_(config_.controller.geometry.wheel_radius),
      vendor_(config_.vendor_frames_wait, config_.request_answer_timeout),
      tracker_(tracker_config(config_, source_.get())),
      requests_(request_timing(config_)),
      snapshots_(first_snapshot(config_, bus_name_)),
      waker_(clock) {}

Driver::~Driver() {
  stop();
}

void Driver::start() {
  if (thread_.joinable() || stopped_) return;
  thread_ = std::thread([this] { loop(); });
}

void Driver::stop() {
  mailbox_.request_stop();
  waker_.wake();
  if (thread_.joinable()) {
    thread_.join();  // the thread sends the stop on its way out
  } else if (!stopped_) {
    finish(clock_.now());  // lock-step owner (or a thread that never started): stop here
  }
  stopped_ = true;
}

// ---- mailbox --------------------------------------------------------------------------------

Status Driver::command(const MotionRequest& request) {
  const Status st = mailbox_.post_command(request, bus_name_);
  waker_.wake();  // also to report a refusal
  return st;
}

Status Driver::set_motion_mode(std::optional<protocol::MotionMode> mode) {
  if (mode) {
    if (Status st = check_drivable(*mode, snapshot()->profile); !st) return st;
  }
  mailbox_.post([&](DriverMail& m) { m.mode = mode; });
  waker_.wake();
  return ok_status();
}

std::uint64_t Driver::post(RequestOutcome::Kind kind, std::string what, bool on,
                           std::uint8_t code) {
  const std::uint64_t id = requests_.add(kind, std::move(what), on);
  mailbox_.post([&](DriverMail& m) { m.actions.push_back({kind, id, code, on}); });
  waker_.wake();
  return id;
}

Result<std::uint64_t> Driver::clear_errors(std::uint8_t code) {
  if (code > protocol::kMaxErrorClearCode) {
    return Error{Errc::kInvalidArgument, "code " + std::to_string(code) +
                                             " is not an error-clearing code (valid 0.." +
                                             std::to_string(protocol::kMaxErrorClearCode) + ")"};
  }
  return post(RequestOutcome::Kind::kClearErrors, "clear_errors " + text::hex(code, 2), false,
              code);
}

std::uint64_t Driver::set_ultrasonic(bool enable) {
  return post(RequestOutcome::Kind::kUltrasonic,
              std::string("ultrasonic ") + (enable ? "on" : "off"), enable, 0);
}

std::uint64_t Driver::resume() {
  return post(RequestOutcome::Kind::kResume, "resume", false, 0);
}

std::uint64_t Driver::set_park(bool on) {
  return post(RequestOutcome::Kind::kPark, std::string("park ") + (on ? "on" : "off"), on, 0);
}

std::uint64_t Driver::set_drive_mode(protocol::DriveMode mode) {
  const std::uint64_t id =
      requests_.add(RequestOutcome::Kind::kDriveMode,
                    "drive_mode " + std::string(protocol::to_string(mode)), false, {}, mode);
  mailbox_.post([&](DriverMail& m) {
    m.actions.push_back(
        {RequestOutcome::Kind::kDriveMode, id, static_cast<std::uint8_t>(mode), false});
  });
  waker_.wake();
  return id;
}

void Driver::standstill_probe(std::optional<StandstillProbe> probe) {
  mailbox_.post([&](DriverMail& m) { m.probe = probe; });
  waker_.wake();
}

Result<std::uint64_t> Driver::set_lights(const LightsRequest& lights) {
  for (const auto& [side, mode, brightness] :
       {std::tuple{"front", lights.front, lights.front_brightness},
        std::tuple{"rear", lights.rear, lights.rear_brightness}}) {
    if (auto checked = light_brightness(side, mode, brightness); !checked) return checked.error();
  }
  const std::uint64_t id = requests_.add(RequestOutcome::Kind::kLights,
                                         "lights " + describe(lights.front, lights.front_brightness,
                                                              lights.rear, lights.rear_brightness),
                                         false, lights);
  mailbox_.post([&](DriverMail& m) {
    m.vendor.push_back({VendorAction::Kind::kLights, id, lights});
  });
  waker_.wake();
  return id;
}

std::uint64_t Driver::request_firmware_version() {
  const std::uint64_t id =
      requests_.add(RequestOutcome::Kind::kFirmwareVersion, "firmware_version");
  mailbox_.post([&](DriverMail& m) { m.vendor.push_back({VendorAction::Kind::kVersion, id, {}}); });
  waker_.wake();
  return id;
}

RequestOutcome Driver::wait_for(std::uint64_t id, std::chrono::nanoseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const auto s = snapshots_.wait_until(
      [&](const DriverSnapshot& snap) {
        const RequestOutcome* r = snap.request(id);
        return (r && r->settled()) || finished_;
      },
      deadline);
  RequestOutcome outcome;
  if (const RequestOutcome* r = s->request(id)) {
    outcome = *r;
    if (!outcome.settled() && finished_) outcome.message = "the driver stopped";
    return outcome;
  }
  outcome.id = id;
  outcome.state = RequestOutcome::State::kFailed;
  outcome.message = "unknown request";
  return outcome;
}

std::chrono::nanoseconds Driver::answer_budget(RequestOutcome::Kind kind) const {
  using namespace std::chrono_literals;
  const ControllerConfig& c = config_.controller;
  const auto answer = config_.request_answer_timeout;
  constexpr auto kMargin = 200ms;  // the driver's next iteration
  switch (kind) {
    case RequestOutcome::Kind::kResume:
      return answer;
    case RequestOutcome::Kind::kClearErrors:
    case RequestOutcome::Kind::kDriveMode:
      return answer + kMargin;
    case RequestOutcome::Kind::kUltrasonic:
      return c.ultrasonic_confirm_timeout * (c.ultrasonic_max_attempts + 1);
    case RequestOutcome::Kind::kPark:  // to rest first, then the switch with its retries
      return c.mode_switch_timeout * (c.mode_switch_max_attempts + 1) + answer + 3s;
    case RequestOutcome::Kind::kLights:  // the vendor frames may still be listened for
    case RequestOutcome::Kind::kFirmwareVersion:
      return config_.vendor_frames_wait + answer + kMargin;
  }
  return answer + kMargin;
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
    mailbox_.set_open(false, bus_error_);
    return;
  }
  bus_error_.clear();
  bus_ = std::move(*bus);
  bus_->set_filter(protocol::all_ids());
  ControllerConfig controller_config = config_.controller;
  if (source_->read_only()) controller_config.listen_only = true;
  controller_ = std::make_unique<ChassisController>(*bus_, controller_config);
  controller_->set_send_observer([this](const SentFrame& sent) {
    if (const auto* command = std::get_if<MotionCommand>(&sent.message)) {
      odometry_.on_command(*command, sent.frame.stamp + frame_clock_offset_);
    }
    sent_.push_back(SentEvent{sent, sent_wall_time_ ? std::chrono::system_clock::now()
                                                    : std::chrono::system_clock::time_point{}});
  });
  settings_.start(*controller_, source_->read_only());
  mailbox_.set_open(true, "");
}

void Driver::handle_frame(const CanFrame& frame, Timestamp now) {
  if (frame_tap_) frame_tap_(frame);
  const bool identifying = settings_.identifying();
  settings_.on_frame(frame, now);
  if (frame.is_error) {
    controller_->on_frame(frame, now);  // counts it
    return;
  }
  Result<Message> message = decode(frame, profile_);
  if (frames_.record(frame.id, now, message.ok(),
                     protocol::extra_bytes(frame, profile_.frame_layout))) {
    tracker_.frames_padded(frame.id, now, step_events_);
  }
  // While listening, nothing reaches the controller: read under settings not decided yet, a
  // counter would be phantom faults, and those would latch.
  if (settings_.listening()) return;
  if (!identifying) settings_.monitor_frame(frame, now);
  if (!message) {
    if (!identifying) settings_.monitor_rejected(frame, message.error().code, now);
    controller_->on_frame(frame, now);  // counts and records the decode error
    return;
  }
  vendor_.on_message(*message, now);
  controller_->on_message(*message, frame.stamp, now);
  if (frame.stamp.count() != 0) frame_clock_offset_ = frame.stamp - now;
  if (settings_.odometry_readable()) {
    odometry_.on_message(*message, frame.stamp);
    odometry_fed_ = true;
  }
  if (settings_.joints_readable()) joints_.on_message(*message, frame.stamp);
}

void Driver::apply_mail(Timestamp now) {
  DriverMail mail = mailbox_.take();
  if (mail.mode) {
    controller_->request_motion_mode(*mail.mode, now);
    tracker_.motion_mode_requested(*mail.mode, now, step_events_);
  }
  if (mail.probe) settings_.set_standstill_probe(*mail.probe);
  if (mail.command) {
    if (mail.zero_seen && !is_zero(mail.command->twist)) {
      controller_->set_command(MotionRequest{}, now);  // its re-arm must not be lost
    }
    controller_->set_command(*mail.command, now);
  }
  for (const DriverMail::Action& a : mail.actions)
    apply_action(a, now);
  for (const VendorAction& a : mail.vendor)
    vendor_.post(a);
}

void Driver::apply_action(const DriverMail::Action& a, Timestamp now) {
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
    case RequestOutcome::Kind::kDriveMode:
      st = controller_->set_drive_mode(static_cast<protocol::DriveMode>(a.code), now);
      break;
    case RequestOutcome::Kind::kResume:
      settings_.resume(*controller_);
      st = controller_->resume(now);
      resumed_ = resumed_ || st.ok();
      break;
    case RequestOutcome::Kind::kLights:
    case RequestOutcome::Kind::kFirmwareVersion:
      break;  // vendor actions (DriverMail::vendor, VendorFeatures)
  }
  requests_.applied(a.id, now, st);
}

void Driver::settle_requests(Timestamp now) {
  const std::optional<LightsState>& lights = vendor_.lights();
  requests_.settle(RequestEvidence{now, &controller_->state(), &controller_->feedback(), &lights,
                                   &vendor_.firmware(), profile_.error_word});
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
  settings_.on_profile(profile);
}

void Driver::publish(Timestamp now) {
  std::shared_ptr<DriverSnapshot> s = snapshots_.blank();
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
  s->identification = settings_.status();
  s->plausibility = settings_.plausibility();
  s->loop_iterations = loop_iterations_;
  s->vendor_frames = vendor_.frames();
  s->remote = vendor_.remote();
  s->lights = vendor_.lights();
  s->firmware = vendor_.firmware();
  const auto& mode = s->feedback.motion_mode;
  s->drive_mode = mode && mode->value.drive_mode
                      ? protocol::drive_mode_from_wire(*mode->value.drive_mode)
                      : std::nullopt;
  requests_.copy_to(s->requests);
  snapshots_.publish(std::move(s));
}

void Driver::deliver() {
  for (const SentEvent& e : sent_)
    tracker_.frame_sent(e.sent, e.sent.frame.stamp, step_events_);
  events_.append(step_events_);
  std::vector<SentEvent> sent;
  sent.swap(sent_);
  std::vector<DriverEvent> events;
  events.swap(step_events_);
  if (sent_observer_) {
    for (const SentEvent& e : sent)
      sent_observer_(e);
  }
  if (event_observer_) {
    for (const DriverEvent& e : events)
      event_observer_(e);
  }
}

void Driver::step(Timestamp now) {
  ++loop_iterations_;
  resumed_ = false;
  if (!bus_) try_open(now);
  std::optional<Error> refusal;
  if (const std::uint64_t refused = mailbox_.take_refused(refusal); refused > 0 && refusal) {
    tracker_.command_refused(*refusal, refused, now, step_events_);
  }
  if (bus_) {
    // What has arrived (one system call per batch, no clock read); an error ends the list: the
    // bus reports it and reopens.
    received_.clear();
    bus_->receive_queued(received_, kMaxFramesPerIteration);
    for (const Result<CanFrame>& frame : received_) {
      if (frame) handle_frame(*frame, now);
    }
    apply_mail(now);
    settings_.run_identification(now, *controller_, odometry_fed_);
    settings_.run_standstill_probe(*controller_);
    const ControllerState& c = controller_->state();
    const bool may_send = c.link == LinkState::kConnected && !c.quiet &&
                          !config_.controller.listen_only && !(source_ && source_->read_only());
    vendor_.update(now, *controller_, may_send, profile_.revision, requests_);
    controller_->tick(now);
    settings_.run_plausibility(now, *controller_, odometry_.state());
    settle_requests(now);
  }
  publish(now);
  for (const RequestOutcome& r : requests_.take_settled())
    tracker_.request_settled(r, now, step_events_);
  tracker_.observe(snapshots_.published(), resumed_, step_events_);
  deliver();
  if (step_observer_) {
    try {
      step_observer_(snapshot());
    } catch (...) {  // the observer's own business; the driver goes on
    }
  }
}

void Driver::finish(Timestamp now) {
  if (controller_) controller_->shutdown(now);
  finished_ = true;  // the publication below wakes the waiters
  const bool stop_sent = std::any_of(sent_.begin(), sent_.end(), [](const SentEvent& e) {
    return e.sent.shutdown && std::holds_alternative<MotionCommand>(e.sent.message);
  });
  if (!stop_sent) {
    tracker_.no_stop_sent(!bus_ ? "the bus " + bus_name_ + " was never opened"
                          : source_ && source_->read_only()
                              ? "the bus is read-only (nothing is ever sent on it)"
                              : "the driver had nothing to stop",
                          now, step_events_);
  }
  publish(now);
  deliver();
}

// ---- the thread ------------------------------------------------------------------------------

void Driver::loop() {
  ::pthread_setname_np(::pthread_self(), config_.thread_name.substr(0, 15).c_str());
  try {
    while (!mailbox_.stop_requested()) {
      const Timestamp now = clock_.now();
      step(now);
      // Woken by the next due instant (at least once a second), or by wake().
      waker_.sleep_until(std::min(next_due(), now + std::chrono::seconds(1)));
    }
  } catch (const std::exception& e) {  // never let an exception escape the thread
    bus_error_ = std::string("driver thread failed: ") + e.what();
  } catch (...) {
    bus_error_ = "driver thread failed";
  }
  finish(clock_.now());
}

}  // namespace ranger
