"""The watchdog's heartbeat bound follows the machine's load (issue 31 item 7): more margin when busy."""

import pytest

from studyapp.engine import config, load_margin
from studyapp.engine.load_margin import MAX_BOUND, busy_warning, hang_timeout_for


@pytest.mark.parametrize("load, bound", [(0.0, 0.08), (1.0, 0.08), (1.5, 0.12), (3.0, 0.24), (6.0, MAX_BOUND)])
def test_the_bound_grows_with_the_load_per_core_up_to_its_ceiling(load, bound):
    assert hang_timeout_for(load, 0.08) == pytest.approx(bound)


def test_an_engine_started_on_a_busy_machine_gets_the_margin_and_an_explicit_bound_is_kept(monkeypatch):
    monkeypatch.setattr(config, "load_per_core", lambda: 2.0)
    assert config.EngineConfig(rate=5000.0, source="LVT").hang_timeout == pytest.approx(0.16)
    assert config.EngineConfig(rate=5000.0, source="LVT", hang_timeout=0.08).hang_timeout == 0.08
    monkeypatch.setattr(config, "load_per_core", lambda: 0.3)
    assert config.EngineConfig(rate=5000.0, source="LVT").hang_timeout == config.HANG_TIMEOUT


def test_a_busy_machine_is_warned_about_before_a_session(monkeypatch):
    monkeypatch.setattr(load_margin.os, "cpu_count", lambda: 2)
    assert busy_warning(0.8, 0.08) is None
    warning = busy_warning(4.0, 0.08)
    assert "load 8.0 on 2 cores" in warning and "250 ms" in warning and "instead of 80 ms" in warning
