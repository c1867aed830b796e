"""Our numerical study beside the paper's: Table 1 and the findings of Sec. 7 (``evaluate --compare-paper``).

``paper_comparison.csv`` (columns ``estimator, parameter, paper, ours``): for
each of the thirteen estimators of Table 1, each parameter Table 1 gives (the
ones Table 2 tunes, ``space.PAPER_TUNED``), the paper's value beside the one
evaluate was given (``--params``; empty when the estimator was not
evaluated). The paper's values are the estimators' defaults, which are Table 1.

``findings.csv``: the paper's findings of Sec. 7, each judged by a stated
quantitative rule (``findings.py`` lists them), under both parameter sets
side by side (issue 42: which findings hold depends on the parameters).
Columns ``finding, paper, ours, agrees, verdict`` are the evaluated set's
(the tuned file given with ``--params``, else Table 1), as before; then
``verdict_table1, holds_table1, ours_table1`` (the paper's Table 1, made for
the recordings' rate, on the same recordings) and ``verdict_tuned,
holds_tuned, ours_tuned`` (the file's; empty without ``--params``: one set).
A finding judged under one set only has the other's cells empty.
"""

import numpy as np

from studyapp.estimators.foaw import window_sizes
from studyapp.estimators.registry import spec
from studyapp.evaluation.findings import FINDING_COLUMNS, HOLDS, findings
from studyapp.evaluation.space import PAPER_ESTIMATORS, PAPER_TUNED
from studyapp.evaluation.tables import write_csv

PARAMETER_COLUMNS = ["estimator", "parameter", "paper", "ours"]
SETS = ("table1", "tuned")
SET_COLUMNS = ("verdict", "holds", "ours")
BOTH_COLUMNS = FINDING_COLUMNS + [f"{column}_{s}" for s in SETS for column in SET_COLUMNS]


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


def both_sets(table1_rows, tuned_rows=None):
    """``findings.csv`` rows: each finding under Table 1 and under the tuned set (None: one set, Table 1's).

    The first five columns are the evaluated set's, the tuned one's when given; a finding judged under one
    set only comes after the others, with the other set's cells empty.
    """
    by_set = {"table1": {r["finding"]: r for r in table1_rows},
              "tuned": {r["finding"]: r for r in tuned_rows or []}}
    own = tuned_rows if tuned_rows is not None else table1_rows
    order = list(dict.fromkeys([r["finding"] for r in own] + [r["finding"] for r in table1_rows]))
    rows = []
    for finding in order:
        main = by_set["tuned" if tuned_rows is not None else "table1"].get(finding)
        row = dict(main) if main is not None else {"finding": finding, "paper": by_set["table1"][finding]["paper"]}
        row.update({f"{column}_{s}": None for s in SETS for column in SET_COLUMNS})
        for s in SETS:
            judged = by_set[s].get(finding)
            if judged is not None:
                row.update({f"verdict_{s}": judged["verdict"], f"holds_{s}": judged["verdict"] == HOLDS,
                            f"ours_{s}": judged["ours"]})
        rows.append(row)
    return rows


def holds_count(rows, which):
    """(findings holding, findings judged) under the set ``which`` ("table1" or "tuned"); None if not judged."""
    judged = [r for r in rows if r.get(f"verdict_{which}") is not None]
    return (sum(r[f"holds_{which}"] for r in judged), len(judged)) if judged else None


def counts(rows):
    """The holding counts of ``both_sets`` rows, for evaluation.json and stdout."""
    out = {"parameter_sets": [s for s in SETS if holds_count(rows, s) is not None]}
    for s in SETS:
        count = holds_count(rows, s)
        out[f"holds_{s}"], out[f"judged_{s}"] = count if count is not None else (None, None)
    return out


def write(output, result, rows):
    """Write ``paper_comparison.csv`` (of the evaluated set) and ``findings.csv`` (``both_sets`` rows)."""
    write_csv(output / "paper_comparison.csv", parameter_rows(result.params), PARAMETER_COLUMNS)
    write_csv(output / "findings.csv", rows, BOTH_COLUMNS)
