"""The margins of the Python suites' wall-clock bounds (issue 34), for the conftest.py of the
binding's tests (libranger_can/python/tests) and of the ROS 2 node's (ros2/ranger_base/test):
each wait that ends in time is recorded (record), and the run ends with the three that came
closest to their bounds, in the terminal and as the JUnit testsuite property `measured`, which
scripts/junit_summary.py --measured prints in scripts/test.sh's summary. A conftest.py takes the
fixture and the hook by importing them:

    from pytest_wait_margins import record, wait_margins, pytest_terminal_summary  # noqa: F401
"""

import pytest

# (fraction of its bound used, seconds, bound, what)
_waits = []


def record(what, seconds, bound):
    """A wait on `what` ended in time after `seconds` of its `bound`."""
    _waits.append((seconds / bound, seconds, bound, what))


def closest_line():
    """The waits that came closest to their bounds, as one line (None before any)."""
    if not _waits:
        return None
    closest = sorted(_waits, reverse=True)[:3]
    return (f"wall-clock waits: {len(_waits)} ended in time; the closest to its bound: " +
            "; ".join(f"{what} {seconds:.2f} s of {bound:g} s ({100 * used:.0f} %)"
                      for used, seconds, bound, what in closest))


@pytest.fixture(scope="session", autouse=True)
def wait_margins(record_testsuite_property):
    """The closest waits in the JUnit report (property `measured`)."""
    yield
    line = closest_line()
    if line:
        record_testsuite_property("measured", line)


def pytest_terminal_summary(terminalreporter):
    line = closest_line()
    if line:
        terminalreporter.write_line(line)
