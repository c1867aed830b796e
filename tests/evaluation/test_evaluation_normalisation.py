"""The adaptive normalisation (eqs. 27-32) and steps 1-8, against values computed by hand."""

import numpy as np
import pytest

from studyapp.evaluation.normalisation import ObjectiveSum, bounds, global_objective


def test_two_estimators_three_iterations_hand_computed():
    # One recording: raw objectives [E_0, D_0]. Tolerance 0: any fall counts.
    s = ObjectiveSum(tolerance=0.0)

    # Steps 1-4: A = (2, 4), B = (4, 2). Bounds: E in [2, 4], D in [2, 4]:
    # O = (-2, -2), S = (2, 2); F_A = 0/2 + 2/2 = 1, F_B = 2/2 + 0/2 = 1.
    s.start({"A": [2.0, 4.0], "B": [4.0, 2.0]})
    assert s.offsets.tolist() == [-2.0, -2.0] and s.scales.tolist() == [2.0, 2.0]
    assert s.objectives() == {"A": 1.0, "B": 1.0}

    # Iteration 1 under scale b_1 = 0: A' = (1, 4): -1/2 + 2/2 = 0.5 < 1, accepted;
    # B' = (5, 2): 3/2 + 0 = 1.5 > 1, rejected. New bounds from bests A = (1, 4), B = (4, 2):
    # E in [1, 4] -> O = -1, S = 3; D in [2, 4] -> O = -2, S = 2.
    d = s.step({"A": [1.0, 4.0], "B": [5.0, 2.0]})
    assert (d["A"].candidate, d["A"].best, d["A"].accepted) == (0.5, 1.0, True)
    assert (d["B"].candidate, d["B"].best, d["B"].accepted) == (1.5, 1.0, False)
    assert s.remembered == 1
    assert s.offsets.tolist() == [-1.0, -2.0] and s.scales.tolist() == [3.0, 2.0]

    # Iteration 2 under scale b_2 = 1: A' = (1, 3): 0/3 + 1/2 = 0.5 < F_A = 0/3 + 2/2 = 1, accepted;
    # B' = (2.5, 2.5): 1.5/3 + 0.5/2 = 0.75 < F_B = 3/3 + 0/2 = 1, accepted.
    # New bounds from A = (1, 3), B = (2.5, 2.5): E in [1, 2.5] -> S = 1.5; D in [2.5, 3] -> O = -2.5, S = 0.5.
    d = s.step({"A": [1.0, 3.0], "B": [2.5, 2.5]})
    assert d["A"].candidate == pytest.approx(0.5) and d["A"].best == pytest.approx(1.0) and d["A"].accepted
    assert d["B"].candidate == pytest.approx(0.75) and d["B"].best == pytest.approx(1.0) and d["B"].accepted
    assert s.remembered == 2
    assert s.offsets.tolist() == [-1.0, -2.5] and s.scales.tolist() == [1.5, 0.5]
    # F_A = 0/1.5 + 0.5/0.5 = 1, F_B = 1.5/1.5 + 0 = 1.
    assert s.objectives() == {"A": pytest.approx(1.0), "B": pytest.approx(1.0)}

    # Iteration 3 under scale b_3 = 2: A' = (1.3, 3): 0.3/1.5 + 0.5/0.5 = 1.2 > 1, rejected;
    # B' = (2.5, 2.75): 1.5/1.5 + 0.25/0.5 = 1.5 > 1, rejected. No improvement: b_4 = b_3 = 2.
    d = s.step({"A": [1.3, 3.0], "B": [2.5, 2.75]})
    assert d["A"].candidate == pytest.approx(1.2) and not d["A"].accepted
    assert d["B"].candidate == pytest.approx(1.5) and not d["B"].accepted
    assert s.remembered == 2 and s.iteration == 3
    assert s.offsets.tolist() == [-1.0, -2.5] and s.scales.tolist() == [1.5, 0.5]
    assert s.best["A"].tolist() == [1.0, 3.0] and s.best["B"].tolist() == [2.5, 2.5]


def test_global_objective_is_eq_27_with_unit_weights():
    raw = np.array([[0.01, 3.0, 0.02, 5.0], [0.03, 2.0, 0.01, 9.0], [0.02, 4.0, 0.04, 7.0]])
    offsets, scales = bounds(raw)
    assert np.allclose(offsets, [-0.01, -2.0, -0.01, -5.0])
    assert np.allclose(scales, [0.02, 2.0, 0.03, 4.0])
    # Second estimator: (0.03-0.01)/0.02 + 0/2 + 0/0.03 + (9-5)/4 = 1 + 0 + 0 + 1 = 2.
    assert global_objective(raw[1], offsets, scales) == pytest.approx(2.0)
    assert global_objective([np.inf, 0, 0, 0], offsets, scales) == float("inf")


def test_bounds_without_spread_use_the_magnitude_and_ignore_diverged_estimators():
    offsets, scales = bounds([[0.5, 4.0], [0.5, 4.0], [np.nan, 1.0]])
    assert offsets.tolist() == [-0.5, -4.0]
    assert scales.tolist() == [0.5, 4.0]
    offsets, scales = bounds([[0.0, 0.0]])
    assert scales.tolist() == [1.0, 1.0]


def test_tolerance_and_state_round_trip():
    s = ObjectiveSum(tolerance=0.1)
    s.start({"A": [2.0, 4.0], "B": [4.0, 2.0]})
    d = s.step({"A": [1.9, 4.0]})  # F falls by 0.05 only
    assert not d["A"].accepted and s.remembered == 0
    t = ObjectiveSum.from_state(s.state())
    assert t.objectives() == s.objectives() and t.iteration == 1 and t.tolerance == 0.1
