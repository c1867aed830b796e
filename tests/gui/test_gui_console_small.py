"""Smaller console defects of issue 41, item 12: no Quit; a practice trial headed "repetition 2"; the pacing
line still "paced by the device" after the timer took over. Offscreen Qt, no engine (nothing here needs one)."""

import pytest

from studyapp.experiment.schedule import Trial

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui


@pytest.fixture
def bare_console(qapp):
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    controller = SessionController(audio="null", midi="none")
    console = Console(controller, predict=lambda req, progress=None: {})
    console.show()
    yield console
    console.close()


def test_file_quit_closes_the_console(bare_console, qapp):
    console = bare_console
    menus = [action.text() for action in console.menuBar().actions()]
    assert "&File" in menus
    assert console.quit_action.shortcut().toString() == "Ctrl+Q"
    console.quit_action.trigger()
    qapp.processEvents()
    assert not console.isVisible()


def test_a_practice_trial_is_headed_practice_not_a_repetition(bare_console):
    progress = bare_console.progress
    practice = Trial(step=2, task="adjustment", trial=2, conditions=("LVT",), condition="LVT", practice=True)
    progress.show_trial(practice, 2, 12, "practice", 2, 2)
    assert progress.task_label.text() == "Task: adjustment, practice"
    assert progress.trial_label.text() == "Practice 2 of 2, step 3 of 12"
    real = Trial(step=4, task="adjustment", trial=2, conditions=("LVT",), condition="LVT")
    progress.show_trial(real, 4, 12, "trial", 2, 9)
    assert progress.task_label.text() == "Task: adjustment, repetition 2"


def test_the_pacing_line_follows_the_timer_taking_over_from_the_device(bare_console):
    from studyapp.engine.config import EngineConfig

    console = bare_console
    info = {"rate": 5000.0, "block": 10, "names": [], "audio": "null", "midi": "none", "paced": "device",
            "realtime": False, "device": None}
    console._on_engine("running", info, EngineConfig())
    assert "paced by the device" in console.setup.engine.text()
    assert "device-paced" in console.status.labels["engine"].text()
    console.controller.message("device: it faulted; the timer paces the loop now", "warning", "device")
    assert "paced by the timer" in console.setup.engine.text()
    assert "paced by the device" not in console.setup.engine.text()
    assert "timer-paced" in console.status.labels["engine"].text()


def test_a_relaunch_shows_the_kept_prediction_without_computing_it(qapp, monkeypatch, tmp_path):
    # issue 41, item 10: each launch searched again (7.5 min under load for sinclair2014)
    from studyapp.gui.rig_prediction import RigPrediction
    from studyapp.live import rig_check
    from tests.gui.conftest import wait_until

    monkeypatch.setenv("STUDYAPP_RIG_PREDICTIONS", str(tmp_path / "rig_predictions.json"))
    calls = []

    def model(req, progress=None):
        calls.append(req.key)
        return {"LVT": 3.09, "LOWPASS": 2.85}

    monkeypatch.setattr(rig_check, "predict", model)  # as the model's own: kept on disk
    req = rig_check.Request(("LVT", "LOWPASS"), {}, rig_check.Rig("link", 5000.0, 5), "hash")
    shown = []
    first = RigPrediction(rig_check.predict)
    first.finished.connect(lambda r, p: shown.append(p))
    first.run(req)
    wait_until(qapp, lambda: shown, 60)
    assert calls == [req.key]
    relaunched = RigPrediction(rig_check.predict)
    relaunched.finished.connect(lambda r, p: shown.append(p))
    relaunched.run(req)
    assert shown[-1] == {"LVT": 3.09, "LOWPASS": 2.85} and calls == [req.key]  # at once, not computed again
    stand_in = RigPrediction(lambda r, progress=None: {"LVT": 99.0})  # a test's stand-in is never kept
    assert stand_in.cache.path is None
