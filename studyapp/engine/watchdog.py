"""The parent's watchdog over the worker and the force guard (mixed into ``engine.Engine``).

Once the worker reports ready, a watchdog thread drains the worker's events
and reports faults. The guard (engine/guard.py), not this thread, cuts the
force of a worker whose heartbeat is older than ``hang_timeout`` (default
80 ms): it clears the ``force_enable`` word within ``hang_timeout +
guard.POLL``, whatever the parent is doing (busy in Python, collecting
garbage, stopped). The thread wakes every ``POLL`` seconds, or at once when
the worker or the guard ends (it waits on their sentinels), so:

- a worker that dies (crash, SIGKILL) is noticed within a few milliseconds;
- a worker whose heartbeat is older than ``hang_timeout`` is called hung: the
  guard's cut (``force_off_time``) is reported, or the thread's own finding
  if it comes first (both clear the same word);
- a guard that dies is a fault too: only a restart brings supervision back;
- a force the guard cut because this program was stopped (reason "owner",
  engine/guard.py) is reported as a fault once the program runs again.

Either way the fault is reported (``faults``, ``on_fault``), the
``force_enable`` word is cleared, with the reason "watchdog" and how long the
worker was silent beside it (``StatusBlock.disable_force``; a worker that was
only slow zeroes its force at its next block and latches a fault) and
``force_output`` reads 0: the simulated device, which lives in the worker,
stops with it.

At ``stop()`` the parent waits only while the worker shows signs of life
(``stalled``): a running worker whose heartbeat is older than ``STALL_GRACE``
(or its ``hang_timeout``, the longer; only ``hang_timeout`` once the watchdog
has tripped on it), or a worker closing its devices that has said nothing for
``CLOSE_GRACE``, is stalled (stopped by SIGSTOP, hung in native code) and gets
SIGKILL at once: a stopped process handles neither the stop command nor
SIGTERM, and waiting out the polite timeout kept the parent 12 s behind a
stalled worker. The grace of a worker not yet tripped is 2 s because at 0.5 s
a healthy worker descheduled on a loaded machine was killed at stop and its
summary lost (the MIDI end-to-end test beside two ``yes``, 2026-11-29).
"""

import time
from multiprocessing.connection import wait as wait_for

POLL = 0.01  # s between watchdog checks
STALL_GRACE = 2.0  # s: a running worker's heartbeat this old at stop() means it is stalled (unless already tripped)
CLOSE_GRACE = 3.0  # s: a worker closing its devices may be this quiet (a device close gives up after 2 s)


class Watchdog:
    """The watchdog thread's work and the stall test of ``stop()``, on the engine's processes and status block."""

    def _trip(self, text, when, silence=0.0):
        block = self.status_block
        if block.force_enable:
            block.disable_force("watchdog", silence)
        elif block.force_off_reason == "watchdog":  # the guard was first: its moment is the cut's
            when = block.force_off_time
        self.tripped = True
        self._fault(text, when)

    def _hung(self, silence):
        return (f"watchdog: the engine stopped answering (no heartbeat for {1e3 * silence:.0f} ms, "
                f"{1e3 * self.config.hang_timeout:.0f} ms allowed); force switched off for safety")

    def _watch(self):
        sentinels = [self.process.sentinel, self.guard.sentinel]
        timeout = self.config.hang_timeout
        while not self._stop_watch.is_set():
            ended = wait_for(sentinels, POLL)
            now = time.monotonic()
            while (event := self._next_event(0)) is not None:
                self._handle(event)
            worker_ended = self.process.sentinel in ended
            guard_ended = self.guard.sentinel in ended
            if guard_ended:
                sentinels.remove(self.guard.sentinel)  # a process ends once: wait on it no more
            if self._stopping or self.tripped:
                if worker_ended:
                    return
                continue  # keep passing on the worker's events until stop()
            if worker_ended:
                self.process.join(0.1)
                self._trip(f"watchdog: the worker died (exit code {self.process.exitcode}); force is zero", now)
                return
            if guard_ended:
                self.guard.join(0.1)
                self._trip(f"watchdog: the force guard died (exit code {self.guard.exitcode}); force switched off "
                           "for safety: restart the engine", now)
                continue
            block = self.status_block
            if not block.force_enable and block.force_off_reason == "owner":  # this program was stopped, now runs
                self._trip("watchdog: this program was stopped (SIGSTOP, Ctrl-Z or a debugger); the force guard "
                           "switched the force off for safety: restart the engine", block.force_off_time)
                continue
            if not block.force_enable and block.force_off_reason == "watchdog":
                self.process.join(0.05)  # a killed worker's exit can lag its silence: say it died if it did
                if self.process.exitcode is not None:
                    self._trip(f"watchdog: the worker died (exit code {self.process.exitcode}); force is zero",
                               block.force_off_time)
                    return
                self._trip(self._hung(block.force_off_silence), block.force_off_time)
                continue
            snap = block.read()
            silence = now - snap["heartbeat"]
            if snap["state"] == "running" and silence > timeout:
                self._trip(self._hung(silence), now, silence)

    def stalled(self, heard):
        """The worker has shown no sign of life for longer than it may (module docstring)."""
        snap = self.status_block.read()
        now = time.monotonic()
        if snap["state"] == "running":
            grace = self.config.hang_timeout if self.tripped else max(STALL_GRACE, self.config.hang_timeout)
            return now - max(snap["heartbeat"], heard) > grace
        return now - max(snap["heartbeat"], heard) > CLOSE_GRACE
