"""The bowing breakdown a rig's link predicts for a protocol's conditions (issue 29, items 1 and 5).

``predict(conditions, latency, rate)`` runs the breakdown search
(breakdown.py: the largest F_max at which a velocity source keeps the loop
stable while bowing, judged against TRUE on an ideal link) for each condition
with the simulated device behind the link (link.py: the force from sample k
acts from k + L, L = round(latency * rate); packets and jitter likewise), over
seeds 0..seeds-1, and returns each condition's median F_max (N; inf when
stable up to the search's 200 N).

``lvt_margin(prediction)`` is the paper's effect on that rig: LVT's breakdown
over the best estimator's (the largest median of the conditions other than
LVT and TRUE). The paper found LVT's F_max nearly twice the estimators' (Sec.
8.3, Fig. 7); ``MARGIN`` = 1.5 is the level below which a lab should not
expect to see it (docs/devices.md), and the console warns there.

Cost: one search is about 11 trials of ``duration`` s of the closed loop, each
simulated with the source's estimator only: at 5 kHz and the default 5 s,
2-4 s of one core per condition and seed on this machine (LVT 2.5 s, KALLEV
3.5 s, measured 2026-11-27), so the nine conditions of
protocols/sinclair2014.toml over 5 seeds take 2-3 min of one core, and
scale with the rate, the duration and the seeds. Run it off the GUI thread;
``progress(done, total, condition)`` is called after each condition and seed.
"""

import math

from studyapp.model.breakdown import DURATION, breakdown_fmax, check_seeds
from studyapp.model.link import LinkSpec
from studyapp.model.sources import LVT_SENSOR, TRUE

MARGIN = 1.5  # LVT over the best estimator below which the paper's effect is not expected (docs/devices.md)


def predict(conditions, latency, rate=5000.0, seeds=5, packet=0.0, jitter=0.0, estimators=None,
            duration=DURATION, tolerance=0.02, progress=None):
    """{condition: median breakdown F_max (N)} with the device behind the link (seconds); pure but for ``progress``.

    ``estimators``: name -> params (a protocol's, e.g. ``Protocol.estimators``); a condition not in it runs
    with its defaults. Each condition runs alone in the loop (the others would only observe).
    """
    import numpy as np

    link = LinkSpec(latency=latency, packet=packet, jitter=jitter)
    seeds = check_seeds(seeds)
    params = dict(estimators or {})
    total = len(conditions) * seeds
    done = 0
    result = {}
    for name in conditions:
        own = {} if name in (LVT_SENSOR, TRUE) else {name: params.get(name, {})}
        values = []
        for seed in range(seeds):
            values.append(breakdown_fmax(name, rate=rate, duration=duration, tolerance=tolerance, seed=seed,
                                         estimators=own, link=link))
            done += 1
            if progress is not None:
                progress(done, total, name)
        result[name] = float(np.median(values))
    return result


def lvt_margin(prediction):
    """LVT's breakdown over the best estimator's (largest median other than LVT and TRUE); nan without both."""
    others = [v for name, v in prediction.items() if name not in (LVT_SENSOR, TRUE)]
    if LVT_SENSOR not in prediction or not others:
        return math.nan
    best = max(others)
    lvt = prediction[LVT_SENSOR]
    if math.isinf(best):
        return 1.0 if math.isinf(lvt) else 0.0
    return lvt / best


def keeps_effect(prediction):
    """Whether LVT's breakdown is at least ``MARGIN`` times the best estimator's on this rig."""
    return lvt_margin(prediction) >= MARGIN
