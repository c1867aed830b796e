"""``studyapp gui --measure-scope SECONDS``: the scope's frame rate with every trace on.

The console bows the preview engine (``PreviewBowing``), every trace is
ticked (LVT, selected, string, true velocity, each active estimate, force)
and the window set to its 5 s maximum, the heaviest case. Frames are counted
as real paints of the plot (``FrameRateMeter``) over ``seconds``; the result
is printed as one line and the application exits. Run it on the display the
experimenter uses (or under Xvfb, where Qt paints in software, the worst case).
"""

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication

from studyapp.gui.preview_bowing import PreviewBowing
from studyapp.live.scope_buffer import MAX_SECONDS


class ScopeBenchmark(PreviewBowing):
    def __init__(self, console, seconds=5.0, **kwargs):
        super().__init__(console, **kwargs)
        self.seconds = float(seconds)
        self.result = None

    def ready(self):
        scope = self.console.scope
        scope.show_all(True)
        scope.seconds.setValue(MAX_SECONDS)
        self.frames = scope.meter.frames
        self.started = self.clock()
        QTimer.singleShot(int(self.seconds * 1000), self._measure)

    def _measure(self):
        scope = self.console.scope
        elapsed = self.clock() - self.started
        fps = (scope.meter.frames - self.frames) / elapsed
        host = self.console.controller.host
        self.result = fps
        print(f"scope: {fps:.1f} frames/s over {elapsed:.1f} s with {len(scope.traces)} traces on, "
              f"window {scope.seconds.value():g} s at {host.config.rate:g} Hz "
              f"({QApplication.instance().platformName()} platform)")
        QApplication.instance().exit(0)
