"""Parameter and estimator specifications, with validation.

Every estimator is described by an ``EstimatorSpec``: its parameters (name,
default, unit, allowed range), the inputs it reads, and ``build``, which turns
validated parameters and a sample rate into the compiled kernel's flat
``float64`` parameter vector and the size of its state vector.

Validation follows mido's style: one ``ParameterError`` (a ``ValueError``) whose
message names the estimator, the parameter, the value and what is allowed.
"""

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from studyapp.errors import ParameterError
from studyapp.number_text import shown, to_float

RATE_MIN = 1_000.0
RATE_MAX = 96_000.0
NYQUIST_FRACTION = 0.49  # cut-offs must stay below this fraction of the rate (Table 1 has 2,254 Hz at 5 kHz)


@dataclass(frozen=True)
class Param:
    """One tunable parameter.

    ``kind`` is ``"float"``, ``"int"`` or ``"choice"``. For frequencies,
    ``below_nyquist`` caps ``high`` at ``NYQUIST_FRACTION * rate``.
    ``scale`` is the parameter's natural search scale (``"log"`` or
    ``"linear"``), used by the optimiser.
    """

    name: str
    default: object
    unit: str = ""
    low: float | None = None
    high: float | None = None
    kind: str = "float"
    choices: tuple = ()
    below_nyquist: bool = False
    scale: str = "log"
    doc: str = ""

    def high_at(self, rate):
        if self.below_nyquist and rate is not None:
            cap = NYQUIST_FRACTION * rate
            return cap if self.high is None else min(self.high, cap)
        return self.high

    def allowed(self, rate=None):
        if self.kind == "choice":
            return "one of " + ", ".join(repr(c) for c in self.choices)
        high = self.high_at(rate)
        what = "an integer" if self.kind == "int" else "a number"
        if self.below_nyquist and rate is None:
            return f"{what} from {self.low:g} to min({self.high:g}, {NYQUIST_FRACTION} * rate) {self.unit}".strip()
        return f"{what} from {self.low:g} to {high:g} {self.unit}".strip()

    def validate(self, estimator, value, rate):
        where = f"{estimator} parameter {self.name!r}"
        if self.kind == "choice":
            if value not in self.choices:
                raise ParameterError(f"{where} = {value!r}: allowed is {self.allowed(rate)}")
            return value
        if isinstance(value, str):
            try:
                value = to_float(value)
            except ValueError:
                raise ParameterError(f"{where} = {value!r}: allowed is {self.allowed(rate)}") from None
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ParameterError(f"{where} = {value!r}: allowed is {self.allowed(rate)}")
        value = float(value)
        if not np.isfinite(value):
            raise ParameterError(f"{where} = {value!r}: allowed is {self.allowed(rate)}")
        if self.kind == "int":
            if value != int(value):
                raise ParameterError(f"{where} = {value!r}: allowed is {self.allowed(rate)}")
            value = int(value)
        high = self.high_at(rate)
        if (self.low is not None and value < self.low) or (high is not None and value > high):
            raise ParameterError(f"{where} = {value!r}: allowed is {self.allowed(rate)}")
        return value


@dataclass(frozen=True)
class EstimatorSpec:
    """What an estimator is, what it reads, and how to build its kernel.

    ``build(rate, params) -> (p, state_size)``: ``params`` is a dict of
    validated values; ``p`` is the flat float64 vector the kernel reads;
    the kernel's state starts as ``state_size`` zeros.
    ``check(rate, params)`` may raise ``ParameterError`` for constraints
    between parameters (e.g. LEASTSQ's window > order).
    """

    name: str
    kind: int
    description: str
    inputs: tuple
    params: tuple = ()
    build: Callable = None
    check: Callable | None = None
    reference: str = ""
    extra: dict = field(default_factory=dict)

    def param(self, name):
        for p in self.params:
            if p.name == name:
                return p
        allowed = ", ".join(p.name for p in self.params) or "none"
        raise ParameterError(f"{self.name} has no parameter {name!r}: allowed are {allowed}")

    def validate(self, rate, given):
        rate = validate_rate(rate)
        values = {p.name: p.default for p in self.params}
        for key, value in given.items():
            values[key] = self.param(key).validate(self.name, value, rate)
        for p in self.params:
            values[p.name] = p.validate(self.name, values[p.name], rate)
        if self.check is not None:
            self.check(rate, values)
        return rate, values

    def not_available(self, rate, given=None):
        """Why this estimator, with ``given`` (else Table 1's defaults), cannot exist at ``rate``; None if it can.

        Only the rate counts: values allowed at ``RATE_MAX`` but not at ``rate``
        (a cut-off above ``NYQUIST_FRACTION * rate``, e.g. COMP2's 2,254 Hz
        high-pass below 4.6 kHz). Values bad at every rate raise ``ParameterError``.
        """
        given = given or {}
        try:
            self.validate(rate, given)
        except ParameterError as exc:
            self.validate(RATE_MAX, given)
            return f"not available at {float(rate):g} Hz: {exc}"
        return None

    def describe(self):
        return {
            "name": self.name,
            "description": self.description,
            "inputs": list(self.inputs),
            "reference": self.reference,
            "parameters": [
                {
                    "name": p.name,
                    "default": p.default,
                    "unit": p.unit,
                    "kind": p.kind,
                    "allowed": p.allowed(),
                    **({"choices": list(p.choices)} if p.kind == "choice" else {"low": p.low, "high": p.high}),
                    **({"below_nyquist": True} if p.below_nyquist else {}),
                    "scale": p.scale,
                    "doc": p.doc,
                }
                for p in self.params
            ],
        }


def validate_rate(rate, name="rate"):
    """``rate`` as a float in [RATE_MIN, RATE_MAX]; ``ParameterError`` naming ``name`` (an option, a file's field)."""
    try:
        rate = None if isinstance(rate, bool) else to_float(rate)
    except (TypeError, ValueError):
        rate = None
    if rate is None or not (RATE_MIN <= rate <= RATE_MAX):
        text = "not a number" if rate is None else shown(rate)
        named = f"{name} {text}" if name.startswith("-") else f"{name} = {text}"  # an option, or a file's field
        raise ParameterError(f"{named}: allowed is a number from {RATE_MIN:g} to {RATE_MAX:g} Hz")
    return rate


def cutoff(name, default, doc=""):
    """A cut-off frequency parameter in Hz, below Nyquist."""
    return Param(name, default, "Hz", 1.0, 40_000.0, below_nyquist=True, doc=doc)


Q_CONVENTIONS = ("eq19", "scaled", "continuous")
Q_CONVENTION_DOC = (
    "eq19: Q = q Gamma Gamma^T (paper eq. 19 as printed); scaled: Q = q T Gamma Gamma^T (the authors' "
    "third-order filters); continuous: continuous white noise of spectral density q, for [x, v] "
    "Q = q [[T^3/3, T^2/2], [T^2/2, T]] (the authors' KALPOS)"
)


def q_convention(default):
    """The Kalman filters' process-noise convention (``kalman.py``); ``default`` is the one Table 1 was tuned in."""
    return Param("q_convention", default, kind="choice", choices=Q_CONVENTIONS, scale="linear",
                 doc=Q_CONVENTION_DOC)
