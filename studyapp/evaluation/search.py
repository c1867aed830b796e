"""Pure adaptive search for one estimator (paper Sec. 6.3.3, after Patel, Smith and Zabinsky).

A model-free stochastic sampler that "zooms in": each new parameter set is
drawn around the best point found so far, in the unit cube of the estimator's
``Space`` (each parameter in its natural scale), from a box of half-width
``radius``; coordinates that leave the cube are reflected back in. With
probability ``GLOBAL_FRACTION`` the set is drawn uniformly from the whole
space instead, so the search keeps sampling everywhere and cannot be trapped
for ever by a local minimum of the noisy, non-convex objective.

The radius starts at ``START_RADIUS``, grows by ``GROWTH`` after an improvement
and shrinks after every failure by the factor that takes it from the start to
``MIN_RADIUS`` in ``patience / 2`` failures: the zoom speed follows the one
stopping rule (no improvement in ``patience`` new sets), so the search has no
other hyper-parameter to tune, in the paper's spirit. The box never gets
narrower than one step of an integer parameter, so its neighbours stay in
reach (a draw that rounds back to the same integer leaves it unchanged).

Restarts (issue 23: the result should not hang on the seed). Zooming in
follows one basin; which basin depends on the draws (two seeds put KALMAN's q
six decades apart, one 1.14 worse in F_g). With ``restarts`` R > 0 the search
runs in lanes, one after the other: lane 0 zooms in from the start (Table 1),
lanes 1 .. R from points drawn uniformly over the space, and a last lane zooms
in again from the best set found by any lane (a polish). A lane keeps its own
best and centre: a candidate moves the lane when it beats the lane's best
(``report(..., lane_improved)``; the optimiser judges it under the memorised
scale), and becomes the estimator's best only when it beats that. A lane ends
when its radius has shrunk to ``MIN_RADIUS``, after L = ``patience / (R + 2)``
failures in a row, or, while its best is not the estimator's, after L sets;
the last lane then stays at that radius. The stopping rule is unchanged
(``patience`` new sets in a row without improving the estimator's best), and
all R + 2 lanes fit in one patience: the restarts share its budget, so a run
costs about as many sets as without them. With R = 0 there is one
lane, whose radius reaches ``MIN_RADIUS`` after ``patience / 2`` failures:
the search without restarts, draw for draw.

The search is pure: ``propose()`` draws from its own seeded generator and
``report(params, improved, ...)`` updates it; it never evaluates anything.
"""

import numpy as np

START_RADIUS = 0.25
MIN_RADIUS = 1e-4
GROWTH = 1.5
GLOBAL_FRACTION = 0.1
MAX_TRIES = 100  # draws per proposal before giving up on constraints between parameters


def _reflect(u):
    """Fold coordinates back into [0, 1] (a mirror at each face)."""
    u = np.mod(u, 2.0)
    return np.where(u > 1.0, 2.0 - u, u)


class AdaptiveSearch:
    """Pure adaptive search over one ``Space``, with its own generator seeded by ``seed``."""

    def __init__(self, space, seed, patience, start=None, restarts=0):
        self.space = space
        self.patience = max(1, int(patience))
        self.restarts = max(0, int(restarts))
        self.rng = np.random.default_rng(seed)
        self.best = dict(space.start if start is None else start)
        self.radius = START_RADIUS
        self.lane_length = max(1.0, self.patience / (self.restarts + 2.0))  # failures until the radius is MIN
        self.shrink = (MIN_RADIUS / START_RADIUS) ** (1.0 / self.lane_length)
        self.sets = 0  # parameter sets proposed after the first
        self.since_improvement = 0
        self.lane = 0  # 0 from the start, 1 .. restarts from a drawn point, restarts + 1 the polish
        self.lane_best = dict(self.best)  # None until a restart lane's first set is reported
        self.lane_raw = None  # raw objectives of lane_best; None while it is the estimator's best
        self.lane_failures = 0
        self.lane_sets = 0
        self.centre = space.unit(self.best)

    def propose(self):
        """A new parameter set (a dict of every parameter of the estimator)."""
        d = len(self.space.dims)
        if d == 0:
            return dict(self.best)
        if self.lane_best is None:  # a restart lane's first set: a point drawn over the whole space
            return self._draw(lambda: self.rng.random(d))
        steps = np.array([dim.step for dim in self.space.dims])
        radius = np.maximum(self.radius, steps)

        def near():
            if self.rng.random() < GLOBAL_FRACTION:
                return self.rng.random(d)
            return _reflect(self.centre + self.rng.uniform(-1.0, 1.0, d) * radius)

        return self._draw(near)

    def _draw(self, point):
        for _ in range(MAX_TRIES):
            params = self.space.values(point())
            if self.space.valid(params):
                return params
        return dict(self.best)

    def report(self, params, improved, lane_improved=None, raw=None):
        """Tell the search whether ``params`` (its last proposal) improved on the best.

        ``lane_improved``: whether it beat the lane's best (default: ``improved``, which is the
        same thing while the lane's best is the estimator's); ``raw``: its raw objectives, kept
        as the lane's best when that is not the estimator's best.
        """
        self.sets += 1
        self.lane_sets += 1
        if lane_improved is None:
            lane_improved = improved
        if improved:
            self.best = dict(params)
            self.since_improvement = 0
        else:
            self.since_improvement += 1
        if self.lane_best is None or lane_improved:
            first = self.lane_best is None
            self.lane_best = dict(params)
            self.lane_raw = None if improved else [float(r) for r in raw]
            self.centre = self.space.unit(params)
            if not first:
                self.radius = min(1.0, self.radius * GROWTH)
            self.lane_failures = 0
        else:
            self.radius = max(MIN_RADIUS, self.radius * self.shrink)
            self.lane_failures += 1
        ended = self.lane_failures >= self.lane_length or (
            self.lane_raw is not None and self.lane_sets >= self.lane_length)
        if self.restarts and self.lane <= self.restarts and ended:
            self._next_lane()

    def _next_lane(self):
        self.lane += 1
        self.radius = START_RADIUS
        self.lane_failures = 0
        self.lane_sets = 0
        if self.lane <= self.restarts:
            self.lane_best = None
            self.lane_raw = None
        else:  # the polish: zoom in again from the estimator's best
            self.lane_best = dict(self.best)
            self.lane_raw = None
            self.centre = self.space.unit(self.best)

    @property
    def done(self):
        """True once ``patience`` new sets in a row brought no improvement (the paper's stopping rule)."""
        return self.since_improvement >= self.patience

    def state(self):
        return {
            "rng": self.rng.bit_generator.state,
            "best": self.best,
            "radius": self.radius,
            "sets": self.sets,
            "since_improvement": self.since_improvement,
            "lane": self.lane,
            "lane_best": self.lane_best,
            "lane_raw": self.lane_raw,
            "lane_failures": self.lane_failures,
            "lane_sets": self.lane_sets,
        }

    def restore(self, state):
        self.rng.bit_generator.state = state["rng"]
        self.best = dict(state["best"])
        self.radius = float(state["radius"])
        self.sets = int(state["sets"])
        self.since_improvement = int(state["since_improvement"])
        self.lane = int(state.get("lane", 0))
        lane_best = state.get("lane_best", self.best)
        self.lane_best = None if lane_best is None else dict(lane_best)
        self.lane_raw = state.get("lane_raw")
        self.lane_failures = int(state.get("lane_failures", 0))
        self.lane_sets = int(state.get("lane_sets", 0))
        self.centre = self.space.unit(self.best if self.lane_best is None else self.lane_best)
