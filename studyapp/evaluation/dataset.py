"""The recordings an estimator is measured on, and its raw objectives over them.

A ``Take`` is one recording made ready for evaluation: the measured position,
acceleration and tachometer velocity the estimators read, and the reference
velocity they are judged against, the LVT (``reference="lvt"``, the paper's
choice, eq. 25) or the simulated true velocity (``"true"``). A ``Dataset`` is
a list of takes, the delay bound and the delay method (``metric.py``:
``"normalised"`` or eq. 22's ``"paper"``); ``raw_objectives(name, params)``
runs the estimator on every take, from rest, and returns eq. 28's vector
``[E_0, |D_0|, ..., E_{n-1}, |D_{n-1}|]`` (E in m/s, D in samples; why |D|:
``normalisation.py``).

``RecordingFiles`` is a small picklable pointer to recording files: a worker
process (or a dask worker on a shared file system) loads the files once,
warms up the compiled estimators once, and keeps both for every later task.
``RawObjectives`` is the optimiser's objective over such a source; its
``shares(k)`` split the takes into k contiguous parts whose raw vectors,
joined in order, are the whole vector, so k workers can share every set.
"""

import hashlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from studyapp.errors import InputDataError, ParameterError, UserError
from studyapp.estimators import create
from studyapp.estimators.bounds import all_good
from studyapp.estimators.registry import spec
from studyapp.estimators.spec import RATE_MAX, validate_rate
from studyapp.evaluation import kernels
from studyapp.evaluation.batch import batches
from studyapp.evaluation.metric import DEFAULT_METHOD, Reference, check_method
from studyapp.evaluation.normalisation import raw_objectives
from studyapp.evaluation.subsample_delay import subsample_delay
from studyapp.io.recording import load

REFERENCE_COLUMNS = {"lvt": "velocity_lvt", "true": "velocity_true"}
DEFAULT_MAX_LAG_S = 0.02  # 100 samples at 5 kHz: far beyond any useful estimator's delay


@dataclass
class Take:
    """One recording ready for evaluation (arrays in SI units)."""

    name: str
    rate: float
    position: np.ndarray
    acceleration: np.ndarray
    velocity: np.ndarray
    reference: np.ndarray
    fmax: float | None = None
    sha256: str | None = None

    def __post_init__(self):
        # every sample good for the estimators' input guard (finite and within its physical bound)
        self.finite = all_good(self.position, self.acceleration, self.velocity)


def reference_column(reference):
    try:
        return REFERENCE_COLUMNS[reference]
    except KeyError:
        raise UserError(f"reference = {reference!r}: allowed is 'lvt' or 'true'") from None


def take_from_recording(recording, name, reference="lvt", sha256=None):
    """A ``Take`` from a ``studyapp.io.recording.Recording`` (columns by the CSV names)."""
    columns = recording.columns
    validate_rate(recording.rate, f"{name}: sample rate (metadata 'rate' or the 't' column)")
    wanted = ["position", "acceleration", "velocity_lvt", reference_column(reference)]
    for column in wanted:
        if column not in columns:
            raise InputDataError(f"{name}: no {column!r} column (it has {', '.join(columns)})")
    arrays = {c: np.ascontiguousarray(columns[c], dtype=np.float64) for c in wanted}
    for column, values in arrays.items():  # all NaN: nothing to tune or score, whatever the estimators make of it
        if not np.isfinite(values).any():
            raise InputDataError(f"{name}: column {column!r} has no finite sample: allowed is a recording with "
                                 "measured values")
    fmax = recording.meta.get("fmax") if recording.meta else None
    if fmax is not None and (isinstance(fmax, bool) or not isinstance(fmax, (int, float))):
        raise InputDataError(f"{name}: metadata 'fmax' = {fmax!r}: allowed is a number of newtons")
    return Take(
        name=name, rate=float(recording.rate), position=arrays["position"],
        acceleration=arrays["acceleration"], velocity=arrays["velocity_lvt"],
        reference=arrays[reference_column(reference)],
        fmax=None if fmax is None else float(fmax), sha256=sha256,
    )


def file_sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def load_takes(paths, reference="lvt"):
    """Load recording files (``.h5``, ``.npz`` or ``.csv``) as takes; one-line errors name the file."""
    takes = []
    for path in paths:
        path = Path(path)
        if not path.is_file():
            raise InputDataError(f"{path}: no such recording file")
        takes.append(take_from_recording(load(path), str(path), reference, file_sha256(path)))
    if not takes:
        raise UserError("no recordings given")
    return takes


class Dataset:
    """Takes plus the delay bound and method; measures raw objectives (eq. 28) of a parameter set.

    ``fast=True`` runs the estimators side by side on the takes of each
    ``batch.Batch`` (same output, compiled once per process: for long runs
    such as the optimiser's). ``share=(j, k)`` measures only the j-th of k
    contiguous parts of the takes (the whole list by default).
    """

    def __init__(self, takes, max_lag_s=DEFAULT_MAX_LAG_S, fast=False, delay_method=DEFAULT_METHOD):
        self.fast = bool(fast)
        self.delay_method = check_method(delay_method)
        if not takes:
            raise UserError("no recordings given")
        self.takes = list(takes)
        self.max_lag_s = float(max_lag_s)
        self.references = []
        for take in self.takes:
            max_lag = max(1, int(round(self.max_lag_s * take.rate)))
            if max_lag >= take.reference.shape[0]:
                raise InputDataError(
                    f"{take.name}: {take.reference.shape[0]} samples is too short for a delay bound of "
                    f"{self.max_lag_s:g} s ({max_lag} samples)")
            self.references.append(Reference(take.reference, max_lag, self.delay_method))
        self._batches = {}

    def share(self, share=None):
        """The indices of the takes in ``share`` = (j, k): the j-th of k contiguous parts."""
        n = len(self.takes)
        j, k = (0, 1) if share is None else (int(share[0]), int(share[1]))
        return range(j * n // k, (j + 1) * n // k)

    def load(self):
        return self

    @property
    def names(self):
        return [t.name for t in self.takes]

    def estimate(self, take, name, params):
        """The velocity estimate of ``name`` with ``params`` on one take, started from rest."""
        estimator = create(name, take.rate, **params)
        if self.fast:
            return kernels.run(estimator, take.position, take.acceleration, take.velocity, take.finite)
        return estimator.process(take.position, take.acceleration, take.velocity)

    def delays_and_errors(self, name, params, share=None):
        """(E, D) arrays over the takes (of ``share``)."""
        indices = self.share(share)
        errors = np.empty(len(indices))
        delays = np.empty(len(indices))
        if self.fast:
            for batch in self._batches_of(share):
                for r, (delay, error) in zip(batch.positions, batch.measure(name, params)):
                    delays[r], errors[r] = delay, error
            return errors, delays
        for r, i in enumerate(indices):
            delays[r], errors[r] = self.references[i].measure(self.estimate(self.takes[i], name, params))
        return errors, delays

    def subsample_delays(self, name, params):
        """The sub-sample delay (samples, ``subsample_delay.subsample_delay``) on every take: reported, not optimised."""
        return np.array([subsample_delay(reference.v, self.estimate(take, name, params), reference.max_lag,
                                         self.delay_method)
                         for take, reference in zip(self.takes, self.references)])

    def _batches_of(self, share):
        key = tuple(share or (0, 1))
        if key not in self._batches:
            indices = self.share(share)
            self._batches[key] = batches([self.takes[i] for i in indices], [self.references[i] for i in indices])
        return self._batches[key]

    def raw_objectives(self, name, params, share=None):
        """Eq. 28: [E_0, |D_0|, E_1, |D_1|, ...] (over the takes of ``share``)."""
        return raw_objectives(*self.delays_and_errors(name, params, share))


def warm_up(names, rate=5000.0, fast=False):
    """Run each estimator once on a few samples, so its compiled code is loaded (or compiled) in this process.

    The compiled code is the same at every rate; an estimator whose Table 1
    defaults cannot exist at ``rate`` (COMP2's high-pass below 4.6 kHz) is
    run at the highest rate instead.
    """
    x = np.zeros(16)
    side = np.zeros((16, 2))
    for name in names:
        try:
            estimator = create(name, rate)
        except ParameterError:
            estimator = create(name, RATE_MAX)
        if fast:
            kernels.run(estimator, x, x, x, True)
            kernels.run_many(estimator, side, side, side)
        else:
            estimator.process(x, x, x)


_LOADED = {}


@dataclass(frozen=True)
class RecordingFiles:
    """A picklable pointer to recording files; ``load()`` reads them once per process."""

    paths: tuple
    reference: str = "lvt"
    max_lag_s: float = DEFAULT_MAX_LAG_S
    warm: tuple = ()
    fast: bool = True
    delay_method: str = DEFAULT_METHOD

    def load(self):
        dataset = _LOADED.get(self)
        if dataset is None:
            warm_up(self.warm, fast=self.fast)
            dataset = Dataset(load_takes(self.paths, self.reference), self.max_lag_s, self.fast, self.delay_method)
            _LOADED.clear()
            _LOADED[self] = dataset
        return dataset


@dataclass(frozen=True)
class RawObjectives:
    """The optimiser's objective: ``(name, params) -> eq. 28's vector`` over ``source.load()``'s takes.

    ``source`` is a picklable recipe (``RecordingFiles``, ``simulated.SimulatedSet``); ``share``
    (j, k) limits the vector to the j-th of k contiguous parts of the takes.
    """

    source: object
    share: tuple = (0, 1)

    def __call__(self, name, params):
        return self.source.load().raw_objectives(name, params, self.share)

    def shares(self, k):
        """k objectives whose vectors, joined in order, are this one's (on the whole takes)."""
        return [RawObjectives(self.source, (j, int(k))) for j in range(int(k))]


RECORDING_SUFFIXES = (".npz", ".h5", ".csv")


def _order(path):
    """Sort key: the F_max in a ``fmax_<value>`` file name first (numerically), then the name."""
    stem = path.stem
    if stem.startswith("fmax_"):
        try:
            return (0, float(stem[5:]), path.name)
        except ValueError:
            pass
    return (1, 0.0, path.name)


def expand_paths(items):
    """Recording files from command-line items: files as given, directories by their recordings (by F_max)."""
    paths = []
    for item in items:
        path = Path(item)
        if path.is_dir():
            found = sorted((p for p in path.iterdir() if p.suffix.lower() in RECORDING_SUFFIXES), key=_order)
            if not found:
                raise InputDataError(f"{path}: directory holds no recordings ({', '.join(RECORDING_SUFFIXES)})")
            paths += found
        elif not path.exists():
            raise InputDataError(f"{path}: no such recording file")
        else:
            paths.append(path)
    return [str(p) for p in paths]


def estimator_names(text, default):
    """Names from ``--estimators A,B C`` (comma or space separated), checked; ``default`` when empty."""
    if not text:
        return list(default)
    names = [n for item in text for n in item.replace(",", " ").split()]
    return list(dict.fromkeys(spec(n).name for n in names))
