"""``PreviewBowing``'s timeout line (``studyapp gui --screenshot``, ``bench scope``): it says how long it waited and
for what, not a clock's reading (a loaded run printed "the engine is running after 33016.4 s")."""

from types import SimpleNamespace

import pytest
from PySide6.QtWidgets import QWidget

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui


class _Console(QWidget):
    def __init__(self, state, knobs_enabled, samples):
        super().__init__()
        host = SimpleNamespace(state=state, error=None, config=SimpleNamespace(rate=5000.0))
        self.controller = SimpleNamespace(host=host, state="idle")
        self.knobs = SimpleNamespace(isEnabled=lambda: knobs_enabled)
        self.scope = SimpleNamespace(samples=samples)


@pytest.mark.parametrize("state, knobs, samples, why", [
    ("starting", False, 0, "it never ran"),
    ("running", False, 0, "the knobs were never enabled"),
    ("running", True, 1200, "the scope holds 1200 of the 7500 samples of bowing it waits for"),
])
def test_the_timeout_says_how_long_it_waited_and_for_what(qapp, capsys, monkeypatch, state, knobs, samples, why):
    from studyapp.gui import preview_bowing
    from studyapp.gui.preview_bowing import PreviewBowing

    # never the real QApplication.exit here: with no loop running it sets Qt's "quit now", and every later
    # QDialog.exec() in this process returned at once with its question still open (a whole run's abort test)
    exits = []
    app = SimpleNamespace(exit=exits.append)
    monkeypatch.setattr(preview_bowing, "QApplication", SimpleNamespace(instance=lambda: app))

    now = [33_000.0]  # a monotonic clock reads from the machine's boot
    console = _Console(state, knobs, samples)
    bowing = PreviewBowing(console, timeout=240.0, clock=lambda: now[0])
    bowing.bowing_since = now[0]
    now[0] += 241.0
    bowing._check()
    assert capsys.readouterr().err.strip() == \
        f"studyapp gui: error: the engine is {state} 240 s after the console opened: {why}"
    assert not bowing.timer.isActive() and exits == [1]
