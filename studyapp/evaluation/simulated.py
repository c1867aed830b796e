"""Recordings simulated on demand: a picklable recipe instead of files.

``SimulatedSet`` names one short data set at one rate: a recording per F_max,
each simulated by ``studyapp.model.simulate`` (LVT in the loop, as in the
paper's Sec. 6.1) with the seed ``seed + i``. The simulation is deterministic,
so a worker process that receives the recipe rebuilds the very same samples in
a fraction of a second (about 0.05 s per 2 s recording at 96 kHz) instead of
being sent megabytes of arrays; ``load()`` does it once per process and keeps
the result, as ``dataset.RecordingFiles`` does for files. The optimiser's
objective (``dataset.RawObjectives``) takes either.

The delay of every estimate is measured with ``delay_method`` (see
``metric.py``).
"""

from dataclasses import dataclass

from studyapp.evaluation.dataset import DEFAULT_MAX_LAG_S, Dataset, take_from_recording
from studyapp.evaluation.metric import DEFAULT_METHOD
from studyapp.model.simulate import simulate


def make_dataset(takes, max_lag_s=DEFAULT_MAX_LAG_S, delay_method=DEFAULT_METHOD, fast=True):
    """A ``Dataset`` of ``takes`` whose delays are measured with ``delay_method``."""
    return Dataset(takes, max_lag_s, fast=fast, delay_method=delay_method)


def simulate_takes(rate, fmax_values, duration, seed, reference="lvt"):
    """Short recordings simulated at ``rate``, one per F_max, as takes."""
    takes = []
    for i, fmax in enumerate(fmax_values):
        recording = simulate(fmax, rate=rate, duration=duration, seed=seed + i)
        take = take_from_recording(recording, f"fmax_{fmax:g}@{rate:g}Hz", reference)
        take.fmax = float(fmax)
        takes.append(take)
    return takes


_LOADED = {}


@dataclass(frozen=True)
class SimulatedSet:
    """A picklable recipe for one simulated data set; ``load()`` gives its ``Dataset`` (once per process)."""

    rate: float
    fmax_values: tuple
    duration: float
    seed: int = 0
    reference: str = "lvt"
    max_lag_s: float = DEFAULT_MAX_LAG_S
    delay_method: str = DEFAULT_METHOD

    def load(self):
        dataset = _LOADED.get(self)
        if dataset is None:
            takes = simulate_takes(self.rate, self.fmax_values, self.duration, self.seed, self.reference)
            dataset = make_dataset(takes, self.max_lag_s, self.delay_method)
            _LOADED.clear()
            _LOADED[self] = dataset
        return dataset
