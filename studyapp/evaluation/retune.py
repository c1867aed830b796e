"""Re-tuning every estimator at one sample rate, so that each rate's comparison is fair.

Table 1 was tuned at 5 kHz. At another rate an estimator's best setting moves:
a window counted in samples spans another duration, a Kalman filter's
covariances are per sample, a cut-off sits elsewhere below Nyquist. Comparing
Table 1 across rates therefore compares settings, not estimators. ``retune``
runs the paper's optimiser (objective sum with adaptive normalisation and pure
adaptive search, Sec. 6.3, ``optimiser.py``) on a data set simulated at the
rate, with the estimators evaluated there, and returns its ``Result``.

- Start: each estimator's parameters as the trade uses them untuned, that is
  Table 1 made for the rate (``tradeoff.params_at_rate``: windows keep their
  duration unless ``windows="samples"``).
- Search space: the paper's tuned parameters (Table 2) within the ranges the
  estimators allow at the rate (cut-offs below 0.49 x rate). The narrowed
  window ranges of ``space.SEARCH_RANGES`` (FOAW's sizes 2-64 samples, set at the
  paper's 5 kHz) keep their duration too: their upper end scales with
  rate / 5 kHz, within the estimator's own range.
- Stopping rule: ``patience`` new sets in a row without improvement. The paper
  used 1000; ``studyapp tradeoff --tune`` defaults to a short run (its
  ``DEFAULT_PATIENCE``), enough to move every estimator off Table 1 towards
  the rate's optimum in a few minutes.
"""

from studyapp.estimators.at_rate import TABLE1_RATE  # SEARCH_RANGES were set at it too
from studyapp.estimators.registry import spec
from studyapp.evaluation.dataset import RawObjectives
from studyapp.evaluation.optimiser import Optimiser
from studyapp.evaluation.space import SEARCH_RANGES, Space



def search_spaces(names, rate, windows="seconds"):
    """name -> ``Space`` at ``rate`` (narrowed window ranges scaled with the rate when windows keep seconds)."""
    spaces = {}
    for name in names:
        s = spec(name)
        ranges = {}
        if windows == "seconds":
            narrowed = SEARCH_RANGES.get(s.name, {})
            for p in s.params:
                if p.name in narrowed and p.kind == "int" and p.unit == "samples":
                    low, high = narrowed[p.name]
                    ranges[p.name] = (low, min(p.high_at(rate), max(low, round(high * rate / TABLE1_RATE))))
        spaces[name] = Space(name, rate, "paper", ranges=ranges)
    return spaces


def retune(source, starts, rate, executor, patience, seed=0, windows="seconds", progress=None):
    """Tune the estimators of ``starts`` (name -> first parameter set) on ``source.load()`` at ``rate``."""
    optimiser = Optimiser(
        search_spaces(list(starts), rate, windows), RawObjectives(source), executor,
        patience=patience, seed=seed, progress=progress, starts=starts,
    )
    return optimiser.run()
