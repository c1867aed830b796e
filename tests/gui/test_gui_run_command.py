"""``studyapp run`` in a lab (issue 22, items 8 and 9), on a real X server at a laptop's 1,366 x 768:
the console opens within the screen with every session button in view (it opened at a hard-coded
1,500 x 940), ``--audio``, ``--midi`` and ``--participant-screen`` are taken as ``studyapp gui`` takes
them, and after a crash (the process killed mid-session) ``run --resume`` reopens the participant's
window full-screen on its remembered screen (it left it closed: a black screen)."""

import json
import os
import shutil
import signal
import subprocess
import sys

import pytest

from tests.gui.conftest import DEMO, ROOT, line_within

pytestmark = pytest.mark.gui

SCREEN = (1366, 768)
TIMEOUT = 300


@pytest.fixture(scope="module")
def laptop_display():
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip("Xvfb not installed (Debian xvfb, listed in scripts/system-deps.txt)")
    read, write = os.pipe()
    proc = subprocess.Popen([xvfb, "-displayfd", str(write), "-screen", "0", f"{SCREEN[0]}x{SCREEN[1]}x24",
                             "-nolisten", "tcp"], pass_fds=(write,), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    os.close(write)
    try:
        with os.fdopen(read) as f:
            number = f.readline().strip()
        if not number.isdigit():
            pytest.fail(f"Xvfb did not report a display (exit code {proc.poll()})")
        yield f":{number}"
    finally:
        proc.terminate()
        proc.wait(10)


def probe(display, tmp_path, then, *args):
    env = {**os.environ, "QT_QPA_PLATFORM": "xcb", "DISPLAY": display, "XDG_CONFIG_HOME": str(tmp_path / "config")}
    command = [sys.executable, "-m", "tests.gui.run_probe", then, "--protocol", str(DEMO), "--participant", "P01",
               "--results", str(tmp_path / "results"), *args]
    return subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def first_report(proc):
    line = line_within(proc, TIMEOUT)
    assert line, proc.stderr.read()[-3000:]
    return json.loads(line)


def inside(rect, area):
    x, y, w, h = rect
    ax, ay, aw, ah = area
    return w > 0 and h > 0 and x >= ax and y >= ay and x + w <= ax + aw and y + h <= ay + ah


def test_run_opens_the_console_within_a_1366x768_screen_with_audio_and_midi_options(laptop_display, tmp_path):
    proc = probe(laptop_display, tmp_path, "exit", "--audio", "null", "--midi", "none")
    try:
        shown = first_report(proc)
        assert proc.wait(TIMEOUT) == 0, proc.stderr.read()[-3000:]
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert shown["screen"] == list(SCREEN)
    assert (shown["audio"], shown["midi"]) == ("null", "none")
    assert inside(shown["console"], shown["available"]), shown
    for name, rect in {**shown["buttons"], "blind": shown["blind"]}.items():
        assert inside(rect, shown["available"]), (name, rect, shown["available"])
    assert shown["participant"]["visible"]  # a participant takes part: their window opens with the session


def test_run_resume_after_a_crash_reopens_the_participant_screen_full_screen(laptop_display, tmp_path):
    first = probe(laptop_display, tmp_path, "wait", "--audio", "null", "--midi", "none", "--participant-screen", "0")
    try:
        before = first_report(first)
        assert before["participant"]["screen"] == 0
    finally:
        os.killpg(first.pid, signal.SIGKILL)  # the crash: the app, its engine, all at once
        first.wait(30)
    again = probe(laptop_display, tmp_path, "exit", "--audio", "null", "--midi", "none", "--resume")
    try:
        after = first_report(again)
        assert again.wait(TIMEOUT) == 0, again.stderr.read()[-3000:]
    finally:
        if again.poll() is None:
            os.killpg(again.pid, signal.SIGKILL)
    p = after["participant"]
    assert p["visible"] and p["screen"] == 0, after
    # one screen: the participant's window leaves the console's session buttons in view (issue 31 item 5)
    x = p["geometry"][0]
    assert not p["full_screen"] and x > 0, after
    for name, rect in after["buttons"].items():
        assert rect[0] + rect[2] <= x, (name, rect, p)
    assert after["step"] is not None


def test_headless_refuses_the_consoles_options(tmp_path):
    for option, value in (("--midi", "none"), ("--participant-screen", "0")):
        done = subprocess.run([sys.executable, "-m", "studyapp", "run", "--protocol", str(DEMO), "--participant",
                               "P01", "--simulated-participant", "--headless", "--results", str(tmp_path / "r"),
                               option, value], cwd=ROOT, capture_output=True, text=True, timeout=120)
        assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
        assert option in done.stderr and "--headless" in done.stderr
        assert not (tmp_path / "r").exists()
