"""rviz under Xvfb (software GL) with the driver moving the virtual chassis: a screenshot must
show the robot model (its orange body) and the odometry / ground-truth trail, not a blank or
error view. The screenshot is kept for people to look at:
  $RANGER_TEST_OUTPUT_DIR/rviz_screenshot.png   (default: <tmp>/ranger_tests/)
"""

import os
import shutil
import subprocess
import sys
import tempfile

import pytest

sys.path.insert(0, os.path.dirname(__file__))
from sim_support import Launch, Latest, RosMaster, wait_for  # noqa: E402

OUTPUT_DIR = os.environ.get("RANGER_TEST_OUTPUT_DIR",
                            os.path.join(tempfile.gettempdir(), "ranger_tests"))
WIDTH, HEIGHT = 1200, 800


def read_rgb(png):
    """The screenshot as an (h, w, 3) uint8 array (ImageMagick converts it to binary PPM)."""
    import numpy as np

    ppm = subprocess.run(["convert", png, "-depth", "8", "ppm:-"], check=True,
                         capture_output=True, timeout=60).stdout
    # P6\n<w> <h>\n255\n<data>: ImageMagick writes no comments.
    magic, size, maxval, data = ppm.split(b"\n", 3)
    assert magic == b"P6" and maxval == b"255"
    w, h = map(int, size.split())
    return np.frombuffer(data[:w * h * 3], dtype=np.uint8).reshape(h, w, 3)


def body_pixels(rgb):
    """Pixels of the body's orange (URDF ranger_body 0.93 0.55 0.10) under rviz lighting:
    hue 18-40 deg, strongly saturated, not dark."""
    import numpy as np

    c = rgb.astype(np.float32) / 255.0
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    mx, mn = c.max(axis=2), c.min(axis=2)
    sat = np.where(mx > 0, (mx - mn) / np.maximum(mx, 1e-6), 0)
    hue = np.degrees(np.arctan2(np.sqrt(3) * (g - b), 2 * r - g - b)) % 360
    return int(((hue > 18) & (hue < 40) & (sat > 0.7) & (mx > 0.3) & (r >= g) & (g >= b)).sum())


def trail_pixels(rgb):
    """Pixels of the ground-truth Odometry arrows (rviz config colour 0 200 120)."""
    import numpy as np

    c = rgb.astype(np.int32)
    return int(((c[..., 1] > 120) & (c[..., 1] > c[..., 0] + 60) & (c[..., 1] > c[..., 2] + 20)
                ).sum())


class Xvfb:
    def __init__(self):
        assert shutil.which("Xvfb"), "Xvfb not found: install xvfb (scripts/setup.sh test does)"
        read_fd, write_fd = os.pipe()
        self.process = subprocess.Popen(
            ["Xvfb", "-displayfd", str(write_fd), "-screen", "0", f"{WIDTH}x{HEIGHT}x24",
             "-nolisten", "tcp"], pass_fds=[write_fd], stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        os.close(write_fd)
        with os.fdopen(read_fd) as f:
            number = f.readline().strip()
        assert number, "Xvfb did not start"
        self.display = ":" + number

    def screenshot(self, path):
        subprocess.run(["import", "-display", self.display, "-window", "root", path],
                       check=True, timeout=60, capture_output=True)
        return path

    def stop(self):
        self.process.terminate()
        self.process.wait(timeout=30)


@pytest.fixture(scope="module")
def master():
    m = RosMaster()
    yield m
    m.stop()


def test_rviz_draws_the_moving_robot(master):
    import rospy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry

    os.makedirs(OUTPUT_DIR, exist_ok=True)
    shot = os.path.join(OUTPUT_DIR, "rviz_screenshot.png")
    if os.path.exists(shot):
        os.remove(shot)
    xvfb = Xvfb()
    driver = rviz = None
    try:
        driver = Launch(master, "ranger_minimal.launch", "sim:=true", "log_output:=log",
                        log_name="driver")
        env = dict(master.env, DISPLAY=xvfb.display, LIBGL_ALWAYS_SOFTWARE="1",
                   XDG_RUNTIME_DIR=master.home)
        rviz = Launch(master, "display.launch", log_name="rviz", env=env)
        rospy.init_node("rviz_screenshot_test", anonymous=True, disable_signals=True)
        truth = Latest("/sim/ground_truth", Odometry)
        driver.wait_until(lambda: truth.get() is not None, timeout=60)
        cmd_vel = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        # Drive an arc until the virtual chassis has visibly moved (2 m), so that the trail
        # is there and the model is drawn where TF says, not at a default origin.
        arc = Twist()
        arc.linear.x, arc.angular.z = 0.5, 0.4

        def moved():
            cmd_vel.publish(arc)
            p = truth.get().pose.pose.position
            return (p.x ** 2 + p.y ** 2) ** 0.5 > 2.0

        assert wait_for(moved, timeout=60, interval=0.05), driver.log_text()[-3000:]
        # rviz needs a moment to start and render with software GL; keep driving meanwhile.
        # Mesa's software GL (llvmpipe) has been seen to crash inside libLLVM while rviz starts on
        # a busy machine (SIGSEGV, once in many runs): rviz is started once more then, and the test
        # says so; a second death fails it.
        restarted = False

        def drawn():
            nonlocal rviz, restarted
            if not rviz.alive() and not restarted:
                restarted = True
                print("rviz died; starting it once more. Its log:\n" + rviz.log_text()[-1500:])
                rviz.stop()
                rviz = Launch(master, "display.launch", log_name="rviz-again", env=env)
            cmd_vel.publish(arc)
            xvfb.screenshot(shot)
            rgb = read_rgb(shot)
            # The trail too: a restarted rviz draws it from its start on.
            return body_pixels(rgb) > 0.002 * WIDTH * HEIGHT and trail_pixels(rgb) > 50

        ok = wait_for(drawn, timeout=90, interval=0.5)
        cmd_vel.publish(Twist())
        assert rviz.alive(), rviz.log_text()
        rgb = read_rgb(shot)
        body, trail = body_pixels(rgb), trail_pixels(rgb)
        print(f"screenshot {shot}: {body} body pixels, {trail} trail pixels")
        assert ok, f"no robot body in the screenshot ({body} orange pixels): {shot}\n" + \
            rviz.log_text()[-3000:]
        assert trail > 50, f"no ground-truth trail drawn ({trail} pixels): {shot}"
        # Not a blank or single-colour error view: the picture has plenty of distinct colours.
        colours = len({tuple(p) for p in rgb[::4, ::4].reshape(-1, 3)})
        assert colours > 200, f"only {colours} colours: {shot}"
    finally:
        for launch in (rviz, driver):
            if launch:
                launch.stop()
        xvfb.stop()
