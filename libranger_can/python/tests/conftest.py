"""The margins of the binding tests' wall-clock bounds (issue 34): every Driver.wait_until and
wait_ready that ends in time is timed, and the run ends with the three that came closest to
their bounds, under whatever load the run had. The waits themselves are the library's, unchanged."""

import functools
import inspect
import os
import sys
import time

import ranger_can

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "..", "scripts"))
import pytest_wait_margins as wait_margins  # noqa: E402
from pytest_wait_margins import pytest_terminal_summary  # noqa: E402,F401
from pytest_wait_margins import wait_margins as _wait_margins_fixture  # noqa: E402,F401


def _timed(method):
    signature = inspect.signature(method)

    @functools.wraps(method)
    def wait(self, *args, **kwargs):
        call = signature.bind(self, *args, **kwargs)
        call.apply_defaults()
        start = time.monotonic()
        result = method(self, *args, **kwargs)
        seconds, bound = time.monotonic() - start, call.arguments["timeout"]
        wait_margins.record(method.__name__, seconds, bound)
        return result
    return wait


ranger_can.Driver.wait_until = _timed(ranger_can.Driver.wait_until)
ranger_can.Driver.wait_ready = _timed(ranger_can.Driver.wait_ready)

