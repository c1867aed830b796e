"""The force guard cuts a stalled worker's force whatever the parent does (issue 21, item 10).

These tests check the mechanism, not a time: the cut is made by the guard
process while the parent cannot run a line of Python (one C call holding the
interpreter's lock), and the worker switches its own force off when the guard
goes silent. The times are measured by ``studyapp bench force-cut``.
"""

import ctypes
import os
import signal
import threading
import time

import numpy as np

from studyapp.engine import guard
from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.ring import Ring
from studyapp.engine.status import NUMBERS, StatusBlock
from tests.engine.waiting import wait_for

RATE = 5000.0


def _hold_the_interpreter(seconds):
    """Sleep ``seconds`` in C with the GIL held (``PyDLL`` keeps it): no thread of this process runs."""
    ctypes.PyDLL(None).usleep(int(seconds * 1e6))


def test_the_guard_clears_the_word_for_a_silent_running_worker_only():
    status = StatusBlock.create()
    try:
        status.set(state="running", heartbeat=time.monotonic())
        status.publish()
        guard.watch(status, hang_timeout=10.0, rounds=3)
        assert status.force_enable and status.guard_heartbeat > 0
        status.set(state="starting", heartbeat=time.monotonic() - 5.0)  # compiling: not yet watched
        status.publish()
        guard.watch(status, hang_timeout=0.08, rounds=3)
        assert status.force_enable
        status.set(state="running")
        status.publish()
        guard.watch(status, hang_timeout=0.08, rounds=1)
        assert not status.force_enable and status.force_off_reason == "watchdog"
        assert status.force_off_silence > 4.0 and status.force_off_time > 0
    finally:
        status.close()


def test_when_the_force_goes_off_the_guard_withholds_the_block_a_stopped_worker_left_staged():
    # issue 31: a worker stopped after its last read of the word and before its commit published its
    # block's force on SIGCONT, 10 samples after the trip (test_engine_live_faults.py, 1 run in ~4)
    status = StatusBlock.create()
    ring = Ring.create(["t", "force", "force_scale"], capacity=100)
    block = {"t": np.arange(10.0), "force": np.full(10, -1.9), "force_scale": np.ones(10)}
    try:
        status.set(state="running", heartbeat=time.monotonic())
        status.publish()
        guard.watch(status, hang_timeout=10.0, rounds=1, ring=ring)
        ring.stage(block)  # staged, then stopped before the commit
        guard.watch(status, hang_timeout=10.0, rounds=2, ring=ring)
        assert status.force_enable and np.all(ring._data[1, :10] == -1.9)  # no trip: nothing withheld
        time.sleep(0.03)
        guard.watch(status, hang_timeout=0.02, rounds=1, ring=ring)  # the trip
        ring.commit()  # SIGCONT
        data, _, _ = ring.read_since(0)
        assert not status.force_enable and np.all(data[1] == 0.0) and np.all(data[2] == 0.0)
        np.testing.assert_array_equal(data[0], np.arange(10.0))
        # the emergency stop clears the word from the parent: the guard withholds at that change too
        status.force_enable = True  # the experimenter's Resume
        status.set(heartbeat=time.monotonic() + 60.0)
        status.publish()
        watching = threading.Thread(target=guard.watch, args=(status, 10.0), kwargs={"ring": ring})
        watching.start()
        try:
            ring.stage(block)
            status.disable_force("operator")
            wait_for(lambda: np.all(ring._data[1, 10:20] == 0.0), timeout=5.0)
            ring.commit()
            # once: a block staged while the force stays off is the worker's to withhold, not the guard's
            ring.stage(block)
            time.sleep(20 * guard.POLL)
            assert np.all(ring._data[1, 20:30] == -1.9)
        finally:
            status.set(state="stopped")
            status.publish()
            watching.join(5.0)
    finally:
        ring.close()
        status.close()


def _stay_mid_record(status):
    """The writer's first increment without its second: a worker preempted, or stopped, inside ``publish``."""
    status._seq[0] += 1


def test_the_guard_lives_through_a_writer_that_stays_mid_record_and_cuts_when_its_silence_grows():
    # on main the guard raised "writer never finished a record" after 1,000 yields: at real-time priority
    # above the worker its yields never let the writer finish, so under load the guard died and the
    # worker latched a "guard" fault (the idle_console and replay time-outs in CI of 2026-11-25)
    status = StatusBlock.create()
    try:
        status.set(state="running", heartbeat=time.monotonic())
        status.publish()
        guard.watch(status, hang_timeout=10.0, rounds=1)
        _stay_mid_record(status)
        guard.watch(status, hang_timeout=10.0, rounds=3)
        assert status.force_enable  # mid-record is no silence yet
        time.sleep(0.05)
        guard.watch(status, hang_timeout=0.02, rounds=1)
        assert not status.force_enable and status.force_off_reason == "watchdog"
        assert status.force_off_silence >= 0.05
    finally:
        status.close()


def test_a_reader_gives_the_last_whole_record_while_the_writer_stays_mid_record():
    status = StatusBlock.create()
    try:
        status.set(state="running", heartbeat=12.5, samples=400, fault="none")
        status.publish(texts=True)
        assert status.read()["samples"] == 400
        _stay_mid_record(status)
        status._numbers[NUMBERS.index("samples")] = 999.0  # half of a record being written
        snap = status.read()
        assert (snap["state"], snap["heartbeat"], snap["samples"], snap["fault"]) == ("running", 12.5, 400, "none")
        status._seq[0] += 1  # the writer finishes
        assert status.read()["samples"] == 999
    finally:
        status.close()


def test_a_stopped_worker_loses_its_force_while_the_parent_holds_the_interpreter():
    engine = Engine(EngineConfig(rate=RATE, source="TRUE", fmax=2.0, hang_timeout=0.08)).start()
    try:
        wait_for(lambda: engine.status()["samples"] > 0.2 * RATE)
        stopped = time.monotonic()
        os.kill(engine.process.pid, signal.SIGSTOP)
        _hold_the_interpreter(1.5)  # no thread of this process runs meanwhile
        returned = time.monotonic()
        block = engine.status_block
        assert not block.force_enable and block.force_off_reason == "watchdog"
        assert stopped < block.force_off_time < returned  # cut by the guard while this process was held
        os.kill(engine.process.pid, signal.SIGCONT)
        wait_for(lambda: engine.tripped, timeout=5.0)
        # named by the parent's watchdog ("no heartbeat") or, if the woken worker's own report comes first, by
        # the worker ("stopped answering for 80 ms"): both say the engine stopped answering
        assert "stopped answering" in engine.faults[0], engine.faults
        assert stopped < engine.fault_time
        # the worker wakes, finds the word cleared and computes no force from its first block on
        wait_for(lambda: engine.status()["fault_latched"], timeout=5.0)
        end = engine.status()["samples"]
        wait_for(lambda: engine.status()["samples"] > end + 0.05 * RATE)
        assert np.all(engine.telemetry(int(0.05 * RATE))["force"] == 0.0)
    finally:
        engine.stop()


def test_the_worker_switches_its_force_off_when_the_guard_goes_silent():
    engine = Engine(EngineConfig(rate=RATE, source="TRUE", fmax=2.0)).start()
    try:
        wait_for(lambda: engine.status()["samples"] > 0.2 * RATE)
        os.kill(engine.guard.pid, signal.SIGSTOP)
        wait_for(lambda: engine.status()["fault_latched"], timeout=5.0)
        assert engine.status_block.force_off_reason == "guard"
        assert "force guard stopped answering" in engine.status()["fault"]
        end = engine.status()["samples"]
        wait_for(lambda: engine.status()["samples"] > end + 0.05 * RATE)
        assert np.all(engine.telemetry(int(0.05 * RATE))["force"] == 0.0)
        os.kill(engine.guard.pid, signal.SIGCONT)
    finally:
        engine.stop()


def test_a_dead_guard_is_a_fault_and_the_force_goes_off():
    engine = Engine(EngineConfig(rate=RATE, source="TRUE", fmax=2.0, realtime=False)).start()  # guard without it too
    guard_pid = engine.guard.pid
    try:
        wait_for(lambda: engine.status()["samples"] > 0.2 * RATE)
        os.kill(guard_pid, signal.SIGKILL)
        wait_for(lambda: engine.tripped, timeout=5.0)
        assert "force guard died" in engine.faults[0]
        assert engine.force_output == 0.0
        wait_for(lambda: engine.status()["fault_latched"], timeout=5.0)
    finally:
        engine.stop()
    assert engine.guard is None and engine.process is None


def test_the_guard_cuts_the_force_when_the_engines_owner_is_stopped_or_killed():
    # issue 33, item 4: on main a stopped console left the force on for 6 s (for good) in 10/10 tries, and a
    # killed one for 151-429 ms, cut by the worker when the guard had left; now the guard cuts it, reason
    # "owner" (times: studyapp bench force-cut --mode owner)
    from studyapp.engine.force_cut_benchmark import owner_try

    for mode in ("owner-stop", "owner-kill"):
        cut, reason = owner_try(mode)
        for _ in range(5):  # a loaded machine starved the worker before the stop: try again
            if cut != "void":
                break
            cut, reason = owner_try(mode)
        assert cut is not None and cut != "void" and reason == "owner", (mode, cut, reason)
        assert cut < 1.0, (mode, cut)  # generous under load; the bound measured is 100 ms


def test_the_guard_clears_the_word_for_a_stopped_or_gone_owner():
    status = StatusBlock.create()
    try:
        status.set(state="running", heartbeat=time.monotonic())
        status.publish()
        guard.watch(status, hang_timeout=10.0, owner=lambda: guard.STOPPED, rounds=1)
        assert not status.force_enable and status.force_off_reason == "owner"
    finally:
        status.close()
    assert guard.Owner(os.getpid()).state() == guard.GONE  # not our parent: the owner it watched is gone
