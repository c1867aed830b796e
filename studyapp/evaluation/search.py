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

Ridge draws (issue 23: the accelerometer Kalman filters still hung on the seed
with restarts). Their good sets lie on a narrow, curved ridge in (log q, log
r_acc), and along it F_g jumps between integer delay patterns: KALMAN's best
sets are a pocket about 0.01-0.03 decade wide and 0.25 long beside a strip of
local minima one delay sample worse (docs/evaluation.md). A box around the
best, shrunk to the strip's width, reaches the pocket with a chance of order
1e-4 per draw. So each lane keeps its elite: the unit points of its sets whose
F_g, as judged, was within ``ELITE * max(|F_best|, 1)`` of the lane's best.
With ``ridge`` f > 0, once the elite holds ``MIN_ELITE`` points, a proposal is
with probability f a ridge draw, along the elite's principal axis u (the
eigenvector of its covariance with the largest eigenvalue, its largest
component positive; principal_axis.py computes it without BLAS or LAPACK, so
the draws are the same bits on every machine):

    x = c + t u + z,   t ~ U(t_min - s/2, t_max + s/2),   z ~ N(0, lambda_min I) less its u part,

where c is the lane's centre, t_min..t_max the elite's extent along u (s its
length, at least ``MIN_RADIUS``) and lambda_min the covariance's smallest
eigenvalue (the ridge's width squared; at least ``MIN_RADIUS`` squared). The
draws cover the stretch of ridge found so far and half as much again at each
end, across it as wide as it is, and a draw beyond the ends that is good
enough extends the elite. (With one tuned parameter they cover the elite's
interval, so extended.) Otherwise the proposal is drawn as above. With
``ridge`` = 0 no draw is spent on it: the search as before, draw for draw.

The search is pure: ``propose()`` draws from its own seeded generator and
``report(params, improved, ...)`` updates it; it never evaluates anything.
"""

import math

import numpy as np

from studyapp.evaluation import principal_axis

START_RADIUS = 0.25
MIN_RADIUS = 1e-4
GROWTH = 1.5
GLOBAL_FRACTION = 0.1
MAX_TRIES = 100  # draws per proposal before giving up on constraints between parameters
ELITE = 0.05  # a lane's elite: its sets within this fraction of its best F_g (or of 1, if larger)
MIN_ELITE = 5  # elite points before ridge draws start
MAX_ELITE = 2000  # the oldest are dropped beyond this


def _reflect(u):
    """Fold coordinates back into [0, 1] (a mirror at each face)."""
    u = np.mod(u, 2.0)
    return np.where(u > 1.0, 2.0 - u, u)


class AdaptiveSearch:
    """Pure adaptive search over one ``Space``, with its own generator seeded by ``seed``."""

    def __init__(self, space, seed, patience, start=None, restarts=0, ridge=0.0):
        self.space = space
        self.patience = max(1, int(patience))
        self.restarts = max(0, int(restarts))
        self.ridge = float(ridge)
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
        self.elite = []  # [unit point..., F_g as judged] of the lane's sets near its best

    def propose(self):
        """A new parameter set (a dict of every parameter of the estimator)."""
        d = len(self.space.dims)
        if d == 0:
            return dict(self.best)
        if self.lane_best is None:  # a restart lane's first set: a point drawn over the whole space
            return self._draw(lambda: self.rng.random(d))
        if self.ridge > 0.0 and len(self.elite) >= MIN_ELITE and self.rng.random() < self.ridge:
            axis = self._axis()  # only for a ridge draw: an eigendecomposition per proposal otherwise
            return self._draw(lambda: self._along(*axis))
        steps = np.array([dim.step for dim in self.space.dims])
        radius = np.maximum(self.radius, steps)

        def near():
            if self.rng.random() < GLOBAL_FRACTION:
                return self.rng.random(d)
            return _reflect(self.centre + self.rng.uniform(-1.0, 1.0, d) * radius)

        return self._draw(near)

    def _axis(self):
        """(u, t_low, t_high, width) of the lane's elite (module docstring), or None while it has too few points."""
        if self.ridge <= 0.0 or len(self.elite) < MIN_ELITE:
            return None
        points = [p[:-1] for p in self.elite]
        u, smallest = principal_axis.principal_axis(points)
        t = principal_axis.projections(points, self.centre, u)
        length = max(float(t.max() - t.min()), MIN_RADIUS)
        width = max(math.sqrt(max(smallest, 0.0)), MIN_RADIUS)
        return np.array(u), float(t.min()) - length / 2.0, float(t.max()) + length / 2.0, width

    def _along(self, u, low, high, width):
        x = self.centre + self.rng.uniform(low, high) * u
        if len(u) > 1:
            z = self.rng.normal(0.0, width, len(u))
            x = x + z - principal_axis.dot(z, u) * u
        return _reflect(x)

    def _draw(self, point):
        for _ in range(MAX_TRIES):
            params = self.space.values(point())
            if self.space.valid(params):
                return params
        return dict(self.best)

    def report(self, params, improved, lane_improved=None, raw=None, value=None, lane_value=None):
        """Tell the search whether ``params`` (its last proposal) improved on the best.

        ``lane_improved``: whether it beat the lane's best (default: ``improved``, which is the
        same thing while the lane's best is the estimator's); ``raw``: its raw objectives, kept
        as the lane's best when that is not the estimator's best; ``value`` and ``lane_value``:
        F_g of ``params`` and of the lane's best under the scale they were judged by (the elite's).
        """
        lane = self.lane
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
        if self.ridge > 0.0 and value is not None and self.lane == lane:
            self._keep(params, float(value), float(value if lane_improved or lane_value is None else lane_value))

    def _keep(self, params, value, best):
        """Add ``params`` to the lane's elite if near ``best`` (the lane's best), and drop what no longer is."""
        limit = best + ELITE * max(abs(best), 1.0)
        self.elite = [e for e in self.elite if e[-1] <= limit]
        if value <= limit:
            self.elite.append([*self.space.unit(params).tolist(), value])
            del self.elite[:-MAX_ELITE]

    def _next_lane(self):
        self.lane += 1
        self.elite = []
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
            "elite": self.elite,
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
        self.elite = [[float(v) for v in e] for e in state.get("elite", [])]
        self.centre = self.space.unit(self.best if self.lane_best is None else self.lane_best)
