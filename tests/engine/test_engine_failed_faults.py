"""An engine that fails names what stopped it, not an emergency stop cleared before (issue 41, item 12).

On main the session's ``engine_failed`` record listed every fault the engine
had reported in its life (``Engine.faults``), old emergency stops the
experimenter had cleared included. It lists ``faults_since_clear`` now. A real
engine, a real emergency stop, a real kill of its worker."""

import os
import signal
import time

from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine


def _wait(condition, timeout=30.0):
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.02)
    return condition()


def test_the_faults_of_a_failed_engine_leave_out_a_stop_cleared_before():
    with Engine(EngineConfig(audio="null", midi="none", realtime=False)) as engine:
        engine.status_block.disable_force("operator")  # the experimenter's emergency stop
        assert _wait(lambda: engine.faults), "the stop was never reported"
        stop = list(engine.faults)
        assert engine.faults_since_clear() == stop
        engine.status_block.force_enable = True
        engine.clear_fault()
        assert engine.faults_since_clear() == []
        os.kill(engine.process.pid, signal.SIGKILL)  # the worker dies
        assert _wait(lambda: len(engine.faults) > len(stop)), "the worker's death was never reported"
        failed = engine.faults_since_clear()
        assert failed and not set(stop) & set(failed)
        assert engine.faults == stop + failed
