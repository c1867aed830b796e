"""Frames per second actually painted by a widget (not timer ticks, not ``setData`` calls).

An event filter counts the ``Paint`` events of a widget (for a pyqtgraph plot,
its graphics view's viewport): a frame is counted only when Qt really
repainted it. ``rate()`` is the number of paints over the last ``span``
seconds divided by the time they covered.
"""

import time
from collections import deque

from PySide6.QtCore import QEvent, QObject


class FrameRateMeter(QObject):
    def __init__(self, widget, span=1.0, clock=time.monotonic):
        super().__init__(widget)
        self.span = float(span)
        self.clock = clock
        self.frames = 0
        self._times = deque()
        widget.installEventFilter(self)

    def eventFilter(self, obj, event):
        if event.type() == QEvent.Type.Paint:
            now = self.clock()
            self.frames += 1
            self._times.append(now)
            while self._times and now - self._times[0] > self.span:
                self._times.popleft()
        return False

    def rate(self):
        """Paints per second over the last ``span`` s (0 with fewer than two paints in it)."""
        now = self.clock()
        while self._times and now - self._times[0] > self.span:
            self._times.popleft()
        if len(self._times) < 2:
            return 0.0
        return (len(self._times) - 1) / max(now - self._times[0], 1e-9)
