"""The paper's pairwise Wilcoxon rank-sum tests between conditions (paper Sec. 9, ref. [28]).

The test itself (statistic z, exact or tie-corrected normal p) has one
definition, studyapp/stats/rank_sum.py, shared with ``studyapp evaluate``.

The analysis applies it as the paper did, to every trial of every participant
pooled per condition. The test assumes independent samples, which the trials
of one participant are not (they share that participant's criterion), so its
p-values come out too small: two participants with six trials each give
p ~ 3e-5. Tables and figures label it ``POOLED``; the within-subject tests
(within_subject.py) treat participants as the units.
"""

from itertools import combinations

import numpy as np
import pandas as pd

from studyapp.stats.holm import holm_adjust
from studyapp.stats.rank_sum import rank_sum_test

POOLED = "pooled across participants, as the paper did; trials are not independent"
WILCOXON_COLUMNS = ["condition_a", "condition_b", "statistic", "p_value", "significant"]


def pairwise_rank_sum(groups, alpha=0.05, holm=False):
    """Rank-sum tests of every unordered pair of ``groups`` ({condition: values}), each pair once.

    Returns a DataFrame with ``WILCOXON_COLUMNS`` plus ``p_raw``; the pairs follow
    the order of ``groups`` (a before b). ``significant`` is ``p_value < alpha``;
    with ``holm`` the ``p_value`` column holds Holm-adjusted p-values over all
    the pairs of this table (``p_raw`` keeps the unadjusted ones).
    """
    rows = []
    for name_a, name_b in combinations(list(groups), 2):
        test = rank_sum_test(groups[name_a], groups[name_b])
        rows.append((name_a, name_b, test.statistic, test.p_value))
    table = pd.DataFrame(rows, columns=["condition_a", "condition_b", "statistic", "p_raw"])
    table["condition_a"] = table["condition_a"].astype(object)
    table["condition_b"] = table["condition_b"].astype(object)
    raw = table["p_raw"].to_numpy(dtype=float)
    table["p_value"] = holm_adjust(raw) if holm else raw
    table["significant"] = table["p_value"] < alpha
    return table[WILCOXON_COLUMNS + ["p_raw"]]
