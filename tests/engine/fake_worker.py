"""A ``Worker`` without its process, loop or devices: for testing how it applies commands and controls."""

from studyapp.engine.audio.sinks import Gain
from studyapp.engine.status import StatusBlock
from studyapp.engine.worker import Worker


class FakeLoop:
    rate = 5000.0
    fault = None

    def __init__(self):
        self.fmax, self.source = 0.0, "LVT"

    def set_fmax(self, fmax):
        self.fmax = fmax

    def set_source(self, name):
        if name not in ("LVT", "KALLEV"):
            raise ValueError(f"unknown source {name!r}")
        self.source = name


class Events(list):
    put = list.append


def fake_worker():
    """A worker at block 7 (10 samples a block), F_max ceiling 20 N, a volume-only sink; close ``status`` after."""
    w = Worker.__new__(Worker)
    w.loop, w.events, w.k, w.block, w.actions, w.trial = FakeLoop(), Events(), 7, 10, {}, 0
    w.knob_seen, w.ratings = {}, {}
    w.sink = type("Sink", (), {"gain": Gain(), "set_volume": lambda self, v: setattr(self.gain, "volume", v)})()
    w.safety = type("Safety", (), {"clamp_fmax": staticmethod(lambda f: min(f, 20.0))})()
    w.status = StatusBlock.create()
    return w
