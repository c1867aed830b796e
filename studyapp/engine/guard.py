"""The force guard: a small process that switches the force off when the worker stops answering.

Why a process of its own: a watchdog thread in the parent shares the parent's
interpreter lock, so a parent busy in Python (a long computation, a garbage
collection, one C call that never lets go of the lock) delayed the force cut
to 350-760 ms (issue 21, item 10), and a parent stopped altogether never cut
it. The guard does nothing else, so nothing in the app can keep it busy.

Every ``POLL`` seconds it

1. writes its own heartbeat (``StatusBlock.guard_beat``). The worker reads it
   before every block and switches its force off itself (reason "guard") when
   it is older than ``EngineConfig.guard_timeout``: a guard that died or was
   stopped leaves no force unwatched;
2. reads the worker's heartbeat; while the worker is running and its
   heartbeat is older than ``hang_timeout``, it clears ``force_enable``
   (reason "watchdog", the silence, and the moment, ``force_off_time``).

3. withholds the force of the block the worker has staged in the telemetry
   ring (``Ring.withhold``) whenever it sees ``force_enable`` go from set to
   cleared, whoever cleared it: a worker stopped after its last read of the
   word and before its commit would otherwise publish that block's force on
   SIGCONT, after the trip (engine/safety.py);
4. looks at its owner, the process that started the engine (the console, ``live``):
   when the owner is stopped (SIGSTOP, Ctrl-Z, a debugger: ``/proc/<pid>/stat``
   state ``T`` or ``t``) or gone (a SIGKILL pending, exiting, or the guard's parent
   no longer it: a killed process of a few hundred MB takes 50-360 ms to die), it
   clears ``force_enable`` at once (reason "owner"): no force runs on without
   the program that shows and logs it (issue 33, item 4). On main a stopped
   console left the force on for good and a killed one for 151-429 ms.

A worker stopped (SIGSTOP), hung or killed therefore loses its force within
``hang_timeout + POLL`` (80 + 2 ms by default) plus the OS's wake-up delay of
this process, whatever the parent does; the worker, reading the word before
and after each block, computes and writes no force from then on
(engine/safety.py). The guard asks for real-time priority one step above the
worker's loop (and runs without it where the OS refuses). It leaves when the
worker has stopped or failed, when its parent is gone, or on SIGTERM (the
parent's ``Engine.stop``), clearing the force first when its owner is gone.
"""

import os
import signal
import time

from studyapp.engine import parent_death
from studyapp.engine.ring import Ring
from studyapp.engine.status import StatusBlock
from studyapp.engine.telemetry import WITHHELD

POLL = 0.002  # s between rounds
WATCHED = "running"  # the worker's state in which its heartbeat must keep coming
DONE = ("stopped", "failed")
ALIVE, STOPPED, GONE = "alive", "stopped", "gone"  # the owner's states
PF_EXITING = 0x4  # /proc/<pid>/stat field 9 (flags): the process has begun to exit
SIGKILL_BIT = 1 << (signal.SIGKILL - 1)  # /proc/<pid>/stat field 31: its pending signals


def main(status_name, hang_timeout, priority=None, ring_spec=None, parent=None):
    """Entry point of the guard process (spawned by ``Engine.start``); ``priority``: SCHED_FIFO's, or None;
    ``ring_spec``: the worker's telemetry ring; ``parent``: the PID of the process that spawned it (a parent
    that died before this line is gone, not PID 1 alive)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    parent = os.getppid() if parent is None else parent
    if priority is not None:  # None: the engine runs without real-time priority, and so does its guard
        _try_realtime(priority)
    status = StatusBlock.attach(status_name)
    ring = Ring.attach(ring_spec) if ring_spec is not None else None
    owner = Owner(parent)
    try:
        parent_death.watched()  # the loop below sees the owner gone within a poll
        watch(status, hang_timeout, owner.state, ring=ring)
    finally:
        owner.close()
        if ring is not None:
            ring.close()
        status.close()


class Owner:
    """The state of the process that started the engine: ``ALIVE``, ``STOPPED`` or ``GONE``."""

    def __init__(self, pid):
        self.pid = pid
        try:
            self._stat = os.open(f"/proc/{pid}/stat", os.O_RDONLY | os.O_CLOEXEC)
        except OSError:
            self._stat = None  # no /proc: only its end is seen

    def state(self):
        if os.getppid() != self.pid:
            return GONE
        if self._stat is None:
            return ALIVE
        try:
            data = os.pread(self._stat, 512, 0)
        except OSError:
            return GONE
        fields = data[data.rfind(b")") + 2:].split()  # after the command name, which may hold anything
        state, flags, pending = fields[0], int(fields[6]), int(fields[28])
        if state in (b"Z", b"X") or flags & PF_EXITING or pending & SIGKILL_BIT:
            return GONE  # killed: dying takes a big process 50-360 ms before its children see it gone
        return STOPPED if state in (b"T", b"t") else ALIVE

    def close(self):
        if self._stat is not None:
            os.close(self._stat)
            self._stat = None


def watch(status, hang_timeout, owner=lambda: ALIVE, rounds=None, ring=None):
    """The guard's loop (``owner``: the owner's state now; ``rounds``: stop after that many, for tests;
    ``ring``: the telemetry ring whose staged block loses its force when the force goes off)."""
    enabled = status.force_enable
    while rounds is None or rounds > 0:
        if rounds is not None:
            rounds -= 1
        status.guard_beat()
        state, heartbeat = status.worker_beat()
        now = time.monotonic()
        seen = owner()
        if seen != ALIVE and status.force_enable:
            status.disable_force("owner")
        if state in DONE or seen == GONE:
            return
        silence = now - heartbeat
        if state == WATCHED and silence > hang_timeout and status.force_enable:
            status.disable_force("watchdog", silence)
        was_enabled, enabled = enabled, status.force_enable
        if was_enabled and not enabled and ring is not None:
            ring.withhold(WITHHELD)
        time.sleep(POLL)


def _try_realtime(priority):
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except (OSError, AttributeError):
        pass
