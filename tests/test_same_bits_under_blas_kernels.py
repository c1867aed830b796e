"""The model's numbers do not depend on OpenBLAS's kernels (issue 39): two child processes, one with the kernels
this machine picks and one with OPENBLAS_CORETYPE forcing another set, compute the ZOH discretisation, LEASTSQ's
taps, the search's ridge axis and a short closed loop with LEASTSQ in it, and give the same bits.

Only the children get the variable; the suite's own environment is left as the machine sets it.
scripts/blas_kernels.py runs the whole list (breakdowns, optimiser, evaluate) under every kernel."""

import os
import subprocess
import sys

import numpy as np
import pytest

CHILD = r"""
import hashlib
import numpy as np
from studyapp.estimators import leastsq
from studyapp.evaluation.search import AdaptiveSearch
from studyapp.evaluation.space import Space
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.simulated_device import discretise

h = hashlib.sha256()
for rate in (1000.0, 5000.0, 48000.0, 96000.0):
    for m in discretise(0.1, 0.8, 3000.0, 100.0, 1.0 / rate):
        h.update(np.ascontiguousarray(m).tobytes())
for order, window in ((2, 33), (4, 33), (6, 257)):
    h.update(leastsq.taps(order, window, 5000.0).tobytes())
search = AdaptiveSearch(Space("KALMAN", 5000.0), 0, 1000, ridge=1.0)
rng = np.random.default_rng(0)
search.elite = [[*rng.random(2), 1.0] for _ in range(12)]
search.centre = np.array([0.5, 0.5])
u, low, high, width = search._axis()
h.update(np.array([*u, low, high, width]).tobytes())
loop = ClosedLoop(LoopConfig(rate=5000.0, estimators={"LEASTSQ": {"order": 4, "window": 33}}, source="LEASTSQ",
                             fmax=3.0, seed=1))
block = loop.run(2500)
for key in sorted(block):
    h.update(np.ascontiguousarray(block[key], dtype=np.float64).tobytes())
print(h.hexdigest())
"""


def openblas():
    try:
        config = np.show_config(mode="dicts")
    except TypeError:
        return False
    return "openblas" in str(config.get("Build Dependencies", {}).get("blas", {}).get("name", "")).lower()


def child(coretype):
    env = dict(os.environ)
    if coretype is None:
        env.pop("OPENBLAS_CORETYPE", None)  # the kernels this machine picks
    else:
        env["OPENBLAS_CORETYPE"] = coretype
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    proc = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout.strip()


@pytest.mark.skipif(not openblas(), reason="numpy is not built with OpenBLAS")
def test_the_same_bits_under_the_machines_kernels_and_prescotts():
    """Prescott's kernels run on every x86-64 CPU. Before issue 39's change this failed on an AVX2 machine: the
    discretisation at 5 and 96 kHz, LEASTSQ's taps, the ridge axis and the loop all had other bits (2026-11-28)."""
    other = "Nehalem" if os.environ.get("OPENBLAS_CORETYPE", "").lower() == "prescott" else "Prescott"
    assert child(None) == child(other)
