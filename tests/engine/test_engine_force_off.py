"""Why the force was switched off travels with the ``force_enable`` word (issue 15, item 4): the
experimenter's emergency stop latches a fault that says "operator", never "watchdog"."""

import pytest

from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.status import StatusBlock
from tests.engine.waiting import wait_for


def test_the_reason_and_the_silence_are_shared_with_the_word():
    status = StatusBlock.create()
    other = StatusBlock.attach(status.name)
    try:
        assert other.force_enable and other.force_off_reason == "parent"
        status.disable_force("watchdog", 0.123)
        assert not other.force_enable
        assert other.force_off_reason == "watchdog" and other.force_off_silence == pytest.approx(0.123)
        status.force_enable = True  # the experimenter's clear forgets the reason
        assert other.force_enable and other.force_off_reason == "parent" and other.force_off_silence == 0.0
        status.disable_force("operator")
        assert not other.force_enable and other.force_off_reason == "operator"
    finally:
        other.close()
        status.close()


def test_an_operators_stop_latches_a_fault_that_says_operator():
    engine = Engine(EngineConfig(rate=5000.0, source="LVT", fmax=1.0)).start()
    try:
        engine.status_block.disable_force("operator")
        wait_for(lambda: engine.status()["fault_latched"], timeout=5.0)
        assert engine.status()["fault"] == "Emergency stop (operator): force off — press Resume to clear"
        assert engine.faults == [] or "watchdog" not in engine.faults[0]
        engine.status_block.force_enable = True
        engine.clear_fault()
        wait_for(lambda: not engine.status()["fault_latched"], timeout=5.0)
        assert not engine.tripped
    finally:
        engine.stop()
