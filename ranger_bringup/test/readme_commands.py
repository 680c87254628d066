"""The README-commands check: every command in the project's READMEs, taken from the Markdown
itself, is run exactly as written (or, for the few that cannot run inside the test stage,
verified against what does run them), so that the documentation cannot drift.

What counts as a command (the convention the READMEs follow; README.md, "Documentation is
tested"):
* A fenced block whose info string is bash, sh or console holds commands, one per line: a
  trailing backslash continues a line, '#' outside quotes starts a comment, a leading "$ " prompt
  is dropped. The commands of one block run in order, each as if typed into a terminal of its own
  (a session): a command that keeps running (roslaunch, roscore, rostopic pub) stays up until the
  block is done, and must still be up then. Alternatives therefore go in separate blocks.
* An inline code span is a command when its first word (after VAR=value assignments) is a
  program -- one of PROGRAMS, a ./path, or a relative path with a slash -- and it has arguments or
  starts with ./ ; a bare name (`ranger_can`, `scripts/perf.sh`) names a thing. Each inline
  command is a session of its own.
* A command with placeholders (an UPPER_CASE word such as FILE, [optional] parts, '...', '…', or
  a|b choices) is a synopsis: the program must exist, and its own help (or, for a script, its
  text) must name every --option and placeholder word of the synopsis.
* Every other command must match one of RULES; a command no rule knows fails the check, so a new
  command cannot enter the documentation without saying how CI runs it.

Environment of a session (not part of the command): the workspace sourced as the READMEs say
(install/setup.bash: scripts/test.sh builds it from the tree before the ROS stage), a ROS master
port of its own (ROS_MASTER_URI; roscore, which ignores it, gets it as -p), a throwaway ROS_HOME, an Xvfb display for rviz, stand-ins for
hardware tools.

Run as a script to list the commands and how each is checked:
    /usr/bin/python3 ranger_bringup/test/readme_commands.py
"""

import json
import os
import re
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from typing import Callable, List, Optional

TEST_DIR = os.path.dirname(os.path.abspath(__file__))
PACKAGE_DIR = os.path.dirname(TEST_DIR)
REPO = os.path.dirname(PACKAGE_DIR)
DOCUMENTS = ["README.md", "ranger_base/README.md", "ranger_bringup/README.md"]
PROGRAMS = {"roslaunch", "rosrun", "roscore", "rostopic", "rosnode", "rosservice", "rosparam",
            "rosmsg", "ranger_can", "colcon", "cmake", "ctest", "source", "candump", "cansend",
            "sudo", "python3", "bash", "catkin_make", "apt-get", "ip"}
SHELL_BLOCKS = {"bash", "sh", "console", "shell"}
READY_TIMEOUT = 90.0  # s: bounds how long a command that does not come up is waited for
STOP_TIMEOUT = 30.0


# ---- extraction -----------------------------------------------------------------------------------

@dataclass
class Command:
    document: str  # relative to the repository
    line: int
    text: str
    block: Optional[int]  # index of the fenced block in the document; None: inline

    def where(self):
        return f"{self.document}:{self.line}"


def strip_comment(line):
    """The line up to a '#' that starts a comment (outside quotes, at the start or after a
    blank)."""
    quote = None
    for i, c in enumerate(line):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1] in " \t"):
            return line[:i].rstrip()
    return line.rstrip()


def program_words(text):
    """The words of a command after leading VAR=value assignments."""
    try:
        words = shlex.split(text)
    except ValueError:
        words = text.split()
    while words and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", words[0]):
        words = words[1:]
    return words


def is_inline_command(span):
    words = program_words(span)
    if not words:
        return False
    first = words[0]
    if first.startswith("./") and len(first) > 2:
        return True
    is_program = first in PROGRAMS or ("/" in first and not first.endswith("/"))
    return is_program and len(words) > 1


PLACEHOLDER = re.compile(r"^\[?[A-Z][A-Z0-9_]+(\.\.\.|…)?\]?$")


def is_synopsis(text):
    if "[" in text or "..." in text or "…" in text:
        return True
    for word in program_words(text):
        if "=" not in word and PLACEHOLDER.match(word):
            return True
        if re.search(r"\w\|\w", word):
            return True
    return False


def extract(document):
    """The commands of one Markdown document, in order."""
    with open(os.path.join(REPO, document), encoding="utf-8") as f:
        lines = f.read().split("\n")
    commands = []
    block = -1
    fence = None  # the info string of the open fence, or None outside a block
    pending, pending_line = "", 0
    for number, raw in enumerate(lines, start=1):
        stripped = raw.strip()
        if stripped.startswith("```"):
            if fence is None:
                fence = stripped[3:].strip().lower()
                block += 1
            else:
                fence = None
            continue
        if fence is not None:
            if fence not in SHELL_BLOCKS:
                continue
            text = strip_comment(raw.strip())
            if text.startswith("$ "):
                text = text[2:]
            if not pending:
                pending_line = number
            if text.endswith("\\"):
                pending += text[:-1] + " "
                continue
            text = (pending + text).strip()
            pending = ""
            if text:
                commands.append(Command(document, pending_line, text, block))
            continue
        for span in re.findall(r"(?<!`)`([^`]+)`(?!`)", raw):
            span = span.replace("\\|", "|").strip()  # a table cell escapes its pipes
            if is_inline_command(span):
                commands.append(Command(document, number, span, None))
    return commands


def all_commands():
    return [c for d in DOCUMENTS for c in extract(d)]


@dataclass
class SessionSpec:
    commands: List[Command]
    also_at: List[str] = field(default_factory=list)  # identical sessions elsewhere

    def id(self):
        return self.commands[0].where()


def session_specs():
    """Blocks and inline commands as sessions; identical sessions run once."""
    specs, seen = [], {}
    for d in DOCUMENTS:
        groups = {}
        for c in extract(d):
            key = ("block", c.block) if c.block is not None else ("inline", c.line, c.text)
            groups.setdefault(key, []).append(c)
        for commands in groups.values():
            texts = tuple(c.text for c in commands)
            if texts in seen:
                seen[texts].also_at.append(commands[0].where())
                continue
            spec = SessionSpec(commands)
            seen[texts] = spec
            specs.append(spec)
    return specs


# ---- sessions -------------------------------------------------------------------------------------

def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Process:
    """A command started in a session of its own, its output in a log file."""

    def __init__(self, session, text, name, env):
        self.text, self.name = text, name
        self.log_path = os.path.join(session.home, f"{name}.log")
        self.log = open(self.log_path, "wb")
        self.log_dir = os.path.join(session.home, "log", name)
        env = dict(env, ROS_LOG_DIR=self.log_dir)
        self.process = subprocess.Popen(["/bin/bash", "-c", text], cwd=REPO, env=env,
                                        stdin=subprocess.DEVNULL, stdout=self.log,
                                        stderr=subprocess.STDOUT, start_new_session=True)

    def alive(self):
        return self.process.poll() is None

    def output(self):
        self.log.flush()
        with open(self.log_path, encoding="utf-8", errors="replace") as f:
            return f.read()

    def stop(self):
        """SIGINT, as Ctrl-C in its terminal; then whatever of it outlived that."""
        if self.alive():
            try:
                os.killpg(self.process.pid, signal.SIGINT)
                self.process.wait(timeout=STOP_TIMEOUT)
            except (OSError, subprocess.TimeoutExpired):
                try:
                    os.killpg(self.process.pid, signal.SIGKILL)
                except OSError:
                    pass
                self.process.wait()
        # roslaunch starts each node in a session of its own; a node passes __log:=<log dir>.
        marker = (self.log_dir + os.sep).encode()
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open(f"/proc/{entry}/cmdline", "rb") as f:
                    if marker in f.read():
                        os.kill(int(entry), signal.SIGKILL)
            except OSError:
                continue
        self.log.close()


class Session:
    """The terminals of one block: a private ROS master port, a throwaway ROS_HOME, the commands
    still running."""

    def __init__(self):
        self.home = tempfile.mkdtemp(prefix="ranger-readme-")
        self.port = free_port()
        env = dict(os.environ)
        env.pop("ROS_IP", None)
        env.update(ROS_MASTER_URI=f"http://localhost:{self.port}", ROS_HOME=self.home,
                   ROS_HOSTNAME="localhost", PYTHONUNBUFFERED="1")
        # The packages come from the workspace as the READMEs have the user source it
        # (install/setup.bash, which test.sh has just built from this tree).
        self.env = env
        self.running = []  # Process, in start order
        self.robots = []  # namespaces of the virtual robots started ("" = root)
        self.xvfb = None
        self.count = 0

    def name(self, prefix):
        self.count += 1
        return f"{self.count:02d}-{prefix}"

    def display_env(self):
        if self.xvfb is None:
            assert shutil.which("Xvfb"), "Xvfb not found (scripts/setup.sh test installs it)"
            read_fd, write_fd = os.pipe()
            self.xvfb = subprocess.Popen(
                ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "1024x768x24", "-nolisten",
                 "tcp"], pass_fds=[write_fd], stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL)
            os.close(write_fd)
            with os.fdopen(read_fd) as f:
                number = f.readline().strip()
            assert number, "Xvfb did not start"
            self.display = ":" + number
        return dict(self.env, DISPLAY=self.display, LIBGL_ALWAYS_SOFTWARE="1",
                    XDG_RUNTIME_DIR=self.home)

    def run(self, text, timeout=120, env=None):
        """Runs a command to its end; returns (exit status, output)."""
        try:
            r = subprocess.run(["/bin/bash", "-c", text], cwd=REPO, env=env or self.env,
                               stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, timeout=timeout, text=True,
                               start_new_session=True)
        except subprocess.TimeoutExpired as e:
            raise AssertionError(f"`{text}` did not finish within {timeout} s:\n{e.output}")
        return r.returncode, r.stdout

    def start(self, text, env=None):
        p = Process(self, text, self.name(program_words(text)[0]), env or self.env)
        self.running.append(p)
        return p

    def probe(self, process, conditions, timeout=READY_TIMEOUT):
        """Waits until the ROS graph shows `conditions` (readme_probe.py) while `process` runs."""
        probe = subprocess.Popen(
            ["/usr/bin/python3", os.path.join(TEST_DIR, "readme_probe.py"), str(timeout),
             json.dumps(conditions)], env=self.env, stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, text=True, start_new_session=True)
        while probe.poll() is None:
            if not process.alive():
                probe.kill()
                probe.wait()
                raise AssertionError(f"`{process.text}` exited ({process.process.returncode}) "
                                     f"before it came up:\n{process.output()[-3000:]}")
            time.sleep(0.2)
        report = probe.stdout.read()
        assert probe.returncode == 0, (
            f"`{process.text}` did not come up:\n{report}\n--- its output:\n"
            f"{process.output()[-3000:]}")

    def close(self, check_alive=True):
        """Ends the block: every command still meant to run must be running; then stops them,
        the last started first."""
        dead = [p for p in self.running if not p.alive()] if check_alive else []
        for p in reversed(self.running):
            p.stop()
        if self.xvfb is not None:
            self.xvfb.terminate()
            self.xvfb.wait(timeout=STOP_TIMEOUT)
        outputs = "\n".join(f"--- `{p.text}`:\n{p.output()[-2000:]}" for p in dead)
        shutil.rmtree(self.home, ignore_errors=True)
        assert not dead, "stopped before the block was done:\n" + outputs


# ---- rules: how each kind of command runs ---------------------------------------------------------

def launch_args(text):
    """The name:=value arguments of a roslaunch/rosrun command line."""
    return dict(w.split(":=", 1) for w in shlex.split(text) if ":=" in w)


def settled(topic):
    """The driver is in CAN command mode with its protocol settings decided: forced, or
    identified (`protocol: auto`, the default, identifies the chassis before anything moves)."""
    return [{"topic": topic, "type": "ranger_msgs/SystemState", "field": "control_mode",
             "equals": 1},
            {"topic": topic, "type": "ranger_msgs/SystemState", "field": "identification",
             "in": ["", "decided"]}]


def robot_conditions(ns, sim, port):
    p = f"/{ns}" if ns else ""
    conditions = [{"node": f"{p}/ranger_base_node"}, {"node": f"{p}/robot_state_publisher"}]
    if sim:  # the node reached CAN command mode with the virtual chassis, its settings decided
        conditions += settled(f"{p}/system_state")
    else:  # no adapter here: the node runs and reports the missing interface by name
        conditions.append({"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray",
                           "status": f"{ns + '/' if ns else ''}ranger_base_node: CAN link",
                           "level": 2, "message_contains": port})
    if ns:  # never in the root namespace, where it would replace another robot's driver
        conditions.append({"no_node": "/ranger_base_node"})
    return conditions


def aggregated(robots):
    """The aggregated status names ranger_diagnostics.launch promises for `robots`."""
    statuses = ["CAN link", "Control mode", "Protocol", "Chassis errors", "Battery",
                "Frame rates"]
    prefixes = [f"/RANGER/{r}/" for r in robots] if robots else ["/RANGER/"]
    return {"topic": "/diagnostics_agg", "type": "diagnostic_msgs/DiagnosticArray",
            "names": [p + s for p in prefixes for s in statuses]}


def launch_robot(session, cmd, match):
    """ranger_minimal.launch / ranger_sim.launch: the driver comes up in its namespace (in
    CAN command mode on the virtual chassis; on can0, reporting the missing adapter)."""
    args = launch_args(cmd.text)
    ns = (args.get("ns") or args.get("namespace") or "").strip("/")
    sim = (match.group("file") == "ranger_sim" or args.get("sim") == "true"
           or bool(args.get("sim_variant")))
    rviz = args.get("rviz") == "true"
    process = session.start(cmd.text, env=session.display_env() if rviz else None)
    conditions = robot_conditions(ns, sim, args.get("port_name", "can0"))
    if not ns:
        conditions.append({"node": "/diagnostic_aggregator"})
    if rviz:
        conditions.append({"node": f"/{ns + '/' if ns else ''}rviz"})
    session.probe(process, conditions)
    if sim:
        session.robots.append(ns)


def launch_two_robots(session, cmd, match):
    process = session.start(cmd.text)
    conditions = robot_conditions("robot1", True, "") + robot_conditions("robot2", True, "")
    session.probe(process, conditions + [{"node": "/diagnostic_aggregator"},
                                         aggregated(["robot1", "robot2"])])
    session.robots += ["robot1", "robot2"]


def launch_diagnostics(session, cmd, match):
    robots = [r.strip("/") for r in launch_args(cmd.text).get("robots", "").split()]
    process = session.start(cmd.text)
    session.probe(process, [{"node": "/diagnostic_aggregator"}, aggregated(robots)])


def launch_display(session, cmd, match):
    ns = (launch_args(cmd.text).get("ns") or launch_args(cmd.text).get("namespace") or "")
    process = session.start(cmd.text, env=session.display_env())
    session.probe(process, [{"node": f"/{ns.strip('/') + '/' if ns.strip('/') else ''}rviz"}])


def teleop_in_a_terminal(session, cmd, match):
    """In a pseudo-terminal, as a user runs it: the teleop starts, and quitting it (Ctrl-D) ends
    roslaunch cleanly, without a REQUIRED-process-died banner."""
    sys.path.insert(0, TEST_DIR)
    from rostest_support import PtyProcess

    env = dict(session.env, ROS_LOG_DIR=os.path.join(session.home, "log", "teleop"))
    teleop = PtyProcess(["/bin/bash", "-c", cmd.text], env)
    try:
        end = time.monotonic() + READY_TIMEOUT
        while "RANGER keyboard teleop" not in teleop.text():
            assert teleop.process.poll() is None and time.monotonic() < end, (
                f"`{cmd.text}` did not show the teleop:\n{teleop.text()[-3000:]}")
            time.sleep(0.1)
        teleop.type("\x04")
        assert teleop.wait_exit(timeout=STOP_TIMEOUT) == 0, teleop.text()[-3000:]
        assert "REQUIRED" not in teleop.text(), teleop.text()[-3000:]
    finally:
        teleop.close()


def roscore(session, cmd, match):
    """roscore listens on port 11311 whatever ROS_MASTER_URI says (the machine's shared port):
    a stand-in first on the PATH runs the real one with the session's port (-p)."""
    real = shutil.which("roscore", path=session.env["PATH"])
    assert real, "roscore is not installed"
    bin_dir = os.path.join(session.home, "roscore-bin")
    os.makedirs(bin_dir, exist_ok=True)
    with open(os.path.join(bin_dir, "roscore"), "w") as f:
        f.write(f'#!/bin/bash\nexec {shlex.quote(real)} -p {session.port} "$@"\n')
    os.chmod(os.path.join(bin_dir, "roscore"), 0o755)
    process = session.start(cmd.text, env=dict(session.env,
                                               PATH=bin_dir + os.pathsep + session.env["PATH"]))
    session.probe(process, [{"node": "/rosout"}])


def node_alone(session, cmd, match):
    port = launch_args(cmd.text).get("_port_name", "can0")
    sim = port == "sim" or port.startswith("sim:")
    process = session.start(cmd.text)
    session.probe(process, robot_conditions("", sim, port)[:1] + (
        settled("/system_state") if sim else []))


def drive_one_robot(session, cmd, match):
    """`rostopic pub .../<ns>/cmd_vel`: that robot moves, every other virtual robot stays put."""
    ns = match.group("ns").strip("/")
    assert ns in session.robots, f"no virtual robot '{ns}' started before `{cmd.text}`"
    process = session.start(cmd.text)
    conditions = [{"topic": f"/{ns}/sim/ground_truth", "type": "nav_msgs/Odometry",
                   "moved_more_than": 0.05}]
    conditions += [{"topic": f"/{r}/sim/ground_truth" if r else "/sim/ground_truth",
                    "type": "nav_msgs/Odometry", "at_rest_within": 1e-3}
                   for r in session.robots if r != ns]
    session.probe(process, conditions)


# What the virtual robot's system_state shows after a sim/inject line a README uses.
INJECTED_STATE = {
    "estop on": [("vehicle_status", 1), ("motion_inhibited_reason", "estop")],
    "estop off": [("vehicle_status", 0), ("rearm_required", True)],
    "remote on": [("control_mode", 3), ("motion_inhibited_reason", "remote")],
    "remote sticks 0.2 -0.3": [("control_mode", 3), ("motion_mode", 0)],
    "remote swd bottom": [("control_mode", 3), ("motion_mode", 1)],
    "remote can": [("control_mode", 1), ("rearm_required", True)],
}
# ... and the sim/inject lines after which the robot moves (its ground truth).
INJECTED_MOVES = {"remote sticks 0.2 -0.3"}


def inject_fault(session, cmd, match):
    """`rostopic pub -1 .../sim/inject std_msgs/String "data: 'LINE'"` against a virtual robot
    started before: exits 0, and the robot's system_state then shows what LINE does."""
    ns = match.group("ns").strip("/")
    assert ns in session.robots, f"no virtual robot '{ns}' started before `{cmd.text}`"
    line = match.group("line")
    assert line in INJECTED_STATE, (
        f"`{cmd.text}`: say in INJECTED_STATE what '{line}' shows in system_state")
    run_ok(session, cmd, match)
    topic = f"/{ns}/system_state" if ns else "/system_state"
    conditions = [{"topic": topic, "type": "ranger_msgs/SystemState", "field": f, "equals": v}
                  for f, v in INJECTED_STATE[line]]
    if line in INJECTED_MOVES:
        conditions.append({"topic": f"/{ns}/sim/ground_truth" if ns else "/sim/ground_truth",
                           "type": "nav_msgs/Odometry", "moved_more_than": 0.05})
    session.probe(session.running[-1], conditions)


def call_resume(session, cmd, match):
    """`rosservice call .../resume` against a virtual robot: answers success, and the robot is
    re-armed (system_state.rearm_required false)."""
    ns = match.group("ns").strip("/")
    assert ns in session.robots, f"no virtual robot '{ns}' started before `{cmd.text}`"

    def check(out):
        assert "success: True" in out, out
    run_ok(session, cmd, match, check=check)
    topic = f"/{ns}/system_state" if ns else "/system_state"
    session.probe(session.running[-1], [
        {"topic": topic, "type": "ranger_msgs/SystemState", "field": "rearm_required",
         "equals": False}])


def launch_refused(session, cmd, match):
    """A launch with an argument the driver refuses: roslaunch exits non-zero, with the driver's
    reason on the console, before anything starts (nothing is left running)."""
    rc, out = session.run(cmd.text, timeout=120)
    assert rc != 0, f"`{cmd.text}` exited 0:\n{out[-3000:]}"
    assert "the launch is refused before anything starts" in out, out[-3000:]
    assert f"parameter ~{match.group('name')} = \"{match.group('value')}\"" in out, out[-3000:]


def run_ok(session, cmd, match, timeout=120, check=None):
    rc, out = session.run(cmd.text, timeout=timeout)
    assert rc == 0, f"`{cmd.text}` exited {rc}:\n{out[-3000:]}"
    if check:
        check(out)


def ranger_can(session, cmd, match):
    def check(out):
        if match.group("rest") == "--version":
            assert re.fullmatch(r"ranger_can \d+\.\d+\.\d+\n", out), out
    run_ok(session, cmd, match, check=check)


def library_build(session, cmd, match):
    """The plain-CMake build as written. test.sh has built build/lib (with Ninja) before the ROS
    stage, so this reconfigures, finds nothing to build and runs the unit tests once more."""
    assert os.path.isfile(os.path.join(REPO, "build", "lib", "CMakeCache.txt")), (
        "build/lib is not configured: run scripts/build.sh lib first (scripts/test.sh does)")
    run_ok(session, cmd, match, timeout=900)


def colcon_list(session, cmd, match):
    def check(out):
        for package in ("ranger_base", "ranger_bringup", "ranger_can", "ranger_description",
                        "ranger_msgs"):
            assert package in out, out
    run_ok(session, cmd, match, check=check)


def can_adapter(session, cmd, match):
    """bringup_can2usb.bash needs a USB adapter and root: it runs against stand-ins for sudo,
    ip and modprobe and a fake /sys/class/net holding can0 (as test_can2usb.py does)."""
    fake = os.path.join(session.home, "fake")
    bin_dir, net = os.path.join(fake, "bin"), os.path.join(fake, "net")
    os.makedirs(os.path.join(net, "can0"))
    os.makedirs(bin_dir)
    with open(os.path.join(net, "can0", "type"), "w") as f:
        f.write("280\n")  # ARPHRD_CAN
    calls = os.path.join(fake, "calls.log")
    for name, body in (("sudo", 'echo "sudo $*" >> "$CALLS"; exec "$@"'),
                       ("ip", 'echo "ip $*" >> "$CALLS"'),
                       ("modprobe", 'echo "modprobe $*" >> "$CALLS"'),
                       ("candump", "exit 0"), ("sleep", "exit 0")):
        path = os.path.join(bin_dir, name)
        with open(path, "w") as f:
            f.write("#!/bin/bash\n" + body + "\n")
        os.chmod(path, 0o755)
    env = dict(session.env, PATH=bin_dir + os.pathsep + session.env["PATH"], CALLS=calls,
               RANGER_SYSFS_NET=net)
    rc, out = session.run(cmd.text, env=env)
    assert rc == 0, f"`{cmd.text}` exited {rc}:\n{out}"
    assert "can0 is up at 500000 bit/s" in out, out
    with open(calls) as f:
        assert "ip link set can0 up" in f.read()


def read(relative):
    with open(os.path.join(REPO, relative), encoding="utf-8") as f:
        return f.read()


def test_sh_is_what_ci_runs(session, cmd, match):
    """scripts/test.sh runs this check: it is verified, not run (no recursion). CI's entry point
    must run it, and every stage the command names must exist."""
    assert re.search(r"^exec \./scripts/test\.sh\s*$", read(".ci/run"), re.M), read(".ci/run")
    test_sh = read("scripts/test.sh")
    for stage in (match.group("stages") or "").strip("\"'").split():
        assert re.search(rf"^stage_{stage}\(\)", test_sh, re.M), f"test.sh has no stage '{stage}'"


def demo_runs_in_test_demo(session, cmd, match):
    """test_demo.py runs scripts/demo.sh, adding only --no-setup --no-build (test.sh has just run
    setup and build; a build inside the test stage would rewrite the install space the tests run
    from), --headless and --output: those options must exist in demo.sh."""
    test_demo = read("ranger_bringup/test/test_demo.py")
    assert '"scripts", "demo.sh"' in test_demo, "test_demo.py no longer runs scripts/demo.sh"
    demo = read("scripts/demo.sh")
    for option in ("--no-setup", "--no-build", "--headless", "--output"):
        assert f'"{option}"' in test_demo, f"test_demo.py does not pass {option}"
        assert re.search(rf"^\s*{option}\)", demo, re.M), f"demo.sh has no option {option}"


def build_sh_runs_first(session, cmd, match):
    """scripts/build.sh is what test.sh runs before every stage (`all` = lib + ros); running it
    again inside the ROS stage would rebuild the install space the tests run from."""
    assert "scripts/build.sh all" in read("scripts/test.sh")
    assert re.search(r"lib \| ros \| all\)", read("scripts/build.sh"))


WORKSPACE_STEPS = {  # tool -> (scripts/test_workspaces.sh's step, the space it makes)
    "catkin_make": ("catkin_make", "devel"),
    "catkin_make_isolated": ("catkin_make_isolated", "devel_isolated"),
    "catkin build": ("catkin_build", "devel"),
    "colcon build": ("colcon", "install"),
}


def workspace_build_in_ci(session, cmd, match):
    """A build in a ROS 1 workspace (~/catkin_ws, the repository in its src/): verified, not run
    (a fresh workspace build takes minutes): scripts/test_workspaces.sh has a step that runs the
    same tool in a fresh workspace, the setup file is the one that tool makes, and test.sh's
    `workspaces` stage runs the script."""
    tool, space = match.group("tool"), match.group("space")
    step, made = WORKSPACE_STEPS[tool]
    assert space == made, f"{tool} makes {made}/setup.bash, not {space}/setup.bash"
    body = re.search(rf"^step_{step}\(\) {{\n(.*?)^}}", read("scripts/test_workspaces.sh"),
                     re.M | re.S)
    assert body, f"scripts/test_workspaces.sh has no step_{step}"
    assert re.search(rf"(^|\s){tool}(\s|$)", body.group(1), re.M), \
        f"step_{step} does not run {tool}:\n{body.group(1)}"
    stage = r"^stage_workspaces\(\) \{ scripts/test_workspaces\.sh"
    assert re.search(stage, read("scripts/test.sh"), re.M), \
        "test.sh has no workspaces stage running scripts/test_workspaces.sh"


def pip_install_in_ros2_stage(session, cmd, match):
    """`pip install ./libranger_can`: verified, not run here (it builds the library, minutes):
    the ros2 stage (scripts/test_ros2.sh) installs it into a fresh venv and runs the README's
    Python example with it."""
    script = read("scripts/test_ros2.sh")
    assert re.search(r'pip" install .*\./libranger_can', script), "test_ros2.sh: no pip install"
    assert re.search(r"^stage_ros2\(\) \{ scripts/test_ros2\.sh", read("scripts/test.sh"), re.M)


def ros2_workspace_build(session, cmd, match):
    """The ROS 2 workspace build: verified, not run here: the ros2 stage runs the same colcon
    command in a workspace whose src/ranger_ros is this checkout, then sources its setup.bash
    (scripts/ros2_env.sh) for the tests."""
    script = read("scripts/test_ros2.sh")
    assert 'ln -sfn "$root" "$ws/src/ranger_ros"' in script
    assert "build --paths src/ranger_ros/ros2/*" in script
    assert "ws=$root/build/ros2_ws_$distro" in script  # a workspace per distribution
    assert "source scripts/ros2_env.sh" in script  # the tests run in that workspace's setup
    assert 'source "$ranger_root/build/ros2_ws_$ranger_distro/install/setup.bash"' in \
        read("scripts/ros2_env.sh")


def ros2_launch_checked(session, cmd, match):
    """A ROS 2 launch (no `ros2` command or `launch` here): verified by the ros2 stage's
    test_launch_files.py, which runs every `ros2 launch ranger_bringup` line of this README
    through the file with stand-ins for launch and checks every executable, parameter and file it
    names; the file must exist."""
    assert os.path.exists(os.path.join(REPO, "ros2", "ranger_bringup", "launch",
                                       match.group("file")))
    assert "README.md" in read("ros2/ranger_bringup/test/test_launch_files.py")


@dataclass
class Rule:
    pattern: str  # matched against the whole command
    check: Callable
    how: str  # one line: how CI runs it


RULES = [
    Rule(r"rosrun ranger_bringup bringup_can2usb\.bash", can_adapter,
         "run against stand-ins for sudo/ip/modprobe and a fake /sys/class/net with can0"),
    Rule(r"roslaunch ranger_bringup ranger_minimal\.launch sim:=true (?P<name>protocol):=(?P<value>xyz)",
         launch_refused, "runs; exits non-zero before anything starts, with the driver's reason "
         "naming the parameter"),
    Rule(r"roslaunch ranger_bringup (?P<file>ranger_minimal|ranger_sim)\.launch( .*)?",
         launch_robot, "runs until its nodes are up (sim: in CAN command mode with the protocol "
         "settings decided; can0: reporting the missing adapter), in its namespace only"),
    Rule(r"roslaunch ranger_bringup ranger_sim_two\.launch", launch_two_robots,
         "runs until both robots are in CAN command mode with their protocol settings decided "
         "and one aggregator shows both"),
    Rule(r"roslaunch ranger_bringup ranger_diagnostics\.launch( .*)?", launch_diagnostics,
         "runs until /diagnostics_agg shows every robot it names"),
    Rule(r"roslaunch ranger_bringup display\.launch( .*)?", launch_display,
         "runs under Xvfb until rviz is up"),
    Rule(r"roslaunch ranger_bringup ranger_teleop_keyboard\.launch( .*)?", teleop_in_a_terminal,
         "runs in a pseudo-terminal; Ctrl-D ends it cleanly, without a REQUIRED banner"),
    Rule(r"roscore", roscore, "runs (on the session's port) until the master is up"),
    Rule(r"rosrun ranger_base ranger_base_node( .*)?", node_alone,
         "runs until the node is up (in CAN command mode with its protocol settings decided with "
         "_port_name:=sim)"),
    Rule(r"rostopic pub -r \S+ (?P<ns>/\S+)/cmd_vel geometry_msgs/Twist .*", drive_one_robot,
         "runs until that robot moves; every other virtual robot must stay put"),
    Rule(r"rostopic pub -1 (?P<ns>(/[^/\s]+)*)/sim/inject std_msgs/String "
         r"\"data: '(?P<line>[^']*)'\"", inject_fault,
         "runs against the virtual robot started before; its system_state then shows the fault"),
    Rule(r"rosservice call (?P<ns>(/[^/\s]+)*)/resume", call_resume,
         "runs against the virtual robot started before: success, and it is re-armed"),
    Rule(r"ranger_can (?P<rest>.*)", ranger_can, "runs; exit status 0"),
    Rule(r"source install/setup\.bash", run_ok, "runs; exit status 0"),
    Rule(r"cmake -S \. -B build/lib && cmake --build build/lib && ctest --test-dir build/lib "
         r"-LE vcan", library_build, "runs (incremental: test.sh built build/lib); exit status 0"),
    Rule(r"colcon list", colcon_list, "runs; lists the five packages"),
    Rule(r"cd ~/catkin_ws && (?P<tool>catkin_make|catkin_make_isolated|catkin build|colcon build)"
         r" && source (?P<space>devel|devel_isolated|install)/setup\.bash", workspace_build_in_ci,
         "verified: scripts/test_workspaces.sh (test.sh's workspaces stage; catkin_make_isolated "
         "on request) has a step running that tool in a fresh workspace"),
    Rule(r"(RANGER_STAGES=(?P<stages>\S+|\"[^\"]*\") )?\./scripts/test\.sh", test_sh_is_what_ci_runs,
         "verified: it runs this check; .ci/run runs it; the stages named exist"),
    Rule(r"\./scripts/demo\.sh|scripts/demo\.sh --no-setup --no-build --headless",
         demo_runs_in_test_demo, "verified: test_demo.py runs it (--no-setup --no-build "
         "--headless --output)"),
    Rule(r"pip install \./libranger_can", pip_install_in_ros2_stage,
         "verified: the ros2 stage installs it into a fresh venv and runs the Python example"),
    Rule(r"cd ~/ros2_ws && colcon build --paths src/ranger_ros/ros2/\* && "
         r"source install/setup\.bash", ros2_workspace_build,
         "verified: the ros2 stage runs that colcon command in a workspace holding this checkout"),
    Rule(r"ros2 launch ranger_bringup (?P<file>\S+\.launch\.py)( .*)?", ros2_launch_checked,
         "verified: the ros2 stage's test_launch_files.py runs it with stand-ins for launch"),
    Rule(r"scripts/build\.sh (lib|ros|all)", build_sh_runs_first,
         "verified: test.sh runs scripts/build.sh all before every stage"),
]


# ---- synopses -------------------------------------------------------------------------------------

def synopsis_words(text):
    """The --options and PLACEHOLDER words a synopsis names."""
    options = set(re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", text))
    placeholders = {w.strip("[].…") for w in re.split(r"[\s|]+", text)
                    if "=" not in w and PLACEHOLDER.match(w)}
    return options, placeholders


def check_synopsis(session, cmd):
    """The program exists and its help (a script: its text) names the synopsis's options."""
    words = program_words(cmd.text)
    options, placeholders = synopsis_words(cmd.text)
    first = words[0]
    if first == "ranger_can":
        rc, top = session.run("ranger_can --help")
        assert rc == 0, top
        sub = words[1] if len(words) > 1 else ""
        if sub and not PLACEHOLDER.match(sub) and not sub.startswith("-"):
            assert re.search(rf"^  {re.escape(sub)} ", top, re.M), f"no ranger_can {sub}:\n{top}"
            rc, text = session.run(f"ranger_can {shlex.quote(sub)} --help")
            assert rc == 0, text
        else:
            text = top
        missing = [o for o in options if o not in text]
        assert not missing, f"`{cmd.text}`: ranger_can's help does not name {missing}"
        return
    if first == "rosrun":
        rc, text = session.run(f"rosrun {shlex.quote(words[1])} {shlex.quote(words[2])} --help")
        assert rc == 0, text
        missing = [o for o in options if o not in text]
        assert not missing, f"`{cmd.text}`: its --help does not name {missing}"
        return
    if "/" in first:  # a script: relative to its README, else to the repository
        candidates = [os.path.join(REPO, os.path.dirname(cmd.document), first),
                      os.path.join(REPO, first)]
        path = next((p for p in candidates if os.path.isfile(p)), None)
        assert path, f"`{cmd.text}`: no such file {first}"
        assert os.access(path, os.X_OK), f"{first} is not executable"
        with open(path, encoding="utf-8") as f:
            text = f.read()
        missing = [w for w in options | placeholders if w not in text]
        assert not missing, f"`{cmd.text}`: {first} does not mention {missing}"
        return
    assert shutil.which(first), f"`{cmd.text}`: {first} is not installed"


# ---- running a session ----------------------------------------------------------------------------

def rule_for(cmd):
    for rule in RULES:
        m = re.fullmatch(rule.pattern, cmd.text)
        if m:
            return rule, m
    return None, None


def run_session(spec):
    session = Session()
    ok = False
    try:
        for cmd in spec.commands:
            if is_synopsis(cmd.text):
                check_synopsis(session, cmd)
                continue
            rule, m = rule_for(cmd)
            assert rule, (f"{cmd.where()}: `{cmd.text}` is a command no rule runs: add one to "
                          f"RULES in {os.path.relpath(__file__, REPO)}")
            try:
                rule.check(session, cmd, m)
            except AssertionError as e:
                raise AssertionError(f"{cmd.where()}: {e}") from None
        ok = True
    finally:
        session.close(check_alive=ok)


def describe():
    for spec in session_specs():
        also = f" (also {', '.join(spec.also_at)})" if spec.also_at else ""
        print(f"{spec.id()}{also}")
        for cmd in spec.commands:
            if is_synopsis(cmd.text):
                how = "synopsis: the program's help names its options"
            else:
                rule, _ = rule_for(cmd)
                how = rule.how if rule else "NO RULE: the check fails"
            print(f"  {cmd.text}\n      -> {how}")


if __name__ == "__main__":
    describe()
