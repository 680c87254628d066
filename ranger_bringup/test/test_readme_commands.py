"""Every command in README.md, ranger_base/README.md and ranger_bringup/README.md, run as written
(readme_commands.py says what counts as a command and how each kind runs). One test per block
or inline command; identical ones run once.

Needs the workspace environment (source install/setup.bash) and, for the plain-CMake command, the
library build in build/lib, both of which scripts/test.sh provides."""

import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(__file__))
import readme_commands as rc  # noqa: E402

SPECS = rc.session_specs()


def test_the_extraction_finds_the_documented_commands():
    """A broken extractor would check nothing: these commands must be among the ones found."""
    found = {(c.document, c.text) for c in rc.all_commands()}
    for expected in [
        ("README.md", "./scripts/demo.sh"),
        ("README.md", "./scripts/test.sh"),
        ("README.md", 'RANGER_STAGES="unit ros" ./scripts/test.sh'),
        ("README.md", "rosrun ranger_bringup bringup_can2usb.bash"),
        ("README.md", "roslaunch ranger_bringup ranger_minimal.launch ns:=robot1"),
        ("README.md", "roslaunch ranger_bringup ranger_minimal.launch sim:=true"),
        ("README.md", "ranger_can decode [FILE] [--json] [--protocol auto|manual|agx_v2|mini_v3] "
                      "[--set NAME=VALUE]..."),
        ("ranger_base/README.md", "rosrun ranger_base ranger_base_node _port_name:=sim"),
        ("ranger_bringup/README.md", "roslaunch ranger_bringup ranger_sim.launch rviz:=true"),
    ]:
        assert expected in found, expected
    # Names, table cells and other languages' blocks are not commands.
    texts = {text for _, text in found}
    assert "ranger_can" not in texts and "scripts/perf.sh" not in texts
    assert not any(t.startswith("q   w   e") for t in texts)


def test_every_command_has_a_rule():
    unknown = [f"{c.where()}: `{c.text}`" for c in rc.all_commands()
               if not rc.is_synopsis(c.text) and rc.rule_for(c)[0] is None]
    assert not unknown, ("commands no rule of readme_commands.py runs (add one):\n"
                         + "\n".join(unknown))


@pytest.mark.parametrize("text,expected", [
    ("ranger_can decode [FILE] [--json]", True),
    ("scripts/fuzz.sh [SECONDS] [TARGET...]", True),
    ("rosrun ranger_bringup demo_route --output-dir DIR", True),
    ("ranger_can odom [FILE] [--source wheels|motion]", True),
    ("roslaunch ranger_bringup ranger_minimal.launch ns:=robot1", False),
    ('RANGER_STAGES="unit ros" ./scripts/test.sh', False),
    ("cmake -S . -B build/lib && cmake --build build/lib", False),
    ("rostopic pub -r 10 /robot1/cmd_vel geometry_msgs/Twist '{linear: {x: 0.3}}'", False),
])
def test_synopses_are_told_from_commands(text, expected):
    assert rc.is_synopsis(text) == expected


@pytest.mark.parametrize("span,expected", [
    ("roslaunch ranger_bringup ranger_minimal.launch sim:=true", True),
    ("./scripts/demo.sh", True),
    ("RANGER_STAGES=ros ./scripts/test.sh", True),
    ("scripts/fuzz.sh 3600", True),
    ("ranger_can", False),
    ("scripts/perf.sh", False),
    ("libranger_can/", False),
    ("port_name:=can0", False),
    ("./", False),
    ("cmd_vel", False),
])
def test_inline_commands_are_told_from_names(span, expected):
    assert rc.is_inline_command(span) == expected


@pytest.mark.parametrize("spec", SPECS, ids=[s.id() for s in SPECS])
def test_readme_commands_run_as_written(spec):
    rc.run_session(spec)
