"""The console on a lab laptop's 1,366 x 768 screen during a session (issue 41, item 11).

Before: the Apparatus panel's "link PATH: waiting for the handshake…" ran past the panel, cut mid-line (a path
has no space to wrap at), and the rig check's table pushed the Progress box (state, trial x of y) below the
fold of the left column's scroll area once a session ran. Now a path wraps, and Progress is in view without
scrolling, whatever the set-up above it holds. Offscreen Qt; the picture ``studyapp gui --size 1366x768
--screenshot`` writes is checked in test_gui_screenshot.py.
"""

import pytest
from PySide6.QtCore import QPoint, QRect, Qt

from studyapp.live import rig_check
from tests.gui.conftest import ENGINE_START, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

NINE = {"LVT": 3.09, "LOWPASS": 2.85, "LEASTSQ": 2.58, "FOAW": 2.58, "LEVANT": 2.85, "LEVANTLP": 2.89,
        "KALPOS": 2.94, "KALLEV": 2.46, "KALFOAW": 2.34}  # sinclair2014's nine conditions: the tallest table


def wrapped_width(label):
    """The width ``label``'s text needs when wrapped at word boundaries (as a QLabel wraps) within its own
    width, and that width: more than it has is a line cut mid-line."""
    from PySide6.QtGui import QTextLayout, QTextOption

    room = label.contentsRect().width()
    layout = QTextLayout(label.text(), label.font())
    option = QTextOption()
    option.setWrapMode(QTextOption.WrapMode.WordWrap)
    layout.setTextOption(option)
    layout.beginLayout()
    need = 0.0
    while (line := layout.createLine()).isValid():
        line.setLineWidth(room)
        need = max(need, line.naturalTextWidth())
    layout.endLayout()
    return need, room


def in_view(widget, window):
    rect = QRect(widget.mapTo(window, QPoint(0, 0)), widget.size())
    return widget.isVisibleTo(window) and window.rect().contains(rect) and not widget.visibleRegion().isEmpty()


def test_a_long_link_path_wraps_in_the_apparatus_panel(idle_console, qapp):
    console = idle_console
    console.set_size(1366, 768)
    panel = console.device_panel
    panel.show_device("/tmp/pytest-of-root/pytest-146/test_a_device_fault_stops_the_0/studyapp-emulator-device",
                      "starting")
    qapp.processEvents()
    need, room = wrapped_width(panel.summary)
    assert need <= room, (need, room, panel.summary.text())
    assert "waiting for the handshake" in panel.summary.text()
    panel.show_device(None, "running")  # the shared console's own device again


def test_progress_stays_in_view_at_1366x768_with_the_rig_checks_table(idle_console, qapp, tmp_path):
    console = idle_console
    c = console.controller
    console.set_size(1366, 768)
    qapp.processEvents()
    assert (console.width(), console.height()) == (1366, 768)
    try:
        console.setup.participant.setText("FIT01")
        console.setup.results.setText(str(tmp_path / "results"))
        assert console.start_session(seed=2) is not None, console.setup.error.text()
        wait_until(qapp, lambda: c.playing and c.runner.trial is not None, ENGINE_START)
        console.device_panel.show_verdict(rig_check.verdict(NINE, rig_check.Rig("link", 5000.0, 5)))
        for _ in range(5):
            qapp.processEvents()
        assert console.device_panel.table.rowCount() == 9
        assert in_view(console.progress, console), console.progress.geometry()
        assert in_view(console.trial_label, console) and "of" in console.trial_label.text()
        assert in_view(console.state_label, console) and console.state_label.text() == "Running"
        for button in (console.pause_button, console.abort_button, console.stop_button):
            assert in_view(button, console)
    finally:
        console.abort_session()
        console.set_size(1400, 900)
