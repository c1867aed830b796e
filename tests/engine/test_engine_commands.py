"""Typed commands: one handler per command type; controls take one route; a failed engine exits 1."""

import dataclasses

import pytest

from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.engine.worker import Worker
from studyapp.errors import EngineError, UserError
from studyapp.model.fmax_knob import fmax_from_knob
from tests.engine.fake_worker import fake_worker
from tests.like import Like


def test_every_command_type_has_exactly_one_handler():
    types = set(cmd.Command.__subclasses__())
    assert types == set(Worker.HANDLERS)
    for kind in types:
        assert dataclasses.is_dataclass(kind) and kind.__dataclass_params__.frozen
    made = cmd.SetFmax(2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        made.newtons = 3.0
    assert made.sent > 0


@pytest.mark.parametrize("make, value, words", [
    (cmd.SetFmax, float("nan"), "F_max = nan"), (cmd.SetFmax, -0.5, "F_max = -0.5"),
    (cmd.SetFmax, float("inf"), "F_max = inf"), (cmd.SetFmax, "2", "F_max = '2'"),
    (cmd.SetVolume, 4.5, "volume = 4.5"), (cmd.SetVolume, -0.1, "volume = -0.1"),
    (cmd.SetVolume, float("nan"), "volume = nan"), (cmd.SetVolume, None, "volume = None"),
])
def test_f_max_and_volume_are_checked_where_they_are_made(make, value, words):
    """A command made here with a value the worker would refuse is refused at once, naming the value and what is
    allowed (issue 41 item 17's rule, now for SetFmax and SetVolume too); the worker still checks what a pipe
    brings (unpickling makes no check), and a value above the ceiling is the worker's to clamp."""
    with pytest.raises(UserError) as err:
        make(value)
    assert str(err.value).startswith(words) and "allowed is" in str(err.value)
    assert cmd.SetFmax(1e3).newtons == 1e3 and cmd.SetVolume(0).gain == 0


@pytest.fixture
def worker():
    w = fake_worker()
    yield w
    w.status.close()


def test_a_control_takes_the_installed_mapping_and_reports_its_trial(worker):
    worker.apply(cmd.Control("knob1", 30 / 127, sent=1.0))  # no mapping yet: nothing happens
    assert worker.loop.fmax == 0.0 and worker.events[-1].latency is None
    worker.apply(cmd.InstallActions({"knob1": ("fmax_log", 40.0, 2.0), "knob2": ("select", "KALLEV", 1.0)},
                                    trial=3))
    worker.apply(cmd.Control("knob1", 30 / 127, sent=1.0))
    assert worker.loop.fmax == pytest.approx(fmax_from_knob(30, 40.0, 2.0))
    applied = worker.events[-1]
    assert isinstance(applied, ev.Applied) and (applied.control, applied.trial, applied.block) == ("knob1", 3, 7)
    assert applied.latency > 0 and applied.origin == "screen"
    assert applied.commands == (Like(cmd.SetFmax, newtons=pytest.approx(fmax_from_knob(30, 40.0, 2.0)), sent=1.0),)
    worker.apply(cmd.Control("knob2", 0.0, sent=1.0))
    assert (worker.loop.source, worker.loop.fmax) == ("KALLEV", 1.0)
    worker.apply(cmd.Control("knob1", 30 / 127, sent=1.0))
    worker.apply(cmd.InstallActions({}, trial=3))  # a pause: the knob is reported but acts on nothing
    worker.apply(cmd.Control("knob1", 1.0, sent=1.0))
    assert worker.loop.fmax == pytest.approx(fmax_from_knob(30, 40.0, 2.0))


def test_a_refused_command_is_a_warning_not_a_crash(worker):
    assert worker.apply(cmd.SetSource("NOPE")) is None
    notice = worker.events[-1]
    assert isinstance(notice, ev.Notice) and notice.level == "warning" and "NOPE" in notice.text
    assert worker.apply(cmd.SetFmax(50.0)) >= 0 and worker.loop.fmax == 20.0  # the safety ceiling


def test_an_engine_failure_is_not_bad_input_and_exits_1_in_one_line(monkeypatch, capsys):
    from studyapp.cli import main
    from studyapp.engine.engine import Engine

    assert not issubclass(EngineError, UserError)

    def fail(self, timeout=None):
        raise EngineError("engine: the worker exited while starting (exit code 1)")

    monkeypatch.setattr(Engine, "start", fail)
    code = main(["live", "--audio", "null", "--midi", "none", "--seconds", "1"])
    err = capsys.readouterr().err
    assert code == 1
    assert err.strip().splitlines() == ["studyapp: error: engine: the worker exited while starting (exit code 1)"]
