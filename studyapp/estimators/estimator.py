"""``Estimator`` (one) and ``Bank`` (several on one stream): the block form.

Both keep their state between calls to ``process``, so a stream may be cut
into blocks anywhere: the output equals per-sample stepping exactly.
"""

import numpy as np

from studyapp.errors import InputDataError
from studyapp.estimators.dispatch import GUARD, run_bank, run_block, step_guarded
from studyapp.estimators.registry import spec as lookup


def _column(name, values, n, needed, who):
    if values is None:
        if needed:
            raise InputDataError(f"{who} reads {name}: pass {name}= (an array of {n} samples)")
        return np.zeros(n)
    arr = np.ascontiguousarray(values, dtype=np.float64)
    if arr.ndim != 1 or arr.shape[0] != n:
        raise InputDataError(f"{name}: expected a 1-D array of {n} samples, got shape {arr.shape}")
    return arr


def _inputs(position, acceleration, velocity, reads, who):
    x = np.ascontiguousarray(position, dtype=np.float64)
    if x.ndim != 1:
        raise InputDataError(f"position: expected a 1-D array, got shape {x.shape}")
    n = x.shape[0]
    a = _column("acceleration", acceleration, n, "acceleration" in reads, who)
    v = _column("velocity", velocity, n, "velocity" in reads, who)
    if "position" not in reads and position is None:
        x = np.zeros(n)
    return x, a, v


class Estimator:
    """One velocity estimator at a fixed sample rate.

    ``process(position, acceleration=None, velocity=None)`` returns the
    velocity estimate for a block and continues from its state across calls;
    ``reset()`` returns it to its start. ``bad_samples`` counts the bad input
    samples (NaN, inf, or beyond the physical bounds of ``bounds.py``) that
    were replaced by the last good one.
    """

    def __init__(self, name, rate, **params):
        self.spec = lookup(name)
        self.rate, self.params = self.spec.validate(rate, params)
        self.p, self.state_size = self.spec.build(self.rate, self.params)
        self.p = np.ascontiguousarray(self.p, dtype=np.float64)
        self.state = np.zeros(GUARD + self.state_size)

    @property
    def name(self):
        return self.spec.name

    @property
    def kind(self):
        return self.spec.kind

    @property
    def bad_samples(self):
        return int(self.state[3])

    def reset(self):
        self.state[:] = 0.0

    def process(self, position, acceleration=None, velocity=None):
        x, a, v = _inputs(position, acceleration, velocity, self.spec.inputs, self.name)
        out = np.empty_like(x)
        run_block(self.spec.kind, self.state, self.p, x, a, v, out)
        return out

    def step(self, x, a=0.0, v=0.0):
        """One sample through the streaming form (slow from Python: for tests and tools)."""
        return step_guarded(self.spec.kind, self.state, self.p, float(x), float(a), float(v))

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"Estimator({self.name!r}, rate={self.rate:g}{', ' if args else ''}{args})"


class Bank:
    """Several estimators on one stream of samples, advanced together a block at a time.

    ``estimators`` is a list of names (defaults) or a dict ``{name: {param: value}}``.
    ``process`` returns an array of shape ``(len(names), n)``; row ``i`` is
    ``names[i]``. The packed ``kinds``, ``states`` and ``params`` arrays are
    what a compiled loop passes to ``step_guarded`` row by row.
    """

    def __init__(self, rate, estimators):
        if not isinstance(estimators, dict):
            estimators = {name: {} for name in estimators}
        members = [Estimator(name, rate, **params) for name, params in estimators.items()]
        self.rate = float(rate)
        self.names = [m.name for m in members]
        self.reads = sorted({i for m in members for i in m.spec.inputs})
        self.kinds = np.array([m.kind for m in members], dtype=np.int64)
        width_p = max([len(m.p) for m in members], default=1)
        width_s = max([len(m.state) for m in members], default=1)
        self.params = np.zeros((len(members), width_p))
        self.states = np.zeros((len(members), width_s))
        for i, m in enumerate(members):
            self.params[i, : len(m.p)] = m.p

    def index(self, name):
        return self.names.index(name)

    def reset(self):
        self.states[:] = 0.0

    def process(self, position, acceleration=None, velocity=None):
        x, a, v = _inputs(position, acceleration, velocity, self.reads, "this bank")
        out = np.empty((len(self.names), x.shape[0]))
        run_bank(self.kinds, self.states, self.params, x, a, v, out)
        return out
