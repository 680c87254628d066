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
