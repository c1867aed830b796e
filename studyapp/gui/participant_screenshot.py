"""``studyapp gui --participant-screenshot FILE``: the participant's window, as the participant sees it, saved as a PNG.

The window is opened (full-screen if a screen was chosen) and grabbed at
once, or with ``--start`` once the session's first trial is on screen
(``QWidget.grab``: no window manager needed); the PNG is written atomically,
its path printed, and the application exits with 0. An engine that fails, or
no trial within ``timeout`` seconds, is one line on stderr and exit code 1.
"""

import sys
import time

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication

from studyapp.gui.screenshot import save_widget


class ParticipantScreenshot:
    def __init__(self, console, path, wait_for_trial, timeout=120.0, clock=time.monotonic):
        self.console = console
        self.path = path
        self.wait_for_trial = wait_for_trial
        self.clock = clock
        self.timeout = float(timeout)
        self.deadline = clock() + self.timeout
        self.timer = QTimer(console)
        self.timer.setInterval(50)
        self.timer.timeout.connect(self._check)
        self.timer.start()

    def _exit(self, code, text, stream):
        self.timer.stop()
        print(text, file=stream)
        QApplication.instance().exit(code)

    def _check(self):
        c = self.console.controller
        host = c.host
        state = host.state if host is not None else "not started (no protocol)"
        if state == "failed":
            self._exit(1, f"studyapp gui: error: the engine failed: {host.error or 'its worker stopped'}", sys.stderr)
        elif self.clock() > self.deadline:
            self._exit(1, f"studyapp gui: error: nothing to show after {self.timeout:g} s "
                          f"(engine {state}, session {c.state})", sys.stderr)
        elif not self.wait_for_trial or (state == "running" and c.state == "running" and c.runner.trial):
            save_widget(self.console.participant_window, self.path)
            self._exit(0, self.path, sys.stdout)
