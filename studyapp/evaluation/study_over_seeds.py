"""The numerical study over seeds (issue 30): Table 1, the metrics and the findings of each seed, and their spread.

``studyapp evaluate RECORDINGS --params s0.toml s1.toml s2.toml -o DIR
--compare-paper`` (the files from ``optimise --seed 0, 1, 2``) evaluates every
file on the same recordings, each on its own (as ``evaluate`` does one file:
its own LOWPASS baseline, its own scale of eqs. 29-32), and writes beside the
first file's ``paper_comparison.csv`` and ``findings.csv``:

- ``paper_comparison_seeds.csv`` (``estimator, parameter, paper, median, min,
  max``, then ``ours LABEL`` per file): each parameter of Table 1 over the
  files, the median (of an even count, the mean of the middle two) and range;
- ``metrics_seeds.csv`` (``estimator, metric, median, min, max``, then
  ``LABEL`` per file): per estimator, over group a (F_max 0 to 7.7 N) the
  median error as % of LOWPASS, the median |D| in whole samples and the
  median sub-sample |D| (``subsample_delay.subsample_delay``), and F_g under the file's
  own scale;
- ``findings_seeds.csv`` (``finding, paper, verdict, holds_on, fails_on,
  undecided_on``, then ``verdict LABEL`` and ``ours LABEL`` per file): each
  finding judged on every file (``findings.py``), and over the files it
  *holds* when it holds on every one, *fails* when it fails on every one, and
  is otherwise "undecided (ties)" when undecided on some file, else
  "undecided (mixed)" (it holds on some and fails on others). A finding
  left out on some file is reported on the others only.

The labels are ``seed S`` when the files' seeds differ, else the file names
(``seed_spread.labels``).
"""

import numpy as np

from studyapp.evaluation.findings import FAILS, HOLDS, UNDECIDED
from studyapp.evaluation.paper_comparison import table_1
from studyapp.evaluation.report import finite_median

METRICS = ("error_pct_lowpass", "abs_delay_samples", "abs_delay_subsample", "F_g")


def _spread(values):
    finite = np.array([v for v in values if v is not None and np.isfinite(v)], dtype=np.float64)
    if not finite.size:
        return {"median": None, "min": None, "max": None}
    return {"median": float(np.median(finite)), "min": float(finite.min()), "max": float(finite.max())}


def parameter_rows(params_by_label):
    """Table 1 beside each file's parameters, with their median and range."""
    rows = []
    for name, values in table_1().items():
        for parameter, paper in values.items():
            ours = {label: params[name][parameter] if name in params else None
                    for label, params in params_by_label.items()}
            rows.append({"estimator": name, "parameter": parameter, "paper": paper,
                         **_spread([float(v) for v in ours.values() if v is not None]),
                         **{f"ours {label}": v for label, v in ours.items()}})
    return rows


def _metrics(result):
    mask = result.group_mask("a")
    return {name: {
        "error_pct_lowpass": finite_median(result.error_pct(name)[mask]),
        "abs_delay_samples": finite_median(np.abs(result.delays[name][mask])),
        "abs_delay_subsample": finite_median(result.abs_delays(name)[mask]),
        "F_g": result.objective[name],
    } for name in result.names}


def metric_rows(results_by_label):
    """Per estimator and metric (group a), each file's value and their median and range."""
    per_label = {label: _metrics(result) for label, result in results_by_label.items()}
    names = [n for n in next(iter(results_by_label.values())).names
             if all(n in m for m in per_label.values())]
    rows = []
    for name in names:
        for metric in METRICS:
            values = {label: per_label[label][name][metric] for label in per_label}
            rows.append({"estimator": name, "metric": metric, **_spread(list(values.values())),
                         **{label: v if np.isfinite(v) else None for label, v in values.items()}})
    return rows


MIXED = "undecided (mixed)"


def overall(verdicts):
    """holds / fails on every file; else undecided (ties) when tied on some file, or undecided (mixed)."""
    if verdicts and all(v == HOLDS for v in verdicts):
        return HOLDS
    if verdicts and all(v == FAILS for v in verdicts):
        return FAILS
    return UNDECIDED if UNDECIDED in verdicts else MIXED


def finding_rows(findings_by_label):
    """Each finding's verdict on every file and over the files."""
    order, by_finding = [], {}
    for label, rows in findings_by_label.items():
        for row in rows:
            if row["finding"] not in by_finding:
                order.append(row["finding"])
                by_finding[row["finding"]] = {"paper": row["paper"], "rows": {}}
            by_finding[row["finding"]]["rows"][label] = row
    out = []
    for finding in order:
        rows = by_finding[finding]["rows"]
        verdicts = [r["verdict"] for r in rows.values()]
        out.append({"finding": finding, "paper": by_finding[finding]["paper"], "verdict": overall(verdicts),
                    "holds_on": verdicts.count(HOLDS), "fails_on": verdicts.count(FAILS),
                    "undecided_on": verdicts.count(UNDECIDED),
                    **{f"verdict {label}": rows[label]["verdict"] if label in rows else None
                       for label in findings_by_label},
                    **{f"ours {label}": rows[label]["ours"] if label in rows else None
                       for label in findings_by_label}})
    return out
