"""The validation comparison of the paper's Sec. 7.3.

The tuned parameters are evaluated on a second, independent set of recordings
(``simulate-set --validation``: same F_max values, similar gestures, another
seed). Recordings are matched by F_max; for every estimator and matching pair

    error difference (%)   = 100 |E_val - E_train| / E_train
    delay difference       = |D_val - D_train| (samples)

and the summary is their mean and standard deviation over all estimators and
matched recordings (the paper: 10.3 +- 7.76 percent, 2.60 +- 2.02 samples),
plus the same per estimator, and Pearson's r between each estimator's mean
delay difference and its standard deviation (the paper: r = 0.72).
"""

import numpy as np
from scipy import stats

from studyapp.errors import UserError


def _match(train, validation):
    """Pairs of recording indices (train, validation) with equal F_max."""
    pairs = []
    lookup = {}
    for j, f in enumerate(validation.fmax):
        if f is not None:
            lookup.setdefault(round(f, 6), j)
    for i, f in enumerate(train.fmax):
        if f is not None and round(f, 6) in lookup:
            pairs.append((i, lookup[round(f, 6)]))
    if not pairs:
        raise UserError("--validation: no recording has an F_max that matches one of the evaluated recordings")
    return pairs


def compare(train, validation):
    """(summary dict, rows): the Sec. 7.3 comparison of two ``Evaluation``s of the same estimators."""
    pairs = _match(train, validation)
    rows = []
    for name in train.names:
        for i, j in pairs:
            e0, e1 = train.errors[name][i], validation.errors[name][j]
            d0, d1 = train.delays[name][i], validation.delays[name][j]
            with np.errstate(divide="ignore", invalid="ignore"):
                e_pct = 100.0 * abs(e1 - e0) / e0 if e0 > 0 else float("nan")
            rows.append({
                "estimator": name, "fmax": train.fmax[i], "recording": train.recordings[i],
                "validation_recording": validation.recordings[j], "error": e0, "error_validation": e1,
                "error_difference_pct": e_pct, "delay": int(d0), "delay_validation": int(d1),
                "delay_difference": abs(int(d1) - int(d0)),
            })
    e = np.array([r["error_difference_pct"] for r in rows], dtype=np.float64)
    d = np.array([r["delay_difference"] for r in rows], dtype=np.float64)
    per = {}
    for name in train.names:
        mine = [r for r in rows if r["estimator"] == name]
        ee = np.array([r["error_difference_pct"] for r in mine], dtype=np.float64)
        dd = np.array([r["delay_difference"] for r in mine], dtype=np.float64)
        per[name] = {
            "error_difference_pct_mean": _f(np.nanmean(ee)) if np.isfinite(ee).any() else None,
            "error_difference_pct_std": _f(np.nanstd(ee, ddof=1)) if np.isfinite(ee).sum() > 1 else None,
            "delay_difference_mean": _f(np.mean(dd)),
            "delay_difference_std": _f(np.std(dd, ddof=1)) if dd.size > 1 else None,
        }
    means = [v["delay_difference_mean"] for v in per.values()]
    stds = [v["delay_difference_std"] for v in per.values()]
    pearson = None
    if len(means) > 2 and all(s is not None for s in stds) and np.ptp(means) > 0 and np.ptp(stds) > 0:
        r, p = stats.pearsonr(means, stds)
        pearson = {"r": _f(r), "p": _f(p)}
    summary = {
        "matched_recordings": len(pairs),
        "error_difference_pct_mean": _f(np.nanmean(e)) if np.isfinite(e).any() else None,
        "error_difference_pct_std": _f(np.nanstd(e, ddof=1)) if np.isfinite(e).sum() > 1 else None,
        "delay_difference_mean": _f(np.mean(d)),
        "delay_difference_std": _f(np.std(d, ddof=1)) if d.size > 1 else None,
        "delay_mean_vs_std_pearson": pearson,
        "estimators": per,
    }
    return summary, rows


def _f(x):
    x = float(x)
    return x if np.isfinite(x) else None
