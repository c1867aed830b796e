"""How much a tuned result depends on the optimiser's seed: F_g of several parameter files under one scale.

``studyapp evaluate RECORDINGS --params A.toml B.toml C.toml`` (e.g. ``optimise
--seed 0, 1, 2``) measures every estimator of every file on the same
recordings (eq. 28's raw objectives) and scores them all under one common
scale: the offsets and scales of eqs. 30 and 32 taken over every (file,
estimator) pair at once, so the F_g (eq. 27) of one estimator from different
files are comparable. Per estimator it reports F_g from each file and

    spread = (max_f F_g - min_f F_g) / min_f F_g   (in %),

the relative loss of the worst file against the best (issue 23 asks for at
most 2 % over seeds 0-2), and ``spread`` = max - min in units of F_g. Under
the common scale the best (file, estimator) pair on every objective scores
0, so ``spread_pct`` is empty (None) where the best F_g is 0 and the files
differ; a diverged estimator (F_g infinite) leaves both empty. (A file's own
``[objective]`` table cannot be compared across files: each run's final scale
is its own.) Only estimators present in every file are compared.

Where F_g differs, what differs: ``delays_apart``, the recordings on which the
files' |D_r| (eq. 22, whole samples) are not all equal, ``max_delay_apart``,
the largest such difference (samples), and ``error_spread_pct``, the largest
100 (max - min) / min of E_r (eq. 24) over the recordings. Under a common
scale whose delay spread S_i is one sample, one sample on one recording
moves F_g by a whole unit (docs/evaluation.md).
"""

import numpy as np

from studyapp.evaluation.normalisation import bounds, global_objective


def seed_spread(dataset, sets):
    """Rows (estimator, F_g per label, spread_pct) for ``sets``: label -> (name -> parameters)."""
    labels = list(sets)
    names = [name for name in sets[labels[0]] if all(name in sets[label] for label in labels)]
    raws = {(label, name): dataset.raw_objectives(name, sets[label][name]) for label in labels for name in names}
    offsets, scales = bounds(np.array(list(raws.values())))
    rows = []
    for name in names:
        values = [global_objective(raws[label, name], offsets, scales) for label in labels]
        low, high = min(values), max(values)
        finite = bool(np.isfinite(high))
        pct = 0.0 if high == low else 100.0 * (high - low) / abs(low) if finite and low != 0 else None
        rows.append({"estimator": name, **{f"F_g {label}": v if np.isfinite(v) else None
                                           for label, v in zip(labels, values)},
                     "spread": high - low if finite else None, "spread_pct": pct,
                     **apart(np.array([raws[label, name] for label in labels]))})
    return rows


def apart(raws):
    """What differs between the files' raw objectives (rows: files; eq. 28's [E_0, |D_0|, E_1, ...])."""
    errors, delays = raws[:, 0::2], raws[:, 1::2]
    if not np.all(np.isfinite(raws)):
        return {"delays_apart": None, "max_delay_apart": None, "error_spread_pct": None}
    gaps = delays.max(axis=0) - delays.min(axis=0)
    low = errors.min(axis=0)
    spread = np.divide(errors.max(axis=0) - low, low, out=np.zeros_like(low), where=low > 0)
    return {"delays_apart": int(np.count_nonzero(gaps)), "max_delay_apart": int(gaps.max()),
            "error_spread_pct": float(100.0 * spread.max())}


def labels(paths, provenances):
    """A column label per parameter file: ``seed N`` when the files' seeds differ, else the file name."""
    seeds = [p.get("seed") for p in provenances]
    if None not in seeds and len(set(seeds)) == len(seeds):
        return [f"seed {s}" for s in seeds]
    return [str(p) for p in paths]
