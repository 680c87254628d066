#include "ranger_can/control/settings_supervisor.hpp"

#include <algorithm>
#include <utility>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {

SettingsSupervisor::SettingsSupervisor(SettingsSupervisorConfig config, UseProfile use_profile)
    : config_(std::move(config)),
      use_profile_(std::move(use_profile)),
      monitor_(config_.plausibility, config_.geometry, config_.configured) {}

void SettingsSupervisor::start(ChassisController& controller, bool read_only) {
  if (config_.protocol != ProtocolChoice::kAuto) return;
  // Listen before speaking: the controller hears nothing and says nothing until the
  // identification has proposed the settings.
  status_changed_ = true;
  identifier_.emplace(config_.identification, config_.geometry, config_.identify_revision,
                      read_only);
  controller.set_quiet(true);
  controller.set_identifying(IdentificationPhase::kListening);
}

bool SettingsSupervisor::identifying() const {
  return identifier_ && !identifier_->status().done();
}

bool SettingsSupervisor::listening() const {
  return identifying() && identifier_->status().phase == IdentificationPhase::kListening;
}

bool SettingsSupervisor::decided() const {
  return !identifier_ || identifier_->status().decided_ok();
}

bool SettingsSupervisor::joints_readable() const {
  return !identifier_ || identifier_->wheel_angles_known();
}

bool SettingsSupervisor::odometry_readable() const {
  if (decided()) return true;
  // The wheels' odometry reads 0x271 and 0x281 (whose unit no revision changes); 0x221's needs
  // the whole decision.
  return config_.odometry_source == OdometrySource::kWheels && identifier_->wheel_angles_known();
}

void SettingsSupervisor::on_frame(const CanFrame& frame, Timestamp now) {
  if (identifying()) identifier_->on_frame(frame, now);
}

void SettingsSupervisor::monitor_frame(const CanFrame& frame, Timestamp now) {
  monitor_.on_frame(frame, now);
}

void SettingsSupervisor::monitor_rejected(const CanFrame& frame, Errc code, Timestamp now) {
  monitor_.on_rejected(frame, code, now);
}

ProtocolProfile SettingsSupervisor::with_configured_settings(const IdentificationStatus& st) const {
  // What the identification kept from its revision's preset, the configured profile (a model's
  // own readings: the MINI V1's mode numbering, spin field and sign) has a better value for,
  // when it is of the same revision.
  ProtocolProfile p = st.profile;
  const ProtocolProfile& configured = config_.configured;
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

void SettingsSupervisor::hold_probe_for(MotionRefusal refusal) {
  // The probe is motion the controller would refuse for a cause of the commander's (a re-arm
  // after the remote control or a stop, an e-stop): it waits for that, not for the chassis.
  switch (refusal) {
    case MotionRefusal::kRearmRequired:
      identifier_->hold_probe("motion needs the re-arm (call resume, or send a zero twist)");
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
}

void SettingsSupervisor::run_identification(Timestamp now, ChassisController& controller,
                                            bool odometry_fed) {
  if (!identifying()) return;
  hold_probe_for(controller.state().refusal);
  identifier_->tick(now);
  const IdentificationStatus& st = identifier_->status();
  if (st.decided_ok()) {
    // A chassis driven (by its remote) before the decision keeps the pose it reached.
    use_profile_(with_configured_settings(st), /*reset_odometry=*/!odometry_fed);
    controller.set_probe(std::nullopt, std::nullopt);
    controller.set_quiet(false);
    controller.set_identifying(std::nullopt);
    return;
  }
  if (st.phase == IdentificationPhase::kFailed) {
    // At rest, and saying why: the refusal stays, with the message naming what to set.
    controller.set_probe(std::nullopt, std::nullopt);
    controller.set_identifying(IdentificationPhase::kFailed);
    return;
  }
  const IdentificationRequest r = identifier_->request();
  if (r.profile) use_profile_(*r.profile, /*reset_odometry=*/!odometry_fed);
  controller.set_quiet(r.quiet);
  controller.set_probe(r.mode, r.probe);
  controller.set_identifying(st.phase);
}

void SettingsSupervisor::run_standstill_probe(ChassisController& controller) {
  if (!decided()) return;  // the identification's
  if (probe_) {
    MotionCommand c;
    c.steering_angle = interpretation::manual_from_rep103_command_steering(probe_->steering);
    controller.set_standstill_probe(true);
    controller.set_probe(probe_->mode, c);
    probe_active_ = true;
  } else if (probe_active_) {
    controller.set_probe(std::nullopt, std::nullopt);
    controller.set_standstill_probe(false);
    probe_active_ = false;
  }
}

void SettingsSupervisor::run_plausibility(Timestamp now, ChassisController& controller,
                                          const OdometryState& odometry) {
  if (!decided()) return;
  monitor_.update(now, controller.state(), controller.feedback(), odometry);
  const auto stop = monitor_.status().stop;
  if (!stop || !applied_stop_.empty()) return;
  applied_stop_ = stop->text();
  controller.set_implausible(applied_stop_);  // the stop, latched
  // Auto: a setting the identification could not decide at rest is learned here. The stop stays
  // latched (a zero twist or resume re-arms); the cause itself is gone with the setting.
  if (identifier_) status_changed_ = true;  // adopt() records the stop either way
  if (identifier_ && identifier_->adopt(stop->setting, stop->try_value, stop->detail)) {
    use_profile_(with_configured_settings(identifier_->status()), /*reset_odometry=*/false);
    controller.set_implausible("");
    applied_stop_.clear();
  }
}

void SettingsSupervisor::resume(ChassisController& controller) {
  // The operator takes a plausibility stop on: the monitors start over (and trip again if the
  // mismatch persists).
  if (applied_stop_.empty()) return;
  monitor_.reset();
  applied_stop_.clear();
  controller.set_implausible("");
}

std::shared_ptr<const IdentificationStatus> SettingsSupervisor::status() {
  if (!identifier_) {
    status_.reset();
  } else if (!status_ || !status_->done() || status_changed_) {
    status_ = std::make_shared<const IdentificationStatus>(identifier_->status());
    status_changed_ = false;
  }
  return status_;
}

}  // namespace ranger
