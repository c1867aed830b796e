"""The host's compiled shadow of a device loop run as the model (device/shadow.py run_rows, MODEL: the controller
and every other estimator per row of recorded sensors) equals Control.sample called sample by sample with no
truth, then observe_others: every output row, every estimate and every array of the loop (string, body filter,
monitor, microphone, fault), bit for bit. It is the C loop's reference (tests/device/test_c_loop.py) and
``bench loop``'s numba loop."""

import numpy as np
import pytest

from studyapp.device import shadow
from studyapp.device.loop_benchmark import sensor_rows
from studyapp.model import control
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import LVT_SENSOR

RATE = 5000.0
BANK = {"LOWPASS": {}, "KALLEV": {}, "FOAW": {}, "KALFOAWACC": {}}


def make(source, seed):
    return ClosedLoop(LoopConfig(rate=RATE, estimators=BANK, source=source, fmax=3.0, seed=seed,
                                 accelerometer=True), judge=False)


@pytest.mark.parametrize("source", ["KALLEV", LVT_SENSOR])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_shadows_rows_equal_sample_by_sample(source, seed):
    rec = make(LVT_SENSOR, seed).run(1600)
    x, a, v = (np.array(rec[k]) for k in ("position", "acceleration", "velocity_lvt"))
    rng = np.random.default_rng(seed)
    for i in rng.integers(800, 1600, 2):  # a bad sample late on: the fault, then the ringing string
        (x, a, v)[int(rng.integers(0, 3))][i] = np.nan
    block, single = make(source, seed), make(source, seed)
    n_est = len(BANK)
    for start, stop in ((0, 700), (700, 1600)):
        n = stop - start
        out, est = np.zeros((len(control.OUTPUTS), n)), np.zeros((n_est, n))
        rows = sensor_rows(x[start:stop], a[start:stop], v[start:stop])
        shadow.run_rows(block.control.arrays, 0, rows, 0.0, shadow.MODEL, out, est, np.zeros(2))
        ref, ref_est = np.zeros((len(control.OUTPUTS), n)), np.zeros((n_est, n))
        for k in range(n):
            i = start + k
            single.control.sample(k, (x[i], a[i], v[i]), None, ref, ref_est)
        control.observe_others(int(single.control.arrays[0][control.C_SOURCE]), *single.control.arrays[4:7],
                               ref, ref_est)
        assert np.array_equal(out.view(np.uint64), ref.view(np.uint64))
        assert np.array_equal(est.view(np.uint64), ref_est.view(np.uint64))
        for mine, theirs in zip(block.control.arrays, single.control.arrays):
            assert np.array_equal(mine, theirs, equal_nan=True)
    assert block.control.arrays[1][control.L_FAULT] == control.FAULT_SENSOR
    assert np.any(out[control.O_STICK] == 1.0) and np.all(np.isfinite(out[control.O_AUDIO]))
