#!/usr/bin/python3
"""Generates a RANGER URDF from a geometry file (Debian's ROS has no xacro).

The build runs it to produce urdf/ranger.urdf (and urdf/<model>.urdf for every model), and the
launch files run it to fill robot_description, so the URDF and ranger_base_node's parameters
always come from the same file:

    generate_urdf.py [GEOMETRY_YAML] [-o OUTPUT]     (default: this package's geometry.yaml, stdout)
    generate_urdf.py --model MODEL [--models-dir DIR] [-o OUTPUT]

A geometry file is either config/geometry.yaml's form (the node's parameters, a nested
`description:` block) or a model file, libranger_can/models/<model>.yaml: flat `key: value` lines,
`description/<key>` for the URDF's figures and `description/ultrasonic_<n>: [x, y, yaw]` for the
sensors (the same files libranger_can embeds as its model presets).
"""

import argparse
import math
import os
import re
import sys
import xml.dom.minidom
import xml.etree.ElementTree as ET

import yaml

SCRIPT_DIR = os.path.dirname(os.path.abspath(__file__))
DEFAULT_GEOMETRY = os.path.join(SCRIPT_DIR, os.pardir, "config", "geometry.yaml")
# Where --model looks for <model>.yaml, first to last: --models-dir, $RANGER_MODELS_DIR, the copy
# this package installs (share/ranger_description/config/models), the source tree's.
MODELS_DIRS = (os.path.join(SCRIPT_DIR, os.pardir, "config", "models"),
               os.path.join(SCRIPT_DIR, os.pardir, os.pardir, "libranger_can", "models"))

# Wheel order and joint names: libranger_can's geometry.hpp (kWheelNames, kSteeringJointNames,
# kWheelJointNames). test/test_urdf.py checks that both lists agree.
WHEELS = ("front_right", "rear_right", "rear_left", "front_left")
STEERING_JOINTS = tuple(w + "_steering_joint" for w in WHEELS)
WHEEL_JOINTS = tuple(w + "_wheel_joint" for w in WHEELS)
ULTRASONIC_COUNT = 8

TOTAL_MASS = 135.0  # kg with one battery (manual 1.1): the default of description/total_mass
COLOURS = {
    "ranger_body": (0.93, 0.55, 0.10, 1.0),  # orange: the screenshot test looks for this colour
    "ranger_tyre": (0.12, 0.12, 0.12, 1.0),
    "ranger_steering": (0.55, 0.55, 0.58, 1.0),
    "ranger_sensor": (0.10, 0.35, 0.85, 1.0),
}


class GeometryError(ValueError):
    """A geometry file that cannot describe a vehicle; the message names the field."""


def _number(table, key, where, positive=True):
    if key not in table:
        raise GeometryError(f"{where}{key}: missing")
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise GeometryError(f"{where}{key}: expected a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise GeometryError(f"{where}{key}: must be finite, got {value}")
    if positive and value <= 0.0:
        raise GeometryError(f"{where}{key}: must be > 0, got {value}")
    return value


def unflatten(raw):
    """A model file's flat `description/<key>` and `description/ultrasonic_<n>` keys in
    geometry.yaml's nested form (a geometry.yaml comes back unchanged)."""
    out = {k: v for k, v in raw.items() if "/" not in k}
    flat = {k: v for k, v in raw.items() if "/" in k}
    if not flat:
        return out
    desc = out.setdefault("description", {})
    if not isinstance(desc, dict):
        raise GeometryError("description: both a value and description/... keys")
    sensors = {}
    for key, value in flat.items():
        prefix, _, name = key.partition("/")
        if prefix != "description" or not name or "/" in name:
            raise GeometryError(f"{key}: only description/<key> may contain a '/'")
        m = re.fullmatch(r"ultrasonic_(\d+)", name)
        if m:
            sensors[int(m.group(1))] = value
        else:
            desc[name] = value
    if sensors:
        if sorted(sensors) != list(range(1, len(sensors) + 1)):
            raise GeometryError("description/ultrasonic_<n>: expected ultrasonic_1 to "
                                f"ultrasonic_{ULTRASONIC_COUNT}, got {sorted(sensors)}")
        desc["ultrasonic"] = [sensors[n] for n in sorted(sensors)]
    return out


def model_path(model, models_dir=None):
    """The model file of `model`: the first <dir>/<model>.yaml that exists; the error lists the
    models found."""
    dirs = [d for d in (models_dir, os.environ.get("RANGER_MODELS_DIR")) if d] + list(MODELS_DIRS)
    for d in dirs:
        path = os.path.join(d, model + ".yaml")
        if os.path.isfile(path):
            return path
    names = sorted({f[:-5] for d in dirs if os.path.isdir(d) for f in os.listdir(d)
                    if f.endswith(".yaml")})
    raise GeometryError(f"unknown model '{model}' (valid: {', '.join(names) or 'none found'}; "
                        f"looked in {', '.join(dirs)})")


def load_geometry(path):
    """Reads and validates a geometry file (geometry.yaml or a model file); returns a flat dict of
    floats (+ 'ultrasonic' list, 'model' name or None)."""
    with open(path, encoding="utf-8") as f:
        raw = yaml.safe_load(f)
    if not isinstance(raw, dict):
        raise GeometryError(f"{path}: expected a mapping at the top level")
    raw = unflatten(raw)
    desc = raw.get("description")
    if not isinstance(desc, dict):
        raise GeometryError("description: missing or not a mapping")
    g = {k: _number(raw, k, "") for k in ("wheelbase", "track", "wheel_radius")}
    g["model"] = raw.get("model")
    g["source"] = os.path.basename(path)
    g["total_mass"] = (_number(desc, "total_mass", "description/") if "total_mass" in desc
                       else TOTAL_MASS)
    for key in ("body_length", "body_width", "body_height", "body_clearance", "wheel_width",
                "wheel_mass", "steering_module_mass", "steering_limit", "steering_velocity",
                "steering_effort", "wheel_velocity", "wheel_effort", "ultrasonic_height"):
        g[key] = _number(desc, key, "description/")
    if g["body_clearance"] >= g["body_height"]:
        raise GeometryError("description/body_clearance: must be below body_height")
    if 2 * g["wheel_radius"] > g["body_height"]:
        raise GeometryError("wheel_radius: the wheel does not fit under body_height")
    if g["steering_limit"] > math.pi:
        raise GeometryError("description/steering_limit: must be <= pi")
    if 4 * (g["wheel_mass"] + g["steering_module_mass"]) >= g["total_mass"]:
        raise GeometryError(
            "description/wheel_mass + steering_module_mass: exceed the vehicle mass")
    sensors = desc.get("ultrasonic")
    if not isinstance(sensors, list) or len(sensors) != ULTRASONIC_COUNT:
        raise GeometryError(
            f"description/ultrasonic: expected a list of {ULTRASONIC_COUNT} [x, y, yaw]")
    g["ultrasonic"] = []
    for i, s in enumerate(sensors):
        where = f"description/ultrasonic[{i}]/"
        if not isinstance(s, list) or len(s) != 3:
            raise GeometryError(f"description/ultrasonic[{i}]: expected [x, y, yaw]")
        g["ultrasonic"].append(tuple(_number(dict(zip("xyz", s)), k, where, positive=False)
                                     for k in "xyz"))
    return g


def wheel_position(g, wheel):
    """(x, y) of a wheel centre relative to base_link, as VehicleGeometry::wheel_position."""
    hx, hy = g["wheelbase"] / 2.0, g["track"] / 2.0
    return {"front_right": (hx, -hy), "rear_right": (-hx, -hy), "rear_left": (-hx, hy),
            "front_left": (hx, hy)}[wheel]


def _fmt(*values):
    return " ".join(f"{v:.6g}" for v in values)


def _box_inertia(m, x, y, z):
    return m * (y * y + z * z) / 12, m * (x * x + z * z) / 12, m * (x * x + y * y) / 12


def _cylinder_inertia(m, r, h):
    """Cylinder along its own z axis: (ixx, iyy, izz)."""
    side = m * (3 * r * r + h * h) / 12
    return side, side, m * r * r / 2


def _origin(parent, xyz=(0, 0, 0), rpy=(0, 0, 0)):
    ET.SubElement(parent, "origin", xyz=_fmt(*xyz), rpy=_fmt(*rpy))


def _inertial(link, mass, diag, xyz=(0, 0, 0)):
    inertial = ET.SubElement(link, "inertial")
    _origin(inertial, xyz)
    ET.SubElement(inertial, "mass", value=_fmt(mass))
    ixx, iyy, izz = diag
    ET.SubElement(inertial, "inertia", ixx=_fmt(ixx), ixy="0", ixz="0", iyy=_fmt(iyy), iyz="0",
                  izz=_fmt(izz))


def _shape(link, kind, shape, material=None, xyz=(0, 0, 0), rpy=(0, 0, 0)):
    element = ET.SubElement(link, kind)
    _origin(element, xyz, rpy)
    geometry = ET.SubElement(element, "geometry")
    name, attrs = shape
    ET.SubElement(geometry, name, **attrs)
    if material:
        ET.SubElement(element, "material", name=material)


def _box(x, y, z):
    return "box", {"size": _fmt(x, y, z)}


def _cylinder(r, h):
    return "cylinder", {"radius": _fmt(r), "length": _fmt(h)}


def _joint(robot, name, kind, parent, child, xyz, rpy=(0, 0, 0), axis=None, limit=None):
    joint = ET.SubElement(robot, "joint", name=name, type=kind)
    _origin(joint, xyz, rpy)
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)
    if axis:
        ET.SubElement(joint, "axis", xyz=_fmt(*axis))
    if limit:
        ET.SubElement(joint, "limit", **{k: _fmt(v) for k, v in limit.items()})
    return joint


def build_urdf(g):
    """Returns the URDF as an ElementTree root element."""
    robot = ET.Element("robot", name="ranger")
    source = "config/geometry.yaml" if g.get("source", "geometry.yaml") == "geometry.yaml" else (
        "libranger_can/models/" + g["source"])
    robot.append(ET.Comment(" Generated by ranger_description/scripts/generate_urdf.py from "
                            f"{source}: edit that file, not this one. "))
    for name, rgba in COLOURS.items():
        material = ET.SubElement(robot, "material", name=name)
        ET.SubElement(material, "color", rgba=_fmt(*rgba))

    length, width, height = g["body_length"], g["body_width"], g["body_height"]
    half_h = height / 2.0  # base_link is the centre of the envelope box

    ET.SubElement(robot, "link", name="base_footprint")
    base = ET.SubElement(robot, "link", name="base_link")
    shell_h = height - g["body_clearance"]
    shell_z = g["body_clearance"] + shell_h / 2.0 - half_h
    _shape(base, "visual", _box(length, width, shell_h), "ranger_body", xyz=(0, 0, shell_z))
    _shape(base, "collision", _box(length, width, height))
    body_mass = g.get("total_mass", TOTAL_MASS) - 4 * (g["wheel_mass"] + g["steering_module_mass"])
    _inertial(base, body_mass, _box_inertia(body_mass, length, width, shell_h), (0, 0, shell_z))
    _joint(robot, "base_footprint_joint", "fixed", "base_footprint", "base_link", (0, 0, half_h))

    r, w = g["wheel_radius"], g["wheel_width"]
    axle_z = r - half_h  # wheel centres are one radius above the ground
    module_r, module_h = 0.05, max(g["body_clearance"] - r, 0.0) + r  # axle up to the shell
    for wheel, steering_joint, wheel_joint in zip(WHEELS, STEERING_JOINTS, WHEEL_JOINTS):
        x, y = wheel_position(g, wheel)
        module = ET.SubElement(robot, "link", name=f"{wheel}_steering_link")
        # A vertical post from the axle up to the shell, offset inboard of the tyre.
        inboard = -math.copysign(w / 2.0 + module_r, y)
        post = (0, inboard, module_h / 2.0)
        _shape(module, "visual", _cylinder(module_r, module_h), "ranger_steering", xyz=post)
        _shape(module, "visual", _box(0.04, abs(inboard) + module_r, 0.04), "ranger_steering",
               xyz=(0, inboard / 2.0, 0))
        _shape(module, "collision", _cylinder(module_r, module_h), xyz=post)
        m = g["steering_module_mass"]
        _inertial(module, m, _cylinder_inertia(m, module_r, module_h), post)
        _joint(robot, steering_joint, "revolute", "base_link", module.get("name"), (x, y, axle_z),
               axis=(0, 0, 1),
               limit={"lower": -g["steering_limit"], "upper": g["steering_limit"],
                      "effort": g["steering_effort"], "velocity": g["steering_velocity"]})

        tyre = ET.SubElement(robot, "link", name=f"{wheel}_wheel_link")
        on_side = (math.pi / 2.0, 0, 0)  # cylinder axis from z to y
        _shape(tyre, "visual", _cylinder(r, w), "ranger_tyre", rpy=on_side)
        _shape(tyre, "visual", _cylinder(r * 0.55, w * 1.02), "ranger_steering", rpy=on_side)
        _shape(tyre, "collision", _cylinder(r, w), rpy=on_side)
        m = g["wheel_mass"]
        ixx, iyy, izz = _cylinder_inertia(m, r, w)
        _inertial(tyre, m, (ixx, izz, iyy))  # spin axis is y
        # Positive rotation about +y rolls the wheel forward (+x) when the steering angle is 0.
        _joint(robot, wheel_joint, "continuous", module.get("name"), tyre.get("name"), (0, 0, 0),
               axis=(0, 1, 0),
               limit={"effort": g["wheel_effort"], "velocity": g["wheel_velocity"]})

    for n, (x, y, yaw) in enumerate(g["ultrasonic"], start=1):
        sensor = ET.SubElement(robot, "link", name=f"ultrasonic_{n}_link")
        _shape(sensor, "visual", _cylinder(0.015, 0.02), "ranger_sensor", xyz=(0.005, 0, 0),
               rpy=(0, math.pi / 2.0, 0))
        _joint(robot, f"ultrasonic_{n}_joint", "fixed", "base_link", sensor.get("name"),
               (x, y, g["ultrasonic_height"] - half_h), rpy=(0, 0, yaw))
    return robot


def to_xml(robot):
    text = ET.tostring(robot, encoding="unicode")
    pretty = xml.dom.minidom.parseString(text).toprettyxml(indent="  ")
    return pretty.replace('<?xml version="1.0" ?>', '<?xml version="1.0"?>', 1)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("geometry", nargs="?", default=None,
                        help="geometry YAML (default: this package's config/geometry.yaml)")
    parser.add_argument("--model", help="a model's file instead: libranger_can/models/MODEL.yaml "
                        "(ranger, ranger_mini_v1, ranger_mini_v2, ranger_mini_v3)")
    parser.add_argument("--models-dir", help="where the model files are (default: "
                        "$RANGER_MODELS_DIR, this package's config/models, the source tree's)")
    parser.add_argument("-o", "--output", help="write the URDF here instead of stdout")
    # roslaunch's <param command=...> may append remapping-like arguments; ignore those.
    args, _ = parser.parse_known_args(argv)
    if args.model and args.geometry:
        print("generate_urdf.py: give a GEOMETRY_YAML or --model, not both", file=sys.stderr)
        return 2
    where = args.geometry or (f"--model {args.model}" if args.model else DEFAULT_GEOMETRY)
    try:
        path = model_path(args.model, args.models_dir) if args.model else (
            args.geometry or DEFAULT_GEOMETRY)
        g = load_geometry(path)
        if args.model and g["model"] != args.model:
            raise GeometryError(f"model: '{g['model']}' is not the file's name '{args.model}'")
        text = to_xml(build_urdf(g))
    except (OSError, yaml.YAMLError, GeometryError) as e:
        print(f"generate_urdf.py: {where}: {e}", file=sys.stderr)
        return 1
    if args.output:
        os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
        tmp = args.output + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, args.output)  # never leave a half-written URDF behind
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
