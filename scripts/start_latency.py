"""The time from the experimenter's Start to the participant's first stimulus, through the real console.

    PYTHONPATH=. python scripts/start_latency.py [--runs 5] [--audio null|device] [--protocol FILE] [--json]

Each run opens the console (offscreen Qt unless QT_QPA_PLATFORM says otherwise) with a fresh controller
on ``--protocol`` (default protocols/demo.toml), waits for its preview engine, and clicks Start. Then the
participant goes through the pages as fast as the session lets them (Continue as soon as PAGE_SETTLE_S
has passed) and, the moment the first trial appears, turns knob 1 to 100 and puts the bow on the string
(F_max is 0 until a knob is turned: the rating task, tasks/rating.py). Three times, each from
``time.monotonic()`` in this process:

- ``start_to_page``: Start clicked -> the first page on the participant's screen (the controller's
  ``page`` event, which the window shows at once; the session's engine has started);
- ``ack_to_sound``: the last page before the first trial acknowledged -> the first block of that trial
  with the bow on the string and F_max above 0 (a telemetry sample tagged with the trial, F_max > 0
  and a friction force other than 0);
- ``start_to_sound``: the same protocol without its ``[[pages]]`` (its first step is then the first
  trial): Start clicked -> that first block.

A block is timed when the console's poll (every 10 ms) reads it from the engine's ring, so the times are
upper bounds, late by at most one poll period; the audio device's own output latency is not included.
With ``--audio device`` the engine plays to the default device (e.g. a JACK server). Prints the median
and the range (min - max) of each over the runs.
"""

import argparse
import json
import os
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]
ENGINE_START = 180.0  # s: a cold numba cache on a loaded machine is slow
SESSION = 120.0  # s: a run that has no first sound by then failed


def without_pages(text):
    """A protocol's TOML text without its ``[[pages]]`` tables (each runs to the next table header)."""
    return re.sub(r"^\[\[pages\]\]\n(?:(?!\[).*\n|\n)*", "", text, flags=re.MULTILINE)


def wait(app, predicate, timeout, what):
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise RuntimeError(f"no {what} after {timeout:g} s")
        app.processEvents()
        time.sleep(0.001)


def one_run(app, protocol, audio, results, participant):
    """{start_to_page, ack_to_sound, start_to_sound}: the times of one session of ``protocol`` (s, None
    for what it has not: a protocol without pages has no page)."""
    from studyapp.gui.console import Console
    from studyapp.live.controller import PAGE_SETTLE_S, SessionController

    c = SessionController(audio=audio, midi="none", hang_timeout=0.5)
    console = Console(c)
    console.show()
    console.participant_window.show()
    seen = {}
    trial_started = {}

    def on_page(**_):
        seen.setdefault("page", time.monotonic())

    def on_trial(phase, **_):
        if phase != "page":
            trial_started.setdefault("at", time.monotonic())

    def on_telemetry(block):
        if "sound" in seen or "at" not in trial_started:
            return
        ours = (block["trial"] == c.trial_serial) & (block["fmax"] > 0) & (block["friction"] != 0)
        if ours.any():
            seen["sound"] = time.monotonic()

    c.events.page.connect(on_page)
    c.events.trial.connect(on_trial)
    c.events.telemetry.connect(on_telemetry)
    try:
        if not console.choose_protocol(str(protocol)):
            raise RuntimeError(console.setup.error.text())
        wait(app, lambda: c.engine is not None or c.host.state == "failed", ENGINE_START, "preview engine")
        if c.engine is None:
            raise RuntimeError(f"the engine did not start: {c.host.error}")
        console.setup.participant.setText(participant)
        console.setup.results.setText(str(results))
        start = time.monotonic()
        console.start_button.click()
        if c.state != "starting":
            raise RuntimeError(console.setup.error.text())
        acknowledged = None
        end = start + SESSION
        while "at" not in trial_started:
            if time.monotonic() > end or c.state in ("aborted", "engine_lost"):
                raise RuntimeError(f"no first trial (state {c.state})")
            trial = c.runner.trial if c.playing and c.runner is not None else None
            if trial is not None and trial.page is not None and c.page_age() >= PAGE_SETTLE_S:
                acknowledged = time.monotonic()
                if trial.page.by == "experimenter":
                    console.page_controls.confirm_button.click()
                else:
                    console.participant_window.page_view.continue_button.click()
            app.processEvents()
            time.sleep(0.001)
        c.knob(0, 100)
        c.set_bowing(True)
        wait(app, lambda: "sound" in seen, SESSION, "first sound")
        return {"start_to_page": seen["page"] - start if "page" in seen else None,
                "ack_to_sound": seen["sound"] - acknowledged if acknowledged is not None else None,
                "start_to_sound": seen["sound"] - start if acknowledged is None else None}
    finally:
        console.shut_down()


def summary(values):
    values = [v for v in values if v is not None]
    return {"median": statistics.median(values), "min": min(values), "max": max(values), "runs": len(values)}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="sessions per protocol variant (default 5)")
    parser.add_argument("--audio", default="null", help="the engine's audio: null (default) or device")
    parser.add_argument("--protocol", default=str(ROOT / "protocols" / "demo.toml"),
                        help="a protocol with [[pages]] (default protocols/demo.toml)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication(["start_latency"])
    protocol = Path(args.protocol)
    times = {"start_to_page": [], "ack_to_sound": [], "start_to_sound": []}
    with tempfile.TemporaryDirectory() as tmp:
        bare = Path(tmp) / protocol.name
        bare.write_text(without_pages(protocol.read_text()))
        for run in range(args.runs):
            for path in (protocol, bare):
                got = one_run(app, path, args.audio, Path(tmp) / "results", f"L{run}{'P' if path == protocol else 'N'}")
                for key, value in got.items():
                    if value is not None:
                        times[key].append(value)
    result = {key: summary(values) for key, values in times.items()}
    if args.json:
        print(json.dumps({"audio": args.audio, "protocol": str(protocol), **result}))
        return 0
    print(f"Start to first stimulus, {args.runs} runs, audio {args.audio}, {protocol.name} (s):")
    for key, s in result.items():
        print(f"  {key:15s} median {s['median']:.2f}  range {s['min']:.2f} - {s['max']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
