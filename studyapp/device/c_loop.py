"""The loop in C (firmware/studyapp_loop.c with the estimators of firmware/studyapp_estimators.c) through ctypes.

``CLoop(arrays)`` points the C loop at a loop's own arrays (``Control.arrays``
of model/control.py, as ``ClosedLoop`` builds them: the control vector, the
fault state, the motor limits, the estimator bank, the string): no copies, so
what the host changes between samples (``ClosedLoop.set_source``,
``set_fmax``, ``set_bowing``) the C loop reads at its next sample, and the
string, estimators and fault it advances are the loop's own. One sample k:

    sensors -> source velocity -> bow -> string -> force (F_max, force scale) -> motor limits -> fault latch
    and every other estimator of the bank on the same sample

(firmware/studyapp_loop.h), equal bit for bit to control.sample followed by
control.observe_others (tests/device/test_c_loop.py). The body filter, the
contact microphone and the stability monitor stay on the host: the C loop
leaves their arrays alone.

``sample(k, x_m, a_m, v_m)`` is one sample (the force; ``out`` and ``est``
hold its outputs); ``run(x_m, a_m, v_m)`` a block in one call, for speed.
``library()`` builds the shared library on first use (c_core.build_library:
cached by the hash of the sources and flags); ``studyapp compile`` builds it
ahead. The C's layout constants are checked against the Python ones when it
loads: a C file out of step with control.py fails there, not in a number.
"""

import ctypes

import numpy as np

from studyapp.device.c_core import BuildError, build_library
from studyapp.errors import ParameterError
from studyapp.estimators.dispatch import GUARD
from studyapp.model import bowed_string, control, device
from studyapp.model.sources import LVT_SENSOR_INDEX

NAME = "studyapp_loop"
SOURCES = ("studyapp_loop.c", "studyapp_loop.h")
# the rows of ``run``'s output: sl_out's members, in order
OUT_ROWS = ("force", "source_velocity", "string_velocity", "bridge_velocity", "v_delta", "stick", "friction")
# studyapp_loop.c's LAYOUT table, from the Python constants the numba loop uses
LAYOUT = (
    control.C_GAIN, control.C_SCALE, control.C_FORCE_SCALE, control.C_BOWING, control.C_SOURCE,
    control.C_USE_AUDIO, control.C_PEAK, control.C_BREAKAWAY, control.N_CONTROL,
    control.L_FAULT, control.L_FAULT_SAMPLE, control.N_LOOP_STATE,
    control.FAULT_SENSOR, control.FAULT_ESTIMATE, control.FAULT_STRING, control.FAULT_FORCE,
    LVT_SENSOR_INDEX,
    bowed_string.P_DB, bowed_string.P_DN, bowed_string.P_LOSS_B0, bowed_string.P_LOSS_A1, bowed_string.P_SLOPE,
    bowed_string.P_OFFSET, bowed_string.P_PEAK, bowed_string.P_NUT_GAIN, bowed_string.N_PARAMS,
    bowed_string.S_WRITE, bowed_string.S_LOSS_Y, bowed_string.N_STATE,
    device.LP_IMPULSIVE, device.LP_SUSTAINED, device.LP_RMS_ALPHA, device.N_LIMIT_PARAMS,
    device.LS_MS, device.N_LIMIT_STATE,
    len(OUT_ROWS), GUARD,
)

_f64 = ctypes.POINTER(ctypes.c_double)
_u32 = ctypes.c_uint32


class SlLoop(ctypes.Structure):
    _fields_ = [("ctl", _f64), ("state", _f64), ("lp", _f64), ("ls", _f64),
                ("kinds", ctypes.POINTER(ctypes.c_int64)), ("n_est", _u32),
                ("est_s", _f64), ("est_s_width", _u32), ("est_p", _f64), ("est_p_width", _u32),
                ("sp", _f64), ("ss", _f64), ("bridge", _f64), ("nut", _f64), ("line", _u32),
                ("est_s0", _f64)]


class SlOut(ctypes.Structure):
    _fields_ = [(name, ctypes.c_double) for name in OUT_ROWS]


def sources():
    """The files the library is built from: the loop's and the estimators' (c_estimators.SOURCES)."""
    from studyapp.device import c_estimators

    return SOURCES + tuple(s for s in c_estimators.SOURCES if s not in SOURCES)


def build():
    """The path of the compiled loop (built on first use, then cached; c_core.build_library)."""
    return build_library(NAME, sources())


def _load(path):
    lib = ctypes.CDLL(str(path))
    ptr = ctypes.POINTER(SlLoop)
    lib.sl_sample.argtypes = [ptr, _u32, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                              ctypes.POINTER(SlOut), _f64]
    lib.sl_sample.restype = ctypes.c_double
    lib.sl_run.argtypes = [ptr, _u32, _u32, _f64, _f64, _f64, _f64, _f64]
    lib.sl_run.restype = None
    lib.sl_reset_string.argtypes = [ptr]
    lib.sl_reset.argtypes = [ptr]
    lib.sl_reset_string.restype = None
    lib.sl_check.argtypes = [ptr]
    lib.sl_check.restype = ctypes.c_int
    layout = (ctypes.c_int32 * len(LAYOUT))()
    lib.sl_layout.argtypes = [ctypes.c_void_p]
    lib.sl_layout(layout)
    if tuple(layout) != LAYOUT:
        raise BuildError(f"{path}: its layout {tuple(layout)} differs from the Python loop's {LAYOUT} "
                         "(firmware/studyapp_loop.h out of step with studyapp/model)")
    return lib


_LIB = None


def library():
    global _LIB
    if _LIB is None:
        try:
            _LIB = _load(build())
        except OSError as exc:
            raise BuildError(f"cannot load the C loop: {exc}") from None
    return _LIB


def _pointer(a, dtype, what):
    if not (isinstance(a, np.ndarray) and a.dtype == dtype and a.flags.c_contiguous):
        raise ParameterError(f"C loop: {what} must be a C-contiguous {np.dtype(dtype).name} array")
    return a.ctypes.data_as(ctypes.POINTER(np.ctypeslib.as_ctypes_type(dtype)))


def _rows(n, values, what):
    a = np.ascontiguousarray(values, dtype=np.float64)
    if a.shape != (n,):
        raise ParameterError(f"C loop: {what} must be {n} samples, got shape {a.shape}")
    return a


class CLoop:
    """The C loop on a loop's arrays (``Control.arrays``, model/control.py), shared, not copied."""

    def __init__(self, arrays):
        self._lib = library()
        ctl, state, lp, ls, kinds, est_s, est_p, sp, ss, bridge, nut = arrays[:11]
        self.arrays = arrays  # keeps the memory the C points into alive
        if est_s.ndim != 2 or est_p.ndim != 2 or kinds.shape != (est_s.shape[0],) or est_p.shape[0] != kinds.shape[0]:
            raise ParameterError("C loop: the bank's kinds, states and params must be (n,), (n, ws), (n, wp)")
        if bridge.shape != nut.shape:
            raise ParameterError("C loop: the string's two delay lines must have one length")
        self.n_est = int(kinds.shape[0])
        self.est_s0 = np.array(est_s, dtype=np.float64, order="C")  # the starting states: sl_reset's
        self._loop = SlLoop(
            _pointer(ctl, np.float64, "ctl"), _pointer(state, np.float64, "state"),
            _pointer(lp, np.float64, "lp"), _pointer(ls, np.float64, "ls"),
            _pointer(kinds, np.int64, "kinds"), self.n_est,
            _pointer(est_s, np.float64, "est_s"), est_s.shape[1],
            _pointer(est_p, np.float64, "est_p"), est_p.shape[1],
            _pointer(sp, np.float64, "sp"), _pointer(ss, np.float64, "ss"),
            _pointer(bridge, np.float64, "bridge"), _pointer(nut, np.float64, "nut"), bridge.shape[0],
            _pointer(self.est_s0, np.float64, "est_s0"))
        if self._lib.sl_check(ctypes.byref(self._loop)) != 0:
            raise ParameterError("C loop: the arrays fail sl_check (firmware/studyapp_loop.h says what it needs)")
        self.out = SlOut()
        self.est = np.zeros(self.n_est)
        self._est = _pointer(self.est, np.float64, "est")

    @property
    def nbytes(self):
        """The bytes of the arrays the C loop reads and writes (a device's RAM for the loop's data)."""
        return sum(a.nbytes for a in self.arrays[:11])

    def sample(self, k, x_m, a_m, v_m):
        """Sample k (the index a fault records): the force (N); ``out`` and ``est`` hold its outputs."""
        return self._lib.sl_sample(ctypes.byref(self._loop), int(k), float(x_m), float(a_m), float(v_m),
                                   ctypes.byref(self.out), self._est)

    def run(self, x_m, a_m, v_m, k0=0, out=None, est=None):
        """A block of ``len(x_m)`` samples from sample index ``k0``: (out, est).

        ``out`` has a row per ``OUT_ROWS`` name and ``est`` a row per estimator of the bank, each with a
        column per sample; ``est`` is the transpose of the samples-by-estimators array the C writes. Pass
        ``out`` (rows by samples) and ``est`` (samples by estimators), C-contiguous float64, to fill them.
        """
        n = int(np.shape(x_m)[0])
        x_m, a_m, v_m = (_rows(n, s, w) for s, w in ((x_m, "x_m"), (a_m, "a_m"), (v_m, "v_m")))
        out = np.empty((len(OUT_ROWS), n)) if out is None else out
        est = np.empty((n, self.n_est)) if est is None else est
        if out.shape != (len(OUT_ROWS), n) or est.shape != (n, self.n_est):
            raise ParameterError(f"C loop: out must be {(len(OUT_ROWS), n)} and est {(n, self.n_est)}, "
                                 f"got {out.shape} and {est.shape}")
        self._lib.sl_run(ctypes.byref(self._loop), int(k0), n, _pointer(x_m, np.float64, "x_m"),
                         _pointer(a_m, np.float64, "a_m"), _pointer(v_m, np.float64, "v_m"),
                         _pointer(out, np.float64, "out"), _pointer(est, np.float64, "est"))
        return out, est.T

    def reset_string(self):
        """The string at rest (ClosedLoop.reset_string's part that the C loop holds)."""
        self._lib.sl_reset_string(ctypes.byref(self._loop))

    def reset(self):
        """The loop as built: the string at rest, the estimators at their states when this CLoop was made,
        the mean square force 0, no fault (sl_reset; a device loop runs it at START)."""
        self._lib.sl_reset(ctypes.byref(self._loop))
