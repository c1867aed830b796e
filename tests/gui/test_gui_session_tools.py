"""Issue 22 item 16 in the console: the run sheet before Start, notes, and the master volume and mute."""

import pytest

from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.run_plan import make_plan, plan_markdown
from studyapp.experiment.session import Session
from studyapp.experiment.session_log import read_events
from tests.gui.conftest import DEMO, ENGINE_START, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui


@pytest.fixture
def tools(idle_console, tmp_path):
    console = idle_console
    setup = console.setup
    saved = (setup.participant.text(), setup.results.text(), console.blind.isChecked())
    setup.participant.setText("PLAN1")
    setup.results.setText(str(tmp_path / "results"))
    yield console.tools
    setup.participant.setText(saved[0])
    setup.results.setText(saved[1])
    console.blind.setChecked(saved[2])


def test_the_run_sheet_shows_before_start_as_plan_prints_it(tools, idle_console, tmp_path):
    dialog = tools.show_run_sheet()
    expected = plan_markdown(make_plan(load_protocol(DEMO), "PLAN1", tmp_path / "results"))
    assert dialog is not None and dialog.markdown == expected and dialog.isVisible()
    assert "Run sheet: demo, participant PLAN1" in dialog.view.toPlainText()
    dialog.save(tmp_path / "sheet.md")
    assert (tmp_path / "sheet.md").read_text() == expected
    dialog.close()
    idle_console.blind.setChecked(True)  # the console hides the condition: so does the sheet
    dialog = tools.show_run_sheet()
    assert "Condition names hidden (blinding)." in dialog.markdown and "LVT" not in dialog.markdown
    dialog.close()
    idle_console.setup.participant.setText("not a pseudonym!")
    assert tools.show_run_sheet() is None and "Run sheet: participant ID" in tools.message.text()


def test_notes_and_sound_reach_the_controller(tools, idle_console, tmp_path):
    c = idle_console.controller
    saved = c.last_session
    session = Session.create(load_protocol(DEMO), "NOTE1", tmp_path / "results")
    session.close()
    try:
        c.last_session = session.folder
        tools.note.setText("the lab's door slammed")
        assert tools.add_note() is not None and tools.note.text() == ""
        assert read_events(session.folder / "events.jsonl")[-1]["text"] == "the lab's door slammed"
        tools.note.setText("   ")
        assert tools.add_note() is None and "Note not logged" in tools.message.text()
    finally:
        c.last_session = saved
    tools.volume.setValue(0)  # an earlier test's knob 2 may have left the slider at -12 (adopted, not sent)
    tools.volume.setValue(-12)
    tools.mute.setChecked(True)
    assert c.sound.db == -12.0 and c.sound.muted and tools.volume_label.text() == "-12 dB"
    tools.mute.setChecked(False)
    tools.volume.setValue(0)
    assert c.sound.db == 0.0 and not c.sound.muted


def test_the_preview_volume_knob_moves_the_consoles_slider_without_a_second_record(tools, idle_console, qapp):
    c = idle_console.controller
    wait_until(qapp, lambda: c.engine is not None and c.at_rest, ENGINE_START)
    try:
        tools.volume.setValue(-5)
        assert c.sound.db == -5.0
        c.knob(1, 64)  # knob 2 in the preview: the worker applies the volume and reports it
        db = -40.0 + 40.0 * 64 / 127
        wait_until(qapp, lambda: c.sound.db == pytest.approx(db), 10)
        assert tools.volume.value() == -20 and tools.volume_label.text() == "-20 dB"
    finally:
        tools.volume.setValue(0)
    assert c.sound.db == 0.0
