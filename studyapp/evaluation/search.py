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

The search is pure: ``propose()`` draws from its own seeded generator and
``report(improved)`` updates it; it never evaluates anything.
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

    def __init__(self, space, seed, patience, start=None):
        self.space = space
        self.patience = max(1, int(patience))
        self.rng = np.random.default_rng(seed)
        self.best = dict(space.start if start is None else start)
        self.centre = space.unit(self.best)
        self.radius = START_RADIUS
        self.shrink = (MIN_RADIUS / START_RADIUS) ** (1.0 / max(1.0, self.patience / 2.0))
        self.sets = 0  # parameter sets proposed after the first
        self.since_improvement = 0

    def propose(self):
        """A new parameter set (a dict of every parameter of the estimator)."""
        d = len(self.space.dims)
        if d == 0:
            return dict(self.best)
        steps = np.array([dim.step for dim in self.space.dims])
        radius = np.maximum(self.radius, steps)
        for _ in range(MAX_TRIES):
            if self.rng.random() < GLOBAL_FRACTION:
                u = self.rng.random(d)
            else:
                u = _reflect(self.centre + self.rng.uniform(-1.0, 1.0, d) * radius)
            params = self.space.values(u)
            if self.space.valid(params):
                return params
        return dict(self.best)

    def report(self, params, improved):
        """Tell the search whether ``params`` (its last proposal) improved on the best."""
        self.sets += 1
        if improved:
            self.best = dict(params)
            self.centre = self.space.unit(params)
            self.radius = min(1.0, self.radius * GROWTH)
            self.since_improvement = 0
        else:
            self.radius = max(MIN_RADIUS, self.radius * self.shrink)
            self.since_improvement += 1

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
        }

    def restore(self, state):
        self.rng.bit_generator.state = state["rng"]
        self.best = dict(state["best"])
        self.centre = self.space.unit(self.best)
        self.radius = float(state["radius"])
        self.sets = int(state["sets"])
        self.since_improvement = int(state["since_improvement"])
