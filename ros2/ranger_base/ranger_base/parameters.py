"""The node's parameters: every row of the library's one parameter table (ranger_can.parameters():
libranger_can/include/ranger_can/frontend/node_parameters.hpp, the rows the ROS 1 node reads),
declared with descriptors made from the row (type, range, valid values, meaning). The values
given are checked by the library when the driver is built (ranger_can.Driver: its messages are
the ROS 1 node's, naming the parameter, the value and the valid range, all at once); the node's
own values (frames, rates, covariances, ultrasonic ranges) come back checked (Driver.settings).

ROS 2 names nest with '.', ROS 1's with '/': `linear/x/max_velocity` is `linear.x.max_velocity`.
Every parameter is read-only but the publication rates (nothing else can change while the driver
runs); a change of those is checked against their row (ranger_can.check_parameter).

Beside the table: `diagnostic_period`, which the ROS 1 node has from diagnostic_updater (its own
parameter, not a row of the library's table; ranger_base/README.md names it).
"""

import math
from dataclasses import dataclass, field
from typing import Dict, List

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rcl_interfaces.msg import ParameterType as PT

import ranger_can

from . import rclpy_fast

# What may change while the node runs (ROS 2 only: ROS 1 reads its parameters once).
CHANGEABLE = {"publish_rate", "state_publish_rate"}

# diagnostic_updater's own parameter (ROS 1): /diagnostics every this many seconds.
DIAGNOSTIC_PERIOD = "diagnostic_period"
DIAGNOSTIC_PERIOD_DEFAULT = 1.0

_TYPES = {"bool": PT.PARAMETER_BOOL, "int": PT.PARAMETER_INTEGER, "double": PT.PARAMETER_DOUBLE,
          "string": PT.PARAMETER_STRING, "string_list": PT.PARAMETER_STRING_ARRAY,
          "double_list": PT.PARAMETER_DOUBLE_ARRAY}


def ros2_name(name: str) -> str:
    return name.replace("/", ".")


def ros1_name(name: str) -> str:
    return name.replace(".", "/")


def rows():
    """The library's table, in the README's order."""
    return ranger_can.parameters()


def default_of(row):
    """The value a row is declared with, or None: declared by type alone when its default is not
    a value of its own (the model's, a preset's, -max_velocity) or an empty list (ROS 2 cannot
    type it)."""
    if row.default_note or row.type == "string_list":
        return None
    return row.default


def default_of_port() -> str:
    """port_name's default (the table's): the bus when none is given."""
    return next(r.default for r in rows() if r.name == "port_name")


def descriptor(row) -> ParameterDescriptor:
    name = ros2_name(row.name)
    d = ParameterDescriptor(name=name, type=_TYPES[row.type],
                            read_only=row.name not in CHANGEABLE)
    d.description = row.meaning + (f" ({row.unit})" if row.unit else "")
    constraints = ["valid " + row.valid]
    if row.choices:
        constraints.append("one of " + ", ".join(row.choices))
    if row.default_note:
        constraints.append("default " + row.default_note)
    d.additional_constraints = "; ".join(constraints)
    if row.has_range and math.isfinite(row.lo) and math.isfinite(row.hi):
        if row.type == "double":
            d.floating_point_range = [FloatingPointRange(from_value=float(row.lo),
                                                         to_value=float(row.hi), step=0.0)]
        elif row.type == "int":
            d.integer_range = [IntegerRange(from_value=int(row.lo), to_value=int(row.hi), step=1)]
    return d


@dataclass
class Declared:
    """What the declaration found: the values given (by ROS 1 name), for the library to check;
    diagnostic_period; its problem, if any."""
    given: Dict[str, object] = field(default_factory=dict)
    diagnostic_period: float = DIAGNOSTIC_PERIOD_DEFAULT
    errors: List[str] = field(default_factory=list)


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
        given = rclpy_fast.refused_value(node, name)
        if default is None:
            node.declare_parameter(name, Parameter.Type(_TYPES[type_name]), desc,
                                   ignore_override=True)
        else:
            node.declare_parameter(name, default, desc, ignore_override=True)
        return given


def _declare_diagnostic_period(node, display, out):
    desc = ParameterDescriptor(name=DIAGNOSTIC_PERIOD, type=PT.PARAMETER_DOUBLE, read_only=True,
                               description="/diagnostics every this many seconds "
                                           "(diagnostic_updater's own parameter in ROS 1) (s)",
                               additional_constraints="valid > 0 s")
    refused = _declare(node, DIAGNOSTIC_PERIOD, "double", DIAGNOSTIC_PERIOD_DEFAULT, desc)
    value = refused if refused is not None else node.get_parameter(DIAGNOSTIC_PERIOD).value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not math.isfinite(value) or value <= 0:
        out.errors.append(f"parameter {display}{DIAGNOSTIC_PERIOD} = {value!r}: expected a "
                          "number of seconds > 0")
    else:
        out.diagnostic_period = float(value)


def _plain(value):
    """A list for an array value (rclpy gives arrays as array.array or bytes)."""
    if isinstance(value, (str, bool, int, float)) or value is None:
        return value
    return list(value)


def declare_all(node, display: str) -> Declared:
    """Declares every parameter on `node`; what was given and any problem of
    diagnostic_period (the library checks the rest when the driver is built)."""
    out = Declared()
    for row in rows():
        name = ros2_name(row.name)
        refused = _declare(node, name, row.type, default_of(row), descriptor(row))
        if refused is not None:
            out.given[row.name] = _plain(refused)
        else:
            given = rclpy_fast.given_value(node, name, default_of(row))
            if given is not None:
                out.given[row.name] = _plain(given)
    # ROS 2 gives an empty list as a byte array or an empty array of another type.
    if "sim/errors" in out.given and not out.given["sim/errors"]:
        out.given["sim/errors"] = []
    _declare_diagnostic_period(node, display, out)
    return out


def declared_names() -> List[str]:
    """Every parameter name the node declares (ROS 1 spelling), for the parity test."""
    return [r.name for r in rows()] + [DIAGNOSTIC_PERIOD]
