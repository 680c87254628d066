"""Keyboard teleop for the RANGER on ROS 2: keys from the terminal, geometry_msgs/Twist on
`cmd_vel` (relative: it follows the node's namespace). The key logic is the ROS 1 package's
ranger_bringup.teleop_keys (the same file); this is the terminal and rclpy shell around it.

Parameters: speed (m/s), spin_speed (rad/s), turn_radius (m), max_speed (m/s), max_spin_speed
(rad/s), key_timeout (s), first_repeat_delay (s), rate (Hz). On exit (Ctrl-C, Ctrl-D, Esc,
SIGINT, SIGTERM, end of input) it sends a stop and restores the terminal.
"""

import os
import select
import signal
import sys
import termios
import time

import rclpy
from geometry_msgs.msg import Twist
from rclpy.signals import SignalHandlerOptions

from ranger_bringup.teleop_keys import STOP, Event, Settings, Teleop, split_keys

STOP_REPEATS = 3  # stops sent after a motion ends, in case one is lost
SETTINGS = ("speed", "spin_speed", "turn_radius", "max_speed", "max_spin_speed", "key_timeout",
            "first_repeat_delay")


class RawTerminal:
    """Key-at-a-time input without echo; Ctrl-C arrives as a key (the robot is stopped before
    the teleop leaves). Restores the terminal on exit."""

    def __init__(self, fd):
        self.fd = fd
        self.saved = None

    def __enter__(self):
        self.saved = termios.tcgetattr(self.fd)
        raw = termios.tcgetattr(self.fd)
        raw[0] &= ~(termios.IXON | termios.ICRNL)
        raw[3] &= ~(termios.ICANON | termios.ECHO | termios.ISIG)
        raw[6][termios.VMIN] = 1
        raw[6][termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSADRAIN, raw)
        return self

    def __exit__(self, *exc):
        termios.tcsetattr(self.fd, termios.TCSADRAIN, self.saved)
        return False


def to_twist(command):
    twist = Twist()
    twist.linear.x = command.linear_x
    twist.linear.y = command.linear_y
    twist.angular.z = command.angular_z
    return twist


def run(teleop, publish, fd, out, rate_hz, quit_requested):
    period = 1.0 / rate_hz
    stops_left = 0
    last = None
    out.write("\r\x1b[K" + teleop.help_text().replace("\n", "\r\n") + "\r\n")
    while not quit_requested() and rclpy.ok():
        readable, _, _ = select.select([fd], [], [], period)
        now = time.monotonic()
        if readable:
            data = os.read(fd, 64)
            if not data:
                return "end of input"
            for key in split_keys(data.decode("utf-8", errors="replace")):
                event = teleop.on_key(key, now)
                if event is Event.QUIT:
                    return "quit key"
                if event is Event.HELP:
                    out.write("\r\x1b[K" + teleop.help_text().replace("\n", "\r\n") + "\r\n")
                    last = None
        command = teleop.command(now)
        if not command.is_stop():
            publish(to_twist(command))
            stops_left = STOP_REPEATS
        elif stops_left > 0:
            publish(to_twist(STOP))
            stops_left -= 1
        line = teleop.status_line(now)
        if line != last:
            out.write("\r\x1b[K" + line)
            out.flush()
            last = line
    return "shutdown"


def main(args=None):
    fd = sys.stdin.fileno()
    if not os.isatty(fd):
        sys.stderr.write("ranger_teleop_keyboard: stdin is not a terminal. Run it in a terminal, "
                         "e.g. ros2 run ranger_bringup ranger_teleop_keyboard\n")
        return 1
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("ranger_teleop_keyboard")
    defaults = Settings()
    try:
        values = {n: float(node.declare_parameter(n, float(getattr(defaults, n))).value)
                  for n in SETTINGS}
        teleop = Teleop(Settings(**values))
        rate_hz = float(node.declare_parameter("rate", 20.0).value)
        if not rate_hz > 0:
            raise ValueError(f"rate must be > 0, got {rate_hz}")
    except ValueError as e:
        node.get_logger().fatal(f"ranger_teleop_keyboard: invalid parameter: {e}")
        rclpy.try_shutdown()
        return 2
    publisher = node.create_publisher(Twist, "cmd_vel", 5)
    signals = []
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, lambda n, _frame: signals.append(n))
    reason = "?"
    try:
        with RawTerminal(fd):
            reason = run(teleop, publisher.publish, fd, sys.stdout, rate_hz,
                         lambda: bool(signals))
    finally:
        for _ in range(STOP_REPEATS):
            publisher.publish(to_twist(STOP))
            time.sleep(0.05)
        sys.stdout.write("\r\n")
        if signals:
            reason = f"signal {signals[0]}"
        print(f"ranger_teleop_keyboard: stopped ({reason})", flush=True)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
