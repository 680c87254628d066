"""Helpers for the ranger_bringup tests that need a ROS master: a private rosmaster on a free
port with a throwaway ROS_HOME, and polling without asserting on wall-clock durations (the
timeouts below only bound how long a failing test waits)."""

import os
import pty
import shutil
import signal
import socket
import subprocess
import tempfile
import termios
import threading
import time
import uuid
import xmlrpc.client

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), os.pardir))
SRC_DIR = os.path.join(PACKAGE_DIR, "src")
TELEOP = os.path.join(PACKAGE_DIR, "scripts", "ranger_teleop_keyboard")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(condition, timeout=20.0, interval=0.02):
    """Polls until condition() is truthy; returns its value, or None when the time is up."""
    end = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > end:
            return None
        time.sleep(interval)


class RosMaster:
    """A rosmaster of our own; sets this process's ROS environment to it."""

    def __init__(self):
        self.home = tempfile.mkdtemp(prefix="ranger-test-roshome-")
        self.port = free_port()
        self.uri = f"http://localhost:{self.port}"
        self.env = dict(os.environ, ROS_MASTER_URI=self.uri, ROS_HOME=self.home,
                        ROS_LOG_DIR=os.path.join(self.home, "log"), ROS_HOSTNAME="localhost",
                        PYTHONUNBUFFERED="1")
        self.env["PYTHONPATH"] = os.pathsep.join(
            p for p in (SRC_DIR, os.environ.get("PYTHONPATH")) if p)
        self.env.pop("ROS_IP", None)
        self.process = subprocess.Popen(["rosmaster", "--core", "-p", str(self.port)],
                                        env=self.env, stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL)
        os.environ.update({k: self.env[k] for k in ("ROS_MASTER_URI", "ROS_HOME", "ROS_LOG_DIR",
                                                    "ROS_HOSTNAME")})
        if not wait_for(self._up, timeout=30):
            self.stop()
            raise RuntimeError("rosmaster did not come up")
        # roslaunch sets /run_id when it finds none; two launches started together would race.
        xmlrpc.client.ServerProxy(self.uri).setParam("/rostest_support", "/run_id",
                                                     str(uuid.uuid1()))

    def _up(self):
        try:
            with socket.create_connection(("localhost", self.port), timeout=0.5):
                return True
        except OSError:
            return False

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        shutil.rmtree(self.home, ignore_errors=True)


class PtyProcess:
    """A command on the slave side of a pseudo-terminal (as if typed into a terminal), in a
    session of its own; its output is collected in the background."""

    def __init__(self, args, env):
        self.fd, slave = pty.openpty()
        self.slave = slave
        self.original = termios.tcgetattr(slave)
        self.process = subprocess.Popen(args, stdin=slave, stdout=slave, stderr=slave, env=env,
                                        start_new_session=True)
        self.output = b""
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        while True:
            try:
                data = os.read(self.fd, 4096)
            except OSError:
                return
            if not data:
                return
            self.output += data

    def text(self):
        return self.output.decode("utf-8", errors="replace")

    def type(self, keys):
        os.write(self.fd, keys.encode())

    def hold(self, key, seconds):
        """A held key as a terminal delivers it: one press, then auto-repeat every 33 ms."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.type(key)
            time.sleep(0.033)

    def wait_exit(self, timeout=20):
        try:
            return self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None

    def close(self):
        if self.process.poll() is None:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except OSError:
                pass
            self.process.wait()
        # The reader ends first (with the slave side closed everywhere, a read of the master side
        # fails with EIO), and only then is the master's descriptor closed: closed under a reader
        # still in its loop, its number would be the next pseudo-terminal's, and the old reader
        # would read the next process's output away from it (a teleop that said nothing, seen
        # once under load).
        # A process that escaped its session would keep the slave side open and the reader
        # reading: its descriptor is then left open (never reused) rather than closed.
        os.close(self.slave)
        self.reader.join(timeout=10)
        if not self.reader.is_alive():
            os.close(self.fd)


class TeleopProcess(PtyProcess):
    """scripts/ranger_teleop_keyboard on the slave side of a pseudo-terminal, in namespace `ns`,
    with private parameters from `params`."""

    def __init__(self, master, ns, **params):
        args = ["/usr/bin/python3", TELEOP, f"__ns:={ns}"] + [
            f"_{k}:={v}" for k, v in params.items()]
        super().__init__(args, master.env)
