"""Fig. 5's panels order by |D|: an estimator ahead of the LVT is not better than one in step with it."""

import numpy as np

from studyapp.evaluation.figures import PANELS, panel_order
from tests.evaluation.test_evaluation_findings import _evaluation


def test_the_delay_panel_ranks_and_fills_by_magnitude():
    """KALMAN one sample ahead of the LVT (D = -1) against LEASTSQ in step (D = 0) and LOWPASS 3 behind."""
    rng = np.random.default_rng(0)
    values = {"LOWPASS": (1.0, 3.0), "KALMAN": (0.5, -1.0), "LEASTSQ": (0.9, 0.0),
              "KALPOS": (0.8, 2.0 + rng.uniform(-0.1, 0.1, 10))}
    measures = _evaluation(values).measures("a")
    assert [key for key, _ in PANELS] == list(measures)
    delays = measures["abs_delay_pct_lowpass"]
    np.testing.assert_allclose(delays["KALMAN"], 100 / 3)  # |D| as % of LOWPASS's
    order, best = panel_order(delays)
    assert order == ["LEASTSQ", "KALMAN", "KALPOS", "LOWPASS"]
    assert best == {"LEASTSQ"}  # every recording in step: KALMAN's lead is significantly worse (p < 0.05)
