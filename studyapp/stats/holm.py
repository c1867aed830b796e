"""Holm's step-down correction of p-values for multiple comparisons (Holm 1979).

Nine conditions give 36 pairwise tests, so some p < 0.05 are expected by chance
alone; the paper used none, and we offer Holm's as an option. With the m
p-values sorted ascending, p_(1) <= ... <= p_(m), the adjusted values are

    p~_(i) = max_{j <= i} min(1, (m - j + 1) p_(j))

which controls the family-wise error rate at the chosen alpha without the
independence assumption, and is uniformly more powerful than Bonferroni.
"""

import numpy as np


def holm_adjust(p_values):
    """Holm-adjusted p-values, in the order given."""
    p = np.asarray(p_values, dtype=float).ravel()
    m = p.size
    if m == 0:
        return p.copy()
    order = np.argsort(p, kind="mergesort")
    scaled = np.minimum(1.0, (m - np.arange(m)) * p[order])
    adjusted = np.empty(m)
    adjusted[order] = np.maximum.accumulate(scaled)
    return adjusted
