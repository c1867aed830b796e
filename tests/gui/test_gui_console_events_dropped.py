"""The status bar shows the engine's dropped events (issue 14, item 6): its event ring overwrote them unread.

Real overflows, and ``Engine.status()["events_dropped"]`` counting them, are made in
tests/engine/test_engine_midi_flood.py; here the console shows what the engine's status says."""

import pytest

from tests.gui.conftest import wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui


def test_the_status_bar_shows_events_the_engine_dropped(idle_console, qapp):
    console = idle_console
    label = console.status.labels["dropped"]
    wait_until(qapp, lambda: console.status.labels["rate"].text().startswith("Loop"), 5)
    status = console.controller.engine.status()
    assert status["events_dropped"] == 0 and label.text() == ""
    console.status.show_status({**status, "events_dropped": 7})
    assert label.text() == "Events dropped 7" and "#c00" in label.styleSheet()
    console.status.show_status(status)
    assert label.text() == ""
