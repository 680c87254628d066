"""The fixtures the node's tests share. rclpy is initialised only for a module that asks for it
(the `ros` fixture, or `client`/`robots`, which need it): test_wire and test_adapter never
initialise it (they hold bytes and tables, no node), and test_parameters asks for it itself."""

import itertools
import os
import sys

import pytest
import rclpy
from geometry_msgs.msg import Twist

from support import Client, Robot

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
from pytest_wait_margins import pytest_terminal_summary, wait_margins  # noqa: E402,F401

_ns = itertools.count(1)


@pytest.fixture(scope="module")
def ros():
    """rclpy's default context, for the module that asks (once per module)."""
    rclpy.init()
    yield
    rclpy.shutdown()


@pytest.fixture
def client(ros):
    """A client node of the test's own, spun on a thread."""
    c = Client()
    yield c
    c.close()


@pytest.fixture
def robots(client, tmp_path, request):
    """robots(port="sim", cmd_type=Twist, keep=(), env=None, **params): a ranger_base_node in a
    namespace of its own (the module's NS_PREFIX, the process id, a count), stopped when the test
    ends; keep: (topic, type) pairs whose every message the client keeps; env: variables added
    to the node's environment."""
    started = []
    prefix = getattr(request.module, "NS_PREFIX", "t")

    def start(port="sim", cmd_type=Twist, keep=(), env=None, **params):
        r = Robot(client, f"/{prefix}{os.getpid()}_{next(_ns)}", str(tmp_path),
                  cmd_type=cmd_type, env=env, port_name=port, **params)
        for topic, msg_type in keep:
            client.listen(f"{r.ns}/{topic}", msg_type, keep=True)
        started.append(r)
        return r
    yield start
    for r in started:
        r.stop()

