"""Noisiness ratings against the perceptual audio distance (the paper's Sec. 10 future work).

The paper found that the ranking by median noisiness rating correlated only
moderately with the ranking by numerical delay-corrected error (Spearman's
rho = 0.61) and proposed, as future work, "an objective function based on
models of human perception". ``studyapp evaluate --perceptual`` writes, per
estimator, ``audio_distance``: how far the string's audio with that estimator
in the loop is from the audio with the true velocity, same gesture and seed.
Here, over the conditions that are both rated and evaluated:

    rho(median normalised noisiness per condition, audio_distance per estimator)

next to rho(median noisiness, median error) from numerical.py and the paper's
0.61. Both sides are better when lower, so rho > 0 means the rankings agree.
``audio_distance`` may be one number per estimator or one per recording (then
its median over the finite values); null is skipped. An evaluation.json
without any ``audio_distance`` (written without ``--perceptual``) is not an
error: the row is left empty and ``perceptual_correlation`` returns a one-line
note saying why.
"""

import numpy as np
import pandas as pd

from studyapp.analysis.numerical import number_or_numbers, numerical_scores
from studyapp.stats.spearman import spearman

PERCEPTUAL_COLUMNS = ["comparison", "metric", "n", "rho", "p_value", "paper_rho", "conditions"]
PAPER_ERROR_RHO = 0.61  # paper Sec. 10: noisiness medians against delay-corrected error medians
NO_AUDIO_DISTANCE = (
    "the evaluation has no 'audio_distance' (written by 'studyapp evaluate --perceptual'): "
    "no perceptual correlation, only noisiness against error"
)


def audio_distances(evaluation):
    """Series: each estimator's audio_distance (median over recordings), upper-case names; finite only."""
    scores = {}
    for name, result in evaluation["estimators"].items():
        if "audio_distance" not in result:
            continue
        values = number_or_numbers(result["audio_distance"], f"estimators.{name}.audio_distance")
        finite = values[np.isfinite(values)]
        if finite.size:
            scores[name.upper()] = float(np.median(finite))
    return pd.Series(scores, dtype=float)


def perceptual_correlation(evaluation, noisiness_medians):
    """(DataFrame ``PERCEPTUAL_COLUMNS``, note or None): noisiness against audio_distance and against error.

    ``noisiness_medians`` is a Series of median normalised noisiness indexed by condition.
    """
    distances = audio_distances(evaluation)
    note = None if any("audio_distance" in r for r in evaluation["estimators"].values()) else NO_AUDIO_DISTANCE
    errors, error_metric = numerical_scores(evaluation, "error")
    rows = [
        _row("noisiness vs audio_distance", "audio_distance", noisiness_medians, distances, float("nan")),
        _row("noisiness vs error", error_metric, noisiness_medians, errors, PAPER_ERROR_RHO),
    ]
    table = pd.DataFrame(rows, columns=PERCEPTUAL_COLUMNS)
    for column in ("comparison", "metric", "conditions"):
        table[column] = table[column].astype(object)
    return table, note


def _row(label, metric, noisiness, scores, paper):
    common = [c for c in noisiness.index if c in scores.index]
    rho, p = spearman(noisiness[common].to_numpy(dtype=float), scores[common].to_numpy(dtype=float))
    return label, metric, len(common), rho, p, paper, " ".join(common)
