// Who vouches for the protocol settings while the driver runs: the identification before anything
// moves (DriverConfig::protocol auto, identification.hpp), the plausibility monitors while
// driving (plausibility.hpp), and the commissioning's standstill probe. The driver thread owns
// it; it tells the controller what to do about them (quiet while listening, the probe, the
// identifying refusal, the implausible stop) and hands every new set of settings to the driver
// (UseProfile), which passes it to the controller, the odometry and back here (on_profile).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/driver_snapshot.hpp"
#include "ranger_can/control/geometry.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/control/plausibility.hpp"
#include "ranger_can/wire/frame.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {

// A zero-speed probe at standstill (`ranger_can commission`): the wheels stand in `mode` at
// `steering` (REP-103 rad: the front wheels' reference angle in Ackermann, the direction of travel
// in oblique mode), nothing rolls.
struct StandstillProbe {
  protocol::MotionMode mode = protocol::MotionMode::kAckermann;
  double steering = 0.0;
};

struct SettingsSupervisorConfig {
  ProtocolChoice protocol = ProtocolChoice::kForced;
  std::optional<std::string> identify_revision;  // kAuto: start from this preset
  IdentificationConfig identification;
  PlausibilityConfig plausibility;
  VehicleGeometry geometry;
  ProtocolProfile configured;  // the controller's profile as configured
  OdometrySource odometry_source = OdometrySource::kWheels;
};

class SettingsSupervisor {
 public:
  // Called with every new set of settings; reset_odometry: nothing has moved yet (the pose starts
  // over), else the odometry keeps its pose.
  using UseProfile = std::function<void(const ProtocolProfile&, bool reset_odometry)>;

  SettingsSupervisor(SettingsSupervisorConfig config, UseProfile use_profile);

  // The bus opened: under protocol auto the identification starts (listening: the controller
  // says nothing and refuses motion as identifying). `read_only`: decide from the frames alone.
  void start(ChassisController& controller, bool read_only);

  bool identifying() const;  // the identification runs (not decided, not failed)
  // While listening, no frame reaches the controller (read under settings not decided yet).
  bool listening() const;
  bool decided() const;  // forced settings, or the identification decided them
  // Under protocol auto, before the decision: whether what the joint states / the odometry read
  // is decided (nothing is published that would be a guess).
  bool joints_readable() const;
  bool odometry_readable() const;

  // Every received frame, before it is decoded (the identification's evidence).
  void on_frame(const CanFrame& frame, Timestamp now);
  // Decoded (`rejected`: the codec's refusal) frames for the monitors (not while identifying).
  void monitor_frame(const CanFrame& frame, Timestamp now);
  void monitor_rejected(const CanFrame& frame, Errc code, Timestamp now);

  // ---- per iteration, in this order ----
  // The identification's phase and probe into the controller; its decision into the driver.
  // `odometry_fed`: the odometry has integrated frames (a decision keeps its pose).
  void run_identification(Timestamp now, ChassisController& controller, bool odometry_fed);
  // The commissioning's standstill probe (after the identification, if any).
  void set_standstill_probe(std::optional<StandstillProbe> probe) { probe_ = probe; }
  void run_standstill_probe(ChassisController& controller);
  // After the controller's tick: the monitors judge; a stop goes to the controller (latched)
  // and, under protocol auto, the value the monitor names is adopted.
  void run_plausibility(Timestamp now, ChassisController& controller,
                        const OdometryState& odometry);

  // The operator's resume: a plausibility stop is taken on, the monitors start over.
  void resume(ChassisController& controller);
  // The settings in use from now on (the monitors judge under them).
  void on_profile(const ProtocolProfile& profile) { monitor_.set_profile(profile); }

  // The identification's status for a snapshot (shared while it does not change); null without
  // an identification.
  std::shared_ptr<const IdentificationStatus> status();
  const PlausibilityStatus& plausibility() const { return monitor_.status(); }

 private:
  ProtocolProfile with_configured_settings(const IdentificationStatus& st) const;
  void hold_probe_for(MotionRefusal refusal);

  SettingsSupervisorConfig config_;
  UseProfile use_profile_;
  std::optional<ChassisIdentifier> identifier_;
  // Its status as last published; copied again while the identification runs, and after a
  // change once it is done (a new identifier, a setting adopted while driving).
  std::shared_ptr<const IdentificationStatus> status_;
  bool status_changed_ = false;
  PlausibilityMonitor monitor_;
  std::string applied_stop_;  // the monitor's stop passed to the controller
  std::optional<StandstillProbe> probe_;
  bool probe_active_ = false;
};

}  // namespace ranger
