"""F_max bounds the force by construction (issue 30, item 1).

The bow table's lower clip (rho >= 0.01) let |rho v| grow past its peak beyond
|v_delta| = 8.33 string units; a noisy or unstable source drove the force to
2-7.5 x F_max (BDIFF at 96 kHz, LOWPASS with a 40 kHz cut-off, KALPOS and
LEVANT at corners of their allowed ranges). The sweep drives every source at
F_max = 40 N (the largest a study's ceiling plausibly sets, below the motors'
60 N RMS clamp, so the motor clamps cannot hide an overshoot) at 1, 5, 48 and
96 kHz, with every estimator at Table 1's defaults and with each numeric
parameter at each end of its allowed range at that rate (the others at their
defaults), plus the all-low and all-high corners. 0.2 s each: long enough for
the unstable settings to reach the tail (the test checks that many did).
"""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.estimators.registry import SPECS
from studyapp.model import bow_table, sensors
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import TRUE, is_pseudo

FMAX = 40.0
SECONDS = 0.2
RATES = (1000.0, 5000.0, 48000.0, 96000.0)
TAIL = 8.33  # string units: where 0.01 |v| passes the peak 0.0833


def f0_at(rate):
    return 150.0 if rate < 2640.0 else None  # 440 Hz needs 2.64 kHz (playable.py)


def settings(name, rate):
    """Table 1's defaults, each numeric parameter at each end of its range, and the two corners."""
    spec = SPECS[name]
    numeric = [p for p in spec.params if p.kind != "choice"]
    ends = {p.name: (p.low, p.high_at(rate)) for p in numeric}
    out = [{}]
    for p in numeric:
        for end in ends[p.name]:
            out.append({p.name: int(end) if p.kind == "int" else end})
    if len(numeric) > 1:
        out.append({p.name: int(ends[p.name][0]) if p.kind == "int" else ends[p.name][0] for p in numeric})
        out.append({p.name: int(ends[p.name][1]) if p.kind == "int" else ends[p.name][1] for p in numeric})
    valid = []
    for params in out:
        try:
            spec.validate(rate, params)  # runs the spec's own check too
        except ParameterError:
            continue  # e.g. LEASTSQ's window must exceed its order; COMP2's default at 1 kHz
        valid.append(params)
    return valid


def peak_force(rate, source, params):
    estimators = {} if is_pseudo(source) else {source: params}
    loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=source, fmax=FMAX, f0=f0_at(rate),
                                 audio=False), judge=False)
    block = loop.run(int(SECONDS * rate))
    return np.abs(block["force"]).max(), np.abs(block["v_delta"]).max()


def test_the_friction_is_capped_at_its_peak_everywhere():
    v = np.concatenate([np.linspace(-20, 20, 400001), [-1e300, -1e6, 1e6, 1e300]])
    for slope, offset in ((3.0, 0.0), (3.0, 0.001), (1.0, -0.01)):
        peak = bow_table.peak_friction(slope, offset)
        u = bow_table.friction_table(v, slope, offset)
        assert np.abs(u).max() <= peak
        assert np.abs(u).max() == pytest.approx(peak, rel=1e-4)  # reached at the clip's edge
        head = np.abs(v) < 8.0
        np.testing.assert_array_equal(u[head], bow_table.table(v[head], slope, offset) * v[head])


@pytest.mark.slow
@pytest.mark.parametrize("rate", RATES, ids=lambda r: f"{r / 1000:g}kHz")
def test_force_within_fmax_for_every_source_and_parameter_bound(rate, monkeypatch):
    # the noisiest LVDT the sweep of issue 42 allows, white (no conditioner band): the bound is the bow table's,
    # whatever the sensor, and only a white LVDT still drives the noisy settings into the tail at 48 and 96 kHz
    # (with the conditioner's 250 Hz low-pass none reached it there, 2026-11-29)
    monkeypatch.setenv(sensors.BAND_VARIABLE, "inf")
    # the 16 sources: TRUE, the LVT (sensor and estimator read the same) and the 14 estimators
    cases = [(TRUE, {})] + [(name, params) for name in SPECS for params in settings(name, rate)]
    worst, reached = [], 0
    for source, params in cases:
        peak, v_delta = peak_force(rate, source, params)
        worst.append((peak / FMAX, source, params))
        reached += v_delta > TAIL
    over = [case for case in worst if case[0] > 1.0 + 1e-9]
    assert not over, f"{len(over)} of {len(worst)} over F_max at {rate:g} Hz, e.g. {max(over, key=lambda c: c[0])}"
    assert reached >= 3  # the sweep did drive sources into the tail the cap closes


def test_the_engine_ceiling_bounds_the_force_command_of_a_runaway_source():
    # the worker's path (engine/worker.py): F_max through Safety.clamp_fmax, each block through Safety.check;
    # LEVANT with C = 1e5 drove 7.5 x F_max before the cap
    from studyapp.engine.safety import Safety, SafetyLimits

    loop = ClosedLoop(LoopConfig(rate=5000.0, estimators={"LEVANT": {"c": 1e5}}, source="LEVANT", fmax=1.0,
                                 audio=False), judge=False)
    safety = Safety(loop, SafetyLimits(fmax_ceiling=5.0))
    loop.set_fmax(safety.clamp_fmax(30.0))
    peak = v_delta = 0.0
    for _ in range(10):
        block = loop.run(500)
        fault = safety.check(block)
        assert fault is None or "exceeded its clamp" not in fault
        peak = max(peak, np.abs(block["force"]).max())
        v_delta = max(v_delta, np.abs(block["v_delta"]).max())
    assert v_delta > TAIL  # the source did run into the tail
    assert loop.fmax == 5.0 and 4.9 < peak <= 5.0 * (1 + 1e-9)
