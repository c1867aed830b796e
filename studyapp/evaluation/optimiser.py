"""The objective-sum optimiser (paper Sec. 6.3, steps 1-8, Fig. 3).

Every estimator is tuned by its own ``AdaptiveSearch``; all are tied together
by one ``ObjectiveSum``, whose scale comes from the best and worst estimator.
One iteration:

1. every estimator still searching proposes a new parameter set (step 6);
2. the sets are evaluated on all recordings, in parallel, by an executor
   (step 7): eq. 28's raw objectives [E_0, D_0, ...] of each set;
3. the objective sum accepts or rejects each candidate under the memorised
   scale and memorises a new scale if any estimator improved (step 8);
4. an estimator stops searching once ``patience`` new sets in a row brought no
   improvement; the run ends when none is left (the paper's rule, 1000).

With ``restarts`` the searches run in lanes (``search.py``); a lane whose best
is not the estimator's is judged here, against its own best under the same
memorised scale as the step's decisions. Each search is also told the F_g of
its candidate and of its lane's best under that scale, for its ridge draws.

Work is sent to the executor in few, large tasks: an iteration's sets go out
together, one task per worker (``executors.parallelism``). An objective that
can be split by recordings (``shares(k)``, ``dataset.RawObjectives``) gives
every worker an equal part of the recordings of every set, so all workers stay
busy even when a single estimator is still searching; any other objective
(``objective(name, params)`` alone) has its sets dealt to the workers,
slowest first.

Iterations are synchronous and each estimator draws from its own generator
(seeded from the run's seed and its name), so a run is reproducible whatever
the number of workers and whether it was resumed from a checkpoint. An
estimator's objectives depend only on its parameters, so a repeated set (an
integer-only space revisits points) is taken from a cache instead of being run
again; it still counts as a new set for the stopping rule.
"""

import time
import zlib
from dataclasses import dataclass, field

import numpy as np

from studyapp.errors import UserError
from studyapp.evaluation import checkpoint as checkpoints
from studyapp.evaluation.executors import parallelism
from studyapp.evaluation.normalisation import ObjectiveSum
from studyapp.evaluation.search import AdaptiveSearch


TOLERANCE = 1e-4  # per objective, in units of the spread across estimators


def estimator_seed(seed, name):
    """Independent generator seed per estimator (stable across runs and Python versions)."""
    return [int(seed), zlib.crc32(name.encode("utf-8"))]


def evaluate_sets(objective, sets):
    """The executor's unit of work: ``[(objective(name, params), seconds it took)]`` for each (name, params)."""
    results = []
    for name, params in sets:
        started = time.perf_counter()
        raw = np.asarray(objective(name, params), dtype=np.float64)
        results.append((raw, time.perf_counter() - started))
    return results


def _deal(names, durations, bins):
    """Names dealt to ``bins`` lists, slowest first each to the least loaded (longest processing time first)."""
    loads = [0.0] * bins
    dealt = [[] for _ in range(bins)]
    for name in sorted(names, key=lambda n: -durations.get(n, 0.0)):
        least = loads.index(min(loads))
        dealt[least].append(name)
        loads[least] += durations.get(name, 0.0)
    return [d for d in dealt if d]


def _key(params):
    return tuple(sorted((k, repr(v)) for k, v in params.items()))


@dataclass
class Result:
    """The tuned parameters and how they were found."""

    params: dict  # name -> parameters of the retained set
    objectives: dict  # name -> F_g under the final memorised scale
    raw: dict  # name -> raw objectives [E_0, D_0, ...] of the retained set
    iterations: int
    evaluated: int  # parameter sets run (cache hits not counted)
    sets: dict  # name -> parameter sets proposed (with repeats)
    seconds: float
    resumed: bool = False
    scale: dict = field(default_factory=dict)  # memorised offsets and scales


class Optimiser:
    """Tune several estimators together.

    ``spaces``: name -> ``Space``; ``objective(name, params) -> raw vector`` is a
    picklable callable run by ``executor`` (an object with ``submit``; it may
    be set later, before ``run``); it may offer ``shares(k)`` (see the module
    docstring).
    ``tolerance`` is the least fall of F_g that counts as an improvement (the
    default, ``TOLERANCE`` per objective, is far below any difference that
    matters; without it, ever smaller gains from zooming in on a continuous
    optimum would keep postponing the stopping rule).
    ``fingerprint`` (a JSON-able dict) identifies the run for checkpoints.
    ``starts``: name -> the first parameter set of that estimator (default its
    space's start, Table 1); ``studyapp tradeoff`` starts from Table 1 made
    for the rate (windows kept in seconds).
    ``restarts``: lanes of each search that start from drawn points (``search.py``; 0: none,
    the search as it was before restarts, draw for draw).
    ``ridge``: the share of proposals drawn along the lane's elite (``search.py``; 0: none, the
    search as it was before ridge draws, draw for draw).
    """

    def __init__(self, spaces, objective, executor, patience=1000, seed=0, tolerance=None,
                 max_sets=None, checkpoint=None, checkpoint_interval=30.0, progress=None, fingerprint=None,
                 starts=None, restarts=0, ridge=0.0):
        if not spaces:
            raise UserError("no estimators to optimise")
        self.spaces = dict(spaces)
        self.objective = objective
        self.executor = executor
        self.patience = int(patience)
        if self.patience < 1:
            raise UserError(f"--patience {patience}: allowed is an integer of at least 1")
        self.seed = int(seed)
        self.restarts = int(restarts)
        if self.restarts < 0:
            raise UserError(f"--restarts {restarts}: allowed is an integer of at least 0")
        self.ridge = float(ridge)
        if not 0.0 <= self.ridge <= 1.0:
            raise UserError(f"--ridge {ridge}: allowed is a fraction from 0 to 1")
        self.tolerance = tolerance
        self.max_sets = None if max_sets is None else int(max_sets)
        if self.max_sets is not None and self.max_sets < 1:
            raise UserError(f"--max-sets {max_sets}: allowed is an integer of at least 1")
        self.checkpoint = checkpoint
        self.checkpoint_interval = float(checkpoint_interval)
        self.progress = progress
        starts = dict(starts or {})
        self.fingerprint = {
            "seed": self.seed, "patience": self.patience, "max_sets": self.max_sets, "restarts": self.restarts,
            **({"ridge": self.ridge} if self.ridge else {}),
            "spaces": {name: space.describe() for name, space in self.spaces.items()},
            **({"starts": starts} if starts else {}),
            **(fingerprint or {}),
        }
        self.searches = {
            name: AdaptiveSearch(space, estimator_seed(self.seed, name), self.patience, starts.get(name),
                                 self.restarts, self.ridge)
            for name, space in self.spaces.items()
        }
        self.sum = None
        self.cache = {name: {} for name in self.spaces}
        self.durations = {}  # name -> seconds of its last evaluation
        self.evaluated = 0
        self.seconds = 0.0
        self.resumed = False
        self._snapshot = None

    # -- evaluation ----------------------------------------------------------------
    def _evaluate(self, proposals):
        """Raw objectives of name -> params, from the cache or the executor (one task per worker)."""
        raws = {}
        missing = []
        for name, params in proposals.items():
            hit = self.cache[name].get(_key(params))
            if hit is not None:
                raws[name] = hit
            else:
                missing.append(name)
        workers = parallelism(self.executor)
        if missing and workers > 1 and hasattr(self.objective, "shares"):
            sets = [(name, proposals[name]) for name in missing]
            futures = [self.executor.submit(evaluate_sets, part, sets) for part in self.objective.shares(workers)]
            parts = [future.result() for future in futures]
            results = {name: (np.concatenate([part[i][0] for part in parts]), sum(part[i][1] for part in parts))
                       for i, name in enumerate(missing)}
        elif missing:
            dealt = _deal(missing, self.durations, workers)
            futures = [self.executor.submit(evaluate_sets, self.objective, [(n, proposals[n]) for n in names])
                       for names in dealt]
            results = {}
            for names, future in zip(dealt, futures):
                results.update(zip(names, future.result()))
        for name in missing:
            raw, seconds = results[name]
            self.durations[name] = seconds
            self.cache[name][_key(proposals[name])] = raw
            raws[name] = raw
            self.evaluated += 1
        return {name: raws[name] for name in proposals}

    def _judged(self, raws):
        """name -> (F_g of its candidate, F_g of its search's lane best) under the scale in force, as
        the step's decisions are; the lane's best is the estimator's unless a restart lane has its own."""
        judged = {}
        for name, raw in raws.items():
            lane_raw = self.searches[name].lane_raw
            judged[name] = (self.sum.objective(raw),
                            self.sum.objective(self.sum.best[name] if lane_raw is None else lane_raw))
        return judged

    def _active(self):
        return [name for name, s in self.searches.items()
                if not s.done and (self.max_sets is None or s.sets < self.max_sets)]

    # -- checkpoints ------------------------------------------------------------------
    def state(self):
        return {
            "fingerprint": self.fingerprint,
            "sum": self.sum.state(),
            "searches": {name: s.state() for name, s in self.searches.items()},
            "evaluated": self.evaluated,
            "seconds": self.seconds,
        }

    def _save(self):
        """Write the state as of the last completed iteration (never a half-done one)."""
        if self.checkpoint is not None and self._snapshot is not None:
            checkpoints.write(self.checkpoint, self._snapshot)

    def resume(self, path):
        """Continue from the checkpoint at ``path`` (made by a run with the same fingerprint)."""
        state = checkpoints.read(path)
        saved = state.get("fingerprint")
        if saved != _jsonable(self.fingerprint):
            differ = sorted(k for k in set(saved or {}) | set(self.fingerprint)
                            if (saved or {}).get(k) != _jsonable(self.fingerprint).get(k))
            raise UserError(f"{path}: checkpoint of a different run (differs in: {', '.join(differ)})")
        self.sum = ObjectiveSum.from_state(state["sum"])
        for name, s in self.searches.items():
            s.restore(state["searches"][name])
        self.evaluated = int(state["evaluated"])
        self.seconds = float(state["seconds"])
        self.resumed = True
        self._snapshot = self.state()

    # -- the procedure ------------------------------------------------------------------
    def run(self):
        started = time.monotonic() - self.seconds
        last_save = time.monotonic()
        names = list(self.spaces)
        if self.sum is None:
            # Steps 1-4: a first set per estimator (the spec's defaults, Table 1), b_0 = 0.
            first = {name: self.searches[name].best for name in names}
            raws = self._evaluate(first)
            j = len(next(iter(raws.values())))
            tolerance = TOLERANCE * j if self.tolerance is None else float(self.tolerance)
            self.sum = ObjectiveSum(tolerance)
            self.sum.start(raws)
            self.seconds = time.monotonic() - started
            self._snapshot = self.state()
        try:
            while True:
                active = self._active()
                if not active:
                    break
                # Steps 5-8.
                proposals = {name: self.searches[name].propose() for name in active}
                raws = self._evaluate(proposals)
                judged = self._judged(raws)
                decisions = self.sum.step(raws)
                for name in active:
                    accepted = decisions[name].accepted
                    value, lane_value = judged[name]
                    own_lane = self.searches[name].lane_raw is not None
                    lane_improved = accepted or (own_lane and bool(value < lane_value - self.sum.tolerance))
                    self.searches[name].report(proposals[name], accepted, lane_improved, raws[name],
                                               value, lane_value)
                self.seconds = time.monotonic() - started
                self._snapshot = self.state()
                self._report(final=False)
                if self.checkpoint is not None and time.monotonic() - last_save >= self.checkpoint_interval:
                    self._save()
                    last_save = time.monotonic()
        except KeyboardInterrupt:
            self._save()
            raise
        self.seconds = time.monotonic() - started
        self._save()
        self._report(final=True)
        return Result(
            params={name: dict(self.searches[name].best) for name in names},
            objectives=self.sum.objectives(),
            raw={name: self.sum.best[name].tolist() for name in names},
            iterations=self.sum.iteration,
            evaluated=self.evaluated,
            sets={name: self.searches[name].sets for name in names},
            seconds=self.seconds,
            resumed=self.resumed,
            scale={"offsets": self.sum.offsets.tolist(), "scales": self.sum.scales.tolist()},
        )

    def _report(self, final):
        if self.progress is None:
            return
        done = {name for name in self.spaces if name not in self._active()}
        waiting = {name: s.since_improvement for name, s in self.searches.items()}
        self.progress(self.sum.iteration, self.evaluated, self.sum.objectives(), done, final=final, waiting=waiting)


def _jsonable(value):
    """``value`` as it reads back from JSON (tuples become lists, keys strings)."""
    import json

    return json.loads(json.dumps(value))
