"""The URDF against its two references: config/geometry.yaml (the one source the node and the URDF
share) and libranger_can's geometry.hpp (the library's defaults and the joint names that
ranger_base's joint_states use).

Run: /usr/bin/python3 -m pytest test/test_urdf.py     (colcon test runs it through CTest)
Environment (set by CMakeLists.txt; defaults work from a source checkout):
  RANGER_URDF           the URDF the build generated (checked for staleness and parsed)
  RANGER_GEOMETRY_HPP   libranger_can/include/ranger_can/control/geometry.hpp
"""

import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
import yaml

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), os.pardir))
sys.path.insert(0, os.path.join(PACKAGE_DIR, "scripts"))
import generate_urdf  # noqa: E402

GEOMETRY_YAML = os.path.join(PACKAGE_DIR, "config", "geometry.yaml")
GEOMETRY_HPP = os.environ.get("RANGER_GEOMETRY_HPP", os.path.join(
    PACKAGE_DIR, os.pardir, "libranger_can", "include", "ranger_can", "control", "geometry.hpp"))
BUILT_URDF = os.environ.get("RANGER_URDF")
TOL = 1e-6


# ---- the references ------------------------------------------------------------------------------
def parse_geometry_hpp(path):
    """Joint names, wheel order and VehicleGeometry defaults from the C++ header."""
    with open(path, encoding="utf-8") as f:
        text = f.read()

    def string_array(name):
        m = re.search(name + r"\s*=\s*\{(.*?)\};", text, re.S)
        assert m, f"{name} not found in {path}"
        return re.findall(r'"([^"]*)"', m.group(1))

    def default(field):
        m = re.search(r"double\s+" + field + r"\s*=\s*([0-9.eE+-]+)\s*;", text)
        assert m, f"VehicleGeometry::{field} default not found in {path}"
        return float(m.group(1))

    enum = dict((name, int(value)) for name, value in
                re.findall(r"(k[A-Za-z]+)\s*=\s*(\d+)", re.search(
                    r"enum\s+WheelIndex[^{]*\{(.*?)\}", text, re.S).group(1)))
    sign = {"hx": ("x", 1), "-hx": ("x", -1), "hy": ("y", 1), "-hy": ("y", -1)}
    cases = dict(re.findall(r"case\s+(k[A-Za-z]+)\s*:\s*return\s*\{([^}]*)\}", text))
    m = re.search(r"default\s*:\s*return\s*\{([^}]*)\}", text)
    assert m, "wheel_position default branch not found"
    signs = {}
    for enum_name, index in enum.items():
        expr = cases.get(enum_name, m.group(1))
        parts = [p.replace(" ", "") for p in expr.split(",")]
        assert [sign[p][0] for p in parts] == ["x", "y"], f"unexpected wheel_position: {expr}"
        signs[index] = (sign[parts[0]][1], sign[parts[1]][1])
    return {
        "wheel_names": string_array("kWheelNames"),
        "steering_joints": string_array("kSteeringJointNames"),
        "wheel_joints": string_array("kWheelJointNames"),
        "signs": [signs[i] for i in range(len(signs))],
        "wheelbase": default("wheelbase"),
        "track": default("track"),
        "wheel_radius": default("wheel_radius"),
    }


@pytest.fixture(scope="module")
def hpp():
    return parse_geometry_hpp(GEOMETRY_HPP)


@pytest.fixture(scope="module")
def geometry():
    with open(GEOMETRY_YAML, encoding="utf-8") as f:
        return yaml.safe_load(f)


@pytest.fixture(scope="module")
def urdf_text():
    robot = generate_urdf.build_urdf(generate_urdf.load_geometry(GEOMETRY_YAML))
    return generate_urdf.to_xml(robot)


@pytest.fixture(scope="module")
def robot(urdf_text):
    return ET.fromstring(urdf_text)


def joint(robot, name):
    found = robot.findall(f"joint[@name='{name}']")
    assert len(found) == 1, f"joint {name}: expected exactly one, found {len(found)}"
    return found[0]


def floats(text):
    return [float(v) for v in text.split()]


def world_origin(robot, link):
    """Position of a link's origin in base_footprint, following fixed/zero joint origins."""
    x = y = z = 0.0
    while True:
        parents = [j for j in robot.findall("joint") if j.find("child").get("link") == link]
        if not parents:
            return x, y, z
        (j,) = parents
        ox, oy, oz = floats(j.find("origin").get("xyz"))
        roll, pitch, yaw = floats(j.find("origin").get("rpy"))
        assert roll == pitch == 0.0, "only yaw-rotated frames are expected above the wheels"
        c, s = math.cos(yaw), math.sin(yaw)
        x, y, z = ox + c * x - s * y, oy + s * x + c * y, oz + z
        link = j.find("parent").get("link")


# ---- parsing -------------------------------------------------------------------------------------
def test_check_urdf_parses_the_generated_urdf(tmp_path, urdf_text):
    check_urdf = shutil.which("check_urdf")
    assert check_urdf, "check_urdf not found: install liburdfdom-tools (scripts/setup.sh does)"
    path = tmp_path / "ranger.urdf"
    path.write_text(urdf_text)
    result = subprocess.run([check_urdf, str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout
    assert "root Link: base_footprint" in result.stdout


@pytest.mark.skipif(not BUILT_URDF, reason="RANGER_URDF not set (run through CTest)")
def test_the_built_urdf_is_the_generator_output_of_geometry_yaml(urdf_text):
    with open(BUILT_URDF, encoding="utf-8") as f:
        assert f.read() == urdf_text, f"{BUILT_URDF} is stale: rebuild ranger_description"


def test_the_command_line_writes_what_the_library_builds(tmp_path, urdf_text):
    out = tmp_path / "sub" / "ranger.urdf"
    script = os.path.join(PACKAGE_DIR, "scripts", "generate_urdf.py")
    subprocess.run([sys.executable, script, GEOMETRY_YAML, "-o", str(out)], check=True, timeout=60)
    assert out.read_text() == urdf_text
    stdout = subprocess.run([sys.executable, script], check=True, capture_output=True, text=True,
                            timeout=60).stdout
    assert stdout == urdf_text


# ---- the one source of truth ---------------------------------------------------------------------
def test_geometry_yaml_agrees_with_the_library_defaults(geometry, hpp):
    for key in ("wheelbase", "track", "wheel_radius"):
        assert geometry[key] == pytest.approx(hpp[key], abs=TOL), key


def test_joint_names_are_the_libraries(robot, hpp):
    assert list(generate_urdf.WHEELS) == hpp["wheel_names"]
    assert list(generate_urdf.STEERING_JOINTS) == hpp["steering_joints"]
    assert list(generate_urdf.WHEEL_JOINTS) == hpp["wheel_joints"]
    movable = sorted(j.get("name") for j in robot.findall("joint") if j.get("type") != "fixed")
    assert movable == sorted(hpp["steering_joints"] + hpp["wheel_joints"])


def test_steering_joints_sit_at_the_wheel_positions(robot, geometry, hpp):
    for i, name in enumerate(hpp["steering_joints"]):
        j = joint(robot, name)
        assert j.get("type") == "revolute"
        assert j.find("parent").get("link") == "base_link"
        x, y, _ = floats(j.find("origin").get("xyz"))
        sx, sy = hpp["signs"][i]
        for wheelbase, track in ((geometry["wheelbase"], geometry["track"]),
                                 (hpp["wheelbase"], hpp["track"])):
            assert x == pytest.approx(sx * wheelbase / 2, abs=TOL), name
            assert y == pytest.approx(sy * track / 2, abs=TOL), name
        assert floats(j.find("axis").get("xyz")) == [0, 0, 1]  # CCW positive (REP-103)


def test_wheel_joints_turn_with_their_steering_joint_and_roll_forward(robot, hpp):
    for steering, wheel in zip(hpp["steering_joints"], hpp["wheel_joints"]):
        j = joint(robot, wheel)
        assert j.get("type") == "continuous"
        assert j.find("parent").get("link") == joint(robot, steering).find("child").get("link")
        assert floats(j.find("origin").get("xyz")) == [0, 0, 0]
        assert floats(j.find("axis").get("xyz")) == [0, 1, 0]  # +rotation rolls towards +x


def test_wheels_touch_the_ground_and_have_the_configured_radius(robot, geometry, hpp):
    for wheel in hpp["wheel_joints"]:
        link = joint(robot, wheel).find("child").get("link")
        _, _, z = world_origin(robot, link)
        assert z == pytest.approx(geometry["wheel_radius"], abs=TOL), link
        cylinder = robot.find(f"link[@name='{link}']/collision/geometry/cylinder")
        assert float(cylinder.get("radius")) == pytest.approx(geometry["wheel_radius"], abs=TOL)


def test_base_link_is_the_centre_of_the_body_box(robot, geometry):
    desc = geometry["description"]
    assert world_origin(robot, "base_link") == pytest.approx((0, 0, desc["body_height"] / 2))
    box = robot.find("link[@name='base_link']/collision/geometry/box")
    assert floats(box.get("size")) == pytest.approx(
        [desc["body_length"], desc["body_width"], desc["body_height"]])
    assert [desc["body_length"], desc["body_width"], desc["body_height"]] == [1.228, 0.876, 0.475]


def test_steering_limits_cover_spin_and_oblique(robot, geometry, hpp):
    spin_angle = math.atan2(geometry["wheelbase"] / 2, geometry["track"] / 2)  # about 57.8 deg
    for name in hpp["steering_joints"]:
        limit = joint(robot, name).find("limit")
        lower, upper = float(limit.get("lower")), float(limit.get("upper"))
        assert lower <= -spin_angle and upper >= spin_angle, name
        assert lower == pytest.approx(-math.pi / 2, abs=1e-3) and upper == pytest.approx(
            math.pi / 2, abs=1e-3), "oblique mode needs +-90 deg"
        assert float(limit.get("effort")) > 0 and float(limit.get("velocity")) > 0


def test_masses_add_up_and_inertias_are_physical(robot):
    total = 0.0
    for link in robot.findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        total += float(inertial.find("mass").get("value"))
        i = inertial.find("inertia")
        ixx, iyy, izz = (float(i.get(k)) for k in ("ixx", "iyy", "izz"))
        assert min(ixx, iyy, izz) > 0, link.get("name")
        # Principal moments of a real body satisfy the triangle inequality.
        assert ixx + iyy >= izz and iyy + izz >= ixx and ixx + izz >= iyy, link.get("name")
    assert total == pytest.approx(generate_urdf.TOTAL_MASS)


def test_eight_ultrasonic_frames_on_the_body_outline(robot, geometry):
    desc = geometry["description"]
    for n in range(1, 9):
        x, y, z = world_origin(robot, f"ultrasonic_{n}_link")
        on_front_or_back = abs(abs(x) - desc["body_length"] / 2) < TOL and abs(y) <= desc[
            "body_width"] / 2
        on_side = abs(abs(y) - desc["body_width"] / 2) < TOL and abs(x) <= desc["body_length"] / 2
        assert on_front_or_back or on_side, f"ultrasonic_{n}_link at ({x}, {y})"
        assert z == pytest.approx(desc["ultrasonic_height"])
        # The beam (+x of the frame) points away from the body.
        yaw = floats(joint(robot, f"ultrasonic_{n}_joint").find("origin").get("rpy"))[2]
        assert math.cos(yaw) * x + math.sin(yaw) * y > 0, f"ultrasonic_{n} looks inwards"


# ---- bad geometry is refused with the field's name -----------------------------------------------
def write_variant(tmp_path, geometry, change):
    variant = yaml.safe_load(yaml.safe_dump(geometry))
    change(variant)
    path = tmp_path / "geometry.yaml"
    path.write_text(yaml.safe_dump(variant))
    return str(path)


@pytest.mark.parametrize("change,message", [
    (lambda g: g.update(wheelbase=-0.89), "wheelbase: must be > 0"),
    (lambda g: g.update(track=float("nan")), "track: must be finite"),
    (lambda g: g.pop("wheel_radius"), "wheel_radius: missing"),
    (lambda g: g.update(wheel_radius="big"), "wheel_radius: expected a number"),
    (lambda g: g["description"].update(body_height=0.3, body_clearance=0.1),
     "wheel_radius: the wheel does not fit"),
    (lambda g: g["description"]["ultrasonic"].pop(),
     "description/ultrasonic: expected a list of 8"),
    (lambda g: g["description"].update(steering_limit=4.0), "description/steering_limit"),
])
def test_bad_geometry_is_refused_naming_the_field(tmp_path, geometry, change, message):
    path = write_variant(tmp_path, geometry, change)
    with pytest.raises(generate_urdf.GeometryError, match=re.escape(message)):
        generate_urdf.load_geometry(path)
    script = os.path.join(PACKAGE_DIR, "scripts", "generate_urdf.py")
    result = subprocess.run([sys.executable, script, path], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 1 and message in result.stderr and result.stdout == ""


def test_a_different_geometry_moves_the_joints(tmp_path, geometry):
    path = write_variant(tmp_path, geometry, lambda g: g.update(wheelbase=1.2, track=0.7))
    robot = generate_urdf.build_urdf(generate_urdf.load_geometry(path))
    x, y, _ = floats(joint(robot, "rear_left_steering_joint").find("origin").get("xyz"))
    assert (x, y) == pytest.approx((-0.6, 0.35))


# ---- the models (libranger_can/models/*.yaml: one file per model, flat) ------------------------
MODELS_DIR = os.environ.get("RANGER_MODELS_DIR", os.path.join(
    PACKAGE_DIR, os.pardir, "libranger_can", "models"))
MODEL_URDF_DIR = os.environ.get("RANGER_MODEL_URDF_DIR")
MODELS = ("ranger", "ranger_mini_v1", "ranger_mini_v2", "ranger_mini_v3")


def model_geometry(model):
    return generate_urdf.load_geometry(generate_urdf.model_path(model, MODELS_DIR))


def model_robot(model):
    return ET.fromstring(generate_urdf.to_xml(generate_urdf.build_urdf(model_geometry(model))))


def test_every_model_has_a_file():
    found = sorted(f[:-5] for f in os.listdir(MODELS_DIR) if f.endswith(".yaml"))
    assert found == list(MODELS)


def test_geometry_yaml_is_the_ranger_model():
    """config/geometry.yaml (the node's parameters) and models/ranger.yaml say the same."""
    node_file = generate_urdf.load_geometry(GEOMETRY_YAML)
    model_file = model_geometry("ranger")
    for key in set(node_file) | set(model_file):
        if key in ("model", "source"):
            continue
        assert node_file.get(key) == pytest.approx(model_file.get(key)), key


@pytest.mark.parametrize("model", MODELS)
def test_model_urdf_parses_and_puts_the_wheels_where_the_model_says(tmp_path, model, hpp):
    g = model_geometry(model)
    assert g["model"] == model
    robot = model_robot(model)
    path = tmp_path / f"{model}.urdf"
    path.write_text(generate_urdf.to_xml(generate_urdf.build_urdf(g)))
    result = subprocess.run([shutil.which("check_urdf") or "check_urdf", str(path)],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    for i, name in enumerate(hpp["steering_joints"]):
        x, y, _ = floats(joint(robot, name).find("origin").get("xyz"))
        sx, sy = hpp["signs"][i]
        assert (x, y) == pytest.approx((sx * g["wheelbase"] / 2, sy * g["track"] / 2), abs=TOL)
    for wheel in hpp["wheel_joints"]:
        link = joint(robot, wheel).find("child").get("link")
        assert world_origin(robot, link)[2] == pytest.approx(g["wheel_radius"], abs=TOL)
    total = sum(float(link.find("inertial/mass").get("value"))
                for link in robot.findall("link") if link.find("inertial") is not None)
    assert total == pytest.approx(g["total_mass"])
    # The spin position (atan(L/W)) is within the steering joints' limits.
    limit = joint(robot, hpp["steering_joints"][0]).find("limit")
    assert float(limit.get("upper")) >= math.atan2(g["wheelbase"], g["track"])


def test_models_have_their_geometry():
    assert (model_geometry("ranger_mini_v1")["wheelbase"], model_geometry("ranger_mini_v1")[
        "track"]) == (0.36, 0.36)
    for model in ("ranger_mini_v2", "ranger_mini_v3"):
        g = model_geometry(model)
        assert (g["wheelbase"], g["track"]) == (0.494, 0.364)


@pytest.mark.skipif(not MODEL_URDF_DIR, reason="RANGER_MODEL_URDF_DIR not set (run through CTest)")
@pytest.mark.parametrize("model", MODELS)
def test_the_built_model_urdfs_are_the_generator_output(model):
    with open(os.path.join(MODEL_URDF_DIR, model + ".urdf"), encoding="utf-8") as f:
        built = f.read()
    assert built == generate_urdf.to_xml(generate_urdf.build_urdf(model_geometry(model))), (
        f"{model}.urdf is stale: rebuild ranger_description")


def test_the_command_line_takes_a_model():
    script = os.path.join(PACKAGE_DIR, "scripts", "generate_urdf.py")
    out = subprocess.run([sys.executable, script, "--model", "ranger_mini_v2", "--models-dir",
                          MODELS_DIR], check=True, capture_output=True, text=True,
                         timeout=60).stdout
    assert out == generate_urdf.to_xml(generate_urdf.build_urdf(model_geometry("ranger_mini_v2")))
    assert "libranger_can/models/ranger_mini_v2.yaml" in out
    bad = subprocess.run([sys.executable, script, "--model", "ranger_maxi", "--models-dir",
                          MODELS_DIR], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 1 and bad.stdout == ""
    assert "unknown model 'ranger_maxi' (valid: ranger, ranger_mini_v1" in bad.stderr
    both = subprocess.run([sys.executable, script, GEOMETRY_YAML, "--model", "ranger"],
                          capture_output=True, text=True, timeout=60)
    assert both.returncode == 2 and "not both" in both.stderr


def test_a_flat_file_with_a_gap_in_the_sensors_is_refused(tmp_path):
    with open(generate_urdf.model_path("ranger_mini_v3", MODELS_DIR), encoding="utf-8") as f:
        text = f.read()
    path = tmp_path / "ranger_mini_v3.yaml"
    path.write_text(text.replace("description/ultrasonic_4:", "description/ultrasonic_9:"))
    with pytest.raises(generate_urdf.GeometryError, match="ultrasonic_1 to ultrasonic_8"):
        generate_urdf.load_geometry(str(path))
    path.write_text(text + "protocol/extra: 1\n")
    with pytest.raises(generate_urdf.GeometryError, match="only description/<key>"):
        generate_urdf.load_geometry(str(path))
