"""Friedman's test across conditions, each participant one block (the within-subject omnibus test).

The paper tested pairs of conditions only, on trials pooled across
participants (Sec. 9). Friedman's test asks first whether the conditions
differ at all, with each participant's median per condition as one
observation: within each of the n participants, the k conditions are ranked
1..k (ties share their average rank); with R_j the rank sum of condition j,

    chi2 = [12 / (n k (k + 1)) sum_j R_j^2 - 3 n (k + 1)] / C,
    C    = 1 - sum over blocks of sum(t^3 - t) / (n (k^3 - k))   (ties of size t)

and p from chi-square with k - 1 degrees of freedom
(``scipy.stats.friedmanchisquare``). That is an approximation that needs
enough participants: below about six its p is unreliable (read it as a guide),
and the report says so. Exactly, the most extreme outcome (every participant
ranks the conditions the same way) has probability k! / (k!)^n, so no test on
n participants can give p below (k!)^(1 - n): with three conditions, two
participants can never reach p < 0.05 (1/6). With fewer than three conditions
the test is not computed (two conditions are one signed-rank test), nor with
fewer than two participants. When every participant gives every condition the
same value, C = 0: there is no evidence of a difference, so chi2 = 0 and p = 1.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

MIN_CONDITIONS = 3
RELIABLE_PARTICIPANTS = 6


@dataclass(frozen=True)
class Friedman:
    """Friedman's chi-square, its p-value, and the participants and conditions it used (NaN: not computed)."""

    statistic: float
    p_value: float
    n_participants: int
    n_conditions: int


def friedman_test(medians):
    """``Friedman`` of ``medians``, an (n participants) x (k conditions) array without gaps."""
    table = np.asarray(medians, dtype=float)
    n, k = table.shape
    if n < 2 or k < MIN_CONDITIONS:
        return Friedman(float("nan"), float("nan"), n, k)
    if np.all(table == table[:, :1]):
        return Friedman(0.0, 1.0, n, k)
    result = stats.friedmanchisquare(*table.T)
    return Friedman(float(result.statistic), float(result.pvalue), n, k)


def minimum_p(participants, conditions):
    """The smallest p an exact Friedman test can give: (k!)^(1 - n) (module docstring)."""
    return math.factorial(conditions) ** (1 - participants) if participants > 0 else 1.0
