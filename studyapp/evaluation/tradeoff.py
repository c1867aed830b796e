"""The speed/accuracy trade: what each estimator costs beside how well it does, at several rates.

For every rate (default the haptic rates 5, 10, 20 and 40 kHz; any from 1 to
96 kHz) a short set of recordings is simulated (``simulated.SimulatedSet``:
``studyapp.model.simulate`` with LVT in the loop, as in the paper), every
estimator is evaluated on it (error E, delay D of eqs. 22-24, the global
objective F_g of eqs. 27-32 normalised across the estimators at that rate),
and its cost is measured with ``studyapp.estimators.benchmark.cost`` (median
ns per sample of the streaming form, as the haptic loop runs it). Two Pareto
fronts (all criteria lower is better) say which estimators are worth their
cost: ``pareto`` over (cost, F_g), and ``pareto_error_delay_cost`` over
(median E, median |D|, cost; a delay counts by its magnitude, as in F_g,
since the normalised delay reads an estimate that leads the reference as
D < 0). D is given in samples and in microseconds (D / rate), since a sample
is shorter at a higher rate.

Parameters, three ways:

- ``tune_patience=N``: re-tuned at each rate (``retune.py``: the paper's optimiser on
  the rate's data set, starting from Table 1 made for the rate), so each rate
  compares estimators at their best there;
- else the given set (a tuned PARAMS.toml, or Table 1), made for each rate:
  parameters measured in samples (window lengths, the backward difference's
  steps) keep their duration by default, scaled by rate / ``params_rate`` (the
  rate the set was tuned at, 5 kHz for Table 1), so LEASTSQ's 33-sample window
  at 5 kHz becomes 264 samples at 40 kHz; with ``windows="samples"`` they are
  used as given. Cut-offs, covariances and margins are used unchanged.

An estimator whose parameters cannot exist at a rate (COMP2's 2,254 Hz
high-pass below 4.6 kHz: every cut-off must stay below 0.49 x rate) is not
available there: it gets a row with ``available`` false and the reason, and
the others go on.

F_g and the Pareto fronts are per rate, so compare F_g within a rate; across
rates compare E (m/s) and D in microseconds.
"""

from dataclasses import dataclass, field

import numpy as np

from studyapp.errors import ParameterError, UserError
from studyapp.estimators import conventions
from studyapp.estimators.at_rate import at_rate
from studyapp.estimators.benchmark import cost as streaming_cost
from studyapp.estimators.registry import spec
from studyapp.evaluation.executors import InlineExecutor
from studyapp.evaluation.metric import DEFAULT_METHOD
from studyapp.evaluation.pareto import pareto_front
from studyapp.evaluation.report import evaluate
from studyapp.evaluation.retune import retune
from studyapp.evaluation.simulated import SimulatedSet

DEFAULT_RATES = (5000.0, 10000.0, 20000.0, 40000.0)
DEFAULT_FMAX = (0.5, 1.4, 2.2, 4.4, 7.7)

COLUMNS = [
    "rate", "estimator", "available", "reason", "parameters_source",
    "cost_ns_per_sample", "block_ns_per_sample", "objective", "rank", "pareto", "pareto_error_delay_cost",
    "error_median", "delay_median", "delay_median_us", "error_pct_lowpass_median", "delay_pct_lowpass_median",
    "parameters",
]


def params_at_rate(params, rate, params_rate, windows="seconds"):
    """``params`` (name -> values tuned at ``params_rate``) made for ``rate``.

    Returns ``(available, not_available)``: name -> validated parameters, and
    name -> why the estimator cannot run at ``rate`` (the validation message).
    """
    if windows not in ("seconds", "samples"):
        raise UserError(f"windows = {windows!r}: allowed is 'seconds' or 'samples'")
    available, missing = {}, {}
    for name, values in params.items():
        values = at_rate(name, values, rate, params_rate, windows)
        try:
            _, available[name] = spec(name).validate(rate, values)
        except ParameterError as exc:
            missing[name] = str(exc)
    return available, missing


def check_available(params, rates, params_rate, windows="seconds"):
    """Raise a ``UserError`` when no estimator of ``params`` can run at any of ``rates``."""
    if not any(params_at_rate(params, rate, params_rate, windows)[0] for rate in rates):
        _, missing = params_at_rate(params, rates[0], params_rate, windows)
        raise UserError(f"no estimator is available at {', '.join(f'{r:g}' for r in rates)} Hz: "
                        + "; ".join(missing.values()))


@dataclass
class Trade:
    """The trade table and how it was made."""

    rows: list  # one per rate and estimator (see COLUMNS), unavailable ones included
    not_available: list = field(default_factory=list)  # {"rate", "estimator", "reason"}
    tuning: dict = field(default_factory=dict)  # rate -> {"iterations", "parameter_sets_evaluated", "seconds"}


def _median(values):
    values = np.asarray(values, dtype=np.float64)
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else float("nan")


def _rows(rate, result, costs, source):
    names = result.names
    cost_of = [costs[n]["stream_ns_per_sample"] for n in names]
    errors = [float(np.median(result.errors[n])) for n in names]
    delays = [float(np.median(result.delays[n])) for n in names]
    lags = [float(np.median(np.abs(result.delays[n]))) for n in names]  # a lead counts as a lag, as in F_g
    front = pareto_front([[c, result.objective[n]] for c, n in zip(cost_of, names)])
    front3 = pareto_front([[c, e, d] for c, e, d in zip(cost_of, errors, lags)])
    ranking = result.ranking
    rows = {}
    for i, name in enumerate(names):
        rows[name] = {
            "rate": float(rate), "estimator": name, "available": True, "reason": "", "parameters_source": source,
            "cost_ns_per_sample": float(cost_of[i]),
            "block_ns_per_sample": float(costs[name]["block_ns_per_sample"]),
            "objective": result.objective[name], "rank": ranking.index(name) + 1,
            "pareto": bool(front[i]), "pareto_error_delay_cost": bool(front3[i]),
            "error_median": errors[i], "delay_median": delays[i], "delay_median_us": delays[i] / rate * 1e6,
            "error_pct_lowpass_median": _median(result.error_pct(name)),
            "delay_pct_lowpass_median": _median(result.delay_pct(name)),
            "parameters": {p.name: result.params[name][p.name] for p in spec(name).params},
            "conventions": conventions.of(name, result.params[name]),  # tradeoff.json only
        }
    return rows


def tradeoff(params, rates=DEFAULT_RATES, fmax_values=DEFAULT_FMAX, duration=2.0, seed=0, reference="lvt",
             params_rate=5000.0, windows="seconds", max_lag_s=0.02, cost=None, cost_samples=100_000,
             delay_method=DEFAULT_METHOD, tune_patience=None, executor=None, source_name=None, progress=None,
             tuning_progress=None):
    """The ``Trade`` of the estimators of ``params`` (name -> values) at each of ``rates``.

    ``tune_patience``: re-tune at each rate with this patience, on ``executor``
    (default: in this process); None: use ``params`` as they are. ``source_name`` names where the parameters came from
    (the ``parameters_source`` column). ``progress(line)`` gets a line per
    step; ``tuning_progress(rate)`` gives the optimiser's progress reporter.
    """
    if cost is None:
        cost = streaming_cost
    if duration <= 2 * max_lag_s:
        raise UserError(f"--duration {duration:g}: allowed is more than {2 * max_lag_s:g} s")
    tune = tune_patience is not None
    if tune and executor is None:
        executor = InlineExecutor()
    check_available(params, rates, params_rate, windows)
    source_name = source_name or ("tuned" if tune else "table1")
    say = progress or (lambda line: None)
    trade = Trade(rows=[])
    for k, rate in enumerate(rates, 1):
        step = f"tradeoff: {rate:g} Hz ({k}/{len(rates)}):"
        chosen, missing = params_at_rate(params, rate, params_rate, windows)
        for name, reason in missing.items():
            say(f"{step} {name} not available: {reason}")
            trade.not_available.append({"rate": float(rate), "estimator": name, "reason": reason})
        rows = {name: {"rate": float(rate), "estimator": name, "available": False, "reason": reason}
                for name, reason in missing.items()}
        if chosen:
            say(f"{step} simulating {len(fmax_values)} recordings of {duration:g} s")
            source = SimulatedSet(float(rate), tuple(float(f) for f in fmax_values), float(duration), int(seed),
                                  reference, float(max_lag_s), delay_method)
            dataset = source.load()
            if tune:
                say(f"{step} tuning {len(chosen)} estimators (patience {tune_patience})")
                result = retune(source, chosen, rate, executor, tune_patience, seed, windows,
                                tuning_progress(rate) if tuning_progress else None)
                chosen = result.params
                trade.tuning[float(rate)] = {
                    "iterations": result.iterations, "parameter_sets_evaluated": result.evaluated,
                    "seconds": round(result.seconds, 3),
                }
            say(f"{step} evaluating {len(chosen)} estimators")
            result = evaluate(dataset, chosen)
            costs = {}
            for i, name in enumerate(result.names, 1):
                say(f"{step} timing {name} ({i}/{len(result.names)})")
                costs[name] = cost(name, rate, chosen[name], n=cost_samples)
            rows.update(_rows(rate, result, costs, source_name))
        trade.rows += [rows[name] for name in params]
    return trade
