"""A running driver for the end-to-end tests: `roslaunch ranger_bringup <launch> ...` against the
in-process virtual chassis, on a private master, with helpers to wait for topics.

Needs the workspace environment (source install/setup.bash: ranger_base_node, ranger_msgs);
this package's and ranger_description's source directories come first on ROS_PACKAGE_PATH so
the launch files under test are the ones in the tree."""

import os
import signal
import subprocess
import threading

from rostest_support import PACKAGE_DIR, RosMaster, wait_for

REPO = os.path.dirname(PACKAGE_DIR)


class Launch:
    def __init__(self, master, launch, *args, log_name="roslaunch", env=None):
        self.log_path = os.path.join(master.home, f"{log_name}.log")
        self.log = open(self.log_path, "wb")
        environment = dict(master.env if env is None else env)
        self.log_dir = os.path.join(master.home, "log", log_name)
        environment["ROS_LOG_DIR"] = self.log_dir
        environment["ROS_PACKAGE_PATH"] = os.pathsep.join(
            [PACKAGE_DIR, os.path.join(REPO, "ranger_description")]
            + [p for p in environment.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p])
        self.process = subprocess.Popen(
            ["roslaunch", os.path.join(PACKAGE_DIR, "launch", launch), *args],
            env=environment,
            stdout=self.log, stderr=subprocess.STDOUT, start_new_session=True)

    def log_text(self):
        self.log.flush()
        with open(self.log_path, encoding="utf-8", errors="replace") as f:
            return f.read()

    def alive(self):
        return self.process.poll() is None

    def wait_until(self, condition, timeout):
        """wait_for(condition) that gives up as soon as roslaunch has exited; the log explains."""
        wait_for(lambda: condition() or not self.alive(), timeout=timeout)
        ok = condition()
        assert ok, "roslaunch log:\n" + self.log_text()[-3000:]
        return ok

    def stop(self):
        if self.alive():
            os.killpg(self.process.pid, signal.SIGINT)
            try:
                self.process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
        # roslaunch starts every node in a session of its own and may leave some behind when
        # stopped early: interrupt whatever of this launch outlived it.
        for pid in self._node_pids():
            try:
                os.kill(pid, signal.SIGINT)
            except OSError:
                pass
        self.log.close()

    def _node_pids(self):
        """The nodes this launch started: roslaunch passes __log:=<ROS_LOG_DIR>/... to each,
        and every Launch has a log directory of its own."""
        marker = (self.log_dir + os.sep).encode()
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open(f"/proc/{entry}/cmdline", "rb") as f:
                    if marker in f.read():
                        yield int(entry)
            except OSError:
                continue


class Latest:
    """Keeps the latest message (and a count) of a topic."""

    def __init__(self, topic, msg_type):
        import rospy

        self.lock = threading.Lock()
        self.msg, self.count = None, 0
        self.messages = []
        self.keep = False
        self.sub = rospy.Subscriber(topic, msg_type, self._on, queue_size=50)

    def _on(self, msg):
        with self.lock:
            self.msg = msg
            self.count += 1
            if self.keep:
                self.messages.append(msg)

    def get(self):
        with self.lock:
            return self.msg


__all__ = ["Launch", "Latest", "RosMaster", "wait_for", "REPO", "PACKAGE_DIR"]
