"""A fake engine host for the session controller: no process, no Qt; the engine mimics the worker's mapping.

``FakeEngine.send`` records every command and, like the worker, applies an
on-screen ``Control`` through the mapping installed last, reporting it back
as an ``events.Applied`` tagged with the mapping's trial. ``run(n)`` makes a
telemetry block of n samples tagged likewise, which the host's ``read``
returns once.
"""

import time

import numpy as np

from studyapp.engine import commands as cmd
from studyapp.engine.events import Applied

LATENCY = 0.002  # s, what the fake worker reports for every applied control


class SteppingClock:
    """A clock for the controller that moves ``step`` s at every reading (pages settle at once)."""

    def __init__(self, step=1.0):
        self.now, self.step = 0.0, step

    def __call__(self):
        self.now += self.step
        return self.now


class FakeStatusBlock:
    force_enable = True
    force_off_reason = "parent"

    def disable_force(self, reason, silence=0.0):
        self.force_off_reason = reason
        self.force_enable = False


LINK_INFO = {"name": "studyapp emulator", "serial": "EMU-0000", "latency_ms": 1.0}  # a fake link device's handshake


class FakeEngine:
    def __init__(self, config):
        self.config = config
        self.names = list(config.estimators)
        self.info = {"rate": config.rate, "block": 10, "audio": "null", "midi": "none", "paced": "timer",
                     "realtime": False, "names": self.names}
        if config.device:  # a device on a link: its handshake, as the engine's info carries it
            self.info.update(paced="device", device=dict(LINK_INFO))
        self.sent = []
        self.faults = []
        self.status_block = FakeStatusBlock()
        self.latched = False
        self.actions = dict(config.actions or {})
        self.trial = 0
        self.fmax = 0.0
        self.samples = 0
        self.broken = 0.0
        self.counters = {"deadline_misses": 0, "audio_underruns": 0, "faults": 0, "events_dropped": 0,
                         "audio_limited": 0}
        self._controls = []

    def send(self, command):
        self.sent.append(command)
        if isinstance(command, cmd.InstallActions):
            self.actions, self.trial = dict(command.actions), command.trial
        elif isinstance(command, cmd.SetFmax):
            self.fmax = command.newtons
        elif isinstance(command, cmd.ClearFault):
            self.latched = False
        elif isinstance(command, cmd.Control):
            self.control(command.control, command.value, "screen", arrived=command.sent)

    def control(self, name, value, origin="midi", arrived=None):
        """A control reaches the worker (a MIDI message now; an on-screen one when its command was sent)."""
        arrived = time.monotonic() if arrived is None else arrived
        action = self.actions.get(name)
        commands = cmd.action_commands(action, value, arrived) if action else ()
        for command in commands:
            self.sent.append(command)
            if isinstance(command, cmd.SetFmax):
                self.fmax = command.newtons
        self._controls.append(Applied(name, value, arrived, LATENCY if commands else None, 0, 0, self.trial,
                                      commands, origin))

    def pending(self, name, value, target):
        """A MIDI knob the worker holds back until it passes through ``target`` (pickup)."""
        self._controls.append(Applied(name, value, 0.0, None, 0, 0, self.trial, (), "midi",
                                      pending_pickup=True, pickup_target=target))

    def clear_fault(self):
        self.send(cmd.ClearFault())
        self._cleared = len(self.faults)

    def faults_since_clear(self):
        return self.faults[getattr(self, "_cleared", 0):]

    def controls(self):
        out, self._controls = self._controls, []
        return out

    def status(self):
        latched = self.latched or not self.status_block.force_enable
        return {"fault": "", "fault_latched": latched, "source": "LVT", "fmax": self.fmax, **self.counters}

    def run(self, n):
        start, self.samples = self.samples, self.samples + n
        zeros = np.zeros(n)
        return {"force": zeros, "position": zeros, "trial": np.full(n, float(self.trial)),
                "broken": np.full(n, self.broken), "stability_score": np.full(n, 0.002 * self.broken),
                "estimates": {}, "start": start, "end": start + n}

    def sent_of(self, kind):
        return [c for c in self.sent if isinstance(c, kind)]


class FakeHost:
    made = []

    def __init__(self, config, describe=""):
        self.config = config
        self.describe = describe
        self.engine = FakeEngine(config)
        self.state = "starting"
        self.error = None
        self.position = 0
        self.lost = 0
        self.stopped = False
        self._blocks = []
        FakeHost.made.append(self)

    def start(self):
        return self

    @property
    def running(self):
        return self.state == "running"

    def play(self, seconds):
        """The worker runs ``seconds``; the controller reads it at its next poll."""
        self._blocks.append(self.engine.run(int(round(seconds * self.config.rate))))

    def read(self):
        if not self._blocks or not self.running:
            return None
        block, self._blocks = self._blocks[0], self._blocks[1:]
        self.position = block["end"]
        return block

    def drain(self):
        return []

    def stop(self, wait=True):
        self.stopped = True
        self.state = "stopped"
