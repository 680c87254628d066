"""Keyboard teleop logic for the RANGER, free of ROS and of the terminal (so tests drive it with a
fake clock): keys in, a velocity command and a status text out.

Terminals report key presses, never releases: a held key arrives as a first press, then (after
the keyboard's auto-repeat delay, typically 0.25-0.66 s) as repeats every 30-40 ms. So a motion
lasts `first_repeat_delay` after a new key (long enough for auto-repeat to start), then
`key_timeout` after each repeat, and stops when the repeats stop. Both are shorter than the
time a stale command may live anyway: the teleop sends an explicit stop, and ranger_base_node's
`cmd_vel_timeout` (0.5 s) is only the backstop if the teleop dies.

The three motion modes are chosen by the shape of the command, as ranger_base expects:
  Ackermann  linear.x (+ angular.z for an arc of fixed radius)
  crab       linear.y (oblique mode: all wheels at the same angle)
  spin       angular.z with zero linear velocity
"""

import enum
import math
from dataclasses import dataclass


class Mode(enum.Enum):
    STOPPED = "stopped"
    ACKERMANN = "Ackermann"
    CRAB = "crab"
    SPIN = "spin"


@dataclass(frozen=True)
class Command:
    linear_x: float = 0.0  # m/s, forward
    linear_y: float = 0.0  # m/s, left
    angular_z: float = 0.0  # rad/s, counter-clockwise
    mode: Mode = Mode.STOPPED

    def is_stop(self):
        return self.linear_x == 0.0 and self.linear_y == 0.0 and self.angular_z == 0.0


STOP = Command()

# key -> (mode, forward sign, left sign, turn sign). For Ackermann the turn sign picks an arc
# to the left (+1) or right (-1); the yaw rate follows from speed / turn_radius, so driving
# backwards along a left arc is (x<0, z<0), as a car.
MOTION_KEYS = {
    "w": (Mode.ACKERMANN, +1, 0, 0),
    "x": (Mode.ACKERMANN, -1, 0, 0),
    "q": (Mode.ACKERMANN, +1, 0, +1),
    "e": (Mode.ACKERMANN, +1, 0, -1),
    "z": (Mode.ACKERMANN, -1, 0, +1),
    "c": (Mode.ACKERMANN, -1, 0, -1),
    "a": (Mode.CRAB, 0, +1, 0),
    "d": (Mode.CRAB, 0, -1, 0),
    "j": (Mode.SPIN, 0, 0, +1),
    "l": (Mode.SPIN, 0, 0, -1),
}
STOP_KEYS = {"s", "k", " "}
FASTER_KEYS = {"+", "="}
SLOWER_KEYS = {"-", "_"}
HELP_KEYS = {"h", "?"}
# The deliberate re-arm after a stop the teleop did not ask for (an e-stop, the remote control, a
# fault, link loss): the shell calls the driver's `resume` service. The robot does not move.
REARM_KEYS = {"r"}
QUIT_KEYS = {"\x03", "\x04", "\x1b"}  # Ctrl-C, Ctrl-D, Esc (the terminal's signals are off)

HELP = """\
RANGER keyboard teleop -- hold a key to move, release it to stop
  Ackermann (car-like)    Crab (oblique)        Spin (in place)
     q   w   e              a : left              j : spin left (CCW)
         |                  d : right             l : spin right (CW)
     z   x   c
  w/x forward/back, q/e z/c forward/back along a left/right arc
  s, k or space : stop      + / - : speed up / down by 10 %%
  r : re-arm after a stop (the driver's resume service; a zero twist never re-arms)
  h : this help             Ctrl-C, Ctrl-D or Esc : stop and quit
  arc radius %.2f m; limits: %.2f m/s, %.2f rad/s"""


class Event(enum.Enum):
    MOTION = "motion"
    STOP = "stop"
    SPEED = "speed"
    HELP = "help"
    REARM = "rearm"
    QUIT = "quit"
    IGNORED = "ignored"


@dataclass
class Settings:
    speed: float = 0.3  # m/s for Ackermann and crab
    spin_speed: float = 0.5  # rad/s
    turn_radius: float = 1.5  # m, Ackermann arc radius
    max_speed: float = 1.5  # m/s
    max_spin_speed: float = 1.5  # rad/s
    min_speed: float = 0.05  # m/s, and rad/s for spin
    speed_step: float = 1.1  # factor per + / -
    key_timeout: float = 0.3  # s after a repeat
    first_repeat_delay: float = 0.6  # s after a new key

    def validate(self):
        """Raises ValueError naming the first setting that is out of range."""
        for name in ("speed", "spin_speed", "turn_radius", "max_speed", "max_spin_speed",
                     "min_speed", "key_timeout", "first_repeat_delay"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {value}")
        if not (math.isfinite(self.speed_step) and self.speed_step > 1):
            raise ValueError(f"speed_step must be > 1, got {self.speed_step}")
        if self.min_speed > min(self.max_speed, self.max_spin_speed):
            raise ValueError("min_speed must not exceed max_speed or max_spin_speed")
        if self.first_repeat_delay < self.key_timeout:
            raise ValueError("first_repeat_delay must be >= key_timeout")


def _clamp(value, low, high):
    return min(max(value, low), high)


class Teleop:
    """Feed keys with on_key(key, now); read the command to send with command(now)."""

    def __init__(self, settings=None):
        self.settings = settings or Settings()
        self.settings.validate()
        s = self.settings
        s.speed = _clamp(s.speed, s.min_speed, s.max_speed)
        s.spin_speed = _clamp(s.spin_speed, s.min_speed, s.max_spin_speed)
        self._key = None  # the motion key being held
        self._deadline = None  # when the motion stops unless the key repeats

    def on_key(self, key, now):
        s = self.settings
        if key in MOTION_KEYS:
            repeat = key == self._key and self._deadline is not None and now <= self._deadline
            self._key = key
            self._deadline = now + (s.key_timeout if repeat else s.first_repeat_delay)
            return Event.MOTION
        if key in STOP_KEYS:
            self._release()
            return Event.STOP
        if key in FASTER_KEYS or key in SLOWER_KEYS:
            factor = s.speed_step if key in FASTER_KEYS else 1.0 / s.speed_step
            s.speed = _clamp(s.speed * factor, s.min_speed, s.max_speed)
            s.spin_speed = _clamp(s.spin_speed * factor, s.min_speed, s.max_spin_speed)
            return Event.SPEED
        if key in HELP_KEYS:
            return Event.HELP
        if key in REARM_KEYS:
            return Event.REARM
        if key in QUIT_KEYS:
            self._release()
            return Event.QUIT
        return Event.IGNORED

    def _release(self):
        self._key = None
        self._deadline = None

    def command(self, now):
        """The command for this instant: the held key's motion, or STOP once it timed out."""
        if self._key is None:
            return STOP
        if now > self._deadline:
            self._release()
            return STOP
        s = self.settings
        mode, forward, left, turn = MOTION_KEYS[self._key]
        if mode is Mode.ACKERMANN:
            v = forward * s.speed
            return Command(linear_x=v, angular_z=turn * v / s.turn_radius, mode=mode)
        if mode is Mode.CRAB:
            return Command(linear_y=left * s.speed, mode=mode)
        return Command(angular_z=turn * s.spin_speed, mode=mode)

    def help_text(self):
        s = self.settings
        return HELP % (s.turn_radius, s.max_speed, s.max_spin_speed)

    def status_line(self, now):
        c = self.command(now)
        s = self.settings
        return (f"mode: {c.mode.value:<9} | x {c.linear_x:+.2f} m/s  y {c.linear_y:+.2f} m/s  "
                f"yaw {c.angular_z:+.2f} rad/s | speed {s.speed:.2f} m/s, spin "
                f"{s.spin_speed:.2f} rad/s")


def split_keys(data):
    """Splits terminal input into keys. Escape sequences (arrow keys) count as one ignored key so
    that their bytes are not read as letters; a lone Esc quits."""
    keys, i = [], 0
    while i < len(data):
        ch = data[i]
        if ch == "\x1b" and i + 1 < len(data) and data[i + 1] in "[O":
            j = i + 2
            while j < len(data) and not ("@" <= data[j] <= "~"):
                j += 1
            keys.append(data[i:j + 1])
            i = j + 1
            continue
        keys.append(ch)
        i += 1
    return keys
