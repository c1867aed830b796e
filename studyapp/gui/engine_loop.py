"""The closed loop as ``SessionRunner`` sees it, played by the real-time engine.

``SessionRunner`` drives a loop object with ``ClosedLoop``'s interface
(``set_source``, ``set_fmax``, ``set_bowing``, ``set_gesture``, ``run(n)``,
``rate``, ``monitor``, ``fault``). Headless, ``run(n)`` computes n samples. In
the GUI the engine's worker computes them in real time; ``EngineLoop`` sends
the settings to it as commands (applied at its next block boundary) and
``run(n)`` hands back the n samples the session controller has just read from
the telemetry ring (``feed``), so ``runner.advance(n / rate)`` ticks the task by
exactly the time the engine ran. Nothing here waits.

Stability. The loop's monitor (``studyapp.model.stability``) watches the
handle's velocity in m/s, which the engine publishes: the simulation's true
velocity, or, for a real device (whose true velocity is NaN), its tachometer.
The same ``StabilityMonitor`` is fed with it, so the verdict follows the same
criterion as headless sessions.

Holding. ``hold(True)`` (pause, emergency stop) sends F_max = 0 and lifts the
bow without changing what the runner asked for; ``hold(False)`` sends the
runner's settings again.

A trial's loop starts as ``ClosedLoop`` would: string at rest, bow lifted
(the runner's own ``bowing`` starts False), the protocol's gesture, the
trial's source, F_max = 0. The engine keeps one noise seed for the session,
so the ``loop_seed`` the runner logs per trial is not used here (the session
log says so in its ``engine`` event).
"""

import numpy as np

from studyapp.errors import ParameterError
from studyapp.model.stability import StabilityMonitor


class EngineLoop:
    def __init__(self, engine, estimators, source, gesture):
        missing = [name for name in estimators if name not in engine.names]
        if missing:
            raise ParameterError(f"estimator {missing[0]!r} is not running in the engine: "
                                 f"allowed are {', '.join(engine.names)}")
        self.engine = engine
        self.rate = float(engine.config.rate)
        self.names = list(estimators)
        self.monitor = StabilityMonitor(self.rate)
        self.source = source
        self.fmax = 0.0
        self.bowing = False
        self.gesture = gesture
        self.held = False
        self._pending = None
        self._fault = None
        engine.set_fmax(0.0)
        engine.set_bowing(False)
        engine.reset_string()
        engine.set_gesture(gesture)
        engine.set_source(source)

    # settings, as the runner makes them ---------------------------------------
    def set_source(self, name):
        self.engine.set_source(name)
        self.source = name

    def set_fmax(self, fmax):
        self.fmax = float(fmax)
        if not self.held:
            self.engine.set_fmax(self.fmax)

    def set_bowing(self, on):
        self.bowing = bool(on)
        if not self.held:
            self.engine.set_bowing(self.bowing)

    def set_gesture(self, name):
        self.gesture = name
        self.engine.set_gesture(name)

    def set_hand_target(self, x_m):
        self.engine.set_hand_target(float(x_m))

    def hold(self, on):
        """Zero F_max and lift the bow (True), or give back the runner's settings (False)."""
        self.held = bool(on)
        self.engine.set_fmax(0.0 if self.held else self.fmax)
        self.engine.set_bowing(False if self.held else self.bowing)

    # running --------------------------------------------------------------
    def feed(self, block):
        """The telemetry block (``Engine.telemetry`` layout) that the next ``run`` returns."""
        self._pending = block

    def run(self, n):
        block = self._pending
        self._pending = None
        if block is None or len(block["force"]) != n:
            have = 0 if block is None else len(block["force"])
            raise RuntimeError(f"EngineLoop.run({n}): the controller fed {have} samples")
        velocity = block["velocity_true"]
        if not np.all(np.isfinite(velocity)):
            velocity = block["velocity_lvt"]
        self.monitor.measure(velocity)
        status = self.engine.status()
        self._fault = status["fault"] or "safety fault" if status["fault_latched"] else None
        return block

    @property
    def fault(self):
        """The engine's latched fault (force held at 0), or None."""
        return self._fault
