"""Parity: the ROS 2 node offers what the ROS 1 node offers — the same topics (each in the same
direction), services and message types, and the same parameters.

The ROS 1 node's interface is read from ranger_base/README.md (its topic, service and parameter
tables, which the ROS 1 tests hold to the node: test_parameters checks every parameter row
against the names the node reads, the node tests use every topic and service); the ROS 2 node's
from the running node: the ROS graph and its list_parameters service. A difference either way
fails, naming it."""

import os
import re

from rcl_interfaces.srv import ListParameters

from support import Client, Robot

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
ROS2_INFRASTRUCTURE_TOPICS = {"/rosout", "/parameter_events"}
ROS2_STANDARD_PARAMETERS = {"use_sim_time", "start_type_description_service"}


def section(text, heading):
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start:end if end >= 0 else len(text)]


def first_cells(block):
    for line in block.splitlines():
        if line.startswith("| `"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            yield cells


def names_in(cell):
    names = re.findall(r"`([^`]+)`", cell)
    if "…" in cell and len(names) == 2:  # `ultrasonic/range_1` … `ultrasonic/range_8`
        (stem, a), (_, b) = (re.match(r"(.*?)(\d+)$", n).groups() for n in names)
        return [f"{stem}{i}" for i in range(int(a), int(b) + 1)]
    return names


def ros1_interface():
    with open(os.path.join(REPO, "ranger_base", "README.md"), encoding="utf-8") as f:
        text = f.read()
    topics = {}
    for cells in first_cells(section(text, "## Topics")):
        direction = "in" if "(in)" in cells[0] else "out"
        for name in names_in(cells[0].split("(in)")[0]):
            topics[name] = (direction, cells[1].strip())
    services = {}
    for cells in first_cells(section(text, "## Services")):
        for name in names_in(cells[0]):
            services[name] = cells[1].strip()
    params = set()
    block = section(text, "## Parameters")
    for cells in first_cells(block):
        params.update(names_in(cells[0]))
    params.update(re.findall(r"^`([a-z_/]+)` \(diagnostic_updater's own parameter\)", block, re.M))
    return topics, services, params


def ros2_type(ros1_type, kind):
    package, name = ros1_type.split("/")
    return f"{package}/{kind}/{name}"


def test_readme_tables_parse():
    topics, services, params = ros1_interface()
    assert "cmd_vel" in topics and topics["cmd_vel"] == ("in", "geometry_msgs/Twist")
    assert "ultrasonic/range_8" in topics and "/tf" in topics
    assert services["resume"] == "std_srvs/Trigger"
    assert {"port_name", "linear/y/min_acceleration", "sim/errors", "diagnostic_period"} <= params


def test_ros2_node_has_the_ros1_nodes_topics_services_types_and_parameters(ros, tmp_path):
    topics, services, params = ros1_interface()
    client = Client()
    ns = f"/parity{os.getpid()}"
    robot = Robot(client, ns, str(tmp_path), port_name="sim", publish_cmd=True)
    try:
        node = client.node
        client.wait_for(lambda: any(n == "ranger_base_node" and s == ns
                                    for n, s in node.get_node_names_and_namespaces()),
                        30, "the node")

        def graph():
            pubs = dict(node.get_publisher_names_and_types_by_node("ranger_base_node", ns))
            subs = dict(node.get_subscriber_names_and_types_by_node("ranger_base_node", ns))
            srvs = dict(node.get_service_names_and_types_by_node("ranger_base_node", ns))
            return pubs, subs, srvs

        def local(name):
            return name if not name.startswith(ns + "/") else name[len(ns) + 1:]

        want_topics = {n: (d, ros2_type(t, "msg")) for n, (d, t) in topics.items()}
        want_services = {n: ros2_type(t, "srv") for n, t in services.items()}

        def have():
            pubs, subs, srvs = graph()
            found = {}
            for direction, table in (("out", pubs), ("in", subs)):
                for name, types in table.items():
                    if name not in ROS2_INFRASTRUCTURE_TOPICS:
                        found[local(name)] = (direction, types[0])
            return found, {local(n): t[0] for n, t in srvs.items()
                           if not local(n).startswith("ranger_base_node/")}

        # Discovery reports the node's entities over a moment: wait for it to settle.
        try:
            client.wait_for(lambda: have() == (want_topics, want_services), 30, "the graph")
        except AssertionError:
            pass
        have_topics, have_services = have()
        assert have_topics == want_topics
        assert have_services == want_services

        listed = client.call(ListParameters, f"{ns}/ranger_base_node/list_parameters",
                             ListParameters.Request())
        have_params = {n.replace(".", "/") for n in listed.result.names} - \
            ROS2_STANDARD_PARAMETERS
        assert sorted(have_params - params) == [], "only in ROS 2"
        assert sorted(params - have_params) == [], "only in ROS 1"
    finally:
        robot.stop()
        client.close()
