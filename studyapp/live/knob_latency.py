"""Knob-to-effect latency of a live session: from a control's arrival to the first block run with its effect.

The worker measures each one (``events.Applied.latency``): from the MIDI
message's arrival (rtmidi's callback stamps it with ``time.monotonic()``), or
from the moment the console sent an on-screen control, to the start of the
block that applied the control's action. The controller collects them here;
the status bar shows the last and the largest, and the session log gets one
``knob_latency`` record per trial with the count, median and maximum (s).
"""

import numpy as np

from studyapp.experiment import records


class KnobLatency:
    def __init__(self):
        self.last = None
        self.largest = None
        self._trial = []  # (latency, origin) since the last ``take``

    def add(self, latency, origin):
        self.last = latency
        self.largest = latency if self.largest is None else max(self.largest, latency)
        self._trial.append((latency, origin))

    def take(self):
        """The record for the session log since the last call (``None`` if no control acted)."""
        if not self._trial:
            return None
        values = np.array([latency for latency, _ in self._trial])
        midi = sum(origin == "midi" for _, origin in self._trial)
        self._trial = []
        return records.knob_latency(len(values), midi, float(np.median(values)), float(values.max()))
