"""Two launches of ranger_minimal.launch, one after the other, on one master: the second runs with
the parameters its own arguments give and nothing the first left on the master (roslaunch keeps
a node's parameters after it ends; clear_params removes them at the next launch)."""

import os
import sys
import xmlrpc.client

sys.path.insert(0, os.path.dirname(__file__))
from sim_support import Launch, Latest, RosMaster, wait_for  # noqa: E402

NODE = "/ranger_base_node"


def param(master, name):
    """The parameter's value on the master, or None when it is not set."""
    code, _, value = xmlrpc.client.ServerProxy(master.uri).getParam("/test_relaunch", name)
    return value if code == 1 else None


def test_a_second_launch_inherits_no_parameter_from_the_first(tmp_path):
    import rospy
    from ranger_msgs.msg import SystemState

    missing = str(tmp_path / "no_such_commissioning.yaml")
    master = RosMaster()
    try:
        # First: a commissioning file that does not exist. The node refuses it and, being
        # required, ends the launch; its parameters stay on the master.
        first = Launch(master, "ranger_minimal.launch", "sim:=true", "log_output:=log",
                       f"commissioning_file:={missing}", "publish_odom_tf:=false",
                       log_name="first")
        assert wait_for(lambda: not first.alive(), timeout=60), first.log_text()[-3000:]
        text = first.log_text()
        first.stop()
        assert "REQUIRED process [ranger_base_node" in text, text[-3000:]
        assert param(master, NODE + "/commissioning_file") == missing
        assert param(master, NODE + "/publish_odom_tf") is False

        # Second: no commissioning file. The node starts, identifies the virtual chassis and
        # reaches CAN command mode, with none of the first launch's values.
        rospy.init_node("test_relaunch", anonymous=True, disable_signals=True)
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
