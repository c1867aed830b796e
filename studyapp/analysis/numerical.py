"""Subjective against numerical rankings (paper Sec. 10).

The paper compares the ranking by median noisiness rating with the ranking by
numerical delay-corrected error, and the ranking by median max F_max with the
ranking by numerical delay: Spearman's rho = 0.61 and 0.43.

The numerical side is an ``evaluation.json`` written by ``studyapp evaluate -o
DIR``: ``{"estimators": {NAME: {"error": [...], "delay": [...],
"error_pct_lowpass": [...], "delay_pct_lowpass": [...], "objective": x}},
"ranking": [...]}``, one list entry per recording; with ``--perceptual`` each
estimator also has ``audio_distance`` (a number, or one per recording; read
in perceptual.py). Each estimator's numerical
score is the median over recordings of its error (or delay) as percent of
LOWPASS, Fig. 5's normalisation; when those lists are absent or empty, the
median of the raw ``error`` (``delay``) list. Which one was used is reported.
The delay counts by its magnitude, |D|, as the evaluation's objective counts
it: an estimate one sample ahead of the LVT reference is no closer to it than
one a sample behind.

Both comparisons are oriented so that rho > 0 means the rankings agree:
noisiness and error are both better when lower (rho of the two medians);
F_max is better when higher but delay when lower (rho of -F_max and delay).
Only conditions present on both sides count; rho needs three or more.
"""

from pathlib import Path

import numpy as np
import pandas as pd

from studyapp.stats.spearman import spearman
from studyapp.errors import InputDataError
from studyapp.io.small_files import read_json

EVALUATION_LIMIT = 1 << 26  # bytes: evaluation.json of 13 estimators on 15 recordings is about 100 kB

NUMERICAL_COLUMNS = ["comparison", "subjective", "numerical", "metric", "n", "rho", "p_value", "conditions"]


def load_evaluation(source):
    """The parsed ``evaluation.json`` in folder ``source`` (or the file ``source`` itself), checked."""
    path = Path(source)
    if path.is_dir():
        path = path / "evaluation.json"
    if not path.is_file():
        raise InputDataError(f"{path}: no such evaluation file (expected the output of 'studyapp evaluate -o DIR')")
    data = read_json(path, "evaluation file", EVALUATION_LIMIT)  # a FIFO, a huge or deeply nested file: one line
    estimators = data.get("estimators") if isinstance(data, dict) else None
    if not isinstance(estimators, dict) or not estimators:
        raise InputDataError(f"{path}: field 'estimators' must be a non-empty object of estimator results")
    for name, result in estimators.items():
        if not isinstance(result, dict):
            raise InputDataError(f"{path}: field 'estimators.{name}' must be an object")
        for field in ("error", "delay"):
            if field not in result:
                raise InputDataError(f"{path}: missing field 'estimators.{name}.{field}'")
        for field in ("error", "delay", "error_pct_lowpass", "delay_pct_lowpass"):
            if field in result:
                _numbers(result[field], f"{path}: field 'estimators.{name}.{field}'")
        if "audio_distance" in result:
            number_or_numbers(result["audio_distance"], f"{path}: field 'estimators.{name}.audio_distance'")
    return data


def numerical_scores(evaluation, quantity):
    """(Series of median ``quantity`` per upper-case estimator name, metric name used).

    ``quantity`` is ``"error"`` or ``"delay"``.
    """
    estimators = evaluation["estimators"]
    normalised = f"{quantity}_pct_lowpass"
    use_pct = all(len(r.get(normalised) or []) > 0 for r in estimators.values())
    metric = normalised if use_pct else quantity
    scores = {}
    for name, result in estimators.items():
        values = _numbers(result[metric], metric)
        if quantity == "delay":
            values = np.abs(values)
        finite = values[np.isfinite(values)]
        if finite.size:
            scores[name.upper()] = float(np.median(finite))
    return pd.Series(scores, dtype=float), metric


def compare_with_numerical(evaluation, noisiness_medians, fmax_medians):
    """DataFrame ``NUMERICAL_COLUMNS``: the paper's two Sec. 10 comparisons.

    ``noisiness_medians`` and ``fmax_medians`` are Series indexed by condition.
    """
    rows = []
    for label, subjective_name, subjective, quantity, sign in (
        ("noisiness vs error", "median noisiness", noisiness_medians, "error", 1.0),
        ("max F_max vs delay", "median max F_max", fmax_medians, "delay", -1.0),
    ):
        scores, metric = numerical_scores(evaluation, quantity)
        common = [c for c in subjective.index if c in scores.index]
        rho, p = spearman(sign * subjective[common].to_numpy(dtype=float), scores[common].to_numpy())
        rows.append((label, subjective_name, f"median {quantity}", metric, len(common), rho, p, " ".join(common)))
    table = pd.DataFrame(rows, columns=NUMERICAL_COLUMNS)
    for column in ["comparison", "subjective", "numerical", "metric", "conditions"]:
        table[column] = table[column].astype(object)
    return table


def number_or_numbers(value, where):
    """``value`` (a number, null, or a list of them) as a float array; NaN for null."""
    values = value if isinstance(value, list) else [value]
    if not all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in values):
        raise InputDataError(f"{where} must be a number or a list of numbers")
    return _numbers(values, where)


def _numbers(values, where):
    if not isinstance(values, list) or not all(
        v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in values
    ):
        raise InputDataError(f"{where} must be a list of numbers")
    return np.array([np.nan if v is None else v for v in values], dtype=float)
