"""How each estimator in the loop sounds: its string's audio against the ideal sensor's (paper Sec. 10).

For one estimator and one case (F_max, seed), the closed loop is simulated
twice with ``studyapp.model.simulate``: once with the estimator as the
velocity source, once with ``TRUE`` (the device's true velocity, an ideal
sensor), with the same gesture (``strokes``), F_max, seed (so the same hand,
sensor noise and string) and duration. The estimator's score on the case is
``audio_distance(true_audio, audio, rate)`` (perceptual.py); its
``audio_distance`` is the mean over the cases. The reference sound of each
case is simulated once per process and kept.

Default cases (``Cases()``): F_max = 1, 2.2, 4.4 and 7.7 N (the rating task's
gain, the paper's Sec. 8, and three of its recording gains up to the high-gain
half), seeds 0 and 1, 2 s each (about three and a half strokes) at 5 kHz:
eight pairs of simulations, 16 s of simulated bowing per estimator, about
0.1-0.2 s of computing on one core. Two seeds because one case's score can
differ by 0.1 between seeds at the same F_max; the cases are the same for
every estimator and parameter set, so comparisons between them are paired.

A simulation in which the loop faults (a non-finite value stops it: the force
drops to 0, the bow lifts) scores ``inf`` on its case, so the optimiser never
keeps such a set. A run that the stability monitor flags as broken keeps its
measured distance (it is what one would hear) and is counted in ``broken``.

``perceptual_objective_task(cases, name, params)`` is the optimiser's unit of
work for ``studyapp optimise --objective perceptual``: the one-element raw
objective vector ``[audio_distance]``. With a single objective, F_g (eq. 27)
is an increasing function of it, so a set is kept exactly when its mean
distance falls.
"""

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import spearmanr

from studyapp.errors import ParameterError, UserError
from studyapp.evaluation.perceptual import audio_distance, check_rate, frame_length
from studyapp.model.loop import check_fmax
from studyapp.model.simulate import simulate
from studyapp.model.sources import TRUE, is_pseudo

DEFAULT_FMAX = (1.0, 2.2, 4.4, 7.7)
DEFAULT_SEEDS = (0, 1)
DEFAULT_DURATION = 2.0
DEFAULT_RATE = 5000.0
GESTURE = "strokes"
REFERENCE_SOURCE = TRUE


@dataclass(frozen=True)
class Cases:
    """The simulated cases every estimator is heard on (picklable, hashable)."""

    rate: float = DEFAULT_RATE
    fmax: tuple = DEFAULT_FMAX
    seeds: tuple = DEFAULT_SEEDS
    duration: float = DEFAULT_DURATION
    gesture: str = GESTURE

    def __post_init__(self):
        object.__setattr__(self, "rate", check_rate(self.rate))
        object.__setattr__(self, "fmax", tuple(check_fmax(f) for f in self.fmax))
        object.__setattr__(self, "seeds", tuple(_seed(s) for s in self.seeds))
        if not self.fmax:
            raise ParameterError("fmax: allowed is at least one F_max value")
        if not self.seeds:
            raise ParameterError("seeds: allowed is at least one seed")
        try:
            duration = float(self.duration)
        except (TypeError, ValueError):
            duration = float("nan")
        shortest = frame_length(self.rate) / self.rate
        if not (math.isfinite(duration) and duration >= shortest):
            raise ParameterError(f"duration = {self.duration!r}: allowed is a number of seconds of at least "
                                 f"{shortest:g} (one analysis frame)")
        object.__setattr__(self, "duration", duration)

    def pairs(self):
        return [(f, s) for f in self.fmax for s in self.seeds]

    def describe(self):
        return {**asdict(self), "fmax": list(self.fmax), "seeds": list(self.seeds), "reference": REFERENCE_SOURCE}

    def simulate(self, source, fmax, seed, params=None):
        estimators = {} if is_pseudo(source) else {source: dict(params or {})}
        return simulate(fmax, rate=self.rate, duration=self.duration, source=source, gesture=self.gesture,
                        seed=seed, estimators=estimators)

    def reference(self, fmax, seed):
        """The ideal sensor's audio for one case (simulated once per process)."""
        key = (self, fmax, seed)
        audio = _REFERENCES.get(key)
        if audio is None:
            recording = self.simulate(REFERENCE_SOURCE, fmax, seed)
            if recording.meta["fault"]:
                raise UserError(f"perceptual reference (TRUE at F_max {fmax:g} N, seed {seed}) faulted: "
                                f"{recording.meta['fault']}")
            audio = _REFERENCES[key] = recording["audio"]
        return audio

    def score(self, name, params, fmax, seed):
        """One case: {fmax, seed, audio_distance, broken, fault}."""
        reference = self.reference(fmax, seed)
        recording = self.simulate(name, fmax, seed, params)
        fault = recording.meta["fault"]
        distance = float("inf") if fault else audio_distance(reference, recording["audio"], self.rate)
        return {"fmax": fmax, "seed": seed, "audio_distance": distance, "broken": bool(recording.meta["broken"]),
                "fault": fault}


_REFERENCES = {}


def _seed(value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ParameterError(f"seed = {value!r}: allowed is an integer of at least 0")
    return int(value)


def estimator_score(cases, name, params):
    """{audio_distance: mean over the cases (inf if any faulted), cases: [...], broken: count}."""
    rows = [cases.score(name, params, f, s) for f, s in cases.pairs()]
    distances = np.array([r["audio_distance"] for r in rows])
    return {
        "audio_distance": float(np.mean(distances)) if np.all(np.isfinite(distances)) else float("inf"),
        "broken": sum(r["broken"] for r in rows),
        "cases": rows,
    }


def perceptual_scores(names, params, rate=DEFAULT_RATE, fmax_values=DEFAULT_FMAX, seeds=DEFAULT_SEEDS,
                      duration=DEFAULT_DURATION, progress=None):
    """name -> ``estimator_score`` for each estimator in ``names`` (``params``: name -> parameters, {} = Table 1).

    ``progress(done, total, name)`` is called before each estimator.
    """
    cases = Cases(rate, tuple(fmax_values), tuple(seeds), duration)
    scores = {}
    for i, name in enumerate(names):
        if progress is not None:
            progress(i, len(names), name)
        scores[name] = estimator_score(cases, name, params.get(name, {}))
    if progress is not None:
        progress(len(names), len(names), None)
    return scores


def perceptual_objective_task(cases, name, params):
    """The optimiser's unit of work: [audio_distance] of one parameter set."""
    return np.array([estimator_score(cases, name, params)["audio_distance"]])


def warm_up(cases, names):
    """Load (or compile) the closed loop and each estimator's kernel in this process, on a few samples."""
    short = frame_length(cases.rate) / cases.rate
    for name in (REFERENCE_SOURCE, *names):
        estimators = {} if is_pseudo(name) else {name: {}}
        simulate(cases.fmax[0], rate=cases.rate, duration=short, source=name, gesture=cases.gesture,
                 seed=cases.seeds[0], estimators=estimators)


def spearman(distances, values):
    """Spearman's rank correlation between name -> audio_distance and name -> another measure.

    Over the names where both are finite: {rho, p, n} (rho and p None below 3 names).
    """
    names = [n for n in distances if np.isfinite(distances[n]) and np.isfinite(values.get(n, np.nan))]
    if len(names) < 3:
        return {"rho": None, "p": None, "n": len(names)}
    result = spearmanr([distances[n] for n in names], [values[n] for n in names])
    rho, p = float(result.statistic), float(result.pvalue)
    return {"rho": rho if np.isfinite(rho) else None, "p": p if np.isfinite(p) else None, "n": len(names)}
