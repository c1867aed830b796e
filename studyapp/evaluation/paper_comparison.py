"""Our numerical study beside the paper's: Table 1 and the findings of Sec. 7 (``evaluate --compare-paper``).

``paper_comparison.csv`` (columns ``estimator, parameter, paper, ours``): for
each of the thirteen estimators of Table 1, each parameter Table 1 gives (the
ones Table 2 tunes, ``space.PAPER_TUNED``), the paper's value beside the one
evaluate was given (``--params``; empty when the estimator was not
evaluated). The paper's values are the estimators' defaults, which are Table 1.

``findings.csv`` (columns ``finding, paper, ours, agrees``): the paper's
findings of Sec. 7, each judged by a stated quantitative rule (``findings.py``
lists them).
"""

import numpy as np

from studyapp.estimators.foaw import window_sizes
from studyapp.estimators.registry import spec
from studyapp.evaluation.findings import FINDING_COLUMNS, findings
from studyapp.evaluation.space import PAPER_ESTIMATORS, PAPER_TUNED
from studyapp.evaluation.tables import write_csv

PARAMETER_COLUMNS = ["estimator", "parameter", "paper", "ours"]


def table_1():
    """The paper's Table 1: estimator -> {parameter: value} (the estimators' defaults)."""
    return {
        name: {p.name: p.default for p in spec(name).params if p.name in PAPER_TUNED[name]}
        for name in PAPER_ESTIMATORS
    }


def parameter_rows(params):
    """``paper_comparison.csv`` rows: Table 1 beside ``params`` (estimator -> parameters evaluated)."""
    rows = []
    for name, values in table_1().items():
        ours = params.get(name)
        for parameter, paper in values.items():
            rows.append({"estimator": name, "parameter": parameter, "paper": paper,
                         "ours": None if ours is None else ours[parameter]})
    return rows


def fraction_at_maximum(positions, window, margin):
    """The fraction of all samples of ``positions`` (a list of arrays) at which FOAW uses its largest window.

    ``window`` is FOAW's size (the paper's Size); ``window_sizes`` gives the size chosen at each sample.
    """
    at_maximum = total = 0
    for position in positions:
        sizes = window_sizes(position, window, margin)
        at_maximum += int(np.count_nonzero(sizes == int(window)))
        total += sizes.size
    return at_maximum / total if total else float("nan")


def finding_rows(result, positions, validation=None):
    """``findings.csv`` rows of one evaluation (``positions``: the recordings' positions, for FOAW's window)."""
    fraction = None
    if "FOAW" in result.params:
        foaw = result.params["FOAW"]
        fraction = fraction_at_maximum(positions, foaw["window"], foaw["margin"])
    return findings(result, fraction, validation)


def write(output, result, positions, validation=None):
    """Write ``paper_comparison.csv`` and ``findings.csv`` into the folder ``output``."""
    write_csv(output / "paper_comparison.csv", parameter_rows(result.params), PARAMETER_COLUMNS)
    write_csv(output / "findings.csv", finding_rows(result, positions, validation), FINDING_COLUMNS)
