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


def test_while_it_waits_it_says_so_every_15_s_with_the_rig_checks_searches(qapp, capsys):
    # issue 41, item 10: an offscreen console with the default protocol said nothing for 240 s
    from studyapp.gui.preview_bowing import REPORT_EVERY, PreviewBowing

    now = [1000.0]
    console = _Console("starting", False, 0)
    bar = SimpleNamespace(isVisible=lambda: True, value=lambda: 7, maximum=lambda: 45)
    console.device_panel = SimpleNamespace(progress=bar)
    bowing = PreviewBowing(console, timeout=240.0, clock=lambda: now[0])
    bowing._check()
    assert capsys.readouterr().err == ""
    now[0] += REPORT_EVERY
    bowing._check()
    assert capsys.readouterr().err.strip() == ("studyapp gui: waiting 15 s (at most 240): the engine is starting; "
                                               "rig check (in the background): 7 of 45 searches")
    now[0] += 1.0
    bowing._check()
    assert capsys.readouterr().err == ""  # one line per 15 s, not one per check
    bowing.timer.stop()
