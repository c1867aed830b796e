"""A test that hangs ends its process after ``LIMIT_S``, instead of the whole run at CI's limit.

CI gives the suite 90 minutes; one test that waited forever on a pipe or a process used all of them and
named nothing (issue 41's first stop). Each test's setup, call and teardown together get ``LIMIT_S``, over
ten times the longest test's time on a loaded clean clone (44 s idle, 2026-11-28). Then ``faulthandler``
writes every thread's stack to ``hung-<pid>.txt`` in the temporary directory and ends the process: under
xdist the run goes on and reports "worker crashed while running <test>", and the summary at the end prints
the stacks (``pytest_terminal_summary``); alone, pytest exits non-zero.
faulthandler's timer is a C thread, so a hang in C code (a blocking read, a Qt event loop) is caught too,
and it leaves SIGALRM to the tests that use it (tests/test_bad_input.py ``no_hang``).
"""

import faulthandler
import glob
import os
import tempfile
import time

import pytest

LIMIT_S = 600
STARTED = time.time()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    path = os.path.join(tempfile.gettempdir(), f"hung-{os.getpid()}.txt")
    with open(path, "w") as stacks:
        stacks.write(f"{item.nodeid} ran over {LIMIT_S} s:\n")
        stacks.flush()
        faulthandler.dump_traceback_later(LIMIT_S, exit=True, file=stacks)
        try:
            yield
        finally:
            faulthandler.cancel_dump_traceback_later()
    os.unlink(path)


def pytest_terminal_summary(terminalreporter, config):
    if hasattr(config, "workerinput"):
        return
    for path in sorted(glob.glob(os.path.join(tempfile.gettempdir(), "hung-*.txt"))):
        if os.path.getmtime(path) < STARTED:
            continue
        with open(path) as stacks:
            text = stacks.read()
        # only a file faulthandler wrote stacks into: the header alone is a test still running in another
        # pytest on the same machine
        if "\n" in text.rstrip("\n"):
            terminalreporter.write_sep("=", f"a hung test's stacks ({path})")
            terminalreporter.write(text)
