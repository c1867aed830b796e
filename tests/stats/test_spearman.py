"""Spearman's rho: hand-computed examples (with and without ties) and scipy on the same data."""

import math

import numpy as np
import pytest
from scipy import stats

from studyapp.stats.spearman import spearman


def test_rho_without_ties_by_hand():
    # d = -1, 1, -1, 1, 0 -> sum d^2 = 4 -> rho = 1 - 6 * 4 / (5 * 24) = 0.8.
    rho, p = spearman([1, 2, 3, 4, 5], [2, 1, 4, 3, 5])
    assert rho == pytest.approx(0.8, rel=1e-12)
    t = 0.8 * math.sqrt(3 / (1 - 0.64))
    assert p == pytest.approx(2 * stats.t.sf(t, 3), rel=1e-10)


def test_rho_with_ties_by_hand():
    # Ranks x: 1, 2.5, 2.5, 4; y: 1, 3, 2, 4. Centred: (-1.5, 0, 0, 1.5) and (-1.5, .5, -.5, 1.5):
    # sum xy = 4.5, sum x^2 = 4.5, sum y^2 = 5 -> rho = 4.5 / sqrt(22.5) = 3 / sqrt(10).
    rho, _ = spearman([1, 2, 2, 3], [10, 30, 20, 40])
    assert rho == pytest.approx(3 / math.sqrt(10), rel=1e-12)


def test_equals_scipy_spearmanr():
    rng = np.random.default_rng(4)
    for ties in (False, True):
        x = rng.integers(0, 5, 12) if ties else rng.normal(size=12)
        y = x + rng.normal(0, 1.5, 12)
        ours = spearman(x, y)
        theirs = stats.spearmanr(x, y)
        assert ours[0] == pytest.approx(theirs.statistic, rel=1e-12)
        assert ours[1] == pytest.approx(theirs.pvalue, rel=1e-9)


def test_perfect_agreement_and_reversal():
    assert spearman([3, 1, 2], [30, 10, 20]) == (1.0, 0.0)
    assert spearman([3, 1, 2], [10, 30, 20])[0] == -1.0


def test_undefined_cases_are_nan():
    assert all(math.isnan(v) for v in spearman([1, 2], [2, 1]))
    assert all(math.isnan(v) for v in spearman([1, 1, 1], [1, 2, 3]))
    with pytest.raises(ValueError):
        spearman([1, 2, 3], [1, 2])


@pytest.mark.parametrize("seed", range(5))
def test_equal_or_reversed_rankings_are_exactly_one(seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=int(rng.integers(3, 12)))
    assert spearman(x, np.exp(x)) == (1.0, 0.0)
    assert spearman(x, -x**3) == (-1.0, 0.0)
