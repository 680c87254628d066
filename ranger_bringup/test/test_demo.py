"""The README's demo, headless: scripts/demo.sh --no-setup --no-build against the built workspace
(the one this test runs in). It must drive the whole route through the three motion modes, write
the plot and the summary, and the driver's odometry must track the virtual chassis's ground
truth closely (the virtual chassis is exact, so a large error is a driver bug)."""

import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
from sim_support import REPO  # noqa: E402

DEMO = os.path.join(REPO, "scripts", "demo.sh")
OUTPUT_DIR = os.environ.get("RANGER_TEST_OUTPUT_DIR",
                            os.path.join(tempfile.gettempdir(), "ranger_tests"))


def install_base():
    """The install space that provides ranger_bringup in this environment."""
    share = subprocess.run(["rospack", "find", "ranger_base"], capture_output=True, text=True,
                           check=True, timeout=60).stdout.strip()
    d = share
    while d != os.path.dirname(d):
        # colcon writes this helper into the install base (a catkin package prefix has its own
        # setup.sh, which is not what we want)
        if os.path.isfile(os.path.join(d, "_local_setup_util_sh.py")):
            return d
        d = os.path.dirname(d)
    raise AssertionError(f"no setup.bash / setup.sh above {share}: build with colcon first")


def test_demo_drives_all_modes_and_plots_odometry_against_ground_truth():
    out = os.path.join(OUTPUT_DIR, "demo")
    env = dict(os.environ, RANGER_INSTALL=install_base())
    env.pop("DISPLAY", None)
    result = subprocess.run([DEMO, "--no-setup", "--no-build", "--headless", "--output", out],
                            capture_output=True, text=True, env=env, timeout=300)
    print(result.stdout)
    assert result.returncode == 0, result.stdout + result.stderr
    text = result.stdout
    for label in ("Ackermann", "crab (oblique)", "spin", "mode switch"):
        assert label in text
    assert "[6/6]" in text
    png = os.path.join(out, "odometry_vs_ground_truth.png")
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    assert os.path.getsize(png) > 20000
    with open(os.path.join(out, "summary.txt"), encoding="utf-8") as f:
        summary = f.read()
    m = re.search(r"total: ([\d.]+) m driven \(odometry says ([\d.]+) m\); final pose error "
                  r"([\d.]+) m, ([\d.]+) deg", summary)
    assert m, summary
    driven, odom_driven, error_m, error_deg = map(float, m.groups())
    assert driven > 8.0, "the route is about 10 m long"
    assert abs(odom_driven - driven) < 0.02 * driven
    assert error_m < 0.10 and error_deg < 2.0, summary
    # The spin turns what its label says (the virtual chassis's ground truth, braking included).
    spin = re.search(r"spin left half a turn\s+spin\s+[\d.]+ m\s+(\d+) deg", summary)
    assert spin and abs(int(spin.group(1)) - 180) <= 5, summary
