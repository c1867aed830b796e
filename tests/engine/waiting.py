"""Polling for a condition in a test of a live process, with a timeout."""

import time


def wait_for(predicate, timeout=10.0, step=0.005):
    """The first true value of ``predicate()``; AssertionError after ``timeout`` seconds."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = predicate()
        if value:
            return value
        time.sleep(step)
    raise AssertionError("timed out waiting")
