"""The parameter space an estimator is tuned in (paper Sec. 6.3.3, Table 2).

Each tuned parameter is one dimension, searched in its natural scale within
the range its estimator's spec allows at the sample rate: log10 for
cut-offs, covariances, margins and Levant's C (``Param.scale == "log"``),
linear for windows, orders and steps, which are rounded to integers. A point
of the space is a unit vector u in [0, 1]^d; ``values(u)`` maps it to
parameter values and ``unit(values)`` back.

Which parameters are tuned follows the paper's Table 2 by default
(``PAPER_TUNED``): e.g. the Kalman filters' position covariance R_p stays at
its measured value and the hybrids' inner LEVANT/FOAW settings stay fixed, as
in the paper. ``tune="all"`` tunes every numeric parameter instead. Choice
parameters (the Kalman ``q_convention``) are never tuned: they change the
meaning of q, not its value.

Search ranges are the spec's ranges except where ``SEARCH_RANGES`` narrows
them: FOAW's cost per sample grows with its window and margin (measured:
about 2.5 us per sample at window 256 and a 1 mm margin, against 0.1-0.6 us at
the paper's 17 and 0.1 mm), and long windows only add delay on stick-slip, so
the optimiser searches windows up to 64 and margins from 0.1 um to 1 cm, which
hold the paper's optimum and the LVDT noise (15 um RMS) with orders of
magnitude to spare. ``ranges`` overrides any range (``--range
FOAW.window=2:256``), within the spec's. A search starts from Table 1's
values, each moved to the nearest end of its range where it lies outside.
"""

import math
from dataclasses import dataclass

import numpy as np

from studyapp.errors import ParameterError, UserError
from studyapp.estimators import lvt
from studyapp.estimators.registry import spec as lookup
from studyapp.estimators.spec import validate_rate

PAPER_TUNED = {
    "BDIFF": ("steps",),
    "LOWPASS": ("cutoff_hz",),
    "LEASTSQ": ("order", "window"),
    "FOAW": ("window", "margin"),
    "LEVANT": ("c",),
    "LEVANTLP": ("c", "cutoff_hz"),
    "KALPOS": ("q",),
    "KALMAN": ("q", "r_acc"),
    "KALLEV": ("q", "r_acc"),
    "KALLEVACC": ("q", "r_acc"),
    "KALFOAW": ("q", "r_acc"),
    "KALFOAWACC": ("q", "r_acc"),
    "COMP1": ("cutoff_hz",),
    "COMP2": ("lpf_hz", "hpf_hz"),
    "LVT": (),
}

_FOAW_RANGES = {"window": (2, 64), "margin": (1e-7, 1e-2), "margin_vel": (1e-4, 1e2)}
SEARCH_RANGES = {name: dict(_FOAW_RANGES) for name in ("FOAW", "KALFOAW", "KALFOAWACC")}

# The thirteen estimators of the paper's Table 2 (BDIFF and LVT are ours).
PAPER_ESTIMATORS = [name for name in PAPER_TUNED if name not in ("BDIFF", lvt.NAME)]


@dataclass(frozen=True)
class Dimension:
    """One tuned parameter: its range and natural scale."""

    name: str
    low: float
    high: float
    log: bool
    integer: bool

    def value(self, u):
        u = min(1.0, max(0.0, float(u)))
        if self.log:
            v = 10.0 ** (math.log10(self.low) + u * (math.log10(self.high) - math.log10(self.low)))
        else:
            v = self.low + u * (self.high - self.low)
        if self.integer:
            return int(min(self.high, max(self.low, round(v))))
        return float(min(self.high, max(self.low, v)))

    def unit(self, value):
        value = min(self.high, max(self.low, float(value)))
        if self.high == self.low:
            return 0.0
        if self.log:
            return (math.log10(value) - math.log10(self.low)) / (math.log10(self.high) - math.log10(self.low))
        return (value - self.low) / (self.high - self.low)

    @property
    def step(self):
        """The smallest move in unit coordinates that changes an integer's value (0 for floats)."""
        if not self.integer or self.high == self.low:
            return 0.0
        return 1.0 / (self.high - self.low)


class Space:
    """The tuned dimensions of one estimator at one rate, and its fixed parameters."""

    def __init__(self, name, rate, tune="paper", fixed=None, ranges=None):
        self.spec = lookup(name)
        self.name = self.spec.name
        self.rate = validate_rate(rate)
        given = dict(fixed or {})
        for key in given:
            self.spec.param(key)
        numeric = [p for p in self.spec.params if p.kind != "choice"]
        if tune == "paper":
            tuned = [p for p in numeric if p.name in PAPER_TUNED.get(self.name, ())]
        elif tune == "all":
            tuned = numeric
        else:
            raise UserError(f"tune = {tune!r}: allowed is 'paper' or 'all'")
        tuned = [p for p in tuned if p.name not in given]
        narrowed = {**SEARCH_RANGES.get(self.name, {}), **(ranges or {})}
        for key in ranges or {}:
            self.spec.param(key)
        self.dims = []
        for p in tuned:
            low, high = float(p.low), float(p.high_at(self.rate))
            if p.name in narrowed:
                want_low, want_high = (float(v) for v in narrowed[p.name])
                if p.name in (ranges or {}) and not (low <= want_low <= want_high <= high):
                    raise UserError(f"--range {self.name}.{p.name}={want_low:g}:{want_high:g}: allowed is "
                                    f"{low:g} <= LOW <= HIGH <= {high:g}")
                low, high = max(low, want_low), min(high, want_high)
            log = p.scale == "log" and low > 0
            self.dims.append(Dimension(p.name, low, high, log, p.kind == "int"))
        tuned_names = {d.name for d in self.dims}
        # Fixed parameters keep their given value, else the spec's default (Table 1). A tuned
        # default outside its range (narrowed, or capped by the rate: COMP2's 2,254 Hz high-pass
        # below 4.6 kHz) starts from the range's nearest end.
        start = dict(given)
        for d in self.dims:
            default = self.spec.param(d.name).default
            if not d.low <= default <= d.high:
                start[d.name] = d.value(d.unit(default))
        _, self.start = self.spec.validate(self.rate, start)
        self.fixed = {k: v for k, v in self.start.items() if k not in tuned_names}

    @property
    def names(self):
        return [d.name for d in self.dims]

    def values(self, u):
        """All parameters of the point u: fixed ones plus the tuned ones mapped from u."""
        params = dict(self.fixed)
        for d, x in zip(self.dims, u):
            params[d.name] = d.value(x)
        return params

    def unit(self, params):
        return np.array([d.unit(params[d.name]) for d in self.dims], dtype=np.float64)

    def valid(self, params):
        """True when the estimator accepts ``params`` (ranges and constraints between parameters)."""
        try:
            self.spec.validate(self.rate, params)
        except ParameterError:
            return False
        return True

    def describe(self):
        return {
            "estimator": self.name,
            "rate": self.rate,
            "tuned": [
                {"name": d.name, "low": d.low, "high": d.high, "scale": "log" if d.log else "linear",
                 "integer": d.integer}
                for d in self.dims
            ],
            "fixed": {k: v for k, v in self.fixed.items()},
        }
