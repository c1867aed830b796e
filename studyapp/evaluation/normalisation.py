"""The objective sum with adaptive normalisation (paper Sec. 6.3, eqs. 27-32, steps 1-8).

Each estimator e has 2n raw objectives over n recordings, in the order of eq. 28:

    F_raw^e = [E_0, |D_0|, E_1, |D_1|, ..., E_{n-1}, |D_{n-1}|]

A delay counts by its magnitude. The normalised delay (``metric.py``, the
default) reads an estimate that leads the reference as D < 0, which happens
against the band-limited LVT; a lead is as much a mismatch with the reference
as a lag, and D itself would reward leading it without bound. With eq. 22's
delay (``--delay paper``) D >= 0, so |D| = D and the paper's objective is
unchanged.

Normalisation (eqs. 29-32). At a remembered iteration K, offsets and scales are
taken from the best and worst estimator on each objective i:

    O_i(K) = -min_e F_raw,i^e(K),     S_i(K) = max_e F_raw,i^e(K) - min_e F_raw,i^e(K)

and the global objective (eq. 27 with all weights 1) of a parameter set is

    F_g^e(k, K) = sum_i (F_raw,i^e(k) + O_i(K)) / S_i(K).

The values "at iteration K" are those of every estimator's retained (best so
far) parameter set once iteration K's decisions are made; rejected candidates
never set the scale, so one wild sample cannot stretch it. Where the paper's
text leaves this open, this is our reading of "the range defined by the best
and worst results from a previous iteration".

Where all estimators agree on an objective (S_i = 0: one estimator alone, or
equal integer delays) the spread cannot scale it; the magnitude |min_e| is used
instead (1 if that is 0 too), so the term measures a relative change.

Procedure (steps 1-8). Iteration 0 evaluates a first set for every estimator
and memorises (O, S) from it (b_0 = 0). At each later iteration k every
estimator still searching proposes a new set; each candidate is compared with
its estimator's best under the memorised scale, F_g^e(k, b_k) < F_g^e(best,
b_k) (less a small tolerance, so rounding noise is no improvement). If any
estimator improved, b_{k+1} = k and (O, S) are memorised anew from the updated
bests; otherwise b_{k+1} = b_k. Every comparison is therefore made under one
scale, while the scale follows the estimators as they improve.
"""

from dataclasses import dataclass

import numpy as np


def raw_objectives(errors, delays):
    """Eq. 28's vector [E_0, |D_0|, E_1, |D_1|, ...] from per-recording errors and delays."""
    errors = np.asarray(errors, dtype=np.float64)
    raw = np.empty(2 * errors.shape[0])
    raw[0::2] = errors
    raw[1::2] = np.abs(np.asarray(delays, dtype=np.float64))
    return raw


def bounds(raw):
    """(offsets, scales) of eqs. 30 and 32 from a (estimators x objectives) array.

    Estimators with a non-finite objective are left out of the bounds (a set
    that made an estimator diverge says nothing about the scale).
    """
    raw = np.atleast_2d(np.asarray(raw, dtype=np.float64))
    finite = np.all(np.isfinite(raw), axis=1)
    if not finite.any():
        j = raw.shape[1]
        return np.zeros(j), np.ones(j)
    rows = raw[finite]
    low = rows.min(axis=0)
    spread = rows.max(axis=0) - low
    magnitude = np.abs(low)
    scales = np.where(spread > 0, spread, np.where(magnitude > 0, magnitude, 1.0))
    return -low, scales


def global_objective(raw, offsets, scales):
    """F_g (eq. 27, unit weights) of raw objectives under one memorised scale; inf if any is not finite."""
    raw = np.asarray(raw, dtype=np.float64)
    if not np.all(np.isfinite(raw)):
        return float("inf")
    return float(np.sum((raw + offsets) / scales))


def per_objective(raw, offsets, scales):
    """The normalised objectives F_i (eqs. 29 and 31) themselves."""
    return (np.asarray(raw, dtype=np.float64) + offsets) / scales


@dataclass
class Decision:
    """The outcome of one candidate at one iteration."""

    candidate: float  # F_g of the candidate under the scale in force before the step
    best: float  # F_g of the estimator's retained set under that same scale
    accepted: bool


class ObjectiveSum:
    """The paper's steps 1-8 over raw objectives; knows nothing of estimators or files.

    ``start(raws)`` is steps 1-4 (``raws``: name -> raw objective vector of the
    first sets); ``step(raws)`` is steps 5-8 for the candidates of one
    iteration (any subset of the names) and returns name -> ``Decision``.
    ``tolerance`` is how much F_g must fall to count as an improvement.
    """

    def __init__(self, tolerance=0.0):
        self.tolerance = float(tolerance)
        self.iteration = 0
        self.remembered = 0
        self.best = {}
        self.offsets = None
        self.scales = None

    def start(self, raws):
        self.iteration = 0
        self.remembered = 0
        self.best = {name: np.asarray(raw, dtype=np.float64) for name, raw in raws.items()}
        self._memorise()

    def _memorise(self):
        self.offsets, self.scales = bounds(np.array(list(self.best.values())))

    def objective(self, raw):
        """F_g of raw objectives under the memorised scale."""
        return global_objective(raw, self.offsets, self.scales)

    def step(self, raws):
        self.iteration += 1
        decisions = {}
        for name, raw in raws.items():
            raw = np.asarray(raw, dtype=np.float64)
            candidate = self.objective(raw)
            best = self.objective(self.best[name])
            accepted = bool(candidate < best - self.tolerance)
            decisions[name] = Decision(candidate, best, accepted)
        improved = [name for name, d in decisions.items() if d.accepted]
        for name in improved:
            self.best[name] = np.asarray(raws[name], dtype=np.float64)
        if improved:
            self.remembered = self.iteration
            self._memorise()
        return decisions

    def objectives(self):
        """name -> F_g of each retained set under the memorised scale."""
        return {name: self.objective(raw) for name, raw in self.best.items()}

    def state(self):
        return {
            "tolerance": self.tolerance,
            "iteration": self.iteration,
            "remembered": self.remembered,
            "best": {name: raw.tolist() for name, raw in self.best.items()},
            "offsets": self.offsets.tolist(),
            "scales": self.scales.tolist(),
        }

    @classmethod
    def from_state(cls, state):
        obj = cls(state["tolerance"])
        obj.iteration = int(state["iteration"])
        obj.remembered = int(state["remembered"])
        obj.best = {name: np.asarray(raw, dtype=np.float64) for name, raw in state["best"].items()}
        obj.offsets = np.asarray(state["offsets"], dtype=np.float64)
        obj.scales = np.asarray(state["scales"], dtype=np.float64)
        return obj
