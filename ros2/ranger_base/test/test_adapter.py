"""One adapter: a fact the library holds is the library's in the ROS 2 node, never re-typed in its
Python. The services' numbers (SetMotionMode, SetLights, SetDriveMode) and their modes' names are
the library's (ranger_can.motion_mode_numbers, light_mode_numbers, drive_mode_numbers: the ROS 1
node's frontend/answers.hpp and protocol tables); ranger_msgs' constants are the same numbers; and
no module of ranger_base spells a mode's name as a literal of its own (this fails when one does)."""

import glob
import os
import re

import ranger_can
from ranger_msgs.srv import SetDriveMode, SetLights, SetMotionMode

from ranger_base import node

PACKAGE = os.path.dirname(node.__file__)


def constants(request_type):
    """The message's integer constants, NAME -> value (rosidl keeps them on the metaclass)."""
    return {n: getattr(request_type, n) for n in dir(type(request_type))
            if n.isupper() and isinstance(getattr(request_type, n), int)}


def test_the_messages_numbers_are_the_librarys():
    motion = {v: (None if n == "AUTOMATIC" else n.lower())
              for n, v in constants(SetMotionMode.Request).items()}
    assert motion == dict(ranger_can.motion_mode_numbers())
    lights = {v: n.lower() for n, v in constants(SetLights.Request).items()}
    assert lights == dict(ranger_can.light_mode_numbers())
    drive = {v: n.lower() for n, v in constants(SetDriveMode.Request).items()}
    assert drive == dict(ranger_can.drive_mode_numbers())


def test_the_node_maps_the_librarys_tables():
    assert node.MOTION_MODES == dict(ranger_can.motion_mode_numbers())
    assert node.LIGHT_MODES == dict(ranger_can.light_mode_numbers())
    assert node.DRIVE_MODES == dict(ranger_can.drive_mode_numbers())


def test_no_module_retypes_a_mode_name():
    names = {n for _, n in ranger_can.motion_mode_numbers() if n} | \
        {n for _, n in ranger_can.light_mode_numbers()} | \
        {n for _, n in ranger_can.drive_mode_numbers()}
    found = []
    for path in glob.glob(os.path.join(PACKAGE, "*.py")):
        with open(path, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                for literal in re.findall(r"""["']([a-z_]+)["']""", line):
                    if literal in names:
                        found.append(f"{os.path.basename(path)}:{number}: {line.strip()}")
    assert not found, "the library's mode names re-typed:\n" + "\n".join(found)


# The library's words and numbers a module of ranger_base must not spell itself: the services'
# checks and answers (frontend/answers.hpp), BatteryState's status and health (the library's
# battery report), the Range of nothing seen (range_reading), the refusals and the link states,
# cmd_vel's types and the lines about them (frontend/cmd_vel_type.hpp: ranger_can.CmdVelTypeRule).
RETYPED = ("nothing sent", "not confirmed", "set exactly one", "contradictory request",
           "POWER_SUPPLY_STATUS_", "POWER_SUPPLY_HEALTH_", "math.inf",
           "re-armed", "motion mode pinned",
           "geometry_msgs/", "cmd_vel: taken as", "no publisher yet", "type of its publishers")


def test_no_module_retypes_the_librarys_words_or_numbers():
    names = set(ranger_can.refusal_names()) | {"never_connected", "connected", "stale"}
    found = []
    for path in glob.glob(os.path.join(PACKAGE, "*.py")):
        if os.path.basename(path) == "measure_performance.py":  # a tool, no front end
            continue
        with open(path, encoding="utf-8") as f:
            for number, line in enumerate(f, 1):
                code = line.split("#", 1)[0]
                bad = [w for w in RETYPED if w in code]
                bad += [n for n in re.findall(r"""["']([a-z_]+)["']""", code) if n in names]
                if bad:
                    found.append(f"{os.path.basename(path)}:{number}: {bad}: {line.strip()}")
    assert not found, "the library's words re-typed:\n" + "\n".join(found)


def test_the_librarys_battery_and_range_facts_reach_the_messages():
    from sensor_msgs.msg import BatteryState
    from ranger_base import conversions

    class Reading:  # a raw ultrasonic value beyond max_range, and one of no reading
        stamp_ns, sensor = 1, 1

        def __init__(self, raw):
            self.raw = raw
    params = {"frame_prefix": "", "ultrasonic/field_of_view": 0.5, "ultrasonic/min_range": 0.1,
              "ultrasonic/max_range": 0.5}
    assert conversions.to_range(Reading(4000), params).range == ranger_can.range_reading(4000, 0.5)
    assert conversions.to_range(Reading(4000), params).range == float("inf")
    assert conversions.to_range(Reading(0), params).range != conversions.to_range(
        Reading(0), params).range  # NaN: no reading
    with ranger_can.Driver("sim", protocol="manual", start=False) as d:
        s = d.snapshot()
        msg = conversions.to_battery_state(s, conversions.to_time(5))
        report = s.battery_report
    assert (msg.present, msg.power_supply_status, msg.power_supply_health) == (
        report.present, report.power_supply_status, report.power_supply_health)
    assert msg.power_supply_status == BatteryState.POWER_SUPPLY_STATUS_UNKNOWN  # nothing heard
