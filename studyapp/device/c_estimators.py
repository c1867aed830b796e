"""The estimators in C (firmware/studyapp_estimators.h and its C files), built by c_core.build_library, through ctypes.

The C kernels step the same state and parameter vectors as the numba kernels
(``studyapp.estimators.Estimator``'s ``state`` and ``p``, a ``Bank``'s rows):
the host builds the parameters in Python and hands them to C, and on one
machine both give the same bits (tests/estimators/test_estimators_c.py).
A closed loop in C links these sources with its own (``SOURCES``).

    known(kind)                              1 if the C dispatch has the kind
    step_guarded(kind, s, p, x, a, v)        one sample with the bad-input guard (dispatch.step_guarded)
    step(kind, s, p, x, a, v)                the kernel alone (dispatch.step_any)
    run(kind, s, p, xs, acc, vel)            a block, as dispatch.run_block; returns the estimates
    run_bank(bank, xs, acc, vel)             a Bank's every row over a block, as Bank.process

``s`` and ``p`` are C-contiguous float64 arrays; ``s`` is changed in place.
"""

import ctypes

import numpy as np

from studyapp.device import c_core

SOURCES = ("studyapp_estimators.c", "studyapp_foaw.c", "studyapp_levant.c", "studyapp_kalman.c",
           "studyapp_hybrids.c", "studyapp_estimators.h", "studyapp_estimator_kernels.h")
NAME = "studyapp_estimators"


def build():
    """The path of the compiled estimators (c_core.build_library: a cache keyed by the sources and flags)."""
    return c_core.build_library(NAME, SOURCES)


def _load(path):
    lib = ctypes.CDLL(str(path))
    f64 = ctypes.c_double
    vector = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
    writable = np.ctypeslib.ndpointer(dtype=np.float64, flags=("C_CONTIGUOUS", "WRITEABLE"))
    lib.se_known.argtypes = [ctypes.c_int]
    lib.se_known.restype = ctypes.c_int
    for fn in (lib.se_step_guarded, lib.se_step):
        fn.argtypes = [ctypes.c_int, writable, vector, f64, f64, f64]
        fn.restype = f64
    lib.se_run.argtypes = [ctypes.c_int, writable, vector, vector, vector, vector, writable, ctypes.c_long]
    lib.se_run.restype = None
    return lib


_LIB = None


def library():
    global _LIB
    if _LIB is None:
        try:
            _LIB = _load(build())
        except OSError as exc:
            raise c_core.BuildError(f"cannot load the C estimators: {exc}") from None
    return _LIB


def known(kind):
    return bool(library().se_known(int(kind)))


def step_guarded(kind, s, p, x, a=0.0, v=0.0):
    return library().se_step_guarded(int(kind), s, p, float(x), float(a), float(v))


def step(kind, s, p, x, a=0.0, v=0.0):
    return library().se_step(int(kind), s, p, float(x), float(a), float(v))


def _block(values, n, name):
    arr = np.ascontiguousarray(values, dtype=np.float64)
    if arr.shape != (n,):
        raise ValueError(f"{name}: expected {n} samples, got shape {arr.shape}")
    return arr


def run(kind, s, p, xs, acc, vel):
    """The estimates of one estimator over a block (``s`` advanced in place), as dispatch.run_block."""
    xs = np.ascontiguousarray(xs, dtype=np.float64)
    n = xs.shape[0]
    out = np.empty(n)
    library().se_run(int(kind), s, p, xs, _block(acc, n, "acceleration"), _block(vel, n, "velocity"), out, n)
    return out


def run_bank(bank, xs, acc, vel):
    """A ``Bank``'s estimates over a block, its states advanced in place: row e is ``bank.names[e]``."""
    rows = [run(kind, bank.states[e], bank.params[e], xs, acc, vel) for e, kind in enumerate(bank.kinds)]
    return np.array(rows).reshape(len(bank.kinds), np.asarray(xs).shape[0])
