"""Two launches of ranger_minimal.launch, one after the other, on one master: the first ends with
a `kill -9` of the driver, the second runs with the parameters its own arguments give and nothing
the first left on the master (roslaunch keeps a node's parameters after it ends; clear_params
removes them at the next launch).

A killed driver ends the launch (required="true") with roslaunch's REQUIRED banner naming it and
its exit code; roslaunch itself still exits 0 (ROS 1's roslaunch never passes a node's exit code
on: ros/ros_comm#919), and the killed node stays registered on a master that outlives the launch
until `rosnode cleanup` (ranger_bringup/README.md says both). Parameters the driver would refuse
never get that far: test_launch.py checks that they fail roslaunch itself."""

import os
import signal
import sys
import xmlrpc.client

sys.path.insert(0, os.path.dirname(__file__))
from sim_support import Launch, Latest, RosMaster, wait_for  # noqa: E402

NODE = "/ranger_base_node"


def param(master, name):
    """The parameter's value on the master, or None when it is not set."""
    code, _, value = xmlrpc.client.ServerProxy(master.uri).getParam("/test_relaunch", name)
    return value if code == 1 else None


def node_pid(launch):
    for pid in launch._node_pids():
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            if os.path.basename(f.read().split(b"\0")[0]) == b"ranger_base_node":
                return pid
    return None


def test_a_killed_driver_ends_the_launch_loudly_and_the_next_launch_inherits_nothing():
    import rospy
    from ranger_msgs.msg import SystemState

    master = RosMaster()
    try:
        rospy.init_node("test_relaunch", anonymous=True, disable_signals=True)
        state = Latest("/system_state", SystemState)
        # First: the driver runs (TF off), then is killed with SIGKILL: no stop, no goodbye.
        first = Launch(master, "ranger_minimal.launch", "sim:=true", "log_output:=log",
                       "publish_odom_tf:=false", log_name="first")
        first.wait_until(lambda: state.get() is not None and state.get().link_up, timeout=60)
        pid = node_pid(first)
        assert pid, first.log_text()[-3000:]
        os.kill(pid, signal.SIGKILL)
        assert wait_for(lambda: not first.alive(), timeout=60), first.log_text()[-3000:]
        text = first.log_text()
        first.stop()
        assert "REQUIRED process [ranger_base_node" in text, text[-3000:]
        assert "exit code -9" in text, text[-3000:]
        assert param(master, NODE + "/publish_odom_tf") is False

        # Second: no argument but sim. The node starts, identifies the virtual chassis and
        # reaches CAN command mode, with none of the first launch's values.
        state = Latest("/system_state", SystemState)
        second = Launch(master, "ranger_minimal.launch", "sim:=true", "log_output:=log",
                        log_name="second")
        try:
            second.wait_until(lambda: state.get() is not None and state.get().control_mode == 1
                              and state.get().identification == "decided", timeout=60)
            assert param(master, NODE + "/commissioning_file") is None
            assert param(master, NODE + "/publish_odom_tf") is True
            assert param(master, NODE + "/port_name") == "sim"
        finally:
            second.stop()
    finally:
        master.stop()
