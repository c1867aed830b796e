"""The set-up panel's session information: stored in session.json when the session starts; a bad value
shows one line in the panel and enrols nobody; the command line fills the fields."""

import argparse
import json

import pytest
from PySide6.QtCore import Qt

from studyapp.errors import UserError
from tests.gui.conftest import DEMO, ENGINE_START, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui


def test_the_panels_fields_reach_session_json_and_a_bad_one_is_refused(idle_console, qapp, qtbot, tmp_path):
    console = idle_console
    c = console.controller
    setup = console.setup
    setup.participant.setText("INFO1")
    setup.results.setText(str(tmp_path))
    setup.experimenter.setText("x;y")
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    assert "experimenter 'x;y': allowed is a short name" in setup.error.text() and not c.in_session
    assert list(tmp_path.iterdir()) == []
    setup.experimenter.setText("Ana")
    setup.session_number.setValue(2)
    setup.notes.setText("new headphones")
    setup.order_row.setValue(5)
    assert setup.order_row.text() == "5"
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    assert c.state == "starting", setup.error.text()
    (path,) = tmp_path.glob("demo/INFO1/*/session.json")
    info = json.loads(path.read_text())
    assert {k: info[k] for k in ("experimenter", "session_number", "notes", "order_row", "order_row_source")} == {
        "experimenter": "Ana", "session_number": 2, "notes": "new headphones", "order_row": 5,
        "order_row_source": "set"}
    wait_until(qapp, lambda: c.state == "running", ENGINE_START)
    console.abort_session()
    setup.order_row.setValue(-1)
    assert setup.order_row.text() == "auto" and setup.session_info["order_row"] is None


def test_the_command_line_fills_the_fields_and_a_bad_order_row_stops_before_any_engine(qapp):
    from studyapp.gui.app import build

    args = argparse.Namespace(protocol=str(DEMO), order_row="9", experimenter=None, session_number=None, notes=None)
    with pytest.raises(UserError, match="order row '9': allowed is 0 to 5"):
        build(args)
    args.order_row, args.experimenter, args.session_number, args.notes = "3", "Bo", "7", "n"
    controller, console = build(args)
    try:
        assert console.setup.session_info == {"experimenter": "Bo", "session_number": 7, "notes": "n", "order_row": 3}
    finally:
        console.close()
        controller.close()
