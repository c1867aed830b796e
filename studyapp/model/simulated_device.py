"""The simulated 1-DOF device, held by the virtual hand, behind the device interface (paper Sec. 4).

``SimulatedDevice`` is a ``HapticDevice`` (device.py): the loop drives it as
it drives a real one. It holds what a real device has in the world: the
moving mass, the sensors (sensors.py) with their seeded noise, and the hand
that holds the handle and follows a gesture (hand.py, gestures.py).

The mechanics: two masses. The end-effector (mass m_e: the device's moving
parts and sensors, calibration.DEVICE_MASS) between end stops at +-11 mm (the
LVDT's 2.2 cm range), pushed by the motor; the hand (m_h), held to it by the
grip (a spring K_g and damper B_g, hand.py) and driven by the arm along the
gesture. With s = (x, v, x_h, v_h), end-effector then hand,

    ds/dt = A s + B (F, F_arm),   A = [[0, 1, 0, 0],
                                       [-K_g/m_e, -B_g/m_e, K_g/m_e, B_g/m_e],
                                       [0, 0, 0, 1],
                                       [K_g/m_h, B_g/m_h, -K_g/m_h, -B_g/m_h]],
                                  B = [[0, 0], [1/m_e, 0], [0, 0], [0, 1/m_h]].

The force command F[k] computed from the sensors at sample k is held over
[k, k+1] (zero-order hold), and so is the arm's force F_arm[k] from the state
at k; so the position sampled at k+1 is the first to feel F[k]: the one-step
delay of the paper's Fig. 1 and Sec. 2. Behind a link (``link``, a
link.LinkSpec: latency, packets, jitter, frame loss; link.py states the maths)
the device applies instead the link's force u[k], the newest command that has
arrived: with a fixed latency of L samples u[k] = F[k - L] (0 N before the
first command arrives). The recorded force is the host's command F[k]; the
hand and the mechanics feel u[k]. The default link is ideal: u[k] = F[k].

Over one step the pair moves exactly
(the zero-order-hold discretisation, Phi = exp(A T) and
Gamma = int_0^T exp(A s) ds B, computed once by zoh.py in a fixed order of
float operations, not with scipy.linalg.expm, whose BLAS products round
differently on different CPUs: issue 39), so the stiff grip is stable at
every rate:

    s[k+1] = Phi s[k] + Gamma (u[k], F_arm[k]).

The end-effector's acceleration is its mean over the step, (v[k+1] - v[k]) / T.
An end stop is inelastic: the end-effector's position is held at the stop and
its velocity into it is set to zero (a rigid stop; the hand is not stopped: the
grip stretches).

Two paths give the same samples. ``read_sensors`` / ``write_force`` step the
world one sample (the hand's force and the sensors from the state at k, then
the move under F[k] plus the hand's force); ``exchange`` runs a whole block in
one compiled function that calls the loop's compiled controller
(control.sample) between the same two steps, releasing the GIL (``nogil``:
in the live engine the audio device's callback thread needs it). Python runs
only at block boundaries there: it draws the block's sensor noise from seeded
generators (one per sensor, two for the LVDT's conditioner and converter
noise and two for the accelerometer's white and low-frequency noise, two for
the link's jitter and frame loss, so the stream
does not depend on how the run is cut into blocks or samples), the link's
per-packet delays, and the gesture's target. A gesture defined per
block (``Live``, which ramps to its new target across the next block) ramps
across one sample when read sample by sample.

No accelerometer (filter, noise) when ``accelerometer=False``: it reads 0.

``nudge`` (n rounding steps; nudge.py, default the environment's
``STUDYAPP_NUDGE``, 0) starts the end-effector at n * spacing(travel) instead
of 0: the one-rounding probe of docs/reproducibility.md.

A non-finite hand force (a gesture that overflows) makes the hand let go and
puts the handle at rest at 0, keeping every output finite, and sets ``fault``.
"""

import numpy as np
from numba import njit

from studyapp.estimators.dispatch import step_guarded
from studyapp.model import calibration, contact_mic, control, hand, nudge as rounding, sensors, stability, zoh
from studyapp.model.device import DeviceLimits, HapticDevice
from studyapp.model.gestures import Hold
from studyapp.model.link import IDEAL, Link, step as link_step
from studyapp.model.sources import TRUE_INDEX

DP_T, DP_MASS, DP_TRAVEL, DP_ACCELEROMETER, DP_KG, DP_BG = range(6)
DP_PHI = 6  # Phi, 4 x 4 row-major
DP_GAMMA = DP_PHI + 16  # Gamma, 4 x 2 row-major
N_PARAMS = DP_GAMMA + 8
# state: the end-effector's true position, velocity, acceleration over the last step, the hand's push, fault,
# the hand's position and velocity
DS_X, DS_V, DS_A, DS_PUSH, DS_FAULT, DS_XH, DS_VH = range(7)
N_STATE = 7


def discretise(m_e, m_h, k_g, b_g, t):
    """(Phi, Gamma) of the end-effector and hand on the grip over a step of ``t`` s (zero-order hold)."""
    a = [[0.0, 1.0, 0.0, 0.0],
         [-k_g / m_e, -b_g / m_e, k_g / m_e, b_g / m_e],
         [0.0, 0.0, 0.0, 1.0],
         [k_g / m_h, b_g / m_h, -k_g / m_h, -b_g / m_h]]
    b = [[0.0, 0.0], [1.0 / m_e, 0.0], [0.0, 0.0], [0.0, 1.0 / m_h]]
    phi, gamma = zoh.discretise(a, b, float(t))
    return np.array(phi), np.array(gamma)


@njit(cache=True, inline="always")
def hand_force(hp, ds, x_target, v_target, a_target):
    """The arm's force on the hand now (N), as given (non-finite included)."""
    return hand.force(hp, x_target, v_target, a_target, ds[DS_XH], ds[DS_VH], ds[DS_PUSH])


@njit(cache=True, inline="always")
def grip_force(dp, ds):
    """The grip's force on the end-effector now (N): what the device feels of the hand."""
    return dp[DP_KG] * (ds[DS_XH] - ds[DS_X]) + dp[DP_BG] * (ds[DS_VH] - ds[DS_V])


@njit(cache=True, inline="always")
def sense(use_acc, ds, snp, sns, noise_x, noise_q, noise_v, noise_a, noise_lf):
    """The sensors on the state now: (x_m, a_m, v_m)."""
    x_m = sensors.lvdt(snp, sns, ds[DS_X], noise_x, noise_q)
    v_m = sensors.lvt(snp, sns, ds[DS_V], noise_v)
    a_m = sensors.accelerometer(snp, sns, ds[DS_A], noise_a, noise_lf) if use_acc else 0.0
    return x_m, a_m, v_m


@njit(cache=True, inline="always")
def _row(dp, i, s0, s1, s2, s3, f, f_arm):
    r = DP_PHI + 4 * i
    g = DP_GAMMA + 2 * i
    return dp[r] * s0 + dp[r + 1] * s1 + dp[r + 2] * s2 + dp[r + 3] * s3 + dp[g] * f + dp[g + 1] * f_arm


@njit(cache=True, inline="always")
def advance(dp, ds, f, f_arm):
    """Move end-effector and hand over one sample under the constant motor force ``f`` and arm force ``f_arm`` (N)."""
    t = dp[DP_T]
    s0, s1, s2, s3 = ds[DS_X], ds[DS_V], ds[DS_XH], ds[DS_VH]
    x = _row(dp, 0, s0, s1, s2, s3, f, f_arm)
    v = _row(dp, 1, s0, s1, s2, s3, f, f_arm)
    xh = _row(dp, 2, s0, s1, s2, s3, f, f_arm)
    vh = _row(dp, 3, s0, s1, s2, s3, f, f_arm)
    stop = dp[DP_TRAVEL]
    if x > stop:
        x = stop
        if v > 0.0:
            v = 0.0
    elif x < -stop:
        x = -stop
        if v < 0.0:
            v = 0.0
    ds[DS_X] = x
    ds[DS_A] = (v - s1) / t
    ds[DS_V] = v
    ds[DS_XH] = xh
    ds[DS_VH] = vh


@njit(cache=True, inline="always")
def actuate(dp, ds, hp, f, f_arm):
    """The step [k, k+1] under the command ``f`` and the arm's force ``f_arm`` (from ``hand_force``)."""
    if not np.isfinite(f_arm):
        f_arm = 0.0
        ds[DS_PUSH] = 0.0
        ds[DS_X] = 0.0
        ds[DS_V] = 0.0
        ds[DS_A] = 0.0
        ds[DS_XH] = 0.0
        ds[DS_VH] = 0.0
        ds[DS_FAULT] = 1.0
    ds[DS_PUSH] = hand.learn_push(hp, ds[DS_PUSH], f)
    advance(dp, ds, f, f_arm)


@njit(cache=True, error_model="numpy", nogil=True)
def run_block(c, dp, ds, hp, snp, sns, target, target_v, target_a, noise_x, noise_q, noise_v, noise_a, noise_lf,
              link_s, delays, out, est_out):
    """``target.shape[0]`` samples of the device and the loop's controller ``c``: control.sample's sequence."""
    ctl, state, lp, ls, kinds, est_s, est_p, sp, ss, bridge, nut, body_p, body_s, mon_p, mon_s, mic_p, mic_s = c
    src = int(ctl[control.C_SOURCE])
    use_acc = dp[DP_ACCELEROMETER] != 0.0
    for k in range(target.shape[0]):
        x = ds[DS_X]
        v = ds[DS_V]
        a = ds[DS_A]
        f_arm = hand_force(hp, ds, target[k], target_v[k], target_a[k])
        f_hand = grip_force(dp, ds)
        x_m, a_m, v_m = sense(use_acc, ds, snp, sns, noise_x[k], noise_q[k], noise_v[k], noise_a[k], noise_lf[k])
        control.check_sensors(state, k, x_m, a_m, v_m)
        # control.source_velocity and control.observe, written out: as inline calls they cost 15-20 ns
        # of a 48 kHz sample's 0.8 us (measured 2026-11-23); the per-sample test holds the two equal
        if src >= 0:
            v_src = step_guarded(kinds[src], est_s[src], est_p[src], x_m, a_m, v_m)
            est_out[src, k] = v_src
        elif src == TRUE_INDEX:
            v_src = v
        else:
            v_src = v_m
        f = control.bow_and_force(ctl, state, k, v_src, sp, ss, bridge, nut, body_p, body_s, out)
        stability.observe(mon_p, mon_s, v)
        if ctl[control.C_USE_AUDIO] != 0.0:
            out[control.O_AUDIO, k] += contact_mic.step(mic_p, mic_s, a)
        f = control.command(state, lp, ls, k, f)
        control.record(out, k, x_m, a_m, v_m, x, v, a, f, f_hand if np.isfinite(f_hand) else 0.0)
        actuate(dp, ds, hp, link_step(link_s, f, delays[k]), f_arm)


@njit(cache=True, error_model="numpy")
def read_once(dp, ds, snp, sns, noise_x, noise_q, noise_v, noise_a, noise_lf):
    return sense(dp[DP_ACCELEROMETER] != 0.0, ds, snp, sns, noise_x, noise_q, noise_v, noise_a, noise_lf)


@njit(cache=True, error_model="numpy")
def hand_once(hp, ds, x_target, v_target, a_target):
    return hand_force(hp, ds, x_target, v_target, a_target)


@njit(cache=True, error_model="numpy")
def grip_once(dp, ds):
    return grip_force(dp, ds)


@njit(cache=True, error_model="numpy")
def write_once(dp, ds, hp, f, f_arm, link_s, delay):
    actuate(dp, ds, hp, link_step(link_s, f, delay), f_arm)


class SimulatedDevice(HapticDevice):
    """The simulated device and the virtual hand holding it (calibration.py documents the constants).

    ``seed`` seeds the sensors' noise and the link's draws; ``sensor_spec`` (None: sensors.from_environment(), the
    data sheets' figures unless STUDYAPP_LVDT_BAND / _NOISE say otherwise); ``accelerometer=False`` leaves the accelerometer out
    (it reads 0); ``link`` (a link.LinkSpec, default ideal) is the link between the host and the device;
    ``nudge``: the end-effector starts n rounding steps off rest (nudge.py; None: ``STUDYAPP_NUDGE``, default 0).
    """

    def __init__(self, rate, mass=calibration.DEVICE_MASS, limits=DeviceLimits(), *, hand_impedance=None,
                 sensor_spec=None, seed=0, accelerometer=True, link=None, nudge=None):
        self.rate = float(rate)
        self.mass = float(mass)
        self.limits = limits
        self.hand = hand_impedance or hand.HandImpedance(
            calibration.HAND_MASS, calibration.HAND_STIFFNESS, calibration.HAND_DAMPING, calibration.HAND_REACTION,
            calibration.GRIP_STIFFNESS, calibration.GRIP_DAMPING)
        self.sensor_spec = sensor_spec or sensors.from_environment()
        self.accelerometer = bool(accelerometer)
        self._dp = np.zeros(N_PARAMS)
        self._dp[DP_T] = 1.0 / self.rate
        self._dp[DP_MASS] = self.mass
        self._dp[DP_TRAVEL] = limits.travel
        self._dp[DP_ACCELEROMETER] = 1.0 if self.accelerometer else 0.0
        self._dp[DP_KG] = self.hand.grip_stiffness
        self._dp[DP_BG] = self.hand.grip_damping
        phi, gamma = discretise(self.mass, self.hand.mass, self.hand.grip_stiffness, self.hand.grip_damping,
                                self._dp[DP_T])
        self._dp[DP_PHI:DP_GAMMA] = phi.ravel()
        self._dp[DP_GAMMA:] = gamma.ravel()
        self._ds = np.zeros(N_STATE)
        self.nudge = rounding.steps_from_environment() if nudge is None else rounding.check_steps(nudge)
        self._ds[DS_X] = rounding.initial_position(limits.travel, self.nudge)
        self._hp = self.hand.params(self.mass + self.hand.mass, self.rate)
        self._snp = self.sensor_spec.params(self.rate)
        self._sns = np.zeros(sensors.N_STATE)
        # the accelerometer's low-frequency noise is the 4th child, so the first three streams stay as they were;
        # the link's two draws are the 5th and 6th, the LVDT converter's noise the 7th (spawn(7)[:4] == spawn(4))
        streams = np.random.SeedSequence(int(seed)).spawn(7)
        self._rng_x, self._rng_v, self._rng_a, self._rng_lf = (np.random.default_rng(s) for s in streams[:4])
        self._rng_q = np.random.default_rng(streams[6])
        self.link = link or IDEAL
        self._link = Link(self.link, self.rate, streams[4:6])
        self._sample = 0
        self._gesture = Hold()
        self._gesture_start = 0
        self._target = None  # the hand's target at the sample last read

    @property
    def fault(self):
        if self._ds[DS_FAULT] != 0.0:
            return "the virtual hand's force was non-finite; the hand let go and the handle was put at rest"
        return None

    def follow(self, gesture):
        """The hand follows ``gesture`` from the next sample on."""
        self._gesture = gesture
        self._gesture_start = self._sample

    def truth(self):
        f_hand = grip_once(self._dp, self._ds)
        return (float(self._ds[DS_X]), float(self._ds[DS_V]), float(self._ds[DS_A]),
                f_hand if np.isfinite(f_hand) else 0.0)

    def _targets(self, n):
        target = self._gesture.block(self._sample - self._gesture_start, n, self.rate)
        return tuple(np.ascontiguousarray(t, dtype=np.float64) for t in target)

    def _noise(self, n):
        nx = self._rng_x.standard_normal(n)
        nq = self._rng_q.standard_normal(n)
        nv = self._rng_v.standard_normal(n)
        if self.accelerometer:
            return nx, nq, nv, self._rng_a.standard_normal(n), self._rng_lf.standard_normal(n)
        return nx, nq, nv, np.zeros(n), np.zeros(n)

    def read_sensors(self):
        self._target = tuple(float(t[0]) for t in self._targets(1))
        nx, nq, nv, na, nl = (float(z[0]) for z in self._noise(1))
        return read_once(self._dp, self._ds, self._snp, self._sns, nx, nq, nv, na, nl)

    def write_force(self, force):
        target = self._target if self._target is not None else tuple(float(t[0]) for t in self._targets(1))
        f_arm = hand_once(self._hp, self._ds, *target)
        write_once(self._dp, self._ds, self._hp, float(force), f_arm, self._link.state,
                   float(self._link.delays(1)[0]))
        self._target = None
        self._sample += 1

    def exchange(self, control, n, out, est_out):
        target, target_v, target_a = self._targets(n)
        nx, nq, nv, na, nl = self._noise(n)
        run_block(control.arrays, self._dp, self._ds, self._hp, self._snp, self._sns, target, target_v, target_a,
                  nx, nq, nv, na, nl, self._link.state, self._link.delays(n), out, est_out)
        self._sample += n
