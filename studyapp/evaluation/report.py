"""The numerical comparison of tuned estimators (paper Sec. 7.2, Fig. 5).

For every estimator and recording r: the delay-corrected error E_r (m/s) and
the delay D_r (samples) of eqs. 22-24, by the dataset's delay method (negative
for an estimate that leads the reference, with the normalised method); both as
a percentage of LOWPASS's on the same recording (Fig. 5's normalisation, since
results vary between recordings but are consistent across estimators within
one; a lead gives a negative percentage); and the normalised objectives of
eqs. 29-32, which count |D_r|, with the bounds taken over the evaluated
estimators themselves. A recording's objective is F_2r + F_2r+1; the global
objective F_g is their sum over all recordings (eq. 27), and the ranking is by
F_g, best (lowest) first.

Fig. 5's two groups: (a) the recordings of F_max = 0 to 7.7 N, (b) the
high-gain half, 2.2 to 12.1 N. A recording without a known F_max belongs to
group a only.
"""

from dataclasses import dataclass

import numpy as np

from studyapp.estimators import conventions
from studyapp.evaluation.normalisation import bounds, per_objective, raw_objectives

BASELINE = "LOWPASS"
GROUPS = {"a": (0.0, 7.7), "b": (2.2, 12.1)}
GROUP_TITLES = {"a": "F_max 0 to 7.7 N", "b": "F_max 2.2 to 12.1 N (high gain)"}


def in_group(fmax, group):
    low, high = GROUPS[group]
    if fmax is None:
        return group == "a"
    return low - 1e-9 <= fmax <= high + 1e-9


def finite_median(values):
    """Median of the finite values; NaN when there are none (a percentage of a LOWPASS delay of 0)."""
    values = np.asarray(values, dtype=np.float64)
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else float("nan")


def _percent(values, baseline):
    with np.errstate(divide="ignore", invalid="ignore"):
        # the ratio first: a value against itself is then exactly 100 (100 x / x need not be)
        pct = 100.0 * (np.asarray(values, dtype=np.float64) / np.asarray(baseline, dtype=np.float64))
    return np.where(np.isfinite(pct), pct, np.nan)


@dataclass
class Evaluation:
    """E and D of each estimator on each recording, and what follows from them."""

    names: list  # estimators evaluated, in the order given
    recordings: list  # recording names (files)
    fmax: list  # F_max of each recording (None when unknown)
    rates: list
    params: dict  # name -> parameters used
    errors: dict  # name -> array (m/s)
    delays: dict  # name -> array (samples)
    baseline_errors: np.ndarray
    baseline_delays: np.ndarray
    delay_method: str = "normalised"
    subsample_delays: dict = None  # name -> array (samples, float; subsample_delay.subsample_delay), when measured
    baseline_subsample_delays: np.ndarray = None

    def __post_init__(self):
        raw = np.array([self._raw(name) for name in self.names])
        self.offsets, self.scales = bounds(raw)
        self.recording_objective = {}
        self.objective = {}
        for name, row in zip(self.names, raw):
            f = per_objective(row, self.offsets, self.scales)
            per_recording = f[0::2] + f[1::2]
            self.recording_objective[name] = per_recording
            self.objective[name] = float(np.sum(per_recording)) if np.all(np.isfinite(f)) else float("inf")

    def _raw(self, name):
        return raw_objectives(self.errors[name], self.delays[name])

    @property
    def ranking(self):
        return sorted(self.names, key=lambda n: (self.objective[n], self.names.index(n)))

    def error_pct(self, name):
        return _percent(self.errors[name], self.baseline_errors)

    def delay_pct(self, name):
        return _percent(self.delays[name], self.baseline_delays)

    def abs_delays(self, name):
        """|D| per recording in samples: the sub-sample delay where measured, else the whole-sample D."""
        if self.subsample_delays is not None:
            return np.abs(np.asarray(self.subsample_delays[name], dtype=np.float64))
        return np.abs(np.asarray(self.delays[name], dtype=np.float64))

    def subsample_delay_pct(self, name):
        """The sub-sample delay as % of LOWPASS's (the whole-sample ``delay_pct`` where not measured)."""
        if self.subsample_delays is None:
            return self.delay_pct(name)
        return _percent(self.subsample_delays[name], self.baseline_subsample_delays)

    def group_mask(self, group):
        return np.array([in_group(f, group) for f in self.fmax], dtype=bool)

    def measures(self, group):
        """measure -> name -> values over the group's recordings (Fig. 5's panels and wilcoxon.csv).

        The delay by its magnitude, |D| as % of LOWPASS's |D| (``abs_delay_pct_lowpass``),
        as the objective counts it: a lead of the band-limited LVT is no better than a lag.
        """
        mask = self.group_mask(group)
        return {
            "objective": {n: self.recording_objective[n][mask] for n in self.names},
            "error_pct_lowpass": {n: self.error_pct(n)[mask] for n in self.names},
            "abs_delay_pct_lowpass": {n: np.abs(self.delay_pct(n)[mask]) for n in self.names},
        }

    def to_json(self):
        """The ``studyapp evaluate --json`` structure (NaN becomes null).

        ``parameters``: what each estimator ran with; ``conventions``: what
        those numbers mean (``estimators.conventions.record``).
        """
        return {
            "estimators": {
                name: {
                    "error": _list(self.errors[name]),
                    "delay": [int(d) for d in self.delays[name]],
                    "error_pct_lowpass": _list(self.error_pct(name)),
                    "delay_pct_lowpass": _list(self.delay_pct(name)),
                    "objective": _number(self.objective[name]),
                    **({} if self.subsample_delays is None else
                       {"delay_subsample": _list(self.subsample_delays[name]),
                        "delay_subsample_pct_lowpass": _list(self.subsample_delay_pct(name))}),
                }
                for name in self.names
            },
            "ranking": self.ranking,
            "parameters": {name: dict(self.params[name]) for name in self.names},
            "conventions": conventions.record({name: self.params[name] for name in self.names}),
            "delay_method": self.delay_method,
            "recordings": [
                {"file": r, "fmax": f, "rate": rate}
                for r, f, rate in zip(self.recordings, self.fmax, self.rates)
            ],
        }

    def rows(self):
        """Long-format rows, one per estimator and recording (evaluation.csv)."""
        for name in self.names:
            e_pct, d_pct = self.error_pct(name), self.delay_pct(name)
            for r, recording in enumerate(self.recordings):
                yield {
                    "estimator": name, "recording": recording, "fmax": self.fmax[r],
                    "error": self.errors[name][r], "delay": int(self.delays[name][r]),
                    "delay_s": self.delays[name][r] / self.rates[r],
                    "error_pct_lowpass": e_pct[r], "delay_pct_lowpass": d_pct[r],
                    "recording_objective": self.recording_objective[name][r],
                    "objective": self.objective[name], "rank": self.ranking.index(name) + 1,
                    **({} if self.subsample_delays is None else
                       {"delay_subsample": self.subsample_delays[name][r]}),
                }


def _number(x):
    x = float(x)
    return x if np.isfinite(x) else None


def _list(values):
    return [_number(v) for v in values]


def evaluate(dataset, params):
    """An ``Evaluation`` of each ``name -> parameters`` in ``params`` on ``dataset``.

    LOWPASS is the percentage baseline; when it is not among the names it is
    run with its own entry of ``params`` if any, else Table 1's default.
    """
    names = list(params)
    errors, delays, subsample = {}, {}, {}
    for name in names:
        errors[name], delays[name] = dataset.delays_and_errors(name, params[name])
        subsample[name] = dataset.subsample_delays(name, params[name])
    if BASELINE in errors:
        base_e, base_d, base_s = errors[BASELINE], delays[BASELINE], subsample[BASELINE]
    else:
        base_e, base_d = dataset.delays_and_errors(BASELINE, {})
        base_s = dataset.subsample_delays(BASELINE, {})
    return Evaluation(
        names=names, recordings=dataset.names, fmax=[t.fmax for t in dataset.takes],
        rates=[t.rate for t in dataset.takes], params=params, errors=errors, delays=delays,
        baseline_errors=base_e, baseline_delays=base_d, delay_method=dataset.delay_method,
        subsample_delays=subsample, baseline_subsample_delays=base_s,
    )
