"""Checks a launch of ranger_base_node while roslaunch reads the launch file, before anything
starts: ranger_minimal.launch runs it as a command parameter (its output is the node's port_name),
and a non-zero exit status makes roslaunch itself fail, with the reasons on the console.

    /usr/bin/python3 check_launch.py [--rosparam FILE | NAME:=VALUE]...

(Run by the ROS Python, not executable itself: installed beside the launch files, in the share
directory `$(find ranger_bringup)` names.)

  * The node's parameters, as the launch file gives them: NAME:=VALUE (typed as roslaunch types a
    <param value>) and --rosparam FILE (a YAML file loaded into the node's private namespace), in
    the launch file's order (a later one wins). They are checked by the node itself
    (`ranger_base_node --check-parameters`: every value, every combination, and no name the node
    does not read), never by a copy of its rules.
  * The roslaunch command line: every NAME:=VALUE on it must be an argument the launch files on it
    declare (roslaunch itself ignores any other without a word). Only when roslaunch is what runs
    this (rostest, roslaunch-check and the Python API give their own arguments).

Exit status: 0 all good (port_name on stdout), 1 a problem (each one on stderr)."""

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
import xmlrpc.client

PREFIX = "ranger_bringup: "


def node_parameters(argv):
    """The parameters NAME:=VALUE and --rosparam FILE give, in order."""
    import rosparam
    from roslaunch.loader import convert_value

    params, problems = {}, []
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg == "--rosparam":
            path = argv[i + 1] if i + 1 < len(argv) else ""
            i += 2
            if not path:
                continue
            try:
                for values, _ in rosparam.load_file(path):
                    merge(params, values or {})
            except Exception as e:  # a missing file, invalid YAML: rosparam says which
                problems.append(f"parameter file {path}: {e}")
            continue
        name, sep, value = arg.partition(":=")
        if not sep:
            problems.append(f"not NAME:=VALUE or --rosparam FILE: {arg!r}")
        else:
            params[name] = convert_value(value, "auto")
        i += 1
    return params, problems


def merge(into, values):
    for key, value in values.items():
        if isinstance(value, dict) and isinstance(into.get(key), dict):
            merge(into[key], value)
        else:
            into[key] = value


def node_problems(params):
    """The node's own check of `params` (ranger_base_node --check-parameters)."""
    import roslib.packages

    nodes = roslib.packages.find_node("ranger_base", "ranger_base_node")
    if not nodes:
        return ["ranger_base_node not found (is the workspace built and sourced?)"]
    result = subprocess.run([nodes[0], "--check-parameters"],
                            input=xmlrpc.client.dumps((params,)), capture_output=True, text=True)
    if result.returncode == 0:
        return []
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    return lines or [f"ranger_base_node --check-parameters exited with {result.returncode}"]


def declared_arguments(path):
    """The arguments a launch file declares itself: its <arg>s without a fixed value, not those
    it passes to an <include>."""
    names = set()

    def walk(element):
        for child in element:
            if child.tag == "arg" and child.get("value") is None:  # a value= is no argument
                names.add(child.get("name"))
            elif child.tag != "include":
                walk(child)

    walk(ET.parse(path).getroot())
    return names


def command_line_problems():
    """Every NAME:=VALUE on roslaunch's command line that its launch files do not declare."""
    try:
        with open(f"/proc/{os.getppid()}/cmdline", "rb") as f:
            parent = [a.decode(errors="replace") for a in f.read().split(b"\0") if a]
    except OSError:
        return []
    if len(parent) < 2 or os.path.basename(parent[1]) != "roslaunch":
        return []
    import roslaunch
    import roslaunch.rlutil
    import rosgraph.names

    argv = parent[2:]
    try:
        _, args = roslaunch._get_optparse().parse_args(argv)
        files = [f for f in roslaunch.rlutil.resolve_launch_arguments(args)
                 if f != "-" and ":=" not in f and os.path.isfile(f)]
        declared = set().union(*(declared_arguments(f) for f in files)) if files else set()
    except (SystemExit, Exception):  # roslaunch reports its own command-line errors
        return []
    problems = []
    for name, value in rosgraph.names.load_mappings(argv).items():
        if name.startswith("__") or name in declared:
            continue
        launch = ", ".join(os.path.basename(f) for f in files) or "the launch file"
        problems.append(
            f"unknown argument {name}:={value}: {launch} declares no argument {name} (its "
            f"arguments: {', '.join(sorted(declared))}). roslaunch would ignore it without a "
            f"word; the driver's other parameters go in a file: params_file:=FILE "
            f"(ranger_base/README.md, \"Parameters\")")
    return problems


def main(argv):
    params, problems = node_parameters(argv)
    if not problems:
        problems = node_problems(params)
    problems += command_line_problems()
    if problems:
        sys.stderr.write(PREFIX + "the launch is refused before anything starts:\n" +
                         "".join(f"  {p}\n" for p in problems))
        return 1
    sys.stdout.write(str(params.get("port_name", "")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
