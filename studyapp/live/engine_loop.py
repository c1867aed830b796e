"""The closed loop as ``SessionRunner`` sees it, played by the real-time engine. No Qt.

``SessionRunner`` drives a loop object with ``ClosedLoop``'s interface
(``set_source``, ``set_fmax``, ``set_bowing``, ``set_gesture``, ``run(n)``,
``rate``, ``monitor``, ``fault``). Headless, ``run(n)`` computes n samples. In
a live session the engine's worker computes them in real time; ``EngineLoop``
sends the settings to it as commands (applied at its next block boundary) and
``run(n)`` hands back the n samples the controller has just passed to
``consume``, so ``runner.advance(n / rate)`` ticks the task by exactly the
time the engine ran. Nothing here waits.

Push, not pull. A trial starts with one burst of commands: F_max 0, bow
lifted, ``ResetString`` (string at rest, the worker's stability monitor
afresh, trial clock 0), the gesture, the source, and last the trial's knob
mapping tagged with the trial's number (``InstallActions``, with the knob
positions the task restored: a rated knob's level, for pickup). The worker tags
every block with the mapping's number, so ``consume(block)`` keeps only the
samples run for this trial, with every one of its settings in force. The
stability verdict is the worker's own (``broken`` and ``stability_score``,
published per block by the loop's monitor, model/stability.py): breakdown is
judged once, where the loop runs.

One writer per setting. ``source``, ``fmax`` and ``bowing`` are the
trial's settings as the worker has them (while held: as it gets them back).
They are written from two places only, never guessed: what this loop sends,
and what the worker reports it applied (``applied(commands)``, from its
``events.Applied``): the worker applies the trial's knob actions itself (the
rating knob j selects condition j at the rating F_max, the adjustment knob
sets F_max on the protocol's logarithmic scale, model/fmax_knob.py). A setting
the runner asks for is sent only when it differs from the one in force, so
the runner following a knob the worker has already applied sends nothing: a
knob makes no round trip, and the worker stays the one writer of what its
knobs set.

Holding. ``hold(True)`` (pause, emergency stop) sends F_max = 0, lifts the bow
and installs an empty mapping tagged ``-trial`` (so the held samples and any
control are not the trial's), without changing what the runner asked for;
``hold(False)`` sends the runner's settings and the trial's mapping again.
A physical knob that moved meanwhile must then pass through the level again
before it acts (the worker's pickup, engine/pickup.py).

The engine keeps one noise seed for the session, so the ``loop_seed`` the
runner logs per trial is not used here (the session log says so in its
``engine`` event).
"""

from dataclasses import dataclass

import numpy as np

from studyapp.engine import commands as cmd
from studyapp.errors import ParameterError


@dataclass
class Verdict:
    """The worker's stability verdict on the newest block (``StabilityMonitor``'s ``broken`` and ``score``)."""

    broken: bool = False
    score: float = 0.0


class EngineLoop:
    def __init__(self, engine, estimators, source, gesture, trial=0, actions=None, positions=None):
        missing = [name for name in estimators if name not in engine.names]
        if missing:
            raise ParameterError(f"estimator {missing[0]!r} is not running in the engine: "
                                 f"allowed are {', '.join(engine.names)}")
        self.engine = engine
        self.rate = float(engine.config.rate)
        self.names = list(estimators)
        self.monitor = Verdict()
        self.trial = int(trial)
        self.actions = dict(actions or {})
        self.source = source
        self.fmax = 0.0
        self.bowing = False
        self.gesture = gesture
        self.held = False
        self._pending = None
        self._fault = None
        for command in (cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.ResetString(), cmd.SetGesture(gesture),
                        cmd.SetSource(source),
                        cmd.InstallActions(self.actions, trial=self.trial, positions=dict(positions or {}))):
            self.engine.send(command)

    def applied(self, commands):
        """The worker applied ``commands`` (its own knob action, reported in ``events.Applied``): in force now."""
        for command in commands:
            if isinstance(command, cmd.SetFmax):
                self.fmax = command.newtons
            elif isinstance(command, cmd.SetSource):
                self.source = command.name
            elif isinstance(command, cmd.SetBowing):
                self.bowing = command.on

    # settings, as the runner makes them: sent when they change, and not while held ---------------
    def set_source(self, name):
        if name != self.source:
            self.source = name
            self.engine.send(cmd.SetSource(name))

    def set_fmax(self, fmax):
        fmax = float(fmax)
        if fmax != self.fmax:
            self.fmax = fmax
            if not self.held:
                self.engine.send(cmd.SetFmax(fmax))

    def set_bowing(self, on):
        on = bool(on)
        if on != self.bowing:
            self.bowing = on
            if not self.held:
                self.engine.send(cmd.SetBowing(on))

    def set_gesture(self, name):
        self.gesture = name
        self.engine.send(cmd.SetGesture(name))

    def set_hand_target(self, x_m):
        self.engine.send(cmd.SetHandTarget(float(x_m)))

    def hold(self, on):
        """Zero F_max, lift the bow, take the knobs away (True); or give the runner's settings back (False)."""
        # always sent: a knob the worker applied but the controller has not read yet may have moved F_max
        self.held = bool(on)
        self.engine.send(cmd.SetFmax(0.0 if self.held else self.fmax))
        self.engine.send(cmd.SetBowing(False if self.held else self.bowing))
        # while held the worker tags the samples and controls -trial: neither reaches the trial
        self.engine.send(cmd.InstallActions({}, trial=-self.trial) if self.held
                         else cmd.InstallActions(self.actions, trial=self.trial))

    # running --------------------------------------------------------------
    def consume(self, block):
        """Keep this trial's samples of a telemetry block for the next ``run``; returns how many."""
        ours = block["trial"] == self.trial
        if not ours.any():
            self._pending = None
            return 0
        if not ours.all():
            # the trial's first samples: its mapping came into force at a block boundary inside this read
            block = {**{key: value[ours] for key, value in block.items() if isinstance(value, np.ndarray)},
                     "estimates": {name: value[ours] for name, value in block["estimates"].items()},
                     "start": block["start"] + int(ours.argmax()), "end": block["end"]}
        self._pending = block
        self.monitor = Verdict(bool(block["broken"][-1]), float(block["stability_score"][-1]))
        return len(block["trial"])

    def run(self, n):
        block = self._pending
        self._pending = None
        if block is None or len(block["force"]) != n:
            have = 0 if block is None else len(block["force"])
            raise RuntimeError(f"EngineLoop.run({n}): the controller consumed {have} samples")
        status = self.engine.status()
        self._fault = status["fault"] or "safety fault" if status["fault_latched"] else None
        return block

    @property
    def fault(self):
        """The engine's latched fault (force held at 0), or None."""
        return self._fault
