"""The closed haptic loop (paper Fig. 1): the controller and a device, block by block.

One sample k of the loop:

    device: hand + mechanics at x[k], v[k] -> sensors x_m, v_m, a_m       (a HapticDevice, device.py)
    -> controller: source velocity -> bow -> string -> force F[k],
       clamped to the motor limits                                       (control.py)
    -> device: moves over [k, k+1] under F[k] (plus the hand's force)

so the position sampled at k+1 is the first to feel F[k] (one-step delay).

Every device goes through one path: ``run(n)`` calls
``device.exchange(control, n, out, est_out)`` once. A real driver inherits
the interface's per-sample ``exchange`` (read the sensors, ``control.sample``,
write the force); the simulated device (simulated_device.py, the default)
overrides it with one compiled function per block that fuses its mechanics,
sensors and hand with the same compiled controller, and gives the same
samples. The loop holds no knowledge of which it drives: what a simulation
knows beyond its sensors (the true motion, for the source TRUE and the
recorded ``*_true`` columns) comes through ``device.truth()``, the gesture
through ``device.follow``.

The other active estimators only observe the stream, so they are stepped
after the block over its recorded sensor samples: exactly the per-sample
result (a test checks it against the Bank's block form), without a dispatch
per estimator per sample inside the loop, and every estimator is warm when
the source switches at a block boundary.

The stability monitor (stability.py) is advanced per sample by the
controller. Python runs only at block boundaries: it applies setting changes
(source, F_max, force scale, bowing, gesture) and reads the monitor's
verdict. While the gesture bows, the monitor judges against TRUE's band levels
on it at the loop's F_max (bowing_reference.py; ``judge=False`` leaves the
monitor on its hold criterion, as the reference's own TRUE runs need).

Built only as needed: the default device has no accelerometer (filter,
noise) when no active estimator reads acceleration (unless
``accelerometer=True``), and there is no body filter when ``audio=False``.

The default device's link to the host (``LoopConfig.link``, link.py): ideal
by default; with a latency, packets, jitter or frame loss the device applies
the newest command that has arrived, and F[k] acts later than [k, k+1].

Safety: a non-finite value anywhere (sensor, estimate, string, force) latches
``fault`` (a one-line description); from that sample on the force is 0 and
the bow is lifted. A device that reports its own ``fault`` has it latched at
the end of the block.
"""

from dataclasses import dataclass, field

import numpy as np

from studyapp.errors import ParameterError
from studyapp.estimators import Bank
from studyapp.estimators.registry import SPECS
from studyapp.estimators.spec import validate_rate
from studyapp.model import body, bow_table, bowed_string, bowing_reference, calibration, contact_mic, control
from studyapp.model.control import (
    C_BOWING, C_BREAKAWAY, C_FORCE_SCALE, C_GAIN, C_PEAK, C_SCALE, C_SOURCE, C_USE_AUDIO, FAULT_DEVICE, FAULT_ESTIMATE,
    FAULT_FORCE, FAULT_SENSOR, FAULT_STRING, L_FAULT, L_FAULT_SAMPLE, N_CONTROL, N_LOOP_STATE, OUTPUTS,
)
from studyapp.model.controls import hand_target
from studyapp.model.device import N_LIMIT_STATE, HapticDevice
from studyapp.model.gestures import Hold, Live, Playback, Strokes
from studyapp.model.limits import FMAX_LIMIT, GESTURES
from studyapp.model.link import LinkSpec
from studyapp.model.playable import check_playable
from studyapp.model.simulated_device import SimulatedDevice
from studyapp.model.sources import LVT_SENSOR, LVT_SENSOR_INDEX, TRUE, TRUE_INDEX, with_pseudo_sources
from studyapp.model.stability import StabilityMonitor

F0_RANGE = (20.0, 2000.0)


@dataclass
class LoopConfig:
    """What the loop simulates. ``estimators``: active set, name -> params ({} = Table 1 defaults)."""

    rate: float = 5000.0
    estimators: dict = field(default_factory=dict)
    source: str = LVT_SENSOR
    fmax: float = 1.0
    gesture: str = "strokes"
    f0: float | None = calibration.F0  # None: the default
    seed: int = 0
    audio: bool = True
    accelerometer: bool | None = None  # None: only when an active estimator reads it
    trajectory: np.ndarray | None = None  # for gesture "playback" (m, at the loop rate)
    link: LinkSpec | None = None  # the simulated device's link (link.py); None: ideal


def make_gesture(name, rate, trajectory=None, position=0.0):
    if name == "strokes":
        return Strokes(calibration.STROKE_AMPLITUDE, calibration.STROKE_SPEED,
                       calibration.STROKE_RAMP, calibration.STROKE_DWELL)
    if name == "strokes-validation":
        return Strokes(**calibration.VALIDATION_STROKES)
    if name == "hold":
        return Hold(0.0, calibration.TREMOR_AMPLITUDE, calibration.TREMOR_HZ)
    if name == "live":
        return Live(position)
    if name == "playback":
        if trajectory is None:
            raise ParameterError("gesture 'playback' needs a trajectory (LoopConfig.trajectory)")
        return Playback(trajectory, rate)
    raise ParameterError(f"unknown gesture {name!r}: allowed are {', '.join(GESTURES)}")


def check_fmax(fmax):
    try:
        value = float(fmax)
    except (TypeError, ValueError):
        value = float("nan")
    if not (0.0 <= value <= FMAX_LIMIT):
        raise ParameterError(f"fmax = {fmax!r}: allowed is a number from 0 to {FMAX_LIMIT:g} N")
    return value + 0.0  # -0 is 0 N (recorded and shown as 0)


def check_f0(f0):
    try:
        value = float(f0)
    except (TypeError, ValueError):
        value = float("nan")
    if not (F0_RANGE[0] <= value <= F0_RANGE[1]):
        raise ParameterError(f"f0 = {f0!r}: allowed is a number from {F0_RANGE[0]:g} to {F0_RANGE[1]:g} Hz")
    return value



class ClosedLoop:
    """A device (the simulated one by default, or any ``HapticDevice``) with the string, run block by block.

    ``run(n)`` advances ``n`` samples and returns a dict of length-n arrays
    (``OUTPUTS`` plus ``t`` and ``estimates``, shape (len(names), n)).
    Settings (``set_*``) take effect at the next ``run``.
    """

    def __init__(self, config=None, device=None, judge=True):
        config = config or LoopConfig()
        self._judge_bowing = bool(judge)
        self.config = config
        self.rate = validate_rate(config.rate)
        f0 = check_f0(calibration.F0 if config.f0 is None else config.f0)
        check_playable(self.rate, f0)
        estimators = config.estimators
        if not isinstance(estimators, dict):
            estimators = {name: {} for name in estimators}
        self.bank = Bank(self.rate, estimators)
        self.names = list(self.bank.names)
        self.reads = set(self.bank.reads)
        if device is None:
            use_acc = ("acceleration" in self.reads) if config.accelerometer is None else bool(config.accelerometer)
            device = SimulatedDevice(self.rate, seed=config.seed, accelerometer=use_acc, link=config.link)
        elif not isinstance(device, HapticDevice):
            raise ParameterError(f"device {type(device).__name__}: expected a studyapp.model.device.HapticDevice "
                                 "(subclass it and implement read_sensors and write_force)")
        if getattr(device, "rate", self.rate) != self.rate:
            raise ParameterError(f"device rate {device.rate:g} Hz differs from the loop rate {self.rate:g} Hz")
        self.device = device
        self.string = bowed_string.StringDesign(self.rate, f0)
        self.velocity_scale = calibration.VELOCITY_SCALE
        self._ctl = np.zeros(N_CONTROL)
        self._ctl[C_SCALE] = self.velocity_scale
        self._ctl[C_PEAK] = self.string.peak_friction()
        self._ctl[C_BREAKAWAY] = bow_table.breakaway(self.string.slope, self.string.offset)
        self._ctl[C_FORCE_SCALE] = 1.0
        self._ctl[C_BOWING] = 1.0
        self._ctl[C_USE_AUDIO] = 1.0 if config.audio else 0.0
        self._state = np.zeros(N_LOOP_STATE)
        self._sp = self.string.params()
        self._ss, self._bridge, self._nut = self.string.new_state()
        self._body = body.sections(self.rate).ravel() if config.audio else np.zeros(0)
        self._body_s = np.zeros(2 * (self._body.shape[0] // 5))
        self._mic = contact_mic.params(self.rate)
        self._mic_s = contact_mic.new_state()
        self._sample = 0
        self._fault_text = None
        self.monitor = StabilityMonitor(self.rate, f0)
        self.control = control.Control((
            self._ctl, self._state, device.limits.params(self.rate), np.zeros(N_LIMIT_STATE),
            self.bank.kinds, self.bank.states, self.bank.params, self._sp, self._ss, self._bridge, self._nut,
            self._body, self._body_s, self.monitor.params, self.monitor.state, self._mic, self._mic_s,
        ))
        self.source = None
        self.set_source(config.source)
        self.fmax = None
        self.set_fmax(config.fmax)
        self.gesture_name = None
        self._trajectory = config.trajectory
        self.set_gesture(config.gesture)

    # settings -------------------------------------------------------------
    def set_source(self, name):
        if name == TRUE:
            if self.device.truth() is None:
                raise ParameterError(f"source {TRUE!r} needs the simulated device (a real one has no true velocity)")
            index = TRUE_INDEX
        elif name == LVT_SENSOR:
            index = LVT_SENSOR_INDEX
        elif name in self.names:
            index = self.names.index(name)
        else:
            allowed = ", ".join(with_pseudo_sources(self.names))
            if name in SPECS:
                raise ParameterError(f"source {name!r} is not an active estimator: allowed are {allowed}")
            raise ParameterError(f"unknown source {name!r}: allowed are {allowed}")
        self.source = name
        self._ctl[C_SOURCE] = index

    def set_fmax(self, fmax):
        self.fmax = check_fmax(fmax)
        self._ctl[C_GAIN] = self.fmax / self.string.peak_friction()
        self._engage()

    def set_force_scale(self, g):
        g = float(g)
        if not np.isfinite(g):
            raise ParameterError(f"force scale = {g!r}: allowed is a number from 0 to 1")
        self._ctl[C_FORCE_SCALE] = min(max(g, 0.0), 1.0)
        self._engage()

    def _engage(self):
        """The monitor judges only a loop with friction: at F_max 0 (or no force) it cannot break (stability.py)."""
        self.monitor.engaged = self.fmax * self._ctl[C_FORCE_SCALE] > 0.0

    def set_bowing(self, on):
        self._ctl[C_BOWING] = 1.0 if on else 0.0

    def set_gesture(self, name, trajectory=None):
        if trajectory is not None:
            self._trajectory = trajectory
        truth = self.device.truth()
        position = truth[0] if truth is not None else 0.0
        self._gesture = make_gesture(name, self.rate, self._trajectory, position)
        self.device.follow(self._gesture)
        self.gesture_name = name
        bowing = self._judge_bowing and bowing_reference.TABLE_GESTURE.get(name) is not None
        self.monitor.reference = self.reference_level if bowing else None
        self.monitor.hiss_reference = self.hiss_reference_level if bowing else None
        if bowing:
            self.reference_level()  # the table now (once per process), not in a live block

    def reference_level(self):
        """TRUE's band level (m/s) on this gesture at this F_max: what the monitor judges against while bowing."""
        return bowing_reference.level(self.rate, self.string.f0, self.gesture_name, self.fmax)

    def hiss_reference_level(self):
        """TRUE's upper band level (m/s) on this gesture at this F_max (None where the rate has no upper band)."""
        return bowing_reference.hiss_level(self.rate, self.string.f0, self.gesture_name, self.fmax)

    def set_hand_target(self, x_m):
        x_m = hand_target(x_m)  # 1e308 latched a loop fault: refused like NaN (issue 41, item 17)
        if not isinstance(self._gesture, Live):
            self.set_gesture("live")
        self._gesture.set(x_m)

    def reset_string(self):
        """Put the string (and the body filter) at rest; the stability monitor starts afresh with it.

        A device that runs the loop itself (device/loop_link.py) resets its string at a sample of its own:
        the host's shadow of the loop is put at rest at that same sample, so the reset is handed to it.
        """
        defer = getattr(self.device, "defer_reset", None)
        if defer is not None:
            defer(self._rest)
        else:
            self._rest()

    def _rest(self):
        self._ss[:] = 0.0
        self._bridge[:] = 0.0
        self._nut[:] = 0.0
        self._body_s[:] = 0.0
        self._mic_s[:] = 0.0
        self.monitor.reset()

    @property
    def fault(self):
        return self._fault_text

    @property
    def force_scale(self):
        return float(self._ctl[C_FORCE_SCALE])

    @property
    def bowing(self):
        return bool(self._ctl[C_BOWING])

    # running ---------------------------------------------------------------
    def run(self, n):
        n = int(n)
        if n < 0:
            raise ParameterError(f"n = {n}: allowed is a number of samples >= 0")
        out = np.zeros((len(OUTPUTS), n))
        est = np.zeros((len(self.names), n))
        self.device.exchange(self.control, n, out, est)
        if not getattr(self.device, "steps_every_estimator", False):  # a device loop's shadow steps them per row
            src = int(self._ctl[C_SOURCE])
            control.observe_others(src, self.bank.kinds, self.bank.states, self.bank.params, out, est)
        if self._state[L_FAULT] == 0.0 and self.device.fault:
            self._state[L_FAULT] = FAULT_DEVICE
            self._state[L_FAULT_SAMPLE] = max(n - 1, 0)
        if self._fault_text is None and self._state[L_FAULT] != 0.0:
            self._fault_text = self._describe_fault()
        result = {name: out[i] for i, name in enumerate(OUTPUTS)}
        result["t"] = (self._sample + np.arange(n)) / self.rate
        result["estimates"] = est
        self._sample += n
        self.monitor.judge()
        return result

    def clear_device_fault(self):
        """Unlatch a fault the device reported (after the experimenter re-armed it); True if there was one.

        Only a device fault: a non-finite value inside the loop stays latched for good.
        """
        if self._state[L_FAULT] != FAULT_DEVICE:
            return False
        self._state[L_FAULT] = 0.0
        self._state[L_FAULT_SAMPLE] = 0.0
        self._fault_text = None
        return True

    def _describe_fault(self):
        code = int(self._state[L_FAULT])
        t = (self._sample + max(self._state[L_FAULT_SAMPLE], 0)) / self.rate
        what = {
            FAULT_SENSOR: "a sensor sample",
            FAULT_ESTIMATE: f"the velocity source {self.source}",
            FAULT_STRING: "the string model",
            FAULT_FORCE: "the device force",
        }
        if code == FAULT_DEVICE:
            return f"device fault at t = {t:.4f} s ({self.device.fault}); force held at 0"
        return f"non-finite value from {what[code]} at t = {t:.4f} s; force held at 0"
