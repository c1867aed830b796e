"""An estimator whose parameters cannot exist at a rate is reported and skipped, not fatal (issue 12).

Table 1's COMP2 high-pass is 2,254 Hz; cut-offs must stay below
NYQUIST_FRACTION * rate, so COMP2 cannot exist below 2,254 / 0.49 = 4,600 Hz.
"""

import pytest

from studyapp.errors import ParameterError, UserError
from studyapp.estimators.registry import spec
from studyapp.estimators.spec import NYQUIST_FRACTION
from studyapp.evaluation.parameter_sets import parameter_sets
from studyapp.evaluation.space import Space

THRESHOLD = 2254.0 / NYQUIST_FRACTION  # 4,600 Hz


def test_comp2_is_available_from_its_threshold_up():
    below = spec("COMP2").not_available(THRESHOLD - 1.0)
    assert below.startswith(f"not available at {THRESHOLD - 1.0:g} Hz: COMP2 parameter 'hpf_hz' = 2254.0")
    assert spec("COMP2").not_available(THRESHOLD + 1.0) is None
    assert all(spec(n).not_available(1000.0) is None for n in ("LOWPASS", "KALMAN", "FOAW", "LVT"))


def test_values_bad_at_every_rate_still_raise():
    with pytest.raises(ParameterError, match="hpf_hz"):
        spec("COMP2").not_available(1000.0, {"hpf_hz": 1e6})


def test_parameter_sets_skip_what_the_rate_excludes(tmp_path):
    unavailable = {}
    chosen, _ = parameter_sets(None, ["LOWPASS,COMP2"], 1000.0, unavailable)
    assert list(chosen) == ["LOWPASS"]
    assert list(unavailable) == ["COMP2"] and "not available at 1000 Hz" in unavailable["COMP2"]
    with pytest.raises(UserError, match="hpf_hz"):  # without the dict, as before: an error
        parameter_sets(None, ["COMP2"], 1000.0)
    with pytest.raises(UserError, match="no estimator is available: not available at 1000 Hz: COMP2 parameter"):
        parameter_sets(None, ["COMP2"], 1000.0, {})
    path = tmp_path / "P.toml"
    path.write_text("[COMP2]\nhpf_hz = 3000.0\n[LOWPASS]\ncutoff_hz = -1\n")
    with pytest.raises(UserError, match=r"P.toml: \[LOWPASS\] .*cutoff_hz"):  # bad at any rate
        parameter_sets(path, None, 1000.0, {})
    path.write_text("[COMP2]\nhpf_hz = 3000.0\n[LOWPASS]\ncutoff_hz = 100.0\n")
    unavailable = {}
    assert list(parameter_sets(path, None, 1000.0, unavailable)[0]) == ["LOWPASS"]
    assert unavailable["COMP2"].startswith(f"{path}: [COMP2] not available at 1000 Hz")


def test_the_optimiser_starts_comp2_at_the_top_of_its_range_below_the_threshold():
    space = Space("COMP2", 1000.0)
    assert space.start["hpf_hz"] == pytest.approx(NYQUIST_FRACTION * 1000.0)
    assert Space("COMP2", 5000.0).start["hpf_hz"] == 2254.0
