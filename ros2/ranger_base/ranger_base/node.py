"""ranger_base_node for ROS 2: the ROS 1 node's topics, services, parameters and frames, in rclpy
over the Python binding of libranger_can (import ranger_can).

The driver (the bus, the 20 ms keep-alive, the 500 ms command timeout, the re-arm, the
identification, the odometry) runs in C++ on a thread of the library's own; this node maps:
  * cmd_vel -> Driver.command (the driver's mailbox: never waits for the bus);
  * the driver's snapshots -> odom, /tf, joint_states at publish_rate (each estimate once,
    stamped with its frames' time, only while the chassis is heard), the states at
    state_publish_rate, /diagnostics at 1 Hz, cmd_vel_out for every motion frame sent — on a
    thread of the node's own, which waits for snapshots with the GIL released;
  * the services -> the driver's requests, answered when the chassis answers (they wait on a
    callback group of their own, so cmd_vel is never queued behind them);
  * sim/inject -> the virtual chassis's control language (port sim[:VARIANT]).
All names are relative (push the node into a namespace for several robots); /tf and
/diagnostics are global by their conventions.
"""

import signal
import sys
import threading
import time

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import SetParametersResult
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
try:
    from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
except ImportError:  # Humble: the same classes under their older module name
    from rclpy.qos_event import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from ranger_msgs.msg import (ActuatorStateArray, BmsStateArray, RemoteState, SystemState,
                             UltrasonicState)
from ranger_msgs.srv import ClearErrors, SetDriveMode, SetLights, SetMotionMode, SetUltrasonic
from sensor_msgs.msg import BatteryState, JointState, Range
from std_msgs.msg import String
from std_srvs.srv import SetBool, Trigger
from tf2_msgs.msg import TFMessage

import ranger_can
from ranger_can import RangerError, RequestFailed, RequestTimeout

from . import adapters, conversions, parameters

MOTION_MODES = {SetMotionMode.Request.ACKERMANN: "ackermann",
                SetMotionMode.Request.OBLIQUE: "oblique", SetMotionMode.Request.SPIN: "spin",
                SetMotionMode.Request.SIDE_SLIP: "side_slip",
                SetMotionMode.Request.AUTOMATIC: None}
DRIVE_MODES = {SetDriveMode.Request.CURRENT: "current", SetDriveMode.Request.VOLTAGE: "voltage"}
LIGHT_MODES = {SetLights.Request.OFF: "off", SetLights.Request.ON: "on",
               SetLights.Request.BREATHING: "breathing", SetLights.Request.CUSTOM: "custom"}
LIGHT_CODES = {v: k for k, v in LIGHT_MODES.items()}


def _advance(due, period, now):
    """A fixed-rate schedule: one period after the last due time; after a stall, from now."""
    due += period
    return due if due >= now else now + period


class ParameterError(Exception):
    """Start-up refused: every bad parameter, one per line."""


class RangerNode(Node):
    def __init__(self, **kwargs):
        super().__init__("ranger_base_node", **kwargs)
        display = self.get_fully_qualified_name() + "."
        declared = parameters.declare_all(self, display)
        errors = list(declared.errors)
        self.params = declared.node
        self.port = self.params["port_name"]
        self.driver = None
        try:
            self.driver = ranger_can.Driver(self.port, params=declared.given,
                                            record_sent=self.params["publish_cmd"], start=False,
                                            display_prefix=display)
        except RangerError as e:
            errors.append(str(e))
        if errors:
            text = "\n".join(errors)
            for name in parameters.declared_names():  # ROS 2 spells nesting with '.'
                text = text.replace(f"{display}{name} ", f"{display}{parameters.ros2_name(name)} ")
            raise ParameterError(text)
        self.add_on_set_parameters_callback(self._on_set_parameters)

        ns = self.get_namespace()
        self.hardware_id = f"ranger:{ns}:{self.port}"
        self._stop = threading.Event()
        self._stopped = False
        self._last_odom = self._last_joints = self._last_remote = 0
        self._last_ultrasonic = {}

        q = 10
        self.odom_pub = self._publisher(Odometry, "odom", q)
        self.joint_pub = self._publisher(JointState, "joint_states", q)
        self.system_pub = self._publisher(SystemState, "system_state", q)
        self.actuator_pub = self._publisher(ActuatorStateArray, "actuator_state", q)
        self.bms_pub = self._publisher(BmsStateArray, "bms_state", q)
        self.battery_pub = self._publisher(BatteryState, "battery_state", q)
        self.ultrasonic_pub = self._publisher(UltrasonicState, "ultrasonic_state", q)
        self.remote_pub = self._publisher(RemoteState, "remote_state", q)
        self.range_pubs = [self._publisher(Range, f"ultrasonic/range_{i}", q)
                           for i in range(1, 9)]
        self.cmd_out_pub = (self._publisher(TwistStamped, "cmd_vel_out", 100)
                            if self.params["publish_cmd"] else None)
        self.truth_pub = (self._publisher(Odometry, "sim/ground_truth", q)
                          if self.driver.is_sim else None)
        self.tf_pub = (self._publisher(TFMessage, "/tf", 100)
                       if self.params["publish_odom_tf"] else None)
        self.diag_pub = self._publisher(DiagnosticArray, "/diagnostics", q)

        # cmd_vel on a group of its own: never queued behind a service waiting for the chassis.
        self._cmd_group = MutuallyExclusiveCallbackGroup()
        self._service_group = MutuallyExclusiveCallbackGroup()
        self.cmd_sub = self.create_subscription(
            Twist, "cmd_vel", self._on_cmd_vel, 1, callback_group=self._cmd_group,
            event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))
        self.inject_sub = (self.create_subscription(String, "sim/inject", self._on_inject, 10,
                                                    callback_group=self._service_group)
                           if self.driver.is_sim else None)
        g = self._service_group
        self.servers = [
            self.create_service(Trigger, "resume", self._on_resume, callback_group=g),
            self.create_service(ClearErrors, "clear_errors", self._on_clear_errors,
                                callback_group=g),
            self.create_service(SetUltrasonic, "set_ultrasonic", self._on_set_ultrasonic,
                                callback_group=g),
            self.create_service(SetMotionMode, "set_motion_mode", self._on_set_motion_mode,
                                callback_group=g),
            self.create_service(SetLights, "set_lights", self._on_set_lights, callback_group=g),
            self.create_service(SetBool, "park", self._on_park, callback_group=g),
            self.create_service(SetDriveMode, "set_drive_mode", self._on_set_drive_mode,
                                callback_group=g),
        ]
        self._thread = threading.Thread(target=self._publication_loop, name="ranger_publish",
                                        daemon=True)

    def _publisher(self, msg_type, topic, depth):
        # No QoS event handlers: each one is Python work in every executor wake-up.
        return self.create_publisher(
            msg_type, topic, depth,
            event_callbacks=PublisherEventCallbacks(use_default_callbacks=False))

    # ---- life cycle ----
    def start(self):
        self.driver.start()
        self._thread.start()
        kind = ("the in-process virtual chassis" if self.driver.is_sim else
                "a replayed log: nothing is sent" if self.port.startswith("replay:") else
                "SocketCAN")
        self.get_logger().info(
            f"ranger_base_node on {self.port} ({kind}), publishing odom at "
            f"{self.params['publish_rate']:.1f} Hz ({self.params['odom_frame']} -> "
            f"{self.params['base_frame']}{', TF on' if self.tf_pub else ', TF off'})")
        self.get_logger().info(f"model {self.driver.model}; protocol settings: "
                               f"{self.driver.protocol_source}")

    def shutdown(self):
        """Stops the chassis first (the driver's zero motion command), then publication."""
        if self._stopped:
            return
        self._stopped = True
        if self.cmd_sub is not None:
            self.destroy_subscription(self.cmd_sub)
            self.cmd_sub = None
        self.driver.close()  # the stop; its event ("stop sent to the chassis ...") logged here
        self._log_events()
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()

    def _on_set_parameters(self, params):
        for p in params:
            name = parameters.ros1_name(p.name)
            row = next((r for r in parameters.NODE_ROWS if r.name == name), None)
            if row is None or row.read_only:
                return SetParametersResult(successful=False,
                                           reason=f"{p.name} cannot change while the driver runs")
            value, problem = parameters._check_node_value(row, p.value, "")
            if problem:
                return SetParametersResult(successful=False, reason=problem)
            self.params[name] = value
        return SetParametersResult(successful=True)

    # ---- callbacks ----
    def _on_cmd_vel(self, msg: Twist):
        try:  # all six fields: the driver refuses NaN/inf in any of them, naming it
            self.driver.command(msg.linear.x, msg.linear.y, msg.angular.z, vz=msg.linear.z,
                                wx=msg.angular.x, wy=msg.angular.y)
            if msg.linear.z or msg.angular.x or msg.angular.y:
                self.get_logger().warn("cmd_vel: linear.z, angular.x and angular.y are ignored "
                                       "(planar base)", throttle_duration_sec=5.0)
        except RangerError as e:
            if e.code == "not_finite":
                self.get_logger().error(f"cmd_vel refused, chassis stopped: {e}",
                                        throttle_duration_sec=1.0)
            else:
                self.get_logger().warn(f"cmd_vel not applied: {e}", throttle_duration_sec=5.0)

    def _on_inject(self, msg: String):
        try:
            said = self.driver.inject(msg.data)
        except RangerError as e:
            self.get_logger().warn(f"sim/inject \"{msg.data}\" not applied: {e}")
            return
        self.get_logger().info(f"sim/inject \"{msg.data}\" applied to the virtual chassis"
                               + (f": {said}" if said else ""))

    def _answer(self, what, call):
        """Runs a request; (success, message, outcome)."""
        try:
            outcome = call()
            return True, outcome.message, outcome
        except (RequestFailed, RequestTimeout) as e:
            return False, str(e), e.outcome
        except RangerError as e:
            return False, str(e), None

    def _log_answer(self, what, ok, message):
        (self.get_logger().info if ok else self.get_logger().warn)(f"{what}: {message}")

    def _on_resume(self, request, response):
        s = self.driver.snapshot()
        if not s.bus_open:
            response.success = False
            response.message = f"resume refused: not connected to {self.port}" + (
                f": {s.bus_error}" if s.bus_error else "")
        else:
            ok, message, _ = self._answer("resume", self.driver.resume)
            response.success = ok
            response.message = "re-armed: cmd_vel drives the chassis again" if ok else message
        self._log_answer("resume", response.success, response.message)
        return response

    def _on_clear_errors(self, request, response):
        asked = (f"clear_errors code {request.code} "
                 f"({ranger_can.error_clear_description(request.code)})")
        ok, message, outcome = self._answer(
            "clear_errors", lambda: self.driver.clear_errors(request.code))
        s = self.driver.snapshot()
        if ok and outcome.error_word is not None:
            response.success = True
            response.error_word = outcome.error_word
            names = ranger_can.error_names(outcome.error_word, s.error_layout)
            response.message = (f"{asked}: the chassis answered with error word "
                                f"{outcome.error_word:#010x}"
                                + (f" ({', '.join(names)})" if names else " (no errors)"))
        else:
            response.success = False
            response.error_word = s.error_word
            response.message = message if outcome is None else f"{asked}: {message}"
        self._log_answer("clear_errors", response.success, response.message)
        return response

    def _on_set_ultrasonic(self, request, response):
        if request.enable == request.disable:
            response.success = False
            response.message = (("contradictory request (enable and disable both true)"
                                 if request.enable else
                                 "empty request (neither enable nor disable)")
                                + ": set exactly one of them; nothing sent")
        else:
            ok, message, _ = self._answer(
                "ultrasonic", lambda: self.driver.set_ultrasonic(request.enable))
            response.success = ok
            response.message = message
        response.enabled = bool(self.driver.snapshot().ultrasonic_enabled)
        return response

    def _on_set_motion_mode(self, request, response):
        if request.mode not in MOTION_MODES:
            s = self.driver.snapshot()  # the valid values: the ones valid on this chassis
            valid = [f"{n} ({m})" for n, m in MOTION_MODES.items() if m in s.drivable_modes]
            response.success = False
            response.message = (f"mode {request.mode} unknown: under protocol "
                                f"{s.profile_revision} use {', '.join(valid)} or "
                                f"{SetMotionMode.Request.AUTOMATIC} (automatic)")
            self._log_answer("set_motion_mode", False, response.message)
            return response
        mode = MOTION_MODES[request.mode]
        try:
            self.driver.set_motion_mode(mode)
        except RangerError as e:
            response.success = False
            response.message = str(e)
            self._log_answer("set_motion_mode", False, response.message)
            return response
        response.success = True
        response.message = (f"motion mode pinned to {mode} (the switch happens at standstill)"
                            if mode else "automatic motion-mode selection")
        self._log_answer("set_motion_mode", True, response.message)
        return response

    def _on_set_lights(self, request, response):
        response.success = False
        bad = [f"{side}_mode {mode}" for side, mode in (("front", request.front_mode),
                                                        ("rear", request.rear_mode))
               if mode not in LIGHT_MODES]
        if bad:
            response.message = f"{', '.join(bad)} unknown (0 OFF, 1 ON, 2 BREATHING, 3 CUSTOM): " \
                               "nothing sent"
        else:
            custom = SetLights.Request.CUSTOM
            ok, message, _ = self._answer("set_lights", lambda: self.driver.set_lights(
                front=LIGHT_MODES[request.front_mode], rear=LIGHT_MODES[request.rear_mode],
                front_brightness=request.front_brightness if request.front_mode == custom else 0,
                rear_brightness=request.rear_brightness if request.rear_mode == custom else 0))
            response.success = ok
            response.message = message
        lights = self.driver.snapshot().lights
        if lights is not None:
            response.can_control = lights.can_control
            response.front_mode = LIGHT_CODES.get(lights.front, 0)
            response.rear_mode = LIGHT_CODES.get(lights.rear, 0)
            response.front_brightness = lights.front_brightness
            response.rear_brightness = lights.rear_brightness
        self._log_answer("set_lights", response.success, response.message)
        return response

    def _on_park(self, request, response):
        ok, message, _ = self._answer("park", lambda: self.driver.park(request.data))
        response.success = ok
        response.message = message
        self._log_answer("park", ok, message)
        return response

    def _on_set_drive_mode(self, request, response):
        mode = DRIVE_MODES.get(request.mode)
        if mode is None:
            response.success = False
            response.message = (f"drive mode {request.mode} is not one of 0 (CURRENT), "
                                "1 (VOLTAGE): nothing sent")
        else:
            ok, message, _ = self._answer("set_drive_mode",
                                          lambda: self.driver.set_drive_mode(mode))
            response.success = ok
            response.message = message
        reported = self.driver.snapshot().drive_mode_raw
        response.drive_mode = SystemState.DRIVE_MODE_NONE if reported is None else reported
        if not response.success:
            self.get_logger().warn(f"set_drive_mode: {response.message}")
        return response

    # ---- publication (a thread of the node's own) ----
    def _heard(self, pub):
        return pub is not None and pub.get_subscription_count() > 0

    def _publication_loop(self):
        """Wakes when a publication is due (or, with cmd_vel_out, when a frame was sent), not at
        every driver iteration: motion waits for the driver's next snapshot only when it is due
        and the latest one had no new estimate."""
        next_motion = next_state = next_diag = time.monotonic()
        waiting = False  # motion is due, the latest snapshot had nothing new
        sent = []
        while not self._stop.is_set():
            try:
                self._publish_sent(sent)
                now = time.monotonic()
                s = self.driver.snapshot()
                if now >= next_motion:
                    waiting = not self._publish_motion(s)
                    if not waiting:
                        next_motion = _advance(next_motion, 1.0 / self.params["publish_rate"], now)
                if now >= next_state:
                    self._publish_states(s)
                    next_state = _advance(next_state, 1.0 / self.params["state_publish_rate"], now)
                if now >= next_diag:
                    self._publish_diagnostics(s)
                    next_diag = _advance(next_diag, self.params["diagnostic_period"], now)
                due = min(next_state, next_diag) if waiting else min(next_motion, next_state,
                                                                       next_diag)
                wait = max(0.0, min(due - time.monotonic(), 1.0))
                if waiting:
                    self.driver.wait_snapshot(s.sequence, min(wait, 0.05))
                    sent = self.driver.sent() if self.cmd_out_pub else []
                elif self.cmd_out_pub is not None:
                    sent = self.driver.wait_sent(wait)
                else:
                    self._stop.wait(wait)
            except Exception as e:  # noqa: BLE001 (nothing may end the publication thread)
                self.get_logger().error(f"publishing failed: {e}", throttle_duration_sec=5.0)
                sent = []
                self._stop.wait(0.05)
        # What was taken but not published yet, and the shutdown's stop.
        self._publish_sent(sent + (self.driver.sent() if self.cmd_out_pub else []))

    def _publish_sent(self, sent):
        for m in sent:
            self.cmd_out_pub.publish(conversions.to_twist_stamped(m, self.params["base_frame"]))

    def _publish_motion(self, s) -> bool:
        """odom, /tf, joint_states: each estimate once; False when nothing new was there."""
        if not s.motion_known:
            return True
        published = False
        o = s.odometry
        if o.stamp_ns > self._last_odom:
            self._last_odom = o.stamp_ns
            if self._heard(self.odom_pub) or self._heard(self.tf_pub):
                odom = conversions.to_odometry(o, self.params)
                if self._heard(self.tf_pub):
                    self.tf_pub.publish(TFMessage(transforms=[conversions.to_transform(odom)]))
                if self._heard(self.odom_pub):
                    self.odom_pub.publish(odom)
            published = True
        j = s.joints
        if (j.has_steering or j.has_wheels) and j.stamp_ns > self._last_joints:
            self._last_joints = j.stamp_ns
            if self._heard(self.joint_pub):
                self.joint_pub.publish(conversions.to_joint_state(j))
            published = True
        if published and self._heard(self.truth_pub):
            truth = self.driver.ground_truth()
            self.truth_pub.publish(conversions.to_ground_truth(truth, self.params))
        return published

    def _publish_states(self, s):
        stamp = self.get_clock().now().to_msg()
        if self._heard(self.system_pub):
            self.system_pub.publish(conversions.to_system_state(s, stamp,
                                                                s.refusal_detail))
        if self._heard(self.actuator_pub):
            self.actuator_pub.publish(conversions.to_actuator_state(s.motors, stamp))
        if self._heard(self.bms_pub):
            self.bms_pub.publish(conversions.to_bms_state(s.batteries, stamp))
        if self._heard(self.battery_pub):
            self.battery_pub.publish(conversions.to_battery_state(s, stamp))
        if self._heard(self.ultrasonic_pub):
            self.ultrasonic_pub.publish(conversions.to_ultrasonic_state(s, stamp))
        remote = s.remote
        if remote is not None and remote.received_ns > self._last_remote:
            self._last_remote = remote.received_ns
            if self._heard(self.remote_pub):
                self.remote_pub.publish(conversions.to_remote_state(remote))
        if s.motion_known:
            for u in s.ultrasonic:
                if u.stamp_ns <= self._last_ultrasonic.get(u.sensor, 0):
                    continue
                self._last_ultrasonic[u.sensor] = u.stamp_ns
                pub = self.range_pubs[u.sensor - 1] if 1 <= u.sensor <= 8 else None
                if self._heard(pub):
                    pub.publish(conversions.to_range(u, self.params))
        self._log_events()

    def _log_events(self):
        """The driver's events, each at its severity (the library decides what is a transition
        and words it; the ROS 1 node logs the same)."""
        log = self.get_logger()
        for event in self.driver.events():
            {"debug": log.debug, "info": log.info, "warn": log.warn,
             "error": log.error}.get(event.severity, log.info)(event.text)

    def _publish_diagnostics(self, s):
        groups = adapters.diagnostic_groups(s, self.driver.protocol_source)
        self.diag_pub.publish(conversions.to_diagnostics(
            groups, self.get_clock().now().to_msg(), self.hardware_id))


def main(args=None):
    # SIGINT and SIGTERM are the node's to handle: the chassis is stopped (and the stop published
    # on cmd_vel_out) while ROS is still up, then ROS goes down.
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = RangerNode()
    except ParameterError as e:
        rclpy.logging.get_logger("ranger_base_node").fatal(f"start-up refused:\n{e}")
        rclpy.try_shutdown()
        return 2
    requested = threading.Event()
    # A signal wakes the executor at once (a guard condition), so it need not poll for it.
    wake = node.create_guard_condition(lambda: None)

    def on_signal(*_):
        requested.set()
        wake.trigger()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_signal)
    executor = MultiThreadedExecutor(num_threads=3)
    executor.add_node(node)
    node.start()
    try:
        while not requested.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=1.0)
    except ExternalShutdownException:
        pass
    finally:
        node.get_logger().info("shutting down: stopping the chassis first")
        node.shutdown()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
