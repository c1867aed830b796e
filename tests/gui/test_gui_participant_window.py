"""The participant's window gives nothing away (offscreen Qt): bare dials for the trial's knobs only,
a "Done" pad, the bow on the space bar, refusals without condition names, and the screen it fills."""

import re

import pytest
from PySide6.QtCore import QSettings, QStandardPaths, Qt

from studyapp.estimators import names as estimator_names
from tests.gui.participant_states import STATES, FakeController, put_in_state, visible_texts

pytestmark = pytest.mark.gui

KNOB_LABEL = re.compile(r"\b[KP]\d+\b|knob \d|:\s*\d+$")  # "K1: 75", "P1", "knob 1 (MIDI ...)"


@pytest.fixture(autouse=True)
def active_window_kept(qapp, qtbot):
    """The window active before a test is active again after it (the console's tests press keys in it)."""
    from PySide6.QtWidgets import QApplication

    before = QApplication.activeWindow()
    yield
    if before is not None and before.isVisible() and QApplication.activeWindow() is not before:
        before.activateWindow()
        qtbot.waitUntil(lambda: QApplication.activeWindow() is before, timeout=2000)


@pytest.fixture
def window(qapp):
    from studyapp.gui.participant_window import ParticipantWindow

    controller = FakeController()
    w = ParticipantWindow(controller)
    w.resize(1366, 768)
    w.show()
    yield w
    w.close()


@pytest.fixture
def settings_in(tmp_path):
    """QSettings of this process written under ``tmp_path``, never the user's own."""
    QSettings.setPath(QSettings.Format.NativeFormat, QSettings.Scope.UserScope, str(tmp_path))
    yield tmp_path
    default = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.GenericConfigLocation)
    QSettings.setPath(QSettings.Format.NativeFormat, QSettings.Scope.UserScope, default)


def test_the_console_panel_keeps_its_numbers_the_participant_panel_shows_none(qapp):
    from PySide6.QtWidgets import QLabel

    from studyapp.gui.knobs import KnobPanel

    console, participant = KnobPanel(), KnobPanel(participant=True)
    for panel in (console, participant):
        panel.show_knob(0, 75)
        panel.set_captions(["LVT"])
        assert panel.dials[0].value() == 75
    assert console.values[0].text() == "K1: 75" and console.captions[0].text() == "LVT"
    assert console.pads[0].text() == "P1"
    assert participant.findChildren(QLabel) == []
    assert not any(d.notchesVisible() or d.toolTip() for d in participant.dials)
    assert not any(p.text() or p.toolTip() for p in participant.pads)


@pytest.mark.parametrize("state, knobs", [
    ("idle", []), ("rating3", [0, 1, 2]), ("rating8", list(range(8))), ("adjustment", [0]),
    ("paused", list(range(8))), ("finished", []),
])
def test_only_the_trials_knobs_and_its_confirm_pad_are_shown(window, state, knobs):
    put_in_state(window, window.controller, state)
    assert window.knobs.visible_knobs() == knobs
    pads = [p.text() for p in window.knobs.pads if p.isVisibleTo(window)]
    assert pads == (["Done"] if knobs else [])
    assert window.bow_button.isVisibleTo(window) == bool(knobs)


def test_an_adjustment_trial_shows_the_tasks_own_knob(window):
    c = window.controller
    c.start("sinclair2014.toml", "adjustment", knob=2, confirm_pad=5)
    assert window.knobs.visible_knobs() == [2]
    pressed = []
    window.knobs.pad_pressed.connect(pressed.append)
    (done,) = [p for p in window.knobs.pads if p.isVisibleTo(window)]
    done.click()
    assert done.text() == "Done" and pressed == [5]


@pytest.mark.parametrize("state", STATES)
def test_no_knob_value_condition_or_estimator_is_ever_shown(window, state):
    put_in_state(window, window.controller, state)  # every knob at 75
    window.show_refusal("not rated yet: " + ", ".join(estimator_names()))
    texts = visible_texts(window)
    assert texts
    for text in texts:
        assert not KNOB_LABEL.search(text), text
        assert "75" not in text and "F_max" not in text
        assert not any(re.search(rf"\b{name}\b", text) for name in estimator_names()), text


def test_the_space_bar_and_the_bow_button_put_the_bow_on_and_lift_it(window, qtbot):
    c = window.controller
    now = [100.0]
    window.clock = lambda: now[0]  # a person's presses, half a second apart
    put_in_state(window, c, "rating3")
    assert window.bow_state.text() == "Bow lifted" and not window.bow_button.isChecked()
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert c.bowing_asked == [True]
    assert window.bow_state.text() == "Bowing" and window.bow_button.isChecked()
    now[0] += 0.5
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert c.bowing_asked == [True, False] and window.bow_state.text() == "Bow lifted"
    qtbot.mouseClick(window.bow_button, Qt.MouseButton.LeftButton)
    assert c.bowing_asked == [True, False, True] and window.bow_state.text() == "Bowing"
    c.events.bowing.emit(on=False)  # lifted elsewhere (the console, a pause): the window follows
    assert window.bow_state.text() == "Bow lifted" and not window.bow_button.isChecked()
    window.show_state("paused")
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert c.bowing_asked == [True, False, True] and not window.bow_button.isChecked()


def test_a_second_space_press_25_ms_after_the_first_is_a_bounce_not_a_lift(window, qtbot):
    """Issue 22 item 15: a space press as a trial appears logged the bow on, then off 25 ms later."""
    c = window.controller
    now = [100.0]
    window.clock = lambda: now[0]
    put_in_state(window, c, "rating3")
    qtbot.keyClick(window, Qt.Key.Key_Space)
    now[0] += 0.025
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert c.bowing_asked == [True] and window.bow_state.text() == "Bowing"
    now[0] += 0.3
    qtbot.keyClick(window, Qt.Key.Key_Space)  # a deliberate lift
    assert c.bowing_asked == [True, False]


def test_unset_dials_are_drawn_as_empty_rings_until_turned(window):
    """Issue 22 item 15: an unrated dial rests at the bottom, which reads as "noisiest"."""
    c = window.controller
    c.start("sinclair2014.toml", "rating")
    shown = window.knobs.visible_knobs()
    assert len(shown) == 8 and all(window.knobs.dials[k].unset for k in shown)
    window.knobs.show_knob(shown[2], 40)  # the participant turned the third dial (MIDI or on screen)
    assert [window.knobs.dials[k].unset for k in shown] == [True, True, False, True, True, True, True, True]
    unset = window.knobs.dials[shown[0]].grab().toImage()
    rated = window.knobs.dials[shown[2]].grab().toImage()
    assert unset != rated
    c.start("sinclair2014.toml", "adjustment")  # its knob has a position (F_max 0): drawn as a dial
    assert not any(window.knobs.dials[k].unset for k in window.knobs.visible_knobs())


def test_a_refusal_naming_a_knob_names_the_dial(window):
    """Issue 22 item 15: the refusal said "knob 6" where the docs promise "the sixth dial"."""
    c = window.controller
    c.start("sinclair2014.toml", "rating")
    c.events.refused.emit(reason="listen longer with the bow on: knob 6 needs 0.8 s more")
    assert window.refusal.text() == "Listen longer with the bow on: the sixth dial needs 0.8 s more."
    c.events.refused.emit(reason="not rated yet: knob 2, knob 7")
    assert window.refusal.text() == "Not rated yet: the second dial, the seventh dial."


def test_the_bowing_surface_shows_for_the_participants_bow_only(window):
    c = window.controller
    c.start("sinclair2014.toml", "rating")  # bow = "participant" (the default)
    assert window.surface.isVisibleTo(window)
    c.start("sinclair2014.toml", "adjustment", bow="auto")
    assert not window.surface.isVisibleTo(window)
    window.show_state("finished")
    assert not window.surface.isVisibleTo(window)


def test_a_refused_confirm_is_said_in_plain_words(window):
    c = window.controller
    shown = c.start("demo.toml", "rating")
    conditions = c.runner.task.conditions  # dial j plays conditions[j], left to right
    c.events.refused.emit(reason=f"not rated yet: {conditions[2]}, {conditions[0]}")
    assert window.refusal.text() == "Not rated yet: the third dial, the first dial."
    assert window.refusal.isVisibleTo(window)
    window.show_trial(**shown)  # the next trial starts clean
    assert window.refusal.text() == "" and not window.refusal.isVisibleTo(window)
    c.start("sinclair2014.toml", "adjustment")
    window.show_refusal("F_max is 0: turn the knob up first")
    assert window.refusal.text() == "Nothing is playing yet: turn the knob up first."


def test_the_console_gives_its_participant_window_the_controller(idle_console):
    w = idle_console.participant_window
    assert w.controller is idle_console.controller
    idle_console.set_bowing(True)
    assert w.bow_state.text() == "Bowing"
    idle_console.set_bowing(False)
    assert w.bow_state.text() == "Bow lifted"


def test_a_screen_that_does_not_exist_is_refused_naming_the_screens(qapp, settings_in):
    from PySide6.QtGui import QGuiApplication

    from studyapp.errors import UserError
    from studyapp.gui.participant_screen import choose_screen

    count = len(QGuiApplication.screens())
    with pytest.raises(UserError) as refused:
        choose_screen(count)
    text = str(refused.value)
    assert text.startswith(f"--participant-screen {count}: allowed is 0 to {count - 1}")
    assert "0 = " in text and "\n" not in text
    assert choose_screen(None) is None  # nothing remembered, and the refusal remembered nothing


def test_the_chosen_screen_is_remembered_and_filled(qapp, settings_in):
    from PySide6.QtGui import QGuiApplication

    from studyapp.gui.participant_screen import SETTINGS_KEY, choose_screen
    from studyapp.gui.participant_window import ParticipantWindow

    screen = QGuiApplication.screens()[0]
    assert choose_screen(0) is screen
    assert (settings_in / "studyapp" / "studyapp.conf").is_file()
    assert QSettings("studyapp", "studyapp").value(SETTINGS_KEY) in (0, "0")
    assert choose_screen(None) is screen  # the next launch's --participant-window
    w = ParticipantWindow()
    w.show_full_screen(screen)
    w.show()
    qapp.processEvents()
    assert w.isFullScreen() and w.geometry() == screen.geometry()
    w.close()


@pytest.mark.parametrize("argv, words", [
    (["gui", "--participant-screen", "9"], "--participant-screen 9: allowed is 0 to 0 (the screens here: 0 = "),
    (["gui", "--participant-screenshot", "p.jpg"], "--participant-screenshot p.jpg: allowed is a file name ending in .png"),
])
def test_bad_participant_options_are_one_line(qapp, settings_in, argv, words, capsys):
    from studyapp.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"studyapp: error: {words}") and "\n" not in err


def test_participant_screenshot_waits_for_the_first_trial_then_saves(qapp, tmp_path, capsys, monkeypatch):
    from types import SimpleNamespace

    from PySide6.QtWidgets import QWidget

    from studyapp.gui import participant_screenshot
    from studyapp.gui.participant_screenshot import ParticipantScreenshot
    from studyapp.gui.participant_window import ParticipantWindow

    # no event loop runs here: a real exit() would make every later dialog's exec() return at once
    exits = []
    monkeypatch.setattr(participant_screenshot, "QApplication",
                        SimpleNamespace(instance=lambda: SimpleNamespace(exit=exits.append)))

    now = [0.0]
    controller = SimpleNamespace(host=SimpleNamespace(state="starting", error=None), state="starting",
                                 runner=None)
    console = QWidget()
    console.controller = controller
    console.participant_window = ParticipantWindow()
    path = tmp_path / "p.png"
    shot = ParticipantScreenshot(console, str(path), wait_for_trial=True, timeout=30, clock=lambda: now[0])
    shot._check()
    assert not path.exists() and shot.timer.isActive()  # the session's engine is still starting
    controller.host.state, controller.state = "running", "running"
    controller.runner = SimpleNamespace(trial=object())
    shot._check()
    assert path.is_file() and not shot.timer.isActive()
    assert capsys.readouterr().out.strip() == str(path)

    late = ParticipantScreenshot(console, str(tmp_path / "late.png"), wait_for_trial=True, timeout=30,
                                 clock=lambda: now[0])
    controller.state = "starting"
    now[0] = 31.0
    late._check()
    err = capsys.readouterr().err.strip()
    assert err == "studyapp gui: error: nothing to show after 30 s (engine running, session starting)"
    assert not (tmp_path / "late.png").exists()
    assert exits == [0, 1]
