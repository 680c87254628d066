"""The node's parameters: the library's rows (ranger_can.parameters(): the driver's table, the
vehicle, protocol, limits, odometry and virtual-chassis rows, checked by the library) and the
node's own (frames, publication, covariances, ultrasonic ranges), declared with descriptors.

ROS 2 names nest with '.', ROS 1's with '/': `linear/x/max_velocity` is `linear.x.max_velocity`.
Every parameter is read-only but the publication rates (nothing else can change while the driver
runs). A bad value is reported with the ROS 1 node's message, naming the parameter, the value and
the valid range; all at once.

The node's own rows are listed here until the library's one parameter table covers them (issue
27, point 3): then they come from ranger_can.parameters() like the others.
"""

import math
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rcl_interfaces.msg import ParameterType as PT

import ranger_can

DEFAULT_POSE_COVARIANCE = [1e-4, 1e-4, 1e6, 1e6, 1e6, 1e-3]
DEFAULT_TWIST_COVARIANCE = [1e-3, 1e-3, 1e6, 1e6, 1e6, 2e-3]


@dataclass
class NodeRow:
    """One of the node's own parameters (the library's rows are ranger_can.ParameterRow)."""
    name: str
    type: str  # "bool", "double", "string", "double_list"
    default: object
    meaning: str
    lo: float = 0.0
    hi: float = 0.0
    lo_open: bool = False
    hi_open: bool = False
    has_range: bool = False
    unit: str = ""
    read_only: bool = True


NODE_ROWS = [
    NodeRow("port_name", "string", "can0",
            "the bus: a SocketCAN interface, sim[:VARIANT] or replay:FILE"),
    NodeRow("odom_frame", "string", "odom", "REP-105 odometry frame"),
    NodeRow("base_frame", "string", "base_link", "the robot frame"),
    NodeRow("frame_prefix", "string", "", "prefix of the frames the node names itself"),
    NodeRow("publish_odom_tf", "bool", True, "broadcast odom_frame -> base_frame"),
    NodeRow("publish_rate", "double", 50.0, "odom, TF, joint_states", 0.0, 50.0, True, False,
            True, "Hz", read_only=False),
    NodeRow("state_publish_rate", "double", 10.0, "system_state and the other states", 0.0,
            100.0, True, False, True, "Hz", read_only=False),
    NodeRow("publish_cmd", "bool", False, "publish cmd_vel_out"),
    NodeRow("pose_covariance_diagonal", "double_list", DEFAULT_POSE_COVARIANCE,
            "x, y, z, roll, pitch, yaw: the floor of the pose covariance"),
    NodeRow("twist_covariance_diagonal", "double_list", DEFAULT_TWIST_COVARIANCE,
            "published as the twist covariance"),
    NodeRow("diagnostic_period", "double", 1.0, "/diagnostics every this many seconds", 0.0,
            60.0, True, False, True, "s"),
    NodeRow("ultrasonic/field_of_view", "double", 0.52, "sensor_msgs/Range field_of_view",
            0.0, math.pi, True, False, True, "rad"),
    NodeRow("ultrasonic/min_range", "double", 0.05, "sensor_msgs/Range min_range", 0.0, 10.0,
            False, False, True, "m"),
    NodeRow("ultrasonic/max_range", "double", 5.0, "sensor_msgs/Range max_range", 0.05, 32.767,
            True, False, True, "m"),
]

_TYPES = {"bool": PT.PARAMETER_BOOL, "int": PT.PARAMETER_INTEGER, "double": PT.PARAMETER_DOUBLE,
          "string": PT.PARAMETER_STRING, "string_list": PT.PARAMETER_STRING_ARRAY,
          "double_list": PT.PARAMETER_DOUBLE_ARRAY}


def ros2_name(name: str) -> str:
    return name.replace("/", ".")


def ros1_name(name: str) -> str:
    return name.replace(".", "/")


def _number_text(v: float) -> str:
    return f"{v:g}"


def range_text(lo, hi, lo_open, hi_open, unit="") -> str:
    text = f"{'(' if lo_open else '['}{_number_text(lo)}, {_number_text(hi)}{')' if hi_open else ']'}"
    return f"{text} {unit}" if unit else text


def _default_of(row) -> Optional[object]:
    """A library row's default as a value of its type, or None (the model's, or -max)."""
    text = row.default.split(" ")[0] if row.default else ""
    try:
        if row.type == "bool":
            return {"true": True, "false": False}[text]
        if row.type == "int":
            return int(text)
        if row.type == "double":
            return float(text)
        if row.type == "string":
            return row.default
        if row.type == "string_list":
            return None
    except (KeyError, ValueError):
        return None
    return None


def descriptor(name, type_name, meaning, read_only, unit="", lo=0.0, hi=0.0, lo_open=False,
               hi_open=False, has_range=False, choices=()) -> ParameterDescriptor:
    d = ParameterDescriptor(name=name, type=_TYPES[type_name], read_only=read_only)
    d.description = meaning + (f" ({unit})" if unit else "")
    constraints = []
    if has_range:
        constraints.append("valid " + range_text(lo, hi, lo_open, hi_open, unit))
        if type_name == "double":
            d.floating_point_range = [FloatingPointRange(from_value=float(lo), to_value=float(hi),
                                                         step=0.0)]
        elif type_name == "int":
            d.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi), step=1)]
    if choices:
        constraints.append("one of " + ", ".join(choices))
    d.additional_constraints = "; ".join(constraints)
    return d


@dataclass
class Declared:
    """What the declaration found: the values given (by ROS 1 name), the problems."""
    given: Dict[str, object] = field(default_factory=dict)  # the library's rows, as given
    node: Dict[str, object] = field(default_factory=dict)   # the node's rows, checked values
    errors: List[str] = field(default_factory=list)


def _override(node, name):
    overrides = getattr(node, "_parameter_overrides", {})
    p = overrides.get(name)
    return None if p is None else p.value


def _declare(node, name, type_name, default, desc):
    """Declares with the descriptor; an override rclpy refuses (type, range) is declared away
    and returned as given, for the library's message."""
    from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
    from rclpy.parameter import Parameter
    try:
        if default is None:
            node.declare_parameter(name, Parameter.Type(_TYPES[type_name]), desc)
        else:
            node.declare_parameter(name, default, desc)
        return None
    except (InvalidParameterTypeException, InvalidParameterValueException, TypeError):
        given = _override(node, name)
        if default is None:
            node.declare_parameter(name, Parameter.Type(_TYPES[type_name]), desc,
                                   ignore_override=True)
        else:
            node.declare_parameter(name, default, desc, ignore_override=True)
        return given


def _check_node_value(row: NodeRow, value, display) -> Tuple[object, Optional[str]]:
    """The ROS 1 node's checks of its own rows."""
    name = display + row.name
    if row.type == "double":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return row.default, f"parameter {name} = {value!r}: expected a number in " \
                                f"{range_text(row.lo, row.hi, row.lo_open, row.hi_open, row.unit)}"
        ok = (value > row.lo if row.lo_open else value >= row.lo) and \
             (value < row.hi if row.hi_open else value <= row.hi)
        if not math.isfinite(value) or not ok:
            return row.default, (f"parameter {name} = {_number_text(value)} is out of range: valid "
                                 f"{range_text(row.lo, row.hi, row.lo_open, row.hi_open, row.unit)}")
        return float(value), None
    if row.type == "double_list":
        values = list(value) if isinstance(value, (list, tuple)) else None
        expected = ": expected a list of 6 variances >= 0 (x, y, z, roll, pitch, yaw)"
        if values is None or len(values) != 6 or any(
                isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
                or v < 0 for v in values):
            return row.default, f"parameter {name} = {value!r}{expected}"
        return [float(v) for v in values], None
    if row.type == "bool" and not isinstance(value, bool):
        return row.default, f"parameter {name} = {value!r}: expected true or false"
    if row.type == "string" and not isinstance(value, str):
        return row.default, f"parameter {name} = {value!r}: expected a string"
    return value, None


def _check_frames(values, display, errors):
    for key in ("odom_frame", "base_frame"):
        v = values[key]
        if not v or any(c.isspace() for c in v) or v.startswith("/"):
            errors.append(f"parameter {display}{key} = \"{v}\": expected a tf2 frame id "
                          "(non-empty, no spaces, no leading '/')")
    if values["odom_frame"] == values["base_frame"]:
        errors.append(f"parameter {display}base_frame = \"{values['base_frame']}\" must differ "
                      "from odom_frame")
    prefix = values["frame_prefix"]
    if any(c in prefix for c in " \t") or prefix.startswith("/"):
        errors.append(f"parameter {display}frame_prefix = \"{prefix}\": expected a tf2 frame "
                      "prefix such as \"robot1/\" (no spaces, no leading '/')")


def declare_all(node, display: str) -> Declared:
    """Declares every parameter on `node`; what was given and every problem."""
    out = Declared()
    for row in NODE_ROWS:
        name = ros2_name(row.name)
        desc = descriptor(name, row.type, row.meaning, row.read_only, row.unit, row.lo, row.hi,
                          row.lo_open, row.hi_open, row.has_range)
        refused = _declare(node, name, row.type, row.default, desc)
        value = refused if refused is not None else node.get_parameter(name).value
        value, problem = _check_node_value(row, value, display)
        if problem:
            out.errors.append(problem)
        out.node[row.name] = value
    _check_frames(out.node, display, out.errors)
    umin, umax = out.node["ultrasonic/min_range"], out.node["ultrasonic/max_range"]
    if not umax > umin:
        out.errors.append(f"parameter {display}ultrasonic/max_range = {_number_text(umax)} is out "
                          f"of range: valid ({_number_text(umin)}, 32.767] m")
    for row in ranger_can.parameters():
        name = ros2_name(row.name)
        default = _default_of(row)
        desc = descriptor(name, row.type, row.meaning, True, row.unit, row.lo, row.hi,
                          row.lo_open, row.hi_open, row.has_range, row.choices)
        refused = _declare(node, name, row.type, default, desc)
        if refused is not None:
            out.given[row.name] = refused
        elif _override(node, name) is not None:
            out.given[row.name] = node.get_parameter(name).value
    # ROS 2 gives an empty list as a byte array or an empty array of another type.
    if "sim/errors" in out.given and not out.given["sim/errors"]:
        out.given["sim/errors"] = []
    return out


def declared_names() -> List[str]:
    """Every parameter name the node declares (ROS 1 spelling), for the parity test."""
    return [r.name for r in NODE_ROWS] + [r.name for r in ranger_can.parameters()]
