"""The margins of the binding tests' wall-clock bounds (issue 34): every Driver.wait_until and
wait_ready that ends in time is timed, and the run ends with the three that came closest to
their bounds, under whatever load the run had. The waits themselves are the library's, unchanged."""

import functools
import inspect
import time

import pytest

import ranger_can

_waits = []


def _timed(method):
    signature = inspect.signature(method)

    @functools.wraps(method)
    def wait(self, *args, **kwargs):
        call = signature.bind(self, *args, **kwargs)
        call.apply_defaults()
        start = time.monotonic()
        result = method(self, *args, **kwargs)
        seconds, bound = time.monotonic() - start, call.arguments["timeout"]
        _waits.append((seconds / bound, seconds, bound, method.__name__))
        return result
    return wait


ranger_can.Driver.wait_until = _timed(ranger_can.Driver.wait_until)
ranger_can.Driver.wait_ready = _timed(ranger_can.Driver.wait_ready)


def _closest_waits():
    """The waits that came closest to their bounds, as one line (None before any)."""
    if not _waits:
        return None
    closest = sorted(_waits, reverse=True)[:3]
    return (f"wall-clock waits: {len(_waits)} ended in time; the closest to its bound: " +
            "; ".join(f"{what} {seconds:.2f} s of {bound:g} s ({100 * used:.0f} %)"
                      for used, seconds, bound, what in closest))


@pytest.fixture(scope="session", autouse=True)
def _wait_margins(record_testsuite_property):
    """The closest waits in the JUnit report too (property `measured`: scripts/test.sh's summary
    prints it)."""
    yield
    line = _closest_waits()
    if line:
        record_testsuite_property("measured", line)


def pytest_terminal_summary(terminalreporter):
    line = _closest_waits()
    if line:
        terminalreporter.write_line(line)
