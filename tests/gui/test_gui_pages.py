"""The participant's pages on screen (offscreen Qt): Markdown rendered, Continue, the level check's confirm.

The console runs a session on a fake engine host (tests/live/fakes.py): no
worker process, the controller polled by hand.
"""

from pathlib import Path

import pytest
from PySide6.QtGui import QFont

from studyapp.engine import commands as cmd
from studyapp.experiment.pages import markdown
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.schedule import build_schedule
from studyapp.gui.page_view import PageView
from tests.live.fakes import FakeHost, SteppingClock
from tests.live.test_session_pages import PROTOCOL

ROOT = Path(__file__).resolve().parents[2]


def fragments(document):
    """(text, bold) of every run of equal formatting in ``document``."""
    out = []
    block = document.begin()
    while block.isValid():
        it = block.begin()
        while not it.atEnd():
            fragment = it.fragment()
            out.append((fragment.text(), fragment.charFormat().fontWeight() >= QFont.Weight.Bold.value))
            it += 1
        block = block.next()
    return out


def test_a_pages_markdown_is_rendered_not_shown(qapp):
    view = PageView()
    view.show_page("welcome", "Welcome", "Thank you for **taking part**.\n\nThere are two parts.", "participant")
    document = view.text.document()
    assert "*" not in document.toPlainText()
    assert ("taking part", True) in fragments(document) and ("Thank you for ", False) in fragments(document)
    assert document.blockCount() == 2  # two paragraphs
    assert view.title.text() == "Welcome" and not view.continue_button.isHidden() and view.waiting.isHidden()


def test_a_toml_paragraph_with_hard_line_breaks_is_one_paragraph(qapp):
    protocol = load_protocol(ROOT / "protocols" / "sinclair2014.toml")
    steps, _ = build_schedule(protocol, 0)
    instructions = protocol.task("adjustment").instructions  # four hard-broken lines, one paragraph
    assert instructions.strip().count("\n") == 3
    view = PageView()
    view.show_page("instructions", "Instructions", markdown(instructions), "participant")
    document = view.text.document()
    assert document.blockCount() == 1
    assert "it does\nnot" not in document.toPlainText()
    assert "when you bow, but it does not grip yet" in " ".join(document.toPlainText().split())
    assert "handle" not in document.toPlainText()  # the participant holds no handle (issue 31 item 10)
    shipped = [t.page for t in steps if t.page and t.page.kind == "instructions"]
    view.show_page("instructions", shipped[1].title, shipped[1].text, "participant")
    assert view.text.document().blockCount() == 3  # the shipped page: three paragraphs as written


def test_the_experimenters_page_shows_no_continue(qapp):
    view = PageView()
    view.show_page("calibration", "Headphone level", "A tone.", "experimenter")
    assert view.continue_button.isHidden() and not view.waiting.isHidden()


@pytest.fixture
def paged_console(qapp, tmp_path):
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    path = tmp_path / "pages.toml"
    path.write_text(PROTOCOL)
    controller = SessionController(audio="null", midi="none", make_host=FakeHost, clock=SteppingClock())
    window = Console(controller)
    window.timer.stop()  # polled by hand
    controller.events.status.disconnect(window._on_status)  # the fake engine keeps no loop statistics
    assert window.choose_protocol(str(path))
    yield window
    window.shut_down()  # close() mid-session would ask (Console.confirm)


def up(controller):
    controller.host.state = "running"
    controller.poll()


def test_the_console_and_participant_window_walk_through_the_pages(paged_console, tmp_path):
    window, c = paged_console, paged_console.controller
    up(c)
    c.start_session("P01", tmp_path / "results")
    up(c)
    participant = window.participant_window
    assert not participant.page_view.isHidden() and participant.knobs.isHidden()
    assert participant.page_view.title.text() == "Welcome"
    assert window.page_controls.label.text() == "Page: Welcome (welcome) — the participant continues"
    assert window.page_controls.confirm_button.isHidden()
    participant.page_view.continue_button.click()
    assert c.runner.trial.page.kind == "calibration"
    assert participant.page_view.continue_button.isHidden()
    assert not window.page_controls.confirm_button.isHidden()
    assert "440 Hz at -20 dBFS" in window.page_controls.label.text()
    window.page_controls.confirm_button.click()
    assert c.host.engine.sent_of(cmd.ReferenceTone)[-1] == cmd.ReferenceTone(level_dbfs=None)
    participant.page_view.continue_button.click()  # the rating instructions
    assert c.runner.trial.practice and participant.page_view.isHidden() and not participant.knobs.isHidden()
    assert participant.progress.text() == "Practice 1 of 1" and window.page_controls.isHidden()
    assert window.trial_label.text() == "Practice 1 of 1, step 4 of 11"
    c.knob(0, 100)
    c.pad(0)
    c.poll()
    assert participant.refusal.text() == "Not rated yet: the second dial."  # issue 22 item 15: as the docs promise


def test_space_never_acknowledges_a_page_and_esc_there_is_the_participants_stop(paged_console, qtbot, tmp_path):
    from PySide6.QtCore import Qt

    window, c = paged_console, paged_console.controller
    up(c)
    c.start_session("P01", tmp_path / "results")
    up(c)
    participant = window.participant_window
    participant.show()
    qtbot.mouseClick(participant.page_view.continue_button, Qt.MouseButton.LeftButton)  # welcome, by mouse
    window.page_controls.confirm_button.click()  # the level check, the experimenter's
    step = c.runner.trial.step
    assert c.runner.trial.page is not None
    # the space bar on the participant's window (where the focus is, if anywhere): the bow, never Continue
    qtbot.keyClick(participant.focusWidget() or participant, Qt.Key.Key_Space)
    assert c.runner.trial.step == step and c.runner.trial.page is not None
    qtbot.keyClick(participant.focusWidget() or participant, Qt.Key.Key_Escape)
    assert c.emergency and c.stopped_by == "participant"
    stop = [e for e in c.session.events() if e["type"] == "emergency_stop"]
    assert stop[-1]["by"] == "participant"
    assert "(participant)" in window.state_label.text()
    participant.hide()
