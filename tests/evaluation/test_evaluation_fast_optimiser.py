"""The fast evaluation (side by side, shares, one task per worker) changes no result.

The reference is the unchanged search: every set measured take by take through
``Estimator.process`` (``Dataset(fast=False)``), one set at a time, in this process.
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from studyapp.evaluation.dataset import Dataset, RawObjectives, take_from_recording
from studyapp.evaluation.executors import InlineExecutor
from studyapp.evaluation.optimiser import Optimiser
from studyapp.evaluation.space import Space
from tests.evaluation.conftest import synthetic_recording

ESTIMATORS = ("LOWPASS", "LEASTSQ", "KALMAN", "FOAW")


def _takes():
    takes = [take_from_recording(synthetic_recording(f, duration=d, seed=i), f"r{i}")
             for i, (f, d) in enumerate([(0.5, 0.3), (3.3, 0.3), (7.7, 0.4), (1.1, 0.3)])]
    takes[3].position[50] = np.nan  # a bad sample: this take runs through the input guard
    takes[3].finite = False
    return takes


class Source:
    """A source of the fast dataset, as ``RecordingFiles`` is for files."""

    def __init__(self, dataset):
        self.dataset = dataset

    def load(self):
        return self.dataset


@pytest.fixture(scope="module")
def datasets():
    takes = _takes()
    return Dataset(takes, 0.01, fast=False), Dataset(takes, 0.01, fast=True)


def test_fast_raw_objectives_equal_take_by_take(datasets):
    slow, fast = datasets
    rng = np.random.default_rng(0)
    for name in ESTIMATORS:
        space = Space(name, 5000.0)
        for params in [space.start] + [space.values(rng.random(len(space.dims))) for _ in range(3)]:
            expected = slow.raw_objectives(name, params)
            assert np.array_equal(fast.raw_objectives(name, params), expected)
            for k in (2, 3, 5):  # shares joined in order are the whole vector, even with empty shares
                joined = np.concatenate([RawObjectives(Source(fast), share)(name, params)
                                         for share in [(j, k) for j in range(k)]])
                assert np.array_equal(joined, expected)


def _run(objective, executor, seed):
    spaces = {name: Space(name, 5000.0) for name in ESTIMATORS}
    return Optimiser(spaces, objective, executor, patience=6, seed=seed).run()


@pytest.mark.parametrize("seed", [0, 4])
def test_same_seed_same_result_as_the_unchanged_search(datasets, seed):
    slow, fast = datasets
    unchanged = _run(slow.raw_objectives, InlineExecutor(), seed)
    with ThreadPoolExecutor(2) as pool:
        shared = _run(RawObjectives(Source(fast)), pool, seed)
    inline = _run(RawObjectives(Source(fast)), InlineExecutor(), seed)
    for result in (shared, inline):
        assert result.params == unchanged.params
        assert result.objectives == unchanged.objectives
        assert result.raw == unchanged.raw
        assert result.iterations == unchanged.iterations
        assert result.evaluated == unchanged.evaluated
