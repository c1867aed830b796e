"""Every registered estimator reaches its own kernel through the compiled dispatch; an unknown kind raises.

The reference is the registry's kernel called directly, sample by sample, on a
fresh state: the dispatch's block form (``run_block``) and streaming form
(``step_guarded``) must give the same numbers bit for bit. The output array
starts as NaN, so a kind the block switch skipped would leave NaN (or, before,
whatever ``np.empty`` held), and a kind the streaming switch skipped would have
given 0.0.
"""

import numpy as np
import pytest

from studyapp.estimators import Estimator, kinds, names, registry
from studyapp.estimators.dispatch import GUARD, run_block, step_guarded
from studyapp.estimators.registry import KERNELS, REGISTRY, SPECS

RATE = 5000.0
N = 400


def _signals():
    rng = np.random.default_rng(13)
    t = np.arange(N) / RATE
    x = 0.01 * np.sin(2 * np.pi * 3.0 * t) + 1e-5 * rng.standard_normal(N)
    a = -0.01 * (2 * np.pi * 3.0) ** 2 * np.sin(2 * np.pi * 3.0 * t) + 0.05 * rng.standard_normal(N)
    v = 0.01 * 2 * np.pi * 3.0 * np.cos(2 * np.pi * 3.0 * t) + 1e-3 * rng.standard_normal(N)
    return x, a, v


def test_the_registry_is_the_one_list_of_estimators():
    assert names() == [spec.name for spec, _ in REGISTRY] == list(SPECS) == list(KERNELS)
    assert [spec.kind for spec, _ in REGISTRY] == list(range(len(REGISTRY)))


@pytest.mark.parametrize("name", names())
def test_every_registered_kind_reaches_its_kernel(name):
    x, a, v = _signals()
    est = Estimator(name, RATE)
    kernel = KERNELS[name]

    state = np.zeros(est.state_size)
    direct = np.array([kernel(state, est.p, x[i], a[i], v[i]) for i in range(N)])
    assert np.all(np.isfinite(direct)) and np.ptp(direct) > 0.0  # a real estimate, not a constant

    block = np.full(N, np.nan)
    run_block(est.kind, np.zeros(GUARD + est.state_size), est.p, x, a, v, block)
    assert np.array_equal(block, direct)

    state = np.zeros(GUARD + est.state_size)
    stream = np.array([step_guarded(est.kind, state, est.p, x[i], a[i], v[i]) for i in range(N)])
    assert np.array_equal(stream, direct)


def test_an_unknown_kind_raises_in_both_forms():
    unknown = len(REGISTRY)
    x, a, v = _signals()
    with pytest.raises(ValueError, match="unknown estimator kind"):
        run_block(unknown, np.zeros(GUARD + 8), np.zeros(8), x, a, v, np.full(N, np.nan))
    with pytest.raises(ValueError, match="unknown estimator kind"):
        step_guarded(unknown, np.zeros(GUARD + 8), np.zeros(8), 0.0, 0.0, 0.0)


def test_an_id_out_of_step_with_the_registry_is_refused(monkeypatch):
    monkeypatch.setattr(kinds, "LVT", kinds.COMP2)
    with pytest.raises(RuntimeError, match="LVT: kind 14, position 14, kinds.LVT = 13"):
        registry._check_ids()
