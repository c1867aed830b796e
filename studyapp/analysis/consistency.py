"""Consistency of participants (paper Sec. 9.1).

Each participant's ranking against the global ranking: for every condition,
the participant's median response and the median over everyone (all
participants, this one included, as in the paper); Spearman's rho between the
two over the conditions this participant has. The paper found rho > 0.9 for
every participant on max F_max.

Intra- against inter-subject variance of max F_max, per condition (sample
variances, ddof = 1):

    intra = mean over participants (with >= 2 trials) of the variance of their trials
    inter = variance of the participants' mean responses
    total = variance of all responses, the spread drawn in Fig. 7

The paper says the variance in Fig. 7 "is mostly due to inter-subject
differences, while intra-subject variance was on average 61 percent lower";
we read that as 1 - intra / total per condition, averaged over conditions,
and report it as ``intra_lower_pct``.
"""

import numpy as np
import pandas as pd

from studyapp.stats.spearman import spearman

SPEARMAN_COLUMNS = ["participant", "rho", "p_value"]
VARIANCE_COLUMNS = ["condition", "participants", "intra_variance", "inter_variance", "total_variance", "intra_lower_pct"]


def participant_spearman(values):
    """DataFrame ``participant, rho, p_value, conditions`` from rows with ``participant, condition, value``."""
    global_median = values.groupby("condition")["value"].median()
    rows = []
    for participant, mine in values.groupby("participant", sort=True):
        own = mine.groupby("condition")["value"].median()
        rho, p = spearman(own.to_numpy(), global_median[own.index].to_numpy())
        rows.append((participant, rho, p, len(own)))
    table = pd.DataFrame(rows, columns=SPEARMAN_COLUMNS + ["conditions"])
    table["participant"] = table["participant"].astype(object)
    return table


def variance_decomposition(values, conditions):
    """DataFrame ``VARIANCE_COLUMNS``, one row per condition in ``conditions`` order."""
    rows = []
    for condition in conditions:
        mine = values[values["condition"] == condition]
        per_participant = mine.groupby("participant")["value"]
        sizes = per_participant.size()
        within = per_participant.var(ddof=1)[sizes >= 2]
        intra = float(within.mean()) if len(within) else np.nan
        means = per_participant.mean()
        inter = float(means.var(ddof=1)) if len(means) >= 2 else np.nan
        total = float(mine["value"].var(ddof=1)) if len(mine) >= 2 else np.nan
        lower = 100.0 * (1.0 - intra / total) if np.isfinite(intra) and np.isfinite(total) and total > 0 else np.nan
        rows.append((condition, len(means), intra, inter, total, lower))
    table = pd.DataFrame(rows, columns=VARIANCE_COLUMNS)
    table["condition"] = table["condition"].astype(object)
    return table
