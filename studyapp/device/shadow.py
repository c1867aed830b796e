"""The host's shadow of a device's loop, compiled: telemetry rows through the loop's own controller, compared.

A device that runs the loop (protocol 2, loop_link.py) streams, per sample
j, its sensors (x, a, v), the loop's force F_j, the force it applied and the
bridge velocity b_j. The shadow runs model/control.py's ``sample`` (the
source estimator, the bow, the string, F = -G u g clamped to the motor
limits: eqs. 1, 2 and 20 of the paper) on the same sensors with the loop's
own arrays, and steps every other estimator on the same row, as the device
does (all of them concurrently, every sample, Sec. 8.4). Before the string
moves, the bridge velocity it is about to read is the shadow's b_j
(bowed_string.read_line). Row i is equal when |F_shadow - F_j| <= tol and
|b_shadow - b_j| <= tol, both finite; the force row of ``out`` then takes
the applied force (what acted on the handle is what the session logs).

``run_rows`` runs one setting's rows (one CONTROL in effect: the caller
writes it into the control vector first) and returns the index of the first
row that differs, or -1; that row's force is 0 and the rows after it are not
run. ``mode``: ``CHECK`` compares every row and logs the applied force;
``TRUST`` (after a telemetry gap) runs them without comparing and logs the
applied force; ``MODEL`` runs them as the model's loop on recorded sensors
and keeps its own force (the C loop's reference in the tests, and ``bench
loop``'s numba loop).
"""

import math

import numpy as np
from numba import njit

from studyapp.estimators.dispatch import step_guarded
from studyapp.model import bowed_string
from studyapp.model.control import C_SOURCE, O_FORCE, sample

# the columns of a row as loop_link.py packs them
R_SAMPLE, R_X, R_A, R_V, R_LOOP_FORCE, R_APPLIED, R_BRIDGE, R_CONTROL = range(8)
ROW_WIDTH = 8
# run_rows' modes
TRUST, CHECK, MODEL = 0, 1, 2


@njit(cache=True, error_model="numpy")
def run_rows(c, k0, rows, tol, mode, out, est_out, shadow):
    """Rows ``rows`` (m, ROW_WIDTH) at the loop's samples k0.. of ``out``; the first differing row's index or -1
    (``shadow`` then holds the shadow's force and bridge velocity there)."""
    ctl, kinds, est_s, est_p, sp, ss, bridge = c[0], c[4], c[5], c[6], c[7], c[8], c[9]
    src = int(ctl[C_SOURCE])
    nan = math.nan
    for i in range(rows.shape[0]):
        k = k0 + i
        x, a, v = rows[i, R_X], rows[i, R_A], rows[i, R_V]
        b = bowed_string.read_line(bridge, int(ss[bowed_string.S_WRITE]), sp[bowed_string.P_DB])
        f = sample(c, k, x, a, v, nan, nan, nan, nan, v, a, out, est_out)
        for e in range(kinds.shape[0]):
            if e != src:
                est_out[e, k] = step_guarded(kinds[e], est_s[e], est_p[e], x, a, v)
        if mode == MODEL:
            continue
        if mode == CHECK:
            device_f, device_b = rows[i, R_LOOP_FORCE], rows[i, R_BRIDGE]
            if not (np.isfinite(device_f) and np.isfinite(device_b)) or abs(f - device_f) > tol \
                    or abs(b - device_b) > tol:
                shadow[0] = f
                shadow[1] = b
                out[O_FORCE, k] = 0.0
                return i
        out[O_FORCE, k] = rows[i, R_APPLIED]
    return -1
