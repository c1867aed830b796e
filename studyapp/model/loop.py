"""The closed haptic loop (paper Fig. 1), one compiled function per block.

One sample k of the loop:

    hand + device state x[k], v[k]        (device.py, hand.py)
    -> sensors: LVDT x_m, LVT v_m, accelerometer a_m    (sensors.py)
    -> the source velocity: the selected estimator stepped on (x_m, a_m, v_m)
       (studyapp.estimators.dispatch.step_guarded), the LVT sensor, or TRUE v[k]
    -> bow: v_bow = s * v_source (string units; s = VELOCITY_SCALE, calibration.py)
    -> string step (bowed_string.py): u = rho(v_delta) v_delta
    -> force F[k] = -G u * force_scale, clamped to the motor limits (device.py)
    -> the device moves over [k, k+1] under F[k] plus the hand's force

so the position sampled at k+1 is the first to feel F[k] (one-step delay).
G = F_max / max|rho(v) v| makes the peak friction force F_max (bow_table.py,
paper eqs. 2 and 20).

The other active estimators only observe the stream, so they are stepped
after the block over its recorded sensor samples: exactly the per-sample
result (a test checks it against the Bank's block form), without a dispatch
per estimator per sample inside the loop, and every estimator is warm when
the source switches at a block boundary.

The stability monitor (stability.py) is advanced per sample inside the block.
Python runs only at block boundaries: it draws the block's sensor noise from
seeded generators (one per sensor, two for the accelerometer's white and
low-frequency noise, so the stream does not depend on how the run is cut into
blocks), computes the gesture's target, applies setting
changes (source, F_max, force scale, bowing, gesture) and reads the
monitor's verdict. Everything inside a block is one ``@njit`` function.

Built only as needed: no accelerometer (filter, noise) when no active
estimator reads acceleration (unless ``accelerometer=True``), and no body
filter when ``audio=False``.

Compiled with numpy's error model (as the estimator dispatch is): a division
by zero gives inf, not an exception, and inf is caught as a fault below. The
block releases the GIL (``nogil``): in the live engine the audio device's
callback thread needs it. Holding it through every block, a 10-minute run at
48 kHz on a dummy JACK server had one "client not finished" xrun; releasing
it, two such runs had none.

Safety: a non-finite value anywhere (sensor, estimate, string, device) latches
``fault`` (a one-line description); from that sample on the force is 0 and the
bow is lifted.
"""

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from studyapp.errors import ParameterError
from studyapp.estimators import Bank
from studyapp.estimators.dispatch import run_block as run_estimator_block
from studyapp.estimators.dispatch import step_guarded
from studyapp.estimators.registry import SPECS
from studyapp.estimators.spec import validate_rate
from studyapp.model import body, bow_table, bowed_string, calibration, contact_mic, hand, sensors, stability
from studyapp.model import device as mechanics
from studyapp.model.gestures import Hold, Live, Playback, Strokes
from studyapp.model.sources import LVT_SENSOR, LVT_SENSOR_INDEX, TRUE, TRUE_INDEX, with_pseudo_sources
from studyapp.model.stability import StabilityMonitor

FMAX_LIMIT = 200.0  # N: nothing above the motors' impulsive limit makes sense
F0_RANGE = (20.0, 2000.0)

# control vector
C_GAIN, C_SCALE, C_FORCE_SCALE, C_BOWING, C_SOURCE, C_USE_ACC, C_USE_AUDIO, C_PEAK, C_BREAKAWAY = range(9)
N_CONTROL = 9
# loop state
L_FAULT, L_FAULT_SAMPLE, L_PUSH = range(3)
FAULT_SENSOR, FAULT_ESTIMATE, FAULT_STRING, FAULT_DEVICE = 1, 2, 3, 4
# output rows
(O_POSITION, O_VELOCITY_LVT, O_ACCELERATION, O_VELOCITY_TRUE, O_ACCELERATION_TRUE,
 O_FORCE, O_STRING_VELOCITY, O_AUDIO, O_SOURCE_VELOCITY, O_V_DELTA, O_STICK, O_HAND_FORCE,
 O_FRICTION, O_POSITION_TRUE) = range(14)
OUTPUTS = (
    "position", "velocity_lvt", "acceleration", "velocity_true", "acceleration_true",
    "force", "string_velocity", "audio", "source_velocity", "v_delta", "stick", "hand_force", "friction",
    "position_true",
)

GESTURES = ("strokes", "strokes-validation", "hold", "live", "playback")


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
    return value


def check_f0(f0):
    try:
        value = float(f0)
    except (TypeError, ValueError):
        value = float("nan")
    if not (F0_RANGE[0] <= value <= F0_RANGE[1]):
        raise ParameterError(f"f0 = {f0!r}: allowed is a number from {F0_RANGE[0]:g} to {F0_RANGE[1]:g} Hz")
    return value


@njit(cache=True, inline="always")
def _bad(x):
    return not np.isfinite(x)


@njit(cache=True, inline="always")
def _fault(state, code, k):
    if state[L_FAULT] == 0.0:
        state[L_FAULT] = code
        state[L_FAULT_SAMPLE] = k


@njit(cache=True, inline="always")
def bow_and_force(ctl, state, k, v_src, sp, ss, bridge, nut, body_p, body_s, out):
    """The string and the force for one sample of the source velocity; returns the unclamped force (N)."""
    if _bad(v_src):
        _fault(state, FAULT_ESTIMATE, k)
    faulted = state[L_FAULT] != 0.0
    bowing = ctl[C_BOWING] != 0.0 and not faulted
    v_bow = ctl[C_SCALE] * v_src if bowing else 0.0
    u, v_string, v_bridge, v_delta = bowed_string.step(sp, ss, bridge, nut, v_bow, bowing)
    if _bad(u) or _bad(v_string) or _bad(v_bridge):
        _fault(state, FAULT_STRING, k)
        # a poisoned string is set back to rest so every output stays finite
        bridge[:] = 0.0
        nut[:] = 0.0
        ss[:] = 0.0
        u = 0.0
        v_string = 0.0
        v_bridge = 0.0
        v_delta = 0.0
    if state[L_FAULT] != 0.0:
        u = 0.0
    audio = 0.0
    if ctl[C_USE_AUDIO] != 0.0:
        audio = v_bridge
        for j in range(body_s.shape[0] // 2):
            audio = sensors.section_at(body_p, 5 * j, body_s, 2 * j, audio)
    friction = u / ctl[C_PEAK]
    out[O_SOURCE_VELOCITY, k] = v_src
    out[O_STRING_VELOCITY, k] = v_string / ctl[C_SCALE]
    out[O_AUDIO, k] = audio
    out[O_V_DELTA, k] = v_delta
    out[O_FRICTION, k] = friction
    out[O_STICK, k] = 1.0 if bowing and abs(v_delta) <= ctl[C_BREAKAWAY] else 0.0
    return -ctl[C_GAIN] * u * ctl[C_FORCE_SCALE]


@njit(cache=True, error_model="numpy")
def observe_others(src, kinds, est_s, est_p, out, est_out):
    """Advance every estimator but the source over the block, from the recorded sensor rows.

    They only observe the stream, so stepping each over the whole block in turn
    gives exactly the per-sample result (DESIGN.md, "Data flow").
    """
    for e in range(kinds.shape[0]):
        if e != src:
            run_estimator_block(kinds[e], est_s[e], est_p[e], out[O_POSITION], out[O_ACCELERATION],
                                out[O_VELOCITY_LVT], est_out[e])


@njit(cache=True, error_model="numpy", nogil=True)
def run_block(ctl, state, dp, ds, hp, snp, sns, kinds, est_s, est_p, sp, ss, bridge, nut,
              body_p, body_s, cp, cs, mp, ms, target, target_v, target_a, noise_x, noise_v, noise_a, noise_lf,
              out, est_out):
    """``target.shape[0]`` samples of the simulated world; fills ``out`` and ``est_out``."""
    n = target.shape[0]
    use_acc = ctl[C_USE_ACC] != 0.0
    src = int(ctl[C_SOURCE])
    for k in range(n):
        x = ds[mechanics.DS_X]
        v = ds[mechanics.DS_V]
        a = ds[mechanics.DS_A]
        x_m = sensors.lvdt(snp, x, noise_x[k])
        v_m = sensors.lvt(snp, sns, v, noise_v[k])
        a_m = sensors.accelerometer(snp, sns, a, noise_a[k], noise_lf[k]) if use_acc else 0.0
        if _bad(x_m) or _bad(v_m) or _bad(a_m):
            _fault(state, FAULT_SENSOR, k)
        if src >= 0:
            v_src = step_guarded(kinds[src], est_s[src], est_p[src], x_m, a_m, v_m)
            est_out[src, k] = v_src
        elif src == TRUE_INDEX:
            v_src = v
        else:
            v_src = v_m
        f = bow_and_force(ctl, state, k, v_src, sp, ss, bridge, nut, body_p, body_s, out)
        stability.observe(mp, ms, v)
        if ctl[C_USE_AUDIO] != 0.0:
            out[O_AUDIO, k] += contact_mic.step(cp, cs, a)
        f = mechanics.clamp_force(dp, ds, f)
        f_hand = hand.force(hp, target[k], target_v[k], target_a[k], x, v, state[L_PUSH])
        if _bad(f) or _bad(f_hand):
            _fault(state, FAULT_DEVICE, k)
        if state[L_FAULT] != 0.0:
            f = 0.0
            if _bad(f_hand) or _bad(state[L_PUSH]):
                f_hand = 0.0
                state[L_PUSH] = 0.0
                ds[mechanics.DS_X] = 0.0
                ds[mechanics.DS_V] = 0.0
                ds[mechanics.DS_A] = 0.0
        state[L_PUSH] = hand.learn_push(hp, state[L_PUSH], f)
        out[O_POSITION, k] = x_m
        out[O_VELOCITY_LVT, k] = v_m
        out[O_ACCELERATION, k] = a_m
        out[O_VELOCITY_TRUE, k] = v
        out[O_ACCELERATION_TRUE, k] = a
        out[O_POSITION_TRUE, k] = x
        out[O_FORCE, k] = f
        out[O_HAND_FORCE, k] = f_hand
        mechanics.advance(dp, ds, f + f_hand)
    observe_others(src, kinds, est_s, est_p, out, est_out)


@njit(cache=True, error_model="numpy")
def run_external_sample(ctl, state, k, dp, ds, kinds, est_s, est_p, sp, ss, bridge, nut,
                        body_p, body_s, cp, cs, mp, ms, x_m, a_m, v_m, out, est_out):
    """One sample for a device outside the simulation: returns the clamped force command."""
    if _bad(x_m) or _bad(v_m) or _bad(a_m):
        _fault(state, FAULT_SENSOR, k)
    for e in range(kinds.shape[0]):
        est_out[e, k] = step_guarded(kinds[e], est_s[e], est_p[e], x_m, a_m, v_m)
    src = int(ctl[C_SOURCE])
    v_src = est_out[src, k] if src >= 0 else v_m
    f = bow_and_force(ctl, state, k, v_src, sp, ss, bridge, nut, body_p, body_s, out)
    stability.observe(mp, ms, v_m)
    if ctl[C_USE_AUDIO] != 0.0:
        out[O_AUDIO, k] += contact_mic.step(cp, cs, a_m)
    f = mechanics.clamp_force(dp, ds, f)
    if state[L_FAULT] != 0.0 or _bad(f):
        f = 0.0
    out[O_POSITION, k] = x_m
    out[O_VELOCITY_LVT, k] = v_m
    out[O_ACCELERATION, k] = a_m
    out[O_VELOCITY_TRUE, k] = np.nan
    out[O_ACCELERATION_TRUE, k] = np.nan
    out[O_POSITION_TRUE, k] = np.nan
    out[O_FORCE, k] = f
    out[O_HAND_FORCE, k] = np.nan
    return f


class ClosedLoop:
    """The simulated world (or a real device) with the string, run block by block.

    ``run(n)`` advances ``n`` samples and returns a dict of length-n arrays
    (``OUTPUTS`` plus ``t`` and ``estimates``, shape (len(names), n)).
    Settings (``set_*``) take effect at the next ``run``.
    """

    def __init__(self, config=None, device=None):
        config = config or LoopConfig()
        dev = device
        self.config = config
        self.rate = validate_rate(config.rate)
        f0 = check_f0(calibration.F0 if config.f0 is None else config.f0)
        estimators = config.estimators
        if not isinstance(estimators, dict):
            estimators = {name: {} for name in estimators}
        self.bank = Bank(self.rate, estimators)
        self.names = list(self.bank.names)
        self.reads = set(self.bank.reads)
        if dev is None:
            dev = mechanics.SimulatedDevice(self.rate, calibration.DEVICE_MASS)
        self.device = dev
        self.simulated = isinstance(dev, mechanics.SimulatedDevice)
        if getattr(dev, "rate", self.rate) != self.rate:
            raise ParameterError(f"device rate {dev.rate:g} Hz differs from the loop rate {self.rate:g} Hz")
        self.string = bowed_string.StringDesign(self.rate, f0)
        self.sensor_spec = sensors.SensorSpec()
        self.hand = hand.HandImpedance(calibration.HAND_MASS, calibration.HAND_STIFFNESS, calibration.HAND_DAMPING,
                                       calibration.HAND_REACTION)
        self.velocity_scale = calibration.VELOCITY_SCALE
        use_acc = ("acceleration" in self.reads) if config.accelerometer is None else bool(config.accelerometer)
        self._ctl = np.zeros(N_CONTROL)
        self._ctl[C_SCALE] = self.velocity_scale
        self._ctl[C_PEAK] = self.string.peak_friction()
        self._ctl[C_BREAKAWAY] = bow_table.breakaway(self.string.slope, self.string.offset)
        self._ctl[C_FORCE_SCALE] = 1.0
        self._ctl[C_BOWING] = 1.0
        self._ctl[C_USE_ACC] = 1.0 if use_acc else 0.0
        self._ctl[C_USE_AUDIO] = 1.0 if config.audio else 0.0
        self._state = np.zeros(3)
        # the hand's mass moves with the handle (hand.py)
        self._dp = dev.params(extra_mass=self.hand.mass) if self.simulated else _limits_params(self.rate, dev.limits)
        self._ds = np.zeros(mechanics.N_STATE)
        self._hp = self.hand.params(self._dp[mechanics.DP_MASS], self.rate) if self.simulated else np.zeros(4)
        self._snp = self.sensor_spec.params(self.rate)
        self._sns = np.zeros(sensors.N_STATE)
        self._sp = self.string.params()
        self._ss, self._bridge, self._nut = self.string.new_state()
        self._body = body.sections(self.rate).ravel() if config.audio else np.zeros(0)
        self._body_s = np.zeros(2 * (self._body.shape[0] // 5))
        self._mic = contact_mic.params(self.rate)
        self._mic_s = contact_mic.new_state()
        # the accelerometer's low-frequency noise is the 4th child, so the first three streams stay as they were
        seeds = np.random.SeedSequence(int(config.seed)).spawn(4)
        self._rng_x, self._rng_v, self._rng_a, self._rng_lf = (np.random.default_rng(s) for s in seeds)
        self._sample = 0
        self._fault_text = None
        self.source = None
        self.set_source(config.source)
        self.fmax = None
        self.set_fmax(config.fmax)
        self.gesture_name = None
        self._trajectory = config.trajectory
        self.set_gesture(config.gesture)
        self.monitor = StabilityMonitor(self.rate, f0)

    # settings -------------------------------------------------------------
    def set_source(self, name):
        if name == TRUE:
            if not self.simulated:
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

    def set_force_scale(self, g):
        g = float(g)
        if not np.isfinite(g):
            raise ParameterError(f"force scale = {g!r}: allowed is a number from 0 to 1")
        self._ctl[C_FORCE_SCALE] = min(max(g, 0.0), 1.0)

    def set_bowing(self, on):
        self._ctl[C_BOWING] = 1.0 if on else 0.0

    def set_gesture(self, name, trajectory=None):
        if trajectory is not None:
            self._trajectory = trajectory
        position = self._ds[mechanics.DS_X] if self.simulated else 0.0
        self._gesture = make_gesture(name, self.rate, self._trajectory, position)
        self._gesture_start = self._sample
        self.gesture_name = name

    def set_hand_target(self, x_m):
        x_m = float(x_m)
        if not np.isfinite(x_m):
            raise ParameterError(f"hand target = {x_m!r}: allowed is a finite position in metres")
        if not isinstance(self._gesture, Live):
            self.set_gesture("live")
        self._gesture.set(x_m)

    def reset_string(self):
        """Put the string (and the body filter) at rest; the stability monitor starts afresh with it."""
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
        if self.simulated:
            self._run_simulated(n, out, est)
        else:
            self._run_external(n, out, est)
        if self._fault_text is None and self._state[L_FAULT] != 0.0:
            self._fault_text = self._describe_fault()
        result = {name: out[i] for i, name in enumerate(OUTPUTS)}
        result["t"] = (self._sample + np.arange(n)) / self.rate
        result["estimates"] = est
        self._sample += n
        self.monitor.judge()
        return result

    def _run_simulated(self, n, out, est):
        target, target_v, target_a = self._gesture.block(self._sample - self._gesture_start, n, self.rate)
        nx = self._rng_x.standard_normal(n)
        nv = self._rng_v.standard_normal(n)
        na = self._rng_a.standard_normal(n) if self._ctl[C_USE_ACC] else np.zeros(n)
        nl = self._rng_lf.standard_normal(n) if self._ctl[C_USE_ACC] else np.zeros(n)
        run_block(self._ctl, self._state, self._dp, self._ds, self._hp, self._snp, self._sns,
                  self.bank.kinds, self.bank.states, self.bank.params, self._sp, self._ss,
                  self._bridge, self._nut, self._body, self._body_s, self._mic, self._mic_s,
                  self.monitor.params, self.monitor.state,
                  np.ascontiguousarray(target), np.ascontiguousarray(target_v), np.ascontiguousarray(target_a),
                  nx, nv, na, nl, out, est)

    def _run_external(self, n, out, est):
        dev = self.device
        for k in range(n):
            x_m, a_m, v_m = dev.read_sensors()
            f = run_external_sample(self._ctl, self._state, k, self._dp, self._ds, self.bank.kinds,
                                    self.bank.states, self.bank.params, self._sp, self._ss, self._bridge,
                                    self._nut, self._body, self._body_s, self._mic, self._mic_s, self.monitor.params,
                                    self.monitor.state,
                                    float(x_m), float(a_m), float(v_m),
                                    out, est)
            dev.write_force(f)

    def _describe_fault(self):
        code = int(self._state[L_FAULT])
        t = (self._sample + max(self._state[L_FAULT_SAMPLE], 0)) / self.rate
        what = {
            FAULT_SENSOR: "a sensor sample",
            FAULT_ESTIMATE: f"the velocity source {self.source}",
            FAULT_STRING: "the string model",
            FAULT_DEVICE: "the device force",
        }[code]
        return f"non-finite value from {what} at t = {t:.4f} s; force held at 0"


def _limits_params(rate, limits):
    return mechanics.SimulatedDevice(rate, 1.0, limits).params()
