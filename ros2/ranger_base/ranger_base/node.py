"""ranger_base_node for ROS 2: the ROS 1 node's topics, services, parameters and frames, in rclpy
over the Python binding of libranger_can (import ranger_can).

The driver (the bus, the 20 ms keep-alive, the 500 ms command timeout, the re-arm, the
identification, the odometry) runs in C++ on a thread of the library's own; this node maps:
  * cmd_vel -> Driver.command (the driver's mailbox: never waits for the bus), on a thread of the
    node's own that waits for cmd_vel alone (not the executor, whose every wake-up rebuilds its
    wait set in Python: that costs more than the driver itself and delays the command), taking
    its bytes and reading them in C++ (ranger_can.read_twist: no Python message per command);
    that thread is rclpy's private API, kept in rclpy_fast with its public fallback (cmd_vel in
    a callback group of its own, served by the executor), chosen at start-up and logged;
  * the driver's estimates -> odom, /tf, joint_states at publish_rate (each estimate once,
    stamped with its frames' time, only while the chassis is heard; Driver.wait_motion paces
    them in C++ and hands over ready values for messages allocated once), the states at
    state_publish_rate, /diagnostics at 1 Hz, cmd_vel_out for every motion frame sent — on a
    thread of the node's own, which waits with the GIL released;
  * the services -> the driver's requests, answered when the chassis answers (the executor's
    threads: cmd_vel is never queued behind them);
  * sim/inject -> the virtual chassis's control language (port sim[:VARIANT]).
All names are relative (push the node into a namespace for several robots); /tf and
/diagnostics are global by their conventions.
"""

import os
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
from rclpy.duration import Duration
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

from . import conversions, parameters, rclpy_fast
# Every private call of rclpy's is in rclpy_fast (with its public fallback).
from .rclpy_fast import name_os_thread

# The services' numbers and what they mean: the library's (ranger_msgs' constants are the same
# numbers, test/test_adapter.py), never re-typed here.
MOTION_MODES = dict(ranger_can.motion_mode_numbers())  # None: automatic
DRIVE_MODES = dict(ranger_can.drive_mode_numbers())
LIGHT_MODES = dict(ranger_can.light_mode_numbers())
LIGHT_CODES = {v: k for k, v in LIGHT_MODES.items()}


# The driver's events that answer a call of the node's (a service's request settled, the motion
# mode pinned): each is the service's answer, logged once as the answer (_log_answer); the
# library's list, as the ROS 1 node's.
ANSWER_EVENTS = frozenset(ranger_can.answer_event_kinds())

# s: Python's thread switch interval in the node (sys.setswitchinterval; main() says why).
GIL_SWITCH_INTERVAL = 0.0005

# s: how long the motion publication trusts its last look at who subscribes (a new subscriber
# gets odom, /tf, joint_states at most this late).
AUDIENCE_PERIOD = 0.1


class ParameterError(Exception):
    """Start-up refused: every bad parameter, one per line."""


class RangerNode(Node):
    def __init__(self, **kwargs):
        super().__init__("ranger_base_node", **kwargs)
        display = self.get_fully_qualified_name() + "."
        declared = parameters.declare_all(self, display)
        errors = list(declared.errors)
        self.driver = None
        try:
            # The library checks every value against its row (the ROS 1 node's messages) and
            # gives the node's own values back checked (Driver.settings); publish_cmd records
            # the frames sent for cmd_vel_out.
            self.driver = ranger_can.Driver(parameters.default_of_port(), params=declared.given,
                                            start=False, display_prefix=display)
        except RangerError as e:
            errors.append(str(e))
        if errors:
            text = "\n".join(errors)
            for name in parameters.declared_names():  # ROS 2 spells nesting with '.'
                text = text.replace(f"{display}{name} ", f"{display}{parameters.ros2_name(name)} ")
            raise ParameterError(text)
        self.params = dict(self.driver.settings)
        self.params[parameters.DIAGNOSTIC_PERIOD] = declared.diagnostic_period
        self.port = self.params["port_name"]
        self.add_on_set_parameters_callback(self._on_set_parameters)

        self._diagnostics_ns = self.get_namespace()
        self._stop = threading.Event()
        self._stopped = False
        self._last_remote = 0
        self._last_ultrasonic = {}
        self._motion_audience = (False, False, False, False)

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

        # cmd_vel on a thread of its own: never queued behind a service waiting for the chassis,
        # never behind the executor's wait-set rebuild.
        self._service_group = MutuallyExclusiveCallbackGroup()
        # The bytes, read in C++, where this rmw serialises a Twist as the binding reads it;
        # else messages. Either way _twist_values gives (linear x, y, z, angular x, y, z).
        read_twist = conversions.twist_reader()
        self._read_raw = read_twist is not None
        self._twist_values = read_twist or conversions.twist_values
        # Twist or TwistStamped: the library's rule (cmd_vel_stamped; auto: the publishers'
        # type, the graph looked at again while the publication thread runs).
        self._cmd_lock = threading.Lock()
        self._cmd_rule = ranger_can.CmdVelTypeRule(self.params["cmd_vel_stamped"], "ros2")
        self._cmd_topic = self.resolve_topic_name("cmd_vel")
        self.cmd_sub = self._cmd_thread = None
        taken = self._cmd_rule.start(self._cmd_publisher_types())
        self._subscribe_cmd_vel(bool(taken.stamped))  # none taken yet: Twist until one is
        self.get_logger().info(taken.line)
        joint_names = ranger_can.steering_joint_names() + ranger_can.wheel_joint_names()
        self.motion_messages = conversions.MotionMessages(self.params, joint_names)
        # odom, /tf and joint_states serialised in C++ where this rmw reads the bytes as the
        # messages themselves.
        self.motion_wire, mismatch = conversions.motion_encoder(self.params, joint_names)
        rmw = f"this rmw ({os.environ.get('RMW_IMPLEMENTATION', 'the default')})"
        if mismatch:
            self.get_logger().warning(
                f"{mismatch}: {rmw} does not read the binding's serialised messages as they "
                "were meant; odom, /tf and joint_states are published as messages (more CPU)")
        if read_twist is None:
            self.get_logger().warning(
                f"cmd_vel: {rmw} serialises a Twist otherwise than ranger_can.read_twist reads "
                "it; cmd_vel is taken as messages (more CPU per command)")
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

    # ---- cmd_vel: Twist or TwistStamped ----
    def _cmd_publisher_types(self):
        """The types of cmd_vel's publishers, as the rule takes them (auto only: else none)."""
        if not self._cmd_rule.follows_publishers:
            return []
        return [i.topic_type for i in self.get_publishers_info_by_topic(self._cmd_topic)]

    def _subscribe_cmd_vel(self, stamped):
        """(Re)subscribes cmd_vel with the type asked, on a thread of its own (started when the
        node runs)."""
        with self._cmd_lock:
            if self._stopped:
                return
            old_sub, old_thread = self.cmd_sub, self._cmd_thread
            if old_thread is not None:
                old_thread.stop()
            if old_sub is not None:
                self.destroy_subscription(old_sub)
            msg_type, callback, raw = ((TwistStamped, self._on_cmd_vel_stamped, False) if stamped
                                       else (Twist, self._on_cmd_vel, self._read_raw))
            self.cmd_sub = self.create_subscription(
                msg_type, "cmd_vel", callback, 1, callback_group=rclpy_fast.callback_group(),
                event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False), raw=raw)
            self._cmd_thread = rclpy_fast.serve(self, self.cmd_sub, "ranger_cmd_vel")
            self._cmd_stamped = stamped
            if old_thread is not None:  # the node runs
                self._cmd_thread.start()

    def _recheck_cmd_vel_type(self):
        """cmd_vel_stamped auto: the publishers to the rule; a change of type subscribed and said
        (the rmw matches only the publishers of the subscription's type)."""
        if not self._cmd_rule.follows_publishers:
            return
        d = self._cmd_rule.on_publishers(self._cmd_publisher_types())
        if d.stamped is not None and d.stamped != self._cmd_stamped:
            self._subscribe_cmd_vel(d.stamped)
        if d.line:  # a change, said once
            self.get_logger().info(d.line)

    def _publisher(self, msg_type, topic, depth):
        # No QoS event handlers: each one is Python work in every executor wake-up.
        return self.create_publisher(
            msg_type, topic, depth,
            event_callbacks=PublisherEventCallbacks(use_default_callbacks=False))

    # ---- life cycle ----
    def start(self):
        self.driver.start()
        self._thread.start()
        with self._cmd_lock:
            self._cmd_thread.start()
        kind = ("the in-process virtual chassis" if self.driver.is_sim else
                "a replayed log: nothing is sent" if self.port.startswith("replay:") else
                "SocketCAN")
        self.get_logger().info(
            f"ranger_base_node on {self.port} ({kind}), publishing odom at "
            f"{self.params['publish_rate']:.1f} Hz ({self.params['odom_frame']} -> "
            f"{self.params['base_frame']}{', TF on' if self.tf_pub else ', TF off'})")
        for severity, text in self.driver.startup_lines:  # the library's words, as ROS 1's
            self._log_at(severity, text)
        self.get_logger().info(rclpy_fast.choose().line())

    def shutdown(self):
        """Stops the chassis first (the driver's zero motion command), then publication."""
        if self._stopped:
            return
        with self._cmd_lock:
            self._stopped = True
            self._cmd_thread.stop()
            if self.cmd_sub is not None:
                self.destroy_subscription(self.cmd_sub)
                self.cmd_sub = None
        self.driver.close()  # the stop; its event ("stop sent to the chassis ...") logged here
        self._log_events()
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        if self.cmd_out_pub is not None:  # the stop reaches the subscribers before ROS goes
            self.cmd_out_pub.wait_for_all_acked(Duration(seconds=1.0))

    def _on_set_parameters(self, params):
        for p in params:
            name = parameters.ros1_name(p.name)
            if name not in parameters.CHANGEABLE:
                return SetParametersResult(successful=False,
                                           reason=f"{p.name} cannot change while the driver runs")
            try:
                value = ranger_can.check_parameter(name, p.value)  # the library's row
            except RangerError as e:
                return SetParametersResult(successful=False, reason=str(e))
            self.params[name] = value
        return SetParametersResult(successful=True)

    # ---- callbacks ----
    def _on_cmd_vel(self, msg):
        """cmd_vel: its bytes (a raw subscription, read by conversions.twist_reader) or a
        Twist."""
        self._drive(self._twist_values(msg))

    def _on_cmd_vel_stamped(self, msg):
        """cmd_vel as a TwistStamped: its age by the node's clock goes with it (the driver refuses
        one older than cmd_vel_timeout: stale_command); a zero stamp means now."""
        stamp = msg.header.stamp
        age = None
        if stamp.sec or stamp.nanosec:
            age = (self.get_clock().now().nanoseconds - (stamp.sec * 10**9 + stamp.nanosec)) * 1e-9
        self._drive(conversions.twist_values(msg.twist), age)

    def _drive(self, values, age=None):
        vx, vy, vz, wx, wy, wz = values
        stamped = {} if age is None else {"age": age}
        try:  # all six fields: the driver refuses NaN/inf in any of them, naming it
            self.driver.command(vx, vy, wz, vz=vz, wx=wx, wy=wy, **stamped)
            if vz or wx or wy:
                self.get_logger().warning("cmd_vel: linear.z, angular.x and angular.y are "
                                          "ignored (planar base)", throttle_duration_sec=5.0)
        except RangerError:
            # Logged once, as the driver's command_refused event (its reports spaced) and the
            # refusal in system_state: not again here.
            pass

    def _on_inject(self, msg: String):
        try:
            said = self.driver.inject(msg.data)
        except RangerError as e:
            self.get_logger().warning(f"sim/inject \"{msg.data}\" not applied: {e}")
            return
        self.get_logger().info(f"sim/inject \"{msg.data}\" applied to the virtual chassis"
                               + (f": {said}" if said else ""))

    def _answer(self, what, call):
        """Runs a request; (success, message, outcome): the library's answer to the outcome
        (ranger_can.request_answer, the ROS 1 node's words), or why it was not posted."""
        try:
            outcome = call()
        except (RequestFailed, RequestTimeout) as e:
            outcome = e.outcome
            if outcome is None:
                return False, str(e), None
        except RangerError as e:
            return False, str(e), None
        ok, message = ranger_can.request_answer(outcome)
        return ok, message, outcome

    def _log_answer(self, what, ok, message):
        """Every service answer, one line at its severity (info, or warn for a refusal or a
        failure), in the library's words (the answer's message); the driver's events that are
        the same answer (ANSWER_EVENTS) are not logged again. Every answer has its line: the
        driver's request_settled events leave out an answer alike to the one before it."""
        severity, line = ranger_can.answer_line(what, ok, message)
        self._log_at(severity, line)

    def _on_resume(self, request, response):
        refused = ranger_can.resume_refused_offline(self.driver.snapshot(), self.port)
        if refused is not None:
            response.success = False
            response.message = refused
        else:
            response.success, response.message, _ = self._answer("resume", self.driver.resume)
        self._log_answer("resume", response.success, response.message)
        return response

    def _on_clear_errors(self, request, response):
        _, message, outcome = self._answer(
            "clear_errors", lambda: self.driver.clear_errors(request.code))
        s = self.driver.snapshot()
        if outcome is None:  # not posted (the bus is not open)
            response.success, response.message = False, message
        else:  # the library's words, as the ROS 1 node answers
            response.success, response.message = ranger_can.clear_errors_answer(
                request.code, outcome, s)
        response.error_word = outcome.error_word if response.success else s.error_word
        self._log_answer("clear_errors", response.success, response.message)
        return response

    def _on_set_ultrasonic(self, request, response):
        refused = ranger_can.ultrasonic_request_refused(request.enable, request.disable)
        if refused is not None:
            response.success = False
            response.message = refused
        else:
            ok, message, _ = self._answer(
                "ultrasonic", lambda: self.driver.set_ultrasonic(request.enable))
            response.success = ok
            response.message = message
        response.enabled = bool(self.driver.snapshot().ultrasonic_enabled)
        self._log_answer("set_ultrasonic", response.success, response.message)
        return response

    def _on_set_motion_mode(self, request, response):
        if request.mode not in MOTION_MODES:
            response.success = False  # the valid values: the ones valid on this chassis
            response.message = ranger_can.unknown_motion_mode_number(request.mode,
                                                                     self.driver.snapshot())
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
        response.message = ranger_can.motion_mode_pinned(mode)
        self._log_answer("set_motion_mode", True, response.message)
        return response

    def _on_set_lights(self, request, response):
        response.success = False
        refused = ranger_can.lights_request_refused(request.front_mode, request.front_brightness,
                                                    request.rear_mode, request.rear_brightness)
        if refused is not None:  # the library's check and words, as the ROS 1 node's
            response.message = refused
        else:  # the brightness counts in custom mode only (the library sends 0 otherwise)
            ok, message, _ = self._answer("set_lights", lambda: self.driver.set_lights(
                front=LIGHT_MODES[request.front_mode], rear=LIGHT_MODES[request.rear_mode],
                front_brightness=request.front_brightness,
                rear_brightness=request.rear_brightness))
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
        try:  # the library's check and words, as the ROS 1 node's
            mode = ranger_can.drive_mode_request(request.mode)
        except RangerError as e:
            response.success = False
            response.message = str(e)
        else:
            ok, message, _ = self._answer("set_drive_mode",
                                          lambda: self.driver.set_drive_mode(mode))
            response.success = ok
            response.message = message
        reported = self.driver.snapshot().drive_mode_raw
        response.drive_mode = SystemState.DRIVE_MODE_NONE if reported is None else reported
        self._log_answer("set_drive_mode", response.success, response.message)
        return response

    # ---- publication (a thread of the node's own) ----
    def _heard(self, pub):
        return pub is not None and pub.get_subscription_count() > 0

    def _publication_loop(self):
        """Wakes when the driver has a new estimate and the motion publication is due (paced in
        C++: Driver.wait_motion), when a motion frame was sent (cmd_vel_out), or when the
        states or diagnostics are due; not at every driver iteration."""
        name_os_thread("ranger_publish")
        # The library's fixed-rate schedules (ranger_can.PublicationSchedule), as the ROS 1
        # node's publication thread paces its states and diagnostics.
        start = next_audience = time.monotonic()
        states = ranger_can.PublicationSchedule(self.params["state_publish_rate"])
        diagnostics = ranger_can.PublicationSchedule(1.0 / self.params["diagnostic_period"])
        states.start(start)
        diagnostics.start(start)
        while not self._stop.is_set():
            try:
                now = time.monotonic()
                if states.due(now):
                    self._publish_states(self.driver.snapshot())
                    states.advance(now, self.params["state_publish_rate"])
                if diagnostics.due(now):
                    self._publish_diagnostics()
                    diagnostics.advance(now, 1.0 / self.params["diagnostic_period"])
                if now >= next_audience:
                    self._motion_audience = self._ask_motion_audience()
                    self._recheck_cmd_vel_type()
                    next_audience = now + AUDIENCE_PERIOD
                wait = max(0.0, min(states.wake_at, diagnostics.wake_at, next_audience)
                           - time.monotonic())
                if any(self._motion_audience):
                    update = self.driver.wait_motion(self.params["publish_rate"], wait)
                    self._publish_motion(update)
                    self._publish_sent(update.sent)
                elif self.cmd_out_pub is not None:
                    self._publish_sent(self.driver.wait_sent(wait))
                else:
                    self._stop.wait(wait)
            except Exception as e:  # noqa: BLE001 (nothing may end the publication thread)
                self.get_logger().error(f"publishing failed: {e}", throttle_duration_sec=5.0)
                self._stop.wait(0.05)
        # What was sent but not published yet, and the shutdown's stop.
        self._publish_sent(self.driver.sent() if self.cmd_out_pub else [])

    def _publish_sent(self, sent):
        for m in sent:
            self.cmd_out_pub.publish(conversions.to_twist_stamped(m, self.params["base_frame"]))

    def _ask_motion_audience(self):
        """Whether odom, /tf, joint_states, sim/ground_truth have subscribers: each question is
        a call into the rmw, so it is asked every AUDIENCE_PERIOD, not at every publication."""
        return (self._heard(self.odom_pub), self._heard(self.tf_pub),
                self._heard(self.joint_pub), self._heard(self.truth_pub))

    def _publish_motion(self, update):
        """odom, /tf, joint_states from the estimate's ready values (each estimate once): the
        bytes of the binding's encoder where it matched the rmw, else messages."""
        if not update.new_estimate:
            return
        odom_heard, tf_heard, joints_heard, truth_heard = self._motion_audience
        if self.motion_wire is not None:
            odom, tf, joints = self.motion_wire.encode(update)
            if odom is not None:
                if tf_heard:
                    self.tf_pub.publish(tf)
                if odom_heard:
                    self.odom_pub.publish(odom)
            if joints is not None and joints_heard:
                self.joint_pub.publish(joints)
        else:
            self._publish_motion_messages(update, odom_heard, tf_heard, joints_heard)
        if truth_heard:
            truth = self.driver.ground_truth()
            self.truth_pub.publish(conversions.to_ground_truth(truth, self.params))

    def _publish_motion_messages(self, update, odom_heard, tf_heard, joints_heard):
        m = self.motion_messages
        odometry = update.odometry
        if odometry is not None and (odom_heard or tf_heard):
            m.fill_odometry(odometry)
            if tf_heard:
                self.tf_pub.publish(m.tf)
            if odom_heard:
                self.odom_pub.publish(m.odom)
        joints = update.joints
        if joints is not None and joints_heard:
            m.fill_joints(joints)
            self.joint_pub.publish(m.joints)

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
        for event in self.driver.events():
            if event.kind not in ANSWER_EVENTS:
                self._log_at(event.severity, event.text)

    def _log_at(self, severity, text):
        """A line of the library's at its severity (debug, info, warn, error). A call site of its
        own per severity: rclpy keeps a logging call's context (severity, filters) by where it is
        called from and refuses another severity there (ValueError: the line is lost)."""
        log = self.get_logger()
        if severity == "error":
            log.error(text)
        elif severity == "warn":
            log.warning(text)
        elif severity == "debug":
            log.debug(text)
        else:
            log.info(text)

    def _publish_diagnostics(self):
        """The library's diagnostic groups of the latest snapshot (ranger_can's
        Driver.diagnostics: name, level, message, key/values, hardware_id), one to one onto
        diagnostic_msgs, named as diagnostic_updater names them ("<node>: <group>")."""
        groups = self.driver.diagnostics(self._diagnostics_ns)
        self.diag_pub.publish(conversions.to_diagnostics(
            groups, self.get_clock().now().to_msg(), self.get_name()))


def main(args=None):
    # SIGINT and SIGTERM are the node's to handle: the chassis is stopped (and the stop published
    # on cmd_vel_out) while ROS is still up, then ROS goes down.
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    # A thread waiting for the GIL (cmd_vel's, woken by a command) makes the holder let go after
    # this long, not after Python's default 5 ms: a command never waits behind the publication
    # thread turning a diagnostics report into messages.
    sys.setswitchinterval(GIL_SWITCH_INTERVAL)
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
