"""ranger_can for Python against the in-process virtual chassis: the README's example as written,
driving in every mode with the odometry against the chassis's ground truth, the command timeout,
the e-stop latch and resume, the remote control's takeover, the vendor's features, errors as
exceptions carrying the library's messages, the GIL released while waiting, the stop at exit.

Waiting is on the driver's state (wait_until), never on a wall-clock duration; durations only
pace the commands, as a program would.
"""

import math
import os
import re
import subprocess
import sys
import threading
import time

import pytest

import ranger_can
from ranger_can import RangerError, RequestFailed

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
SAMPLE_LOG = os.path.join(REPO, "libranger_can", "data", "sample.log")


def readme_python_example():
    """The README's Python example: the ```python block that drives ranger_can.Driver."""
    with open(os.path.join(REPO, "README.md"), encoding="utf-8") as f:
        text = f.read()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    examples = [b for b in blocks if "ranger_can.Driver(" in b]
    assert examples, "README.md has no ```python block using ranger_can.Driver"
    return examples[0]


def drive(d, vx=0.0, vy=0.0, wz=0.0, distance=None, angle=None, timeout=30.0):
    """Commands the twist every 50 ms until the ground truth has travelled `distance` m (or
    turned `angle` rad), then stops and waits for the chassis to be at rest."""
    start = d.ground_truth()
    deadline = time.monotonic() + timeout
    while True:
        g = d.ground_truth()
        if distance is not None and g.distance_travelled - start.distance_travelled >= distance:
            break
        if angle is not None and g.yaw_travelled - start.yaw_travelled >= angle:
            break
        assert time.monotonic() < deadline, f"did not get there: {d.snapshot()!r}"
        d.command(vx, vy, wz)
        time.sleep(0.05)
    for _ in range(10):
        d.command(0.0, 0.0, 0.0)
        time.sleep(0.05)
    d.wait_until(lambda s: abs(d.ground_truth().vx) + abs(d.ground_truth().vy) < 1e-3
                 and abs(d.ground_truth().wz) < 1e-3, timeout=10)
    # The odometry has integrated the frames that reported the stop once it says so itself (a
    # wait on what the driver reports, not on a duration: a slow host only makes it later).
    d.wait_until(lambda s: abs(s.odometry.vx) + abs(s.odometry.vy) < 1e-3
                 and abs(s.odometry.wz) < 1e-3, timeout=10)


def assert_odometry_follows(d):
    """Odometry against ground truth: within 1 % of the distance travelled + 2 cm."""
    s = d.snapshot()
    g = d.ground_truth()
    bound = 0.01 * g.distance_travelled + 0.02
    error = math.hypot(s.odometry.x - g.x, s.odometry.y - g.y)
    assert error <= bound, f"odometry ({s.odometry.x:.3f}, {s.odometry.y:.3f}) vs truth " \
                           f"({g.x:.3f}, {g.y:.3f}): {error:.3f} m > {bound:.3f} m"
    yaw_error = abs(math.remainder(s.odometry.yaw - g.yaw, 2 * math.pi))
    assert yaw_error <= 0.01 * g.yaw_travelled + 0.02, (s.odometry.yaw, g.yaw)


@pytest.fixture
def sim():
    with ranger_can.Driver("sim") as d:
        d.wait_ready(timeout=30)
        yield d


def test_readme_example_runs_as_written():
    result = subprocess.run([sys.executable, "-c", readme_python_example()], capture_output=True,
                            text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    x, y, yaw, mode, refusal = result.stdout.split()[:5]
    assert float(x) > 0.5 and abs(float(y)) < 0.05 and abs(float(yaw)) < 0.05
    assert mode == "ackermann"
    assert refusal in ("none", "cmd_timeout")


@pytest.mark.parametrize("port,model,revision", [("sim", "ranger", "manual"),
                                                 ("sim:agx_v2", "ranger", "agx_v2"),
                                                 ("sim:mini_v3", "ranger_mini_v3", "mini_v3")])
def test_drives_every_mode_with_odometry_following_the_ground_truth(port, model, revision):
    with ranger_can.Driver(port, model=model) as d:
        s = d.wait_ready(timeout=30)
        assert s.identification.phase == "decided"
        assert s.profile_revision == revision
        drive(d, vx=0.6, wz=0.2, distance=1.0)  # dual Ackermann, an arc to the left
        assert d.snapshot().motion_mode == "ackermann"
        assert_odometry_follows(d)
        drive(d, vx=0.3, vy=0.3, distance=1.0)  # oblique
        assert d.snapshot().motion_mode == "oblique"
        assert_odometry_follows(d)
        drive(d, wz=0.5, angle=1.5)  # spin
        assert d.snapshot().motion_mode == "spin"
        assert_odometry_follows(d)
        g = d.ground_truth()
        assert g.distance_travelled > 1.9 and g.yaw_travelled > 1.5


def test_no_fresh_command_stops_the_chassis(sim):
    sim.command(vx=0.4)
    sim.wait_until(lambda s: sim.ground_truth().vx > 0.3, timeout=10)
    # No more commands: the driver's 500 ms timeout stops it by itself.
    s = sim.wait_until(lambda s: s.refusal == "cmd_timeout", timeout=10)
    assert s.cmd_timed_out
    sim.wait_until(lambda s: abs(sim.ground_truth().vx) < 1e-3, timeout=10)
    # The commander's own stop: the next command drives again, no re-arm.
    sim.command(vx=0.2)
    sim.wait_until(lambda s: s.refusal == "none" and sim.ground_truth().vx > 0.1, timeout=10)


def test_a_command_older_than_the_timeout_is_not_obeyed(sim):
    """A stamped command's age: within cmd_vel_timeout (or None: unstamped, a zero stamp) it
    drives; older, the driver refuses it ("stale_command", saying how old) and stops."""
    sim.command(vx=0.4, age=0.1)
    sim.wait_until(lambda s: sim.ground_truth().vx > 0.3, timeout=10)

    def stale(s):
        sim.command(vx=0.4, age=2.0)
        return s.refusal == "stale_command" and abs(sim.ground_truth().vx) < 1e-3
    s = sim.wait_until(stale, timeout=10)
    assert "stamped 2 s ago, older than cmd_vel_timeout 0.5 s" in s.refusal_detail, \
        s.refusal_detail

    def fresh(s):
        sim.command(vx=0.4, age=None)
        return s.refusal == "none" and sim.ground_truth().vx > 0.3
    sim.wait_until(fresh, timeout=10)


def test_estop_latches_until_resume(sim):
    sim.events()  # what happened before
    assert sim.inject("estop on") is not None
    s = sim.wait_until(lambda s: s.refusal == "estop", timeout=10)
    assert "emergency_stop" in s.active_causes
    assert "emergency stop" in s.refusal_detail  # the library's words, with what to do
    sim.wait_snapshot()  # the events of the iteration that refused are in the ring by then
    events = sim.events()
    refusals = [e for e in events if e.kind == "refusal_changed"]
    assert refusals and refusals[-1].severity == "warn", events
    assert all(e.kind in ranger_can.event_kinds() for e in events)
    with pytest.raises(RequestFailed, match="emergency_stop"):
        sim.resume()
    sim.inject("estop off")
    # Released, but motion stays refused however long commands keep coming.
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        sim.command(vx=0.3)
        time.sleep(0.05)
    s = sim.snapshot()
    assert s.refusal == "rearm_required" and s.rearm_required
    assert "emergency_stop" in s.latched_causes
    assert abs(sim.ground_truth().vx) < 1e-3
    assert sim.resume().state == "answered"
    sim.command(vx=0.3)
    sim.wait_until(lambda s: s.refusal == "none" and sim.ground_truth().vx > 0.1, timeout=10)


def test_nan_in_a_field_the_chassis_does_not_use_is_refused_and_a_silence_is_said(sim):
    # {linear: {x: 0.3, z: .nan}}: refused, named while it lasts, nothing moves.
    with pytest.raises(RangerError) as e:
        sim.command(vx=0.3, vz=float("nan"))
    assert e.value.code == "not_finite"
    s = sim.wait_until(lambda s: s.refusal == "invalid_command", timeout=10)
    assert "linear.z is NaN" in s.refusal_detail, s.refusal_detail
    assert sim.ground_truth().vx == 0.0
    assert s.drivable_modes == ["ackermann", "oblique", "spin"]  # the manual's chassis
    # Silent for 2 s while driving: the odometry says the gap and its variance grew by it.
    sim.command(vx=0.5)
    s = sim.wait_until(lambda s: sim.ground_truth().vx > 0.4, timeout=10)
    before = s.odometry
    assert before.gaps == 0 and before.last_gap == 0.0 and before.last_gap_end_ns == 0
    sim.inject("silent 2")

    def heard_after_a_gap(s):
        sim.command(vx=0.5)
        return s.link == "connected" and s.odometry.gaps > 0
    o = sim.wait_until(heard_after_a_gap, timeout=10).odometry
    assert o.gaps == 1 and o.last_gap >= 1.95 and o.last_gap_end_ns > 0
    reach = 1.5 * o.last_gap  # the default max_linear_speed, 1.5 m/s
    assert o.pose_variance[0] >= before.pose_variance[0] + reach * reach - 1e-6


def test_remote_control_takes_over_and_stays_won_until_resume(sim):
    sim.inject("remote on")
    s = sim.wait_until(lambda s: s.refusal == "remote", timeout=10)
    assert s.control_mode == "remote"
    sim.inject("remote can")  # the operator hands back with SWB
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        sim.command(vx=0.3)
        time.sleep(0.05)
    assert sim.snapshot().refusal == "rearm_required"
    sim.resume()
    sim.command(vx=0.3)
    sim.wait_until(lambda s: s.refusal == "none" and sim.ground_truth().vx > 0.1, timeout=10)


def test_motion_refused_while_identifying():
    with ranger_can.Driver("sim") as d:
        s = d.wait_until(lambda s: s.link == "connected" or s.refusal == "identifying", timeout=10)
        if s.identification.phase != "decided":
            d.command(vx=0.5)
            s = d.wait_snapshot()
            assert s.refusal == "identifying"
            assert abs(d.ground_truth().vx) < 1e-6
        d.wait_ready(timeout=30)


def test_park_and_lights_on_agx_v2():
    with ranger_can.Driver("sim:agx_v2") as d:
        d.wait_ready(timeout=30)
        outcome = d.set_lights(front="custom", front_brightness=40, rear="breathing")
        assert outcome.state == "answered"
        lights = d.wait_until(lambda s: s.lights is not None, timeout=5).lights
        assert (lights.front, lights.front_brightness, lights.rear) == ("custom", 40, "breathing")
        d.park(True)
        s = d.snapshot()
        assert s.parked and s.refusal == "parked"
        d.command(vx=0.3)
        assert d.wait_snapshot().refusal == "parked"
        d.park(False)
        d.command(vx=0.3)
        d.wait_until(lambda s: d.ground_truth().vx > 0.1, timeout=10)
        assert d.firmware_version() == "ranger_sim 0.1.0"


def test_drive_mode_and_wheel_odometers_on_the_mini_v3():
    with ranger_can.Driver("sim:mini_v3", model="ranger_mini_v3") as d:
        d.wait_ready(timeout=30)
        assert d.snapshot().profile_revision == "mini_v3"
        outcome = d.set_drive_mode("voltage")
        assert outcome.state == "answered"
        s = d.snapshot()
        assert (s.drive_mode, s.drive_mode_raw) == ("voltage", 1)
        d.set_drive_mode("current")
        assert d.snapshot().drive_mode == "current"
        with pytest.raises(RangerError, match="drive mode \"torque\" unknown: one of current"):
            d.set_drive_mode("torque")
        d.command(vx=0.3)
        d.wait_until(lambda s: all(abs(x) > 0.05 for x in s.wheel_odometers), timeout=10)
        d.command(vx=0.0)


def test_the_front_ends_words_are_the_librarys(sim):
    """The answers the ROS 1 node gives (frontend/answers.hpp), for the ROS 2 node to give too."""
    s = sim.snapshot()
    assert ranger_can.unknown_motion_mode_number(7, s) == (
        "mode 7 unknown: under protocol manual use 0 (ackermann), 1 (oblique), 2 (spin) or "
        "255 (automatic)")
    assert ranger_can.motion_mode_pinned("spin") == (
        "motion mode pinned to spin (the switch happens at standstill)")
    assert ranger_can.motion_mode_pinned(None) == "automatic motion-mode selection"
    assert ranger_can.resume_refused_offline(s, "sim") is None
    assert ranger_can.resume_answered() == "re-armed: cmd_vel drives the chassis again"
    lines = sim.startup_lines
    assert lines[0][0] == "info" and lines[0][1].startswith("model ranger (")
    assert any(text.startswith("protocol ") for _, text in lines[1:]), lines
    forced = ranger_can.Driver("sim", params={"protocol": "auto", "spin_sign": "cw"},
                               start=False)
    try:
        assert any(severity == "warn" and "identification is off" in text
                   for severity, text in forced.startup_lines), forced.startup_lines
    finally:
        forced.close()
    sim.wait_ready(timeout=30)
    ok, text = ranger_can.clear_errors_answer(0, sim.clear_errors(0), sim.snapshot())
    assert ok and text.startswith("clear_errors code 0 (")
    assert text.endswith(": the chassis answered with error word 0x00000000 (no errors)")
    with pytest.raises(RangerError, match=r"code 256 out of range \[0, 255\]"):
        ranger_can.clear_errors_answer(256, sim.clear_errors(0), sim.snapshot())


def test_the_cmd_vel_type_rule_is_the_librarys():
    """cmd_vel's type (frontend/cmd_vel_type.hpp) as the ROS 2 node maps it: the graph's names,
    the rule's decisions and its lines."""
    twist, stamped = ranger_can.cmd_vel_type_names()
    assert (twist, stamped) == ("geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped")
    assert ranger_can.cmd_vel_type_names("ros1") == [
        "geometry_msgs/Twist", "geometry_msgs/TwistStamped"]
    fixed = ranger_can.CmdVelTypeRule("true")
    d = fixed.start([twist])
    assert (d.change, d.taken, d.stamped) == ("taken", stamped, True)
    assert d.line == f"cmd_vel: taken as {stamped} (cmd_vel_stamped true)"
    assert not fixed.follows_publishers and fixed.setting == "true"
    assert fixed.on_publishers([twist]).line == ""
    rule = ranger_can.CmdVelTypeRule("auto")
    d = rule.start([])
    assert (d.change, d.taken, d.stamped) == ("none", None, None)
    assert "(cmd_vel_stamped auto: no publisher yet; said again when one appears)" in d.line
    assert rule.follows_publishers and rule.taken is None
    assert rule.on_publishers([twist, stamped]).change == "none"
    d = rule.on_publishers([stamped])
    assert (d.change, d.stamped) == ("taken", True)
    assert d.line == (f"cmd_vel: taken as {stamped} "
                      "(cmd_vel_stamped auto: the type of its publishers)")
    assert rule.on_publishers([stamped]).line == ""
    d = rule.on_publishers([twist], since_last_message=0.1)  # the type taken still comes
    assert d.change == "none" and rule.taken == stamped
    d = rule.on_publishers([twist])
    assert (d.change, d.taken, d.stamped) == ("switched", twist, False)
    assert rule.on_message(stamped).change == "switched"
    with pytest.raises(RangerError, match="std_msgs/msg/String is neither"):
        rule.on_message("std_msgs/msg/String")
    with pytest.raises(RangerError, match="cmd_vel_stamped \"maybe\" unknown"):
        ranger_can.CmdVelTypeRule("maybe")
    with pytest.raises(RangerError, match="type spelling"):
        ranger_can.CmdVelTypeRule("auto", spelling="ros3")


def test_vendor_features_refused_by_name_on_the_manuals_chassis(sim):
    with pytest.raises(RequestFailed, match="unsupported by protocol"):
        sim.set_lights(front="on", rear="on")
    with pytest.raises(RequestFailed, match="park: unsupported"):
        sim.park(True)
    with pytest.raises(RequestFailed, match="unsupported by protocol manual"):
        sim.set_drive_mode("voltage")
    assert sim.snapshot().drive_mode is None
    with pytest.raises(RangerError, match="side_slip: unsupported by protocol manual"):
        sim.set_motion_mode("side_slip")


def test_errors_are_exceptions_with_the_librarys_message():
    with pytest.raises(RangerError) as e:
        ranger_can.Driver("sim", cmd_vel_timeout=100.0, params={"wheelbase": -1,
                                                                 "linear/x/max_velocity": 11})
    message = str(e.value)
    assert "parameter cmd_vel_timeout = 100 is out of range: valid [0.02, 60] s" in message
    assert "parameter wheelbase = -1 is out of range: valid (0, 10] m" in message
    assert "parameter linear/x/max_velocity = 11 is out of range: valid [0, 10] m/s" in message
    assert e.value.code == "invalid_argument"
    with pytest.raises(RangerError, match=r"parameter cmd_vel_timeot unknown"):
        ranger_can.Driver("sim", cmd_vel_timeot=1.0)
    with pytest.raises(RangerError, match=r"model = \"ranger_maxi\": expected one of ranger, "):
        ranger_can.Driver("sim", model="ranger_maxi")
    with pytest.raises(RangerError, match="spin_cw"):  # the valid variants named
        ranger_can.Driver("sim:nonexistent")
    with pytest.raises(RangerError, match="mode_numbering = \"agx\": expected one of manual"):
        ranger_can.Driver("sim", mode_numbering="agx")
    with ranger_can.Driver("sim") as d:
        d.wait_until(lambda s: s.bus_open, timeout=10)
        with pytest.raises(RangerError) as e:
            d.command(vx=float("nan"))
        assert e.value.code == "not_finite"
        with pytest.raises(RangerError, match="valid commands: "):
            d.inject("estop sideways")
        with pytest.raises(RangerError, match="motion mode \"crab\" unknown"):
            d.set_motion_mode("crab")
        with pytest.raises(RangerError, match="light mode"):
            d.set_lights(front="disco")
        with pytest.raises(RangerError, match="code 17 is not an error-clearing code"):
            d.clear_errors(17)
    with pytest.raises(RangerError, match="closed"):
        d.command(vx=0.1)


def test_replay_is_read_only_and_not_a_virtual_chassis():
    with ranger_can.Driver("replay:" + SAMPLE_LOG, protocol="manual") as d:
        s = d.wait_until(lambda s: s.bus_open, timeout=10)
        assert s.read_only
        with pytest.raises(RangerError, match="no virtual chassis"):
            d.inject("estop on")
        assert d.ground_truth() is None


def test_candump_decoding_and_odometry_replay():
    frames = ranger_can.decode(SAMPLE_LOG)
    assert frames[0]["name"] == "system_status" and frames[0]["id"] == 0x211
    assert "errors" in frames[0]
    with open(SAMPLE_LOG, encoding="utf-8") as f:
        assert ranger_can.decode(f.read()) == frames  # the log's text as well as its path
    replay = ranger_can.replay_odometry(SAMPLE_LOG)
    assert replay.steps and set(replay.final) >= {"x", "y", "yaw"}
    assert replay.final["x"] == pytest.approx(replay.steps[-1]["x"])
    with pytest.raises(RangerError, match="protocol"):
        ranger_can.decode(SAMPLE_LOG, protocol="v3")
    with pytest.raises(RangerError):
        ranger_can.decode("garbage\nmore garbage\n")


def test_the_gil_is_released_while_waiting():
    counted = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counted[0] += 1

    with ranger_can.Driver("sim") as d:
        t = threading.Thread(target=count)
        t.start()
        before = counted[0]
        d.wait_sent(timeout=0.3)  # nothing recorded: waits the whole time in C++
        during = counted[0] - before
        stop.set()
        t.join()
    assert during > 1000, f"the other thread ran {during} times while the driver waited"


def test_close_stops_the_chassis_and_is_idempotent():
    d = ranger_can.Driver("sim", record_sent=True)
    d.wait_ready(timeout=30)
    d.command(vx=0.5)
    d.wait_until(lambda s: d.ground_truth().vx > 0.2, timeout=10)
    d.close()
    d.close()
    assert d.stop_sent
    stops = [e for e in d.events() if e.kind == "shutdown_stop"]
    assert stops and "stop sent to the chassis" in stops[-1].text
    sent = d.sent()
    assert sent and sent[-1].shutdown and sent[-1].vx == 0.0
    assert d.closed


def test_an_exception_in_the_with_block_stops_the_chassis():
    with pytest.raises(ZeroDivisionError):
        with ranger_can.Driver("sim") as d:
            d.wait_ready(timeout=30)
            d.command(vx=0.5)
            1 / 0  # noqa: B018
    assert d.closed and d.stop_sent


def test_interpreter_exit_stops_the_chassis():
    # atexit hooks run last-registered first: this one, registered before the import, runs after
    # ranger_can's own and sees what it did.
    script = """
import atexit
drivers = []
atexit.register(lambda: print("stop_sent", drivers[0].stop_sent, flush=True))
import ranger_can
d = ranger_can.Driver("sim")
drivers.append(d)
d.wait_ready(timeout=30)
d.command(vx=0.5)
"""
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            timeout=120, check=False)
    assert result.returncode == 0, result.stderr
    assert "stop_sent True" in result.stdout


def test_parameters_table_names_every_row_with_its_range():
    rows = {r.name: r for r in ranger_can.parameters()}
    assert rows["cmd_vel_timeout"].unit == "s" and rows["cmd_vel_timeout"].hi == 60
    assert rows["model"].choices == ranger_can.model_names()
    assert "agx_v2" in rows["protocol"].choices
    assert rows["linear/x/max_acceleration"].lo_open
    assert rows["sim/errors"].type == "string_list"
    assert set(ranger_can.motion_modes()) >= {"ackermann", "oblique", "spin", "side_slip", "park"}
    assert "estop" in ranger_can.chassis_command_names()


def test_type_stubs_name_everything_the_module_offers():
    import ranger_can._ranger_can as ext
    package = os.path.dirname(ranger_can.__file__)
    with open(os.path.join(package, "_ranger_can.pyi"), encoding="utf-8") as f:
        stub = f.read()
    with open(os.path.join(package, "__init__.pyi"), encoding="utf-8") as f:
        init_stub = f.read()
    for name, value in vars(ext).items():
        if name.startswith("__") or name == "_Session":
            continue
        assert re.search(rf"\b(class|def) {name}\b", stub), f"{name} not in _ranger_can.pyi"
        if isinstance(value, type):
            body = stub.split(f"class {name}")[1].split("\nclass ")[0]
            for attr in dir(value):
                if not attr.startswith("_"):
                    assert re.search(rf"\b{attr}\b", body), f"{name}.{attr} not in the stub"
    for attr in dir(ranger_can.Driver):
        if not attr.startswith("_"):
            assert re.search(rf"\b{attr}\b", init_stub), f"Driver.{attr} not in __init__.pyi"


# ---- the library's parameter table and diagnostics, as they are --------------------------------

def readme_parameter_rows():
    """Every parameter row of ranger_base/README.md (the ROS 1 node's; its tests hold each one
    character for character to the library's table)."""
    with open(os.path.join(REPO, "ranger_base", "README.md"), encoding="utf-8") as f:
        text = f.read()
    block = text[text.index("## Parameters"):]
    block = block[:block.find("\n## ", 1)]
    return [line for line in block.splitlines() if line.startswith("| `")]


def test_parameters_are_the_librarys_table_row_for_row():
    """Fails when the binding's rows drift from the library's table: each row is the README's
    row of the ROS 1 node (markdown_row of the same row), in the same order, nothing more."""
    rows = ranger_can.parameters()
    assert [r.markdown for r in rows] == readme_parameter_rows()
    names = [r.name for r in rows]
    assert len(set(names)) == len(names)
    by_name = {r.name: r for r in rows}
    # The node's own rows and the generated per-axis rows are there, with the library's values.
    assert by_name["publish_rate"].default == 50.0 and by_name["publish_rate"].lo_open
    assert by_name["publish_rate"].valid == "(0, 50] Hz" and not by_name["publish_rate"].driver_setting
    assert by_name["cmd_vel_timeout"].driver_setting and by_name["cmd_vel_timeout"].type == "double"
    assert by_name["pose_covariance_diagonal"].type == "double_list"
    assert by_name["pose_covariance_diagonal"].size == 6
    assert by_name["wheelbase"].default_note.startswith("the model's")
    assert by_name["tx_dlc"].table_type == "choice" and by_name["tx_dlc"].choices == ["0", "8"]
    for axis in ("linear/x", "linear/y", "angular/z"):
        assert f"{axis}/max_velocity" in by_name and f"{axis}/min_acceleration" in by_name


def test_settings_and_check_parameter_are_the_tables():
    rows = {r.name: r for r in ranger_can.parameters()}
    with ranger_can.Driver("sim", start=False, odom_frame="robot1/odom",
                           params={"ultrasonic/max_range": 4.0}) as d:
        s = d.settings
        assert s["odom_frame"] == "robot1/odom" and s["ultrasonic/max_range"] == 4.0
        for name in ("base_frame", "publish_rate", "state_publish_rate", "publish_odom_tf",
                     "pose_covariance_diagonal", "ultrasonic/field_of_view"):
            assert s[name] == rows[name].default, name
        assert s["port_name"] == "sim"
    assert ranger_can.check_parameter("publish_rate", 20) == 20.0
    with pytest.raises(RangerError, match=r"parameter publish_rate = 60 is out of range: "
                                          r"valid \(0, 50\] Hz"):
        ranger_can.check_parameter("publish_rate", 60.0)
    with pytest.raises(RangerError, match="parameter no_such_row unknown"):
        ranger_can.check_parameter("no_such_row", 1)
    with pytest.raises(RangerError, match=r"parameter ultrasonic/max_range = 0.01 is out of range"):
        ranger_can.Driver("sim", start=False, params={"ultrasonic/max_range": 0.01})


def test_diagnostics_are_the_librarys_groups(sim):
    sim.wait_ready(timeout=30)
    groups = sim.diagnostics("/robot1")
    assert [g.name for g in groups] == ranger_can.diagnostic_group_names() == [
        "CAN link", "Control mode", "Protocol", "Chassis errors", "Battery", "Frame rates"]
    assert {g.hardware_id for g in groups} == {"ranger:/robot1:sim"} == {sim.hardware_id("/robot1")}
    link, control = groups[0], groups[1]
    assert link.level == 0 and link.level_name == "OK", str(link)
    assert link.value("Port") == "sim" and link.value("Chassis link") == "connected"
    assert control.value("Motion refused because") in ("none", "cmd_timeout")
    assert str(link).startswith("CAN link: OK: ")
    # A latched e-stop: the control group says so at a level above OK, in the library's words.
    sim.inject("estop on")
    sim.wait_until(lambda s: s.refusal == "estop", timeout=10)
    control = sim.diagnostics("/robot1")[1]
    assert control.level > 0 and control.value("Motion refused because") == "estop", str(control)
    assert "emergency_stop" in control.value("Latched stop causes")
    sim.inject("estop off")


def test_battery_presence_is_the_librarys_freshness(sim):
    sim.wait_ready(timeout=30)
    s = sim.wait_until(lambda s: s.batteries[0].present, timeout=10)
    assert s.batteries[0].soc > 0


def test_motion_wire_encoder_writes_cdr_little_endian(sim):
    """MotionWireEncoder's layout read with struct (the ROS 2 tests hold it to the rmw's own
    serialisation): the encapsulation header, fields aligned to their size from its end."""
    import struct
    joints = ranger_can.steering_joint_names() + ranger_can.wheel_joint_names()
    enc = ranger_can.MotionWireEncoder("odom", "base_link", joints, [0.5] * 6, [0.25] * 6)
    odometry = (1_795_000_000, 42, 1.5, -2.0, 0.6, 0.8, 0.3, -0.1, 0.2, 0.01, 0.02, 0.03)
    odom = enc.odometry(odometry)
    assert odom[:4] == b"\x00\x01\x00\x00" and len(odom) == 724
    body = odom[4:]
    assert struct.unpack_from("<iI", body, 0) == (1_795_000_000, 42)
    assert struct.unpack_from("<I", body, 8) == (5,) and body[12:17] == b"odom\0"
    assert struct.unpack_from("<I", body, 20) == (10,) and body[24:34] == b"base_link\0"
    assert struct.unpack_from("<7d", body, 40) == (1.5, -2.0, 0.0, 0.0, 0.0, 0.6, 0.8)
    pose_cov = struct.unpack_from("<36d", body, 96)
    assert (pose_cov[0], pose_cov[7], pose_cov[14], pose_cov[35]) == pytest.approx(
        (0.51, 0.52, 0.5, 0.53))
    assert pose_cov[1] == 0.0
    assert struct.unpack_from("<6d", body, 384) == (0.3, -0.1, 0.0, 0.0, 0.0, 0.2)
    assert struct.unpack_from("<36d", body, 432)[21] == 0.25
    tf = enc.transform(odometry)
    assert struct.unpack_from("<I", tf, 4) == (1,) and len(tf) == 100
    assert struct.unpack_from("<7d", tf, 44) == (1.5, -2.0, 0.0, 0.0, 0.0, 0.6, 0.8)
    state = enc.joint_state((7, 8, [float(i) for i in range(8)], [-1.0] * 8))
    assert struct.unpack_from("<iII", state, 4) == (7, 8, 1)
    assert struct.unpack_from("<I", state, 20) == (8,)  # the names
    assert struct.unpack_from("<8dI", state, len(state) - 68) == (-1.0,) * 8 + (0,)
    # An update hands all three, each only when its part is new.
    sim.wait_ready(timeout=30)
    update = sim.wait_motion(50.0, 2.0)
    odom, tf, state = enc.encode(update)
    assert update.new_estimate and odom is not None and tf is not None
    with pytest.raises(RangerError, match="joint_names must name the 8 joints"):
        ranger_can.MotionWireEncoder("odom", "base_link", joints[:7], [0.0] * 6, [0.0] * 6)


def test_read_twist_reads_cdr_and_xcdr2_in_either_byte_order():
    """read_twist: linear x, y, z, angular x, y, z right after the 4-byte encapsulation header,
    for plain CDR and plain XCDR2, little and big endian; bytes beyond ignored; what it does not
    read (short, another encapsulation) gives None, for the rmw to read."""
    import struct
    values = (0.5, -0.25, 1e-9, -0.0, 3.0e300, float("-inf"))
    for header, order in ((b"\x00\x01", "<"), (b"\x00\x00", ">"), (b"\x00\x07", "<"),
                          (b"\x00\x06", ">")):
        data = header + b"\x00\x00" + struct.pack(order + "6d", *values)
        assert ranger_can.read_twist(data) == values, header
        assert ranger_can.read_twist(data + b"\x00" * 3) == values  # slack, a longer message
    nan = ranger_can.read_twist(b"\x00\x01\x00\x00" + struct.pack("<6d", *[float("nan")] * 6))
    assert all(v != v for v in nan)  # passed on as NaN: the driver refuses it, naming the field
    good = b"\x00\x01\x00\x00" + struct.pack("<6d", *values)
    assert ranger_can.read_twist(good[:-1]) is None
    assert ranger_can.read_twist(b"") is None
    for other in (b"\x00\x03", b"\x00\x09", b"\x00\x0b", b"\x01\x01"):  # PL_CDR, D_CDR2, ...
        assert ranger_can.read_twist(other + good[2:]) is None, other
