"""Screenshots of a session, step by step, for docs/gui.md: taken by the console itself while it runs one.

    PYTHONPATH=. python scripts/session_screenshots.py DIR [--protocol FILE] [--size 1366x768]
        [--only NAME ...] [--suffix TEXT]

Runs one session of ``--protocol`` (default protocols/demo.toml) through the real console and participant
window (offscreen Qt unless QT_QPA_PLATFORM says otherwise; engine audio and MIDI off), played with the
on-screen controls as a participant would: Continue on each page, each rating knob turned with the bow on,
each adjustment knob turned up and confirmed. Both windows are ``--size``. Each picture is the window's
own rendering (``studyapp.gui.screenshot.save_widget``, as ``studyapp gui --screenshot`` writes it):

- participant-welcome.png: the first page;
- participant-rating.png: the first real rating trial, its knobs turned, bowing;
- participant-bowing.png: that trial, the participant bowing on the bowing surface (a mouse press and
  drag synthesised on it, gui/bowing_surface.py), when the task's bow is the participant's;
- participant-break.png: the first break page;
- console-trial.png: the console during that rating trial (the scope after a second of bowing).

``--only welcome rating bowing break`` takes just those (``rating`` is participant-rating.png and
console-trial.png), stopping as soon as they are taken (``--only bowing`` stops in the rating task); ``--suffix`` is added to each file name (e.g. ``-1366x768``). Prints each path
written.
"""

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT = 180.0  # s for any one wait (a cold numba cache on a loaded machine is slow)


def wait(app, predicate, what, timeout=TIMEOUT):
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise RuntimeError(f"no {what} after {timeout:g} s")
        app.processEvents()
        time.sleep(0.005)


def bow_on_surface(app, surface, fraction):
    """Press the mouse on the participant's bowing surface and drag it to ``fraction`` of its width."""
    from PySide6.QtCore import QPoint, Qt
    from PySide6.QtTest import QTest

    y = surface.height() // 2
    QTest.mousePress(surface, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, QPoint(surface.width() // 2, y))
    for k in range(1, 11):
        x = surface.width() // 2 + round(k / 10 * (fraction - 0.5) * surface.width())
        QTest.mouseMove(surface, QPoint(x, y))
        app.processEvents()


def run(app, protocol, out, size, results, wanted=("welcome", "rating", "bowing", "break"), suffix=""):
    from studyapp.gui.console import Console
    from studyapp.gui.screenshot import save_widget
    from studyapp.live.controller import PAGE_SETTLE_S, SessionController

    c = SessionController(audio="null", midi="none", hang_timeout=0.5)
    console = Console(c)
    participant = console.participant_window
    for window in (console, participant):
        window.resize(*size)
        window.show()
    written = []

    def shoot(widget, name):
        for _ in range(5):
            app.processEvents()
        written.append(save_widget(widget, out / name.replace(".png", f"{suffix}.png")))

    try:
        if not console.choose_protocol(str(protocol)):
            raise RuntimeError(console.setup.error.text())
        wait(app, lambda: c.engine is not None or c.host.state == "failed", "preview engine")
        console.setup.participant.setText("P01")
        console.setup.results.setText(str(results))
        console.setup.experimenter.setText("AB")
        console.start_button.click()
        wait(app, lambda: c.playing or c.state == "aborted", "session engine")
        wanted = set(wanted)
        while wanted and c.state != "finished":
            trial, task = c.runner.trial, c.runner.task
            step = trial.step
            if trial.page is not None:
                if trial.page.kind in wanted:
                    wanted.discard(trial.page.kind)
                    shoot(participant, f"participant-{trial.page.kind}.png")
                wait(app, lambda: c.page_age() >= PAGE_SETTLE_S, "page settled")
                c.acknowledge_page("experimenter" if trial.page.by == "experimenter" else "participant")
            elif trial.task == "rating":
                positions = [127 - round(127 * j / (len(task.conditions) - 1)) for j in range(len(task.conditions))]
                for knob, value in enumerate(positions):
                    console.turn_knob(knob, value)
                    wait(app, lambda: task.values[task.conditions[knob]] == value, "knob")
                    if not c.runner.bowing:
                        if participant.surface.isVisible():
                            bow_on_surface(app, participant.surface, 0.62)
                        else:
                            participant.toggle_bowing()
                    wait(app, lambda: task.heard[task.conditions[knob]] >= max(task.min_listen_s, 0.3), "listening")
                if not trial.practice and wanted & {"rating", "bowing"}:
                    wait(app, lambda: task.elapsed >= 1.5, "a second of the scope")
                    if "rating" in wanted:
                        shoot(participant, "participant-rating.png")
                        shoot(console, "console-trial.png")
                    if "bowing" in wanted and participant.surface.isVisible():
                        shoot(participant, "participant-bowing.png")
                    wanted -= {"rating", "bowing"}
                    if not wanted:
                        break
                console.press_pad(task.confirm_pad)
            else:
                console.turn_knob(0, 0)
                console.turn_knob(0, 60)
                wait(app, lambda: task.value == 60, "knob")
                if not c.runner.bowing:
                    participant.toggle_bowing()
                wait(app, lambda: task.heard[task.condition] >= task.min_listen_s, "listening")
                console.press_pad(task.confirm_pad)
            wait(app, lambda: c.state == "finished" or (c.playing and c.runner.trial.step != step), "next step")
        if wanted:
            raise RuntimeError(f"the session showed no {', '.join(sorted(wanted))}")
    finally:
        console.shut_down()
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", help="where the PNGs go")
    parser.add_argument("--protocol", default=str(ROOT / "protocols" / "demo.toml"), help="default protocols/demo.toml")
    parser.add_argument("--size", default="1366x768", help="both windows' size, WxH (default 1366x768)")
    parser.add_argument("--only", nargs="+", default=["welcome", "rating", "bowing", "break"],
                        choices=["welcome", "rating", "bowing", "break"], help="the pictures to take (default: all)")
    parser.add_argument("--suffix", default="", help="added to each file name, e.g. -1366x768")
    args = parser.parse_args(argv)
    size = tuple(int(n) for n in args.size.split("x"))
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication(["session_screenshots"])
    out = Path(args.dir)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for path in run(app, Path(args.protocol), out, size, Path(tmp) / "results", args.only, args.suffix):
            print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
