"""The loop's controller for one sample: sensors in, force out (paper Fig. 1).

    sensors x_m, a_m, v_m from the device (device.py)
    -> the source velocity: the selected estimator stepped on (x_m, a_m, v_m)
       (studyapp.estimators.dispatch.step_guarded), the LVT sensor, or the true v
    -> bow: v_bow = s * v_source (string units; s = VELOCITY_SCALE, calibration.py)
    -> string step (bowed_string.py): u = rho(v_delta) v_delta
    -> force F = -G u * force_scale, clamped to the motor limits (device.py)

then the stability monitor (stability.py) and the contact microphone
(contact_mic.py) observe the handle's velocity and acceleration: the true ones
when the device knows them (a simulation), else the LVT's and the
accelerometer's. G = F_max / max|rho(v) v| makes the peak friction force
F_max (bow_table.py, paper eqs. 2 and 20).

``sample`` is the sequence for one sample (``Control.sample`` runs it from
Python for a device read and written one sample at a time); its pieces are
compiled inline, so a device's compiled block (simulated_device.py) runs the
same sequence inside its own loop, with the same numbers (a test checks the
two paths sample by sample). The controller's arrays travel as one tuple
(``Control.arrays``, in the order of ``sample``'s unpacking).

Compiled with numpy's error model (as the estimator dispatch is): a division
by zero gives inf, not an exception, and inf is caught as a fault. A
non-finite value from a sensor, the estimate, the string or the force latches
``fault`` (a code and the sample) in the loop state; from that sample on the
force is 0 and the bow is lifted.
"""

import math

import numpy as np
from numba import njit

from studyapp.estimators.dispatch import run_block as run_estimator_block
from studyapp.estimators.dispatch import step_guarded
from studyapp.model import bowed_string, contact_mic, sensors, stability
from studyapp.model.device import clamp_force
from studyapp.model.sources import TRUE_INDEX

# control vector
C_GAIN, C_SCALE, C_FORCE_SCALE, C_BOWING, C_SOURCE, C_USE_AUDIO, C_PEAK, C_BREAKAWAY = range(8)
N_CONTROL = 8
# loop state
L_FAULT, L_FAULT_SAMPLE = range(2)
N_LOOP_STATE = 2
FAULT_SENSOR, FAULT_ESTIMATE, FAULT_STRING, FAULT_FORCE, FAULT_DEVICE = 1, 2, 3, 4, 5
# output rows
(O_POSITION, O_VELOCITY_LVT, O_ACCELERATION, O_VELOCITY_TRUE, O_ACCELERATION_TRUE,
 O_FORCE, O_STRING_VELOCITY, O_AUDIO, O_SOURCE_VELOCITY, O_V_DELTA, O_STICK, O_HAND_FORCE,
 O_FRICTION, O_POSITION_TRUE) = range(14)
OUTPUTS = (
    "position", "velocity_lvt", "acceleration", "velocity_true", "acceleration_true",
    "force", "string_velocity", "audio", "source_velocity", "v_delta", "stick", "hand_force", "friction",
    "position_true",
)


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


@njit(cache=True, inline="always")
def check_sensors(state, k, x_m, a_m, v_m):
    if _bad(x_m) or _bad(v_m) or _bad(a_m):
        _fault(state, FAULT_SENSOR, k)


@njit(cache=True, inline="always")
def source_velocity(src, kinds, est_s, est_p, k, x_m, a_m, v_m, v, est_out):
    """The velocity the bow takes: estimator ``src`` stepped on the sensors, the true ``v``, or the LVT's."""
    if src >= 0:
        v_src = step_guarded(kinds[src], est_s[src], est_p[src], x_m, a_m, v_m)
        est_out[src, k] = v_src
    elif src == TRUE_INDEX:
        v_src = v
    else:
        v_src = v_m
    return v_src


@njit(cache=True, inline="always")
def observe(ctl, mon_p, mon_s, mic_p, mic_s, k, v_obs, a_obs, out):
    """The stability monitor and the contact microphone on the handle's velocity and acceleration."""
    stability.observe(mon_p, mon_s, v_obs)
    if ctl[C_USE_AUDIO] != 0.0:
        out[O_AUDIO, k] += contact_mic.step(mic_p, mic_s, a_obs)


@njit(cache=True, inline="always")
def command(state, lp, ls, k, f):
    """The force command: clamped to the motor limits, 0 once the loop has faulted."""
    f = clamp_force(lp, ls, f)
    if _bad(f):
        _fault(state, FAULT_FORCE, k)
    if state[L_FAULT] != 0.0:
        f = 0.0
    return f


@njit(cache=True, inline="always")
def record(out, k, x_m, a_m, v_m, x, v, a, f, f_hand):
    out[O_POSITION, k] = x_m
    out[O_VELOCITY_LVT, k] = v_m
    out[O_ACCELERATION, k] = a_m
    out[O_VELOCITY_TRUE, k] = v
    out[O_ACCELERATION_TRUE, k] = a
    out[O_POSITION_TRUE, k] = x
    out[O_FORCE, k] = f
    out[O_HAND_FORCE, k] = f_hand


@njit(cache=True, error_model="numpy")
def sample(c, k, x_m, a_m, v_m, x, v, a, f_hand, v_obs, a_obs, out, est_out):
    """Sample k: the sensors (x_m, a_m, v_m) in, the clamped force command out (N).

    (x, v, a, f_hand) are the true motion and the hand's force, recorded only
    (NaN when unknown; v is the source TRUE's velocity); (v_obs, a_obs) are
    what the stability monitor and the contact microphone observe.

    A device's compiled block (simulated_device.run_block) writes the same
    sequence into its own loop instead of calling this function: inlined
    there, this function (17 arrays in) cost 80 ns of the 0.8 us a 48 kHz
    sample takes (measured 2026-11-23), its pieces next to nothing.
    """
    ctl, state, lp, ls, kinds, est_s, est_p, sp, ss, bridge, nut, body_p, body_s, mon_p, mon_s, mic_p, mic_s = c
    check_sensors(state, k, x_m, a_m, v_m)
    v_src = source_velocity(int(ctl[C_SOURCE]), kinds, est_s, est_p, k, x_m, a_m, v_m, v, est_out)
    f = bow_and_force(ctl, state, k, v_src, sp, ss, bridge, nut, body_p, body_s, out)
    observe(ctl, mon_p, mon_s, mic_p, mic_s, k, v_obs, a_obs, out)
    f = command(state, lp, ls, k, f)
    record(out, k, x_m, a_m, v_m, x, v, a, f, f_hand)
    return f


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


class Control:
    """The loop's side of ``HapticDevice.exchange``: the compiled controller's arrays, and one sample from Python."""

    def __init__(self, arrays):
        self.arrays = arrays

    def sample(self, k, sensors, truth, out, est_out):
        """Sample k from the device's ``sensors`` (x, a, v) and ``truth`` (x, v, a, hand force, or None)."""
        x_m, a_m, v_m = (float(s) for s in sensors)
        if truth is None:
            x = v = a = f_hand = math.nan
            v_obs, a_obs = v_m, a_m
        else:
            x, v, a, f_hand = (float(s) for s in truth)
            v_obs, a_obs = v, a
        return sample(self.arrays, k, x_m, a_m, v_m, x, v, a, f_hand, v_obs, a_obs, out, est_out)
