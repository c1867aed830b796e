"""The participant's window on a real X server (Xvfb, Qt's xcb platform) at a lab laptop's and a
desktop's size, in every state a session shows it, each page too: nothing past the window, no clipped
text (a page's whole text shown without scrolling), no knob value and no condition or estimator name; and ``--participant-screenshot`` with
``--participant-screen 0`` (the console's own screen) fills the screen beside the console's left column
and remembers it."""

import json
import os
import re
import subprocess
import sys

import pytest

from studyapp.estimators import names as estimator_names
from tests.gui.conftest import DEMO, ROOT
from tests.gui.participant_states import PAGE_KINDS, STATES

pytestmark = pytest.mark.gui

SIZES = ((1366, 768), (1920, 1080))
DIALS = {"idle": 0, "rating3": 3, "rating8": 8, "adjustment": 1, "paused": 8, "finished": 0,
         **{f"page-{kind}": 0 for kind in PAGE_KINDS}}
KNOB_LABEL = re.compile(r"\b[KP]\d+\b|knob \d|:\s*\d+$")


def _xcb(display, tmp_path):
    return {**os.environ, "QT_QPA_PLATFORM": "xcb", "DISPLAY": display, "XDG_CONFIG_HOME": str(tmp_path / "config")}


def test_every_state_fits_and_gives_nothing_away(xvfb_display, tmp_path):
    done = subprocess.run([sys.executable, "-m", "tests.gui.participant_states", *(f"{w}x{h}" for w, h in SIZES)],
                          cwd=ROOT, env=_xcb(xvfb_display, tmp_path), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    shots = [json.loads(line) for line in done.stdout.splitlines()]
    assert [(tuple(s["size"]), s["state"]) for s in shots] == [(size, state) for size in SIZES for state in STATES]
    for shot in shots:
        where = f"{shot['state']} at {shot['size']}"
        assert shot["image_size"] == shot["size"], where
        assert shot["problems"] == [], where
        assert shot["dials"] == DIALS[shot["state"]], where
        # a page shows its whole text, without scrolling
        assert bool(shot["page"]) == shot["state"].startswith("page-") and not shot["page_scrolls"], where
        for text in shot["texts"]:
            assert not KNOB_LABEL.search(text) and "75" not in text, (where, text)
            assert not any(re.search(rf"\b{name}\b", text) for name in estimator_names()), (where, text)
            assert "F_max" not in text, (where, text)


def test_participant_screenshot_fills_the_chosen_screen(xvfb_display, tmp_path):
    from matplotlib.image import imread

    path = tmp_path / "participant.png"
    env = _xcb(xvfb_display, tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "studyapp", "gui", "--protocol", str(DEMO), "--participant-screen", "0",
         "--participant-screenshot", str(path), "--audio", "null", "--midi", "none",
         "--results", str(tmp_path / "results")],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == str(path)
    # One screen (Xvfb's only one is the console's): the participant's window is not full-screen but fills
    # the screen's whole height right of the console's left column (participant_placement.beside_console,
    # issue 31), so the console's session buttons stay in view.
    height, width = imread(path).shape[:2]
    assert height == 1080 and 1920 // 2 < width < 1920, (height, width)
    settings = (tmp_path / "config" / "studyapp" / "studyapp.conf").read_text()
    assert re.search(r"^screen=0$", settings, re.MULTILINE) and "[participant]" in settings
    assert not (tmp_path / "results").exists()
