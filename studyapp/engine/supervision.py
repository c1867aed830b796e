"""The worker under the force guard's watch (engine/guard.py), seen from the worker's side.

The worker runs its loop only under the guard's watch: it waits for the
guard's first heartbeat before it reports ready (``wait``), and from then on
switches its force off itself (reason "guard") when that heartbeat is older
than ``guard_timeout``: a guard that died or was stopped leaves no force
unwatched. Before and after every block the worker reads the parent's
``force_enable`` word through ``force``.
"""

import time

from studyapp.engine.safety import force_off_text


class GuardWatch:
    """The guard's heartbeat and the ``force_enable`` word in the status block ``status``."""

    def __init__(self, status, guard_timeout):
        self.status = status
        self.guard_timeout = guard_timeout
        self.supervised = False  # the guard's heartbeat is checked from the first timed block on

    def wait(self, timeout=60.0):
        """Block until the force guard has started watching (``RuntimeError`` after ``timeout`` s)."""
        end = time.monotonic() + timeout
        while time.monotonic() - self.status.guard_heartbeat > self.guard_timeout:
            if time.monotonic() > end:
                raise RuntimeError(f"the force guard did not start within {timeout:g} s")
            time.sleep(0.005)
        self.supervised = True

    def force(self):
        """``(enabled, why)``: the parent's ``force_enable`` word, cleared here first if the force guard has gone
        silent, and why it is cleared, in words (None while it is set)."""
        status = self.status
        if self.supervised and status.force_enable:
            silence = time.monotonic() - status.guard_heartbeat
            if silence > self.guard_timeout:
                status.disable_force("guard", silence)
        if status.force_enable:
            return True, None
        return False, force_off_text(status.force_off_reason, status.force_off_silence)
