"""The simulated participant's ear on a loaded machine (issue 31 item 4): no Qt, no worker.

A look that comes late holds more than was asked and the participant counts it, so it keeps the engine's
pace; a look a whole ring behind reads at most half the ring, and a torn read (the writer lapped it) is
looked at again instead of raising out of the participant (before: ``TornRead`` at a load of 26 on 2
cores, and the session sat in "Running").
"""

import threading
from types import SimpleNamespace

import numpy as np

from studyapp.engine.ring import TornRead
from studyapp.experiment.simulated_participant import SimulatedParticipant
from studyapp.live.simulated_session import ParticipantProxy
from studyapp.live.states import State

RATE = 5000.0
CAPACITY = 20000  # samples: the engine's 4 s ring at 5 kHz


class FakeEngine:
    """A telemetry ring the worker has written ``committed`` samples to; the first ``torn`` reads are torn."""

    def __init__(self, committed, torn=0):
        self.ring = SimpleNamespace(committed=committed, capacity=CAPACITY)
        self.torn = torn
        self.reads, self.seen = [], []  # each read's ``since``, and the newest sample then

    def telemetry(self, since):
        self.reads.append(since)
        self.seen.append(self.ring.committed)
        if self.torn:
            self.torn -= 1
            self.ring.committed += 100  # the worker wrote on meanwhile
            raise TornRead("writer lapped the reader")
        n = self.ring.committed - since
        return {"force": np.zeros(n), "start": since, "end": self.ring.committed, "estimates": {}}


class Controller(SimpleNamespace):
    """What the proxy reads of the session controller."""


def proxy_on(engine, fed):
    trial = SimpleNamespace(step=3)
    runner = SimpleNamespace(trial=trial, loop=SimpleNamespace(rate=RATE), task=None)
    c = Controller(state=State.RUNNING, playing=True, engine=engine, fed=fed, trial_serial=1, runner=runner)
    proxy = ParticipantProxy(c, None, lambda fn: fn(), threading.Event())
    proxy._trial, proxy._given = trial, {"task": None, "loop": runner.loop}
    return proxy


def test_a_late_look_returns_every_sample_since_the_call():
    engine = FakeEngine(committed=1000)
    proxy = proxy_on(engine, fed=10**9)  # the controller has fed far more than asked
    engine_writes_on = 1000 + 3000
    engine.ring.committed = 1000  # the call's start
    original = engine.telemetry

    def later(since):
        engine.ring.committed = engine_writes_on  # the look comes 0.6 s late
        return original(since)

    engine.telemetry = later
    block = proxy.advance(0.05)
    assert len(block["force"]) == 3000  # not the 250 asked: all it heard


def test_a_look_a_whole_ring_behind_reads_half_the_ring_and_a_torn_read_is_looked_at_again():
    engine = FakeEngine(committed=50_000, torn=2)
    proxy = proxy_on(engine, fed=None)

    class LateController(type(proxy.controller)):
        @property
        def fed(self):  # every look comes 6 s late: the worker wrote more than the ring holds meanwhile
            engine.ring.committed += 30_000
            return engine.ring.committed

    proxy.controller.__class__ = LateController
    block = proxy.advance(0.05)  # before: TornRead raised out of the participant
    assert len(engine.reads) == 3
    assert all(since >= committed - CAPACITY // 2 for since, committed in zip(engine.reads, engine.seen))
    assert len(block["force"]) == CAPACITY // 2


class LateRunner:
    """A runner whose every look holds ``factor`` times the samples asked (a participant thread looking late)."""

    def __init__(self, factor):
        self.factor = factor
        self.loop = SimpleNamespace(rate=RATE, monitor=SimpleNamespace(broken=False), fault=None)
        self.looks = 0

    def advance(self, seconds):
        self.looks += 1
        return {"force": np.zeros(self.factor * int(round(seconds * RATE)))}


def test_the_participant_counts_what_it_heard_when_it_looks_late():
    participant = SimulatedParticipant(seed=1)
    on_time, late = LateRunner(1), LateRunner(4)
    assert not participant.listen_for_breakdown(on_time, 1.2)
    assert not participant.listen_for_breakdown(late, 1.2)
    assert on_time.looks == 24 and late.looks == 6  # before: 24 looks, however much each held
