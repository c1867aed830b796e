"""The speed/accuracy trade: what each estimator costs beside how well it does, at several rates.

For every rate (default the haptic rates 5, 10, 20 and 40 kHz) a short set of
recordings is simulated with ``studyapp.model.simulate`` (LVT in the loop, as
in the paper), every estimator is evaluated on it (error E, delay D, the
global objective F_g normalised across the estimators at that rate), and its
cost is measured with ``studyapp.estimators.benchmark.cost`` (median ns per
sample of the streaming form, as the haptic loop runs it). The Pareto front
of cost against F_g shows which estimators are worth their cost at each rate.

Parameters measured in samples (window lengths, the backward difference's
steps) keep their duration by default: tuned at ``params_rate`` (5 kHz unless
the parameter file says otherwise), they are scaled by rate / params_rate, so
LEASTSQ's 33-sample window at 5 kHz becomes 264 samples at 40 kHz. With
``windows="samples"`` they are used as given. Cut-offs, covariances and
margins are physical quantities and are used unchanged.

F_g is normalised per rate, so compare F_g within a rate; across rates compare
E (m/s) and D in milliseconds, which the table also gives.
"""

import numpy as np

from studyapp.errors import UserError
from studyapp.evaluation.dataset import Dataset, take_from_recording
from studyapp.evaluation.pareto import pareto_front
from studyapp.evaluation.report import evaluate

DEFAULT_RATES = (5000.0, 10000.0, 20000.0, 40000.0)
DEFAULT_FMAX = (0.5, 1.4, 2.2, 4.4, 7.7)

COLUMNS = [
    "rate", "estimator", "cost_ns_per_sample", "block_ns_per_sample", "objective", "rank", "pareto",
    "error_median", "delay_median", "delay_median_ms", "error_pct_lowpass_median", "delay_pct_lowpass_median",
    "parameters",
]


def params_at_rate(params, rate, params_rate, windows="seconds"):
    """``params`` (name -> values tuned at ``params_rate``) made for ``rate``, validated."""
    from studyapp.estimators.registry import spec

    if windows not in ("seconds", "samples"):
        raise UserError(f"windows = {windows!r}: allowed is 'seconds' or 'samples'")
    out = {}
    for name, values in params.items():
        s = spec(name)
        values = dict(values)
        if windows == "seconds":
            for p in s.params:
                if p.kind == "int" and p.unit == "samples" and p.name in values:
                    scaled = int(round(values[p.name] * rate / params_rate))
                    values[p.name] = int(min(p.high, max(p.low, scaled)))
        _, out[name] = s.validate(rate, values)
    return out


def simulate_takes(rate, fmax_values, duration, seed, reference, simulate=None):
    """Short recordings simulated at ``rate``, one per F_max, as takes."""
    if simulate is None:
        from studyapp.model import simulate
    takes = []
    for i, fmax in enumerate(fmax_values):
        recording = simulate(fmax, rate=rate, duration=duration, seed=seed + i)
        takes.append(take_from_recording(recording, f"fmax_{fmax:g}@{rate:g}Hz", reference))
        takes[-1].fmax = float(fmax)
    return takes


def tradeoff(params, rates=DEFAULT_RATES, fmax_values=DEFAULT_FMAX, duration=2.0, seed=0, reference="lvt",
             params_rate=5000.0, windows="seconds", max_lag_s=0.02, cost=None, cost_samples=100_000,
             simulate=None, progress=None):
    """Rows of the trade table (see ``COLUMNS``), one per rate and estimator."""
    if cost is None:
        from studyapp.estimators.benchmark import cost
    if duration <= 2 * max_lag_s:
        raise UserError(f"--duration {duration:g}: allowed is more than {2 * max_lag_s:g} s")
    rows = []
    for rate in rates:
        if progress:
            progress(f"tradeoff: {rate:g} Hz: simulating {len(fmax_values)} recordings of {duration:g} s")
        takes = simulate_takes(rate, fmax_values, duration, seed, reference, simulate)
        chosen = params_at_rate(params, rate, params_rate, windows)
        result = evaluate(Dataset(takes, max_lag_s), chosen)
        costs = {}
        for name in result.names:
            if progress:
                progress(f"tradeoff: {rate:g} Hz: timing {name}")
            costs[name] = cost(name, rate, chosen[name], n=cost_samples)
        front = pareto_front([[costs[n]["stream_ns_per_sample"], result.objective[n]] for n in result.names])
        ranking = result.ranking
        for name, on_front in zip(result.names, front):
            delays = result.delays[name]
            rows.append({
                "rate": float(rate), "estimator": name,
                "cost_ns_per_sample": float(costs[name]["stream_ns_per_sample"]),
                "block_ns_per_sample": float(costs[name]["block_ns_per_sample"]),
                "objective": result.objective[name], "rank": ranking.index(name) + 1, "pareto": bool(on_front),
                "error_median": float(np.median(result.errors[name])),
                "delay_median": float(np.median(delays)),
                "delay_median_ms": float(np.median(delays / np.asarray(result.rates)) * 1e3),
                "error_pct_lowpass_median": float(np.nanmedian(result.error_pct(name))),
                "delay_pct_lowpass_median": float(np.nanmedian(result.delay_pct(name)))
                if np.isfinite(result.delay_pct(name)).any() else float("nan"),
                "parameters": " ".join(f"{k}={v}" for k, v in chosen[name].items()),
            })
    return rows
