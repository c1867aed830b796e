"""The engine's commands check their inputs where they are made and where the worker obeys them (issue 41, item 17).

On main ``InstallActions`` took a knob law with a ceiling <= 0, 0 decades, NaN,
inf or 1e308; the next MIDI knob move killed the worker (ZeroDivisionError or
ValueError in ``knob_from_fmax``) or sent F_max to the clamp. ``SetHandTarget(1e308)``
was taken and latched a loop fault. Now each is refused with one line when
made, and a command that came through the pipe unchecked (unpickling never runs
its checks) is refused again by the worker with a warning, the worker alive."""

import math
import pickle

import pytest

from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.errors import ParameterError
from studyapp.model.controls import FmaxKnob, FmaxLinear, HandTarget, Select
from studyapp.model.fmax_knob import fmax_from_knob
from studyapp.model.loop import ClosedLoop, LoopConfig
from tests.engine.fake_worker import fake_worker

BAD_KNOBS = [(0.0, 2.0), (-5.0, 2.0), (40.0, 0.0), (40.0, -1.0), (math.nan, 2.0), (40.0, math.nan),
             (math.inf, 2.0), (40.0, math.inf), (1e308, 2.0), (40.0, 1e308)]


@pytest.fixture
def worker():
    w = fake_worker()
    yield w
    w.status.close()


@pytest.mark.parametrize("ceiling, decades", BAD_KNOBS)
def test_a_bad_knob_law_is_refused_where_it_is_made(ceiling, decades):
    for make in (lambda: FmaxKnob(ceiling, decades),
                 lambda: cmd.InstallActions({"knob1": ("fmax_log", ceiling, decades)})):
        with pytest.raises(ParameterError) as refused:
            make()
        assert "knob" in str(refused.value) and "allowed is" in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.parametrize("bad", [("fmax_linear", 0.0, math.nan), ("fmax_linear", 2.0, 2.0), ("fmax_linear", 0.0, 1e308),
                                 ("select", "LVT", math.inf), ("select", "LVT", -1.0), ("hand_target", 0.0, 1e308)])
def test_other_bad_actions_are_refused_where_they_are_made(bad):
    with pytest.raises(ParameterError):
        cmd.InstallActions({"knob1": bad})


def _unchecked(kind, **fields):
    """An action as unpickling makes it: its fields set, its checks never run."""
    action = object.__new__(kind)
    for name, value in fields.items():
        object.__setattr__(action, name, value)
    return action


@pytest.mark.parametrize("ceiling, decades", BAD_KNOBS)
def test_a_bad_knob_law_from_the_pipe_is_refused_by_the_worker_which_stays_alive(worker, ceiling, decades):
    good = cmd.InstallActions({"knob1": ("fmax_log", 40.0, 2.0)}, trial=2)
    worker.apply(good)
    worker.apply(cmd.SetFmax(1.0))
    install = pickle.loads(pickle.dumps(good))
    object.__setattr__(install, "actions", {"knob1": _unchecked(FmaxKnob, ceiling=ceiling, decades=decades)})
    assert worker.apply(install) is None
    notice = worker.events[-1]
    assert isinstance(notice, ev.Notice) and notice.level == "warning" and "knob" in notice.text
    step = FmaxKnob(40.0, 2.0).step(1.0)
    for value in (step, step + 1, 127):  # real MIDI knob moves: the law in force is still the good one
        worker.control("knob1", value / 127, 1.0, 7)
    assert worker.loop.fmax == pytest.approx(min(fmax_from_knob(127, 40.0, 2.0), 20.0))


def test_bad_positions_and_trial_are_refused_made_and_obeyed(worker):
    for fields in ({"positions": {"knob2": 128}}, {"positions": {"knob2": math.nan}}, {"trial": 1.5}):
        with pytest.raises(ParameterError):
            cmd.InstallActions({}, **fields)
    install = cmd.InstallActions({"knob2": Select("LVT", 1.0)}, trial=1, positions={"knob2": 5})
    object.__setattr__(install, "positions", {"knob2": 1e308})
    assert worker.apply(install) is None and worker.actions == {}


def test_a_hand_target_of_1e308_is_refused_like_nan_made_and_obeyed():
    for x in (math.nan, math.inf, 1e308, -0.2):
        with pytest.raises(ParameterError, match="hand target"):
            cmd.SetHandTarget(x)
        with pytest.raises(ParameterError, match="hand target"):
            HandTarget(0.0, x)
    loop = ClosedLoop(LoopConfig(fmax=1.0, source="LVT", gesture="hold"))
    loop.run(500)
    with pytest.raises(ParameterError, match="hand target"):
        loop.set_hand_target(1e308)  # the worker's handler: a warning (Worker.apply), the loop untouched
    loop.run(500)
    assert loop.fault is None
    loop.set_hand_target(0.005)
    assert cmd.SetHandTarget(0.005).metres == 0.005 and FmaxLinear(0.0, 10.0).fmax(0.5) == 5.0
