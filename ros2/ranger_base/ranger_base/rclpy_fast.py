"""Every use of rclpy's private API in ranger_base, each beside its public-API fallback; which of
the two paths the process takes is chosen once, at start-up (choose()), and said once in the
node's log.

The fast path (the default where this rclpy has what it needs):
  * cmd_vel on a thread of its own that waits on a wait set holding only that subscription
    (`_rclpy.WaitSet`) and takes each message itself (`Subscription.handle.take_message`), so no
    executor wakes for a command: an executor's every wake-up rebuilds its wait set in Python,
    which costs more than the driver itself and delays the command;
  * the parameters given at start-up read from rclpy's overrides (`Node._parameter_overrides`):
    what an owner gave, exactly, even a value rclpy refuses for its type or range (the library's
    message then names it).
The public path (RANGER_RCLPY_PATH=public forces it; chosen by itself when this rclpy lacks a
private name the fast path uses):
  * cmd_vel in a callback group of its own, served by the node's multi-threaded executor
    (never queued behind a service: those are mutually exclusive among themselves, and the
    executor has threads to spare);
  * a parameter counts as given when its declared value is not its default; a value rclpy
    refuses is read back through a declaration without constraints (dynamic typing), which is
    then undeclared.
Both paths are tested on each distribution (test/test_rclpy_paths.py).
"""

import os
import threading

from rclpy.callback_groups import CallbackGroup, MutuallyExclusiveCallbackGroup
from rclpy.guard_condition import GuardCondition

# The environment variable that forces a path: "public", or "auto" (the default: fast where
# this rclpy has it).
ENV = "RANGER_RCLPY_PATH"

FAST = "fast"
PUBLIC = "public"


def name_os_thread(name):
    """Names the calling thread as the OS shows it (top -H, /proc/PID/task/TID/comm; Python's
    thread names stay inside Python), as the ROS 1 node names its threads."""
    import ctypes
    try:
        ctypes.CDLL(None).prctl(15, name.encode()[:15], 0, 0, 0)  # PR_SET_NAME
    except (OSError, AttributeError):
        pass


def _private_api():
    """rclpy's private implementation module, or None."""
    try:
        from rclpy.impl.implementation_singleton import rclpy_implementation
        return rclpy_implementation
    except ImportError:
        return None


def missing_private_names():
    """The private names the fast path uses that this rclpy lacks (empty: it has them all)."""
    from rclpy.subscription import Subscription
    impl = _private_api()
    missing = []
    if impl is None:
        missing.append("rclpy.impl.implementation_singleton.rclpy_implementation")
    else:
        waitset = getattr(impl, "WaitSet", None)
        if waitset is None:
            missing.append("_rclpy.WaitSet")
        else:
            for method in ("clear_entities", "add_subscription", "add_guard_condition", "wait"):
                if not hasattr(waitset, method):
                    missing.append(f"_rclpy.WaitSet.{method}")
        sub_type = getattr(impl, "Subscription", None)
        if sub_type is None or not hasattr(sub_type, "take_message"):
            missing.append("_rclpy.Subscription.take_message")
    if not isinstance(getattr(Subscription, "handle", None), property):
        missing.append("Subscription.handle")
    return missing


class Choice:
    """The path chosen (FAST or PUBLIC) and why, in a line for the log."""

    def __init__(self, path, why):
        self.path, self.why = path, why

    @property
    def fast(self):
        return self.path == FAST

    def line(self):
        return f"rclpy: the {self.path} path ({self.why})"


_choice = None
_choice_lock = threading.Lock()


def choose(environ=None):
    """The path of this process, chosen at its first call (later calls give the same choice)."""
    global _choice
    with _choice_lock:
        if _choice is None:
            _choice = decide(os.environ if environ is None else environ)
        return _choice


def decide(environ):
    """The path the environment and this rclpy give (no state kept: choose() keeps it)."""
    asked = environ.get(ENV, "auto").strip().lower() or "auto"
    if asked == PUBLIC:
        return Choice(PUBLIC, f"{ENV}=public")
    missing = missing_private_names()
    if missing:
        return Choice(PUBLIC, "this rclpy lacks " + ", ".join(missing))
    why = "a wait set of cmd_vel's own, the overrides given" + (
        "" if asked in ("auto", FAST) else f"; {ENV}={asked} unknown: auto, fast or public")
    return Choice(FAST, why)


# ---- cmd_vel on a thread of its own (fast) or in the executor (public) -----------------------

class OwnThreadGroup(CallbackGroup):
    """The callback group of what a thread of the node's own serves (cmd_vel): no executor ever
    takes it up, so it stays out of the executor's wait set."""

    def can_execute(self, entity):
        return False

    def beginning_execution(self, entity):
        return False

    def ending_execution(self, entity):
        pass


class SubscriptionThread:
    """Serves one subscription on a thread of its own: waits on a wait set holding only that
    subscription (and a guard condition to end it) with the GIL released, takes each message and
    calls the callback (as rclpy.wait_for_message waits). No executor wakes for it."""

    def __init__(self, node, subscription, name):
        self._sub = subscription
        self._context = node.context
        self._wake = GuardCondition(None, None, context=node.context)
        self._stop = threading.Event()
        self._logger = node.get_logger()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self):
        self._thread.start()

    def stop(self):
        """Ends the thread (the callback does not run afterwards); idempotent."""
        self._stop.set()
        if self._thread.is_alive():
            self._wake.trigger()
            self._thread.join()
        self._wake.destroy()

    def _run(self):
        name_os_thread(self._thread.name)
        sub, handle = self._sub, self._sub.handle
        wait_set = _private_api().WaitSet(1, 1, 0, 0, 0, 0, self._context.handle)
        while not self._stop.is_set():
            try:
                wait_set.clear_entities()
                wait_set.add_subscription(handle)
                wait_set.add_guard_condition(self._wake.handle)
                wait_set.wait(1_000_000_000)
                if self._stop.is_set():
                    break
                while (taken := handle.take_message(sub.msg_type, sub.raw)) is not None:
                    sub.callback(taken[0])
            except Exception as e:  # noqa: BLE001 (nothing may end the thread but stop())
                if not self._context.ok():
                    break
                self._logger.error(f"{sub.topic_name}: {e}", throttle_duration_sec=5.0)
                self._stop.wait(0.05)


class ExecutorServed:
    """The public path's stand-in for SubscriptionThread: the executor serves the subscription
    (its callback group is its own); start and stop have nothing to do."""

    def start(self):
        pass

    def stop(self):
        pass


def callback_group():
    """The callback group of a subscription served apart from the services (cmd_vel)."""
    return OwnThreadGroup() if choose().fast else MutuallyExclusiveCallbackGroup()


def serve(node, subscription, name):
    """What serves `subscription` (created in callback_group()'s group): a thread of its own
    (fast), or the node's executor (public); started by .start(), ended by .stop()."""
    if choose().fast:
        return SubscriptionThread(node, subscription, name)
    return ExecutorServed()


# ---- parameters given at start-up ------------------------------------------------------------

_NOT_GIVEN = object()


def _overrides(node):
    """rclpy's overrides of this node (fast path), or None where this node has none (then the
    public reading serves, on either path)."""
    overrides = getattr(node, "_parameter_overrides", None)
    return overrides if isinstance(overrides, dict) else None


def given_value(node, name, default):
    """The value given for a declared parameter at start-up, or None when none was given.
    Fast: rclpy's overrides. Public: the declared value when it is not the default (a parameter
    declared by type alone: any value)."""
    overrides = _overrides(node) if choose().fast else None
    if overrides is not None:
        return None if name not in overrides else node.get_parameter(name).value
    from rclpy.exceptions import ParameterUninitializedException
    try:
        value = node.get_parameter(name).value
    except ParameterUninitializedException:
        return None
    if value is None:
        return None
    if default is not None and _same(value, default):
        return None
    return value


def refused_value(node, name):
    """The value given for `name` that rclpy refused to declare (its type or range), or None.
    Fast: rclpy's overrides. Public: declared without constraints to read it, then undeclared
    (the caller declares it again, ignoring the override)."""
    overrides = _overrides(node) if choose().fast else None
    if overrides is not None:
        p = overrides.get(name)
        return None if p is None else p.value
    from rcl_interfaces.msg import ParameterDescriptor
    p = node.declare_parameter(name, None, ParameterDescriptor(dynamic_typing=True))
    value = p.value
    node.undeclare_parameter(name)
    return value


def _same(value, default):
    if isinstance(value, (str, bool, int, float)):
        return type(value) is type(default) and value == default
    try:
        return list(value) == list(default)
    except TypeError:
        return False
