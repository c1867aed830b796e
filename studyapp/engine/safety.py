"""Safety around the closed loop: clamps, latched faults, and a runaway detector.

Three layers keep a fault from leaving the device pushing:

1. Clamps. F_max is clamped to the protocol's ceiling (``SafetyLimits.fmax_ceiling``,
   from ``Protocol.fmax_ceiling`` for a session, the console's preview and
   ``live --protocol``; the motors' sustained limit otherwise) before the loop sees it, and the
   friction force is at most F_max by construction (the bow table caps |rho(v) v| at its peak,
   model/bow_table.py: the string and the handle feel that one capped force), so no force command
   exceeds the ceiling on any path; inside the loop the force is also clamped to the motor limits
   (model/device.py). After each block ``check`` verifies that no sample exceeded either bound
   (to 1e-9 relative: the bound is exact, not found numerically).
2. Latched faults. A non-finite value anywhere in a block (the loop latches
   its own fault the moment one appears and zeroes the force from that sample
   on), a clamp found violated, or the ``force_enable`` word cleared (the
   experimenter's emergency stop, the force guard finding the worker silent, or
   the worker finding the guard silent, engine/guard.py: the fault says which,
   ``force_off_text``): the force scale goes to 0 and stays there until
   ``clear()`` (an experimenter's decision, never automatic). The word is read
   twice per block: before the block runs (``before_block``), so a worker
   that was stopped or starved while the watchdog tripped computes its next
   block with zero force from the first sample; and after its telemetry is
   staged in the ring, just before the commit (``check``), so a block in
   flight across the trip has its force withheld (set to 0) instead of
   written. A worker stopped between that read and the commit leaves its
   block staged, and the force guard withholds it (engine/guard.py). After a
   trip not one sample of non-zero force leaves the worker, SIGCONT or not.
3. Runaway. A sample is *suspect* when the motor is saturated (|F| >=
   ``saturation`` x the device's sustained limit, 60 N for the TGR) or the
   handle moves faster than ``velocity_bound``. When suspect samples fill at
   least ``fraction`` of the last ``window`` seconds the loop has run away:
   the force scale ramps linearly to 0 over ``ramp`` seconds
   (``ClosedLoop.set_force_scale``, one step per block) and the fault latches.

   Why these numbers (measured on the simulated loop, 4 s of strokes, 0.25 s
   windows; issue 20's world of a 0.1 kg end-effector on a grip, 2026-11-25):
   the friction force is at most F_max by construction (eq. 20 and the bow
   table's cap), so saturation is measured against the motor, not against F_max. Bowing at the default
   ceiling F_max = 60 N leaves at most 20 % of a window suspect with TRUE,
   17 % with LVT, 21 % with LOWPASS and 32 % with LEVANT; a loop driven at
   F_max = 200 N, where the sustained limit (60 N RMS) chops the force, leaves
   73-79 % suspect with LOWPASS (strokes or hold) and 82-90 % with LVT and
   TRUE. Hence 60 % over 0.25 s (85 % for issue 11's 1 kg handle, which a
   runaway pinned for 90-100 %), and 0.3 m/s (twice the strokes' 0.15 m/s;
   the handle cannot keep up a larger speed for long inside its 22 mm of
   travel).

The detector works at block boundaries, so its reaction comes one block later
than the block that showed the problem; the loop's own non-finite check acts on
the very sample.
"""

from collections import deque
from dataclasses import dataclass

import numpy as np

from studyapp.errors import ParameterError
from studyapp.model.device import DeviceLimits


WATCHDOG = "watchdog: the parent switched the force off"
CLEAR_HINT = "press Resume to clear"


def force_off_text(reason, silence=0.0):
    """The fault, in plain words, for ``force_enable`` cleared for ``reason`` (status.FORCE_OFF_REASONS)."""
    if reason in ("operator", "participant"):
        return f"Emergency stop ({reason}): force off — {CLEAR_HINT}"
    if reason == "watchdog":
        return (f"watchdog: the engine stopped answering for {1e3 * silence:.0f} ms; force switched off for "
                f"safety — {CLEAR_HINT}")
    if reason == "guard":
        return (f"watchdog: the force guard stopped answering for {1e3 * silence:.0f} ms; force switched off for "
                "safety — restart the engine")
    if reason == "owner":
        return ("watchdog: the program that runs the engine was stopped or ended; force switched off for safety "
                "— restart the engine")
    return WATCHDOG


@dataclass(frozen=True)
class SafetyLimits:
    fmax_ceiling: float = DeviceLimits().sustained  # N: the motors' 60 N unless the protocol sets a lower one
    velocity_bound: float = 0.3  # m/s; bowing strokes move at a few cm/s
    saturation: float = 0.95  # fraction of the motor's sustained limit that counts as saturated
    window: float = 0.25  # s
    fraction: float = 0.6  # of the window's samples suspect -> runaway
    ramp: float = 0.5  # s from full force to zero


class Safety:
    """Watches one ``ClosedLoop`` (or anything with ``set_force_scale``, ``fault``, ``fmax``)."""

    def __init__(self, loop, limits=None, motor_limits=None):
        self.loop = loop
        self.limits = limits or SafetyLimits()
        self.rate = float(loop.rate)
        impulsive, sustained = motor_limits if motor_limits is not None else _motor_limits(loop)
        self.motor_limit = float(impulsive)  # the clamp no sample may exceed
        self.motor_sustained = float(sustained)  # the level that counts as saturated
        self.latched = None  # the fault text while latched
        self.faults = []  # every fault raised, in order
        self.scale = 1.0
        self._ramping = False
        self._window = deque()  # (samples, suspect samples) per block
        self._window_samples = 0
        self._window_suspect = 0
        self._previous_force_scale = 1.0

    # clamps -----------------------------------------------------------------
    def clamp_fmax(self, fmax):
        """F_max limited to the ceiling; ``ParameterError`` for a negative or non-finite value."""
        try:
            value = float(fmax)
        except (TypeError, ValueError):
            value = float("nan")
        if not np.isfinite(value) or value < 0:
            raise ParameterError(f"fmax = {fmax!r}: allowed is a number from 0 to {self.limits.fmax_ceiling:g} N")
        return min(value, self.limits.fmax_ceiling) + 0.0  # -0 is 0 N

    # faults -----------------------------------------------------------------
    def latch(self, text):
        """Zero the force from the next block on and hold it there until ``clear``."""
        if self.latched is None:
            self.latched = text
            self.faults.append(text)
        self.scale = 0.0
        self.loop.set_force_scale(0.0)

    def clear(self):
        """The experimenter's reset: full force again, detector restarted."""
        self.latched = None
        self._ramping = False
        self._window.clear()
        self._window_samples = self._window_suspect = 0
        self.scale = 1.0
        self._previous_force_scale = 1.0  # the next block runs at full scale: its clamp is F_max again
        self.loop.set_force_scale(1.0)

    def before_block(self, force_enable, why=WATCHDOG):
        """Just before a block runs: a cleared ``force_enable`` zeroes that block's force already."""
        if not force_enable:
            self.latch(why)

    def check(self, block, force_enable=True, why=WATCHDOG):
        """Inspect one block just run, before its force is written; returns the fault it raised, or ``None``.

        With ``force_enable`` cleared the block's force is withheld: set to 0 in place, and the fault
        latched is ``why`` (``force_off_text``).
        """
        before = len(self.faults)
        if not force_enable:
            self.latch(why)
            block["force"][:] = 0.0
        loop_fault = getattr(self.loop, "fault", None)
        if loop_fault:
            self.latch(f"loop fault: {loop_fault}")
        force = block["force"]
        if self.latched is None:
            bad = _first_nonfinite(block)
            if bad is not None:
                self.latch(f"non-finite {bad} in the loop")
        if self.latched is None and force.size:
            bound = min(self.loop.fmax, self.motor_limit) * self._previous_force_scale
            peak = float(np.max(np.abs(force)))
            # the cap is exact (model/bow_table.py): rounding only
            if peak > bound * (1.0 + 1e-9) + 1e-12:
                self.latch(f"force {peak:.4g} N exceeded its clamp {bound:.4g} N")
        self._runaway(block)
        self._previous_force_scale = self.scale
        return self.faults[-1] if len(self.faults) > before else None

    def _runaway(self, block):
        force = block["force"]
        n = force.shape[0]
        if n == 0:
            return
        if self._ramping or self.latched is not None:
            if self._ramping and self.scale > 0.0:
                self.scale = max(0.0, self.scale - n / (self.rate * self.limits.ramp))
                self.loop.set_force_scale(self.scale)
            return
        velocity = block.get("velocity_true")
        if velocity is None or not np.all(np.isfinite(velocity)):
            velocity = block["source_velocity"]
        suspect = np.abs(velocity) > self.limits.velocity_bound
        suspect |= np.abs(force) >= self.limits.saturation * self.motor_sustained
        count = int(np.count_nonzero(suspect))
        self._window.append((n, count))
        self._window_samples += n
        self._window_suspect += count
        horizon = self.limits.window * self.rate
        while self._window and self._window_samples - self._window[0][0] >= horizon:
            old_n, old_count = self._window.popleft()
            self._window_samples -= old_n
            self._window_suspect -= old_count
        if self._window_samples >= horizon and self._window_suspect >= self.limits.fraction * self._window_samples:
            share = self._window_suspect / self._window_samples
            self.latched = (f"runaway: motor saturated or velocity beyond {self.limits.velocity_bound:g} m/s "
                            f"for {100 * share:.0f}% of {self.limits.window:g} s; force ramped to zero")
            self.faults.append(self.latched)
            self._ramping = True
            self.scale = max(0.0, self.scale - n / (self.rate * self.limits.ramp))
            self.loop.set_force_scale(self.scale)


_WATCHED = ("force", "position", "velocity_lvt", "source_velocity", "string_velocity")


def _first_nonfinite(block):
    for key in _WATCHED:
        values = block.get(key)
        if values is not None and values.size and not np.all(np.isfinite(values)):
            return key
    estimates = block.get("estimates")
    if estimates is not None and estimates.size and not np.all(np.isfinite(estimates)):
        return "estimate"
    return None


def _motor_limits(loop):
    device = getattr(loop, "device", None)
    limits = getattr(device, "limits", None)
    return float(getattr(limits, "impulsive", np.inf)), float(getattr(limits, "sustained", np.inf))
