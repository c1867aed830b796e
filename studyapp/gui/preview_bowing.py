"""Bow the preview engine through the console's own controls, then act: for screenshots and benchmarks.

When the engine runs and no session is in progress, ``PreviewBowing`` turns
knob 1 (the preview's live F_max knob, ``studyapp.engine.commands``) to
F_max = 1 N, picks the scripted strokes and presses "Bow", as an experimenter
checking the set-up would. Once the scope holds ``settle`` seconds of that, it calls ``ready()``
(subclasses say what to do). If the engine fails, or nothing runs within
``timeout`` seconds, it prints one line on stderr and exits the application
with code 1; while it waits it prints what it waits for every ``REPORT_EVERY``
seconds (the engine's state, the rig check's searches).
"""

import sys
import time

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication

from studyapp.model.controls import LIVE_RANGE, FmaxKnob

PREVIEW_FMAX = 1.0  # N, the rating task's F_max
REPORT_EVERY = 15.0  # s between the lines an unattended run prints while it waits


class PreviewBowing:
    def __init__(self, console, settle=1.5, timeout=240.0, clock=time.monotonic):
        self.console = console
        self.settle = float(settle)
        self.clock = clock
        self.timeout = float(timeout)
        self.deadline = clock() + self.timeout
        self.bowing_since = None
        self.next_report = clock() + REPORT_EVERY
        self.timer = QTimer(console)
        self.timer.setInterval(50)
        self.timer.timeout.connect(self._check)
        self.timer.start()

    def fail(self, text):
        self.timer.stop()
        print(f"studyapp gui: error: {text}", file=sys.stderr)
        QApplication.instance().exit(1)

    def _check(self):
        c = self.console.controller
        host = c.host
        state = host.state if host is not None else "not started (no protocol)"
        if state == "failed":
            self.fail(f"the engine failed: {host.error or 'its worker stopped'}")
            return
        if self.clock() > self.deadline:
            self.fail(f"the engine is {state} {self.timeout:g} s after the console opened: {self._waiting(state)}")
            return
        if self.clock() >= self.next_report:
            self.report(state)
        if state != "running" or not self.console.knobs.isEnabled():
            return
        if self.bowing_since is None:
            if c.state not in ("starting", "running", "paused"):
                self.console.turn_knob(0, FmaxKnob(*LIVE_RANGE).step(PREVIEW_FMAX))
                self.console.set_gesture("strokes")
                self.console.set_bowing(True)
            self.bowing_since = self.clock()
            return
        enough = self.console.scope.samples >= self.settle * host.config.rate
        if self.clock() - self.bowing_since < self.settle or not enough:
            return
        self.timer.stop()
        self.ready()

    def report(self, state):
        """One line on stderr every ``REPORT_EVERY`` s while it waits: an unattended console (offscreen, no one to
        see it) said nothing for 240 s under load (issue 41, item 10)."""
        self.next_report = self.clock() + REPORT_EVERY
        waited = self.timeout - (self.deadline - self.clock())
        why = f"the engine is {state}" if state != "running" else self._waiting(state)
        line = f"studyapp gui: waiting {waited:.0f} s (at most {self.timeout:g}): {why}"
        bar = self.console.device_panel.progress
        if bar.isVisible():
            done = f"{bar.value()} of {bar.maximum()} searches" if bar.maximum() else "starting"
            line += f"; rig check (in the background): {done}"
        print(line, file=sys.stderr, flush=True)

    def _waiting(self, state):
        """What the check still waits for, for the timeout's line."""
        if state != "running":
            return "it never ran"
        if not self.console.knobs.isEnabled():
            return "the knobs were never enabled"
        need = self.settle * self.console.controller.host.config.rate
        return f"the scope holds {self.console.scope.samples} of the {need:.0f} samples of bowing it waits for"

    def ready(self):
        raise NotImplementedError
